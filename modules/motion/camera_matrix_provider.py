"""CameraMatrixProvider: where both cameras are, from joint angles and the torso's tilt."""

from __future__ import annotations

from tafel.core import Module, provides, requires
from tafel.modules.motion.kinematics import CAMERA_LINKS, angles_by_name, camera_pose_in_torso, link_poses, robot_frame_from_torso
from tafel.representations.motion import CameraMatrixBottom, CameraMatrixTop, InertialModel, JointSensorData, TorsoPose
from tafel.representations.nao import BOTTOM_CAMERA, TOP_CAMERA


@requires(JointSensorData, InertialModel)
@provides(CameraMatrixTop, CameraMatrixBottom, TorsoPose)
class CameraMatrixProvider(Module):
    """Forward kinematics: the torso placed over the lower foot and tilted as the IMU says, then the
    head joints and the camera mounts of the reference figures."""

    joint_sensor_data: JointSensorData
    inertial_model: InertialModel
    camera_matrix_top: CameraMatrixTop
    camera_matrix_bottom: CameraMatrixBottom
    torso_pose: TorsoPose

    def execute(self) -> None:
        poses = link_poses(angles_by_name(self.joint_sensor_data.position), CAMERA_LINKS)
        torso = robot_frame_from_torso(poses, self.inertial_model.roll, self.inertial_model.pitch)
        self.torso_pose.rotation = torso[:3, :3].copy()
        self.torso_pose.translation = torso[:3, 3].copy()
        for mount, matrix in ((TOP_CAMERA, self.camera_matrix_top), (BOTTOM_CAMERA, self.camera_matrix_bottom)):
            camera = torso @ camera_pose_in_torso(poses, mount)
            matrix.rotation = camera[:3, :3].copy()
            matrix.translation = camera[:3, 3].copy()
            matrix.valid = True
