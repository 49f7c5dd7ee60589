"""InertialFilter: a smoothed view of the IMU for everything downstream."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tafel.core import Module, provides, requires
from tafel.representations.motion import InertialModel, InertialSensorData


@requires(InertialSensorData)
@provides(InertialModel)
class InertialFilter(Module):
    """Low-pass filters the IMU. The torso angles come from the IMU's own fusion (the NAO's board and
    the simulators both deliver them); filtering them takes out sensor noise, not motion."""

    inertial_sensor_data: InertialSensorData
    inertial_model: InertialModel

    @dataclass
    class Parameters:
        angle_smoothing: float = 0.5
        """0..1, weight of the previous angle estimate per frame (0: raw)"""
        rate_smoothing: float = 0.3
        """0..1, weight of the previous gyroscope and accelerometer values per frame"""

    parameters: Parameters

    def __init__(self) -> None:
        self.started = False

    def execute(self) -> None:
        p, imu, model = self.parameters, self.inertial_sensor_data, self.inertial_model
        roll, pitch = float(imu.angles[0]), float(imu.angles[1])
        if not self.started:
            self.started = True
            model.roll, model.pitch = roll, pitch
            model.gyroscope = np.array(imu.gyroscope, dtype=float)
            model.accelerometer = np.array(imu.accelerometer, dtype=float)
            return
        a, b = p.angle_smoothing, p.rate_smoothing
        model.roll = a * model.roll + (1 - a) * roll
        model.pitch = a * model.pitch + (1 - a) * pitch
        model.gyroscope = b * model.gyroscope + (1 - b) * np.asarray(imu.gyroscope)
        model.accelerometer = b * model.accelerometer + (1 - b) * np.asarray(imu.accelerometer)
