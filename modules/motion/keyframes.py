"""Keyframe motions as data: reading, checking and mirroring ``config/motions/*.toml`` (no module here).

A motion file holds keyframes; each says where the joints go (by name, rad), how long getting there
takes (s), and with what stiffness (one number for all joints, or a table by joint name). Joints a
keyframe does not name keep their previous value; before the first keyframe, that is where the joints
are when the motion starts. ``mirror = "kick_left"`` makes a motion the left-right mirror of another;
``then = "getup_sitting"`` plays another motion's keyframes after this one's (the get-ups share their end).
``abort_if_tilted = 0.9`` on a keyframe stops the motion when that keyframe begins with the torso tilted
more than 0.9 rad (roll or pitch): a get-up that has gone wrong starts again from how the robot lies.

    description = "kick with the left foot"
    [[keyframes]]
    duration = 0.5
    stiffness = 0.9
    joints = { LHipRoll = 0.12, RHipRoll = 0.12, LAnkleRoll = -0.12, RAnkleRoll = -0.12 }
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from tafel.representations.motion import JOINT_COUNT, JOINT_INDEX, JOINT_NAMES
from tafel.representations.nao import JOINTS_BY_NAME

#: the motions shipped with the package (config/motions, beside the modules folder)
SHIPPED_MOTIONS = Path(__file__).resolve().parents[2] / "config" / "motions"
#: joints whose angle changes sign in a mirror image (rotations about x and z)
MIRROR_NEGATED = ("HeadYaw", "ShoulderRoll", "ElbowYaw", "ElbowRoll", "WristYaw", "HipRoll", "AnkleRoll")


class MotionFileError(ValueError):
    """A motion file that cannot be played; the message names the file and what is wrong."""


@dataclass
class Keyframe:
    duration: float  # s from the previous keyframe
    targets: dict[int, float]  # joint index -> rad
    stiffness: np.ndarray = field(default_factory=lambda: np.ones(JOINT_COUNT))
    #: rad of torso tilt beyond which the motion stops when this keyframe begins (None: never)
    abort_if_tilted: float | None = None


@dataclass
class KeyframeMotion:
    name: str
    description: str
    keyframes: list[Keyframe]
    #: the head follows the motion (get-up, falls); otherwise the head motion keeps it
    moves_head: bool = False

    @property
    def duration(self) -> float:
        return sum(k.duration for k in self.keyframes)

    def keyframe_at(self, time_s: float) -> int:
        """The index of the keyframe playing ``time_s`` into the motion (the last one after the end)."""
        elapsed = 0.0
        for index, keyframe in enumerate(self.keyframes):
            elapsed += keyframe.duration
            if time_s < elapsed:
                return index
        return len(self.keyframes) - 1

    def at(self, time_s: float, start: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(positions, stiffness) ``time_s`` into the motion that began at the joint positions ``start``."""
        previous = np.array(start, dtype=float)
        elapsed = 0.0
        for keyframe in self.keyframes:
            target = previous.copy()
            for index, angle in keyframe.targets.items():
                target[index] = angle
            if time_s < elapsed + keyframe.duration:
                share = (time_s - elapsed) / keyframe.duration
                blend = 0.5 - 0.5 * math.cos(math.pi * share)
                return previous + (target - previous) * blend, keyframe.stiffness
            elapsed += keyframe.duration
            previous = target
        return previous, self.keyframes[-1].stiffness


def motions_folder(folder: str = "") -> Path:
    """The folder of motion files: ``folder`` if given, else the shipped ``config/motions``."""
    return Path(folder) if folder else SHIPPED_MOTIONS


def read_motion_file(path: Path) -> dict[str, Any]:
    """The TOML of a motion file, or a ``MotionFileError`` that says what is wrong with it."""
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        known = sorted(p.stem for p in path.parent.glob("*.toml"))
        raise MotionFileError(f"no motion file {path}; the motions are {', '.join(known) or 'none'}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise MotionFileError(f"{path}: not valid TOML: {exc}") from None
    except OSError as exc:
        raise MotionFileError(f"{path}: cannot read it ({exc.strerror or exc})") from None


def load_motion(name: str, folder: str = "", _loading: tuple[str, ...] = ()) -> KeyframeMotion:
    """Read and check ``NAME.toml``; mirrored motions are built from their original, ``then`` is appended."""
    path = motions_folder(folder) / f"{name}.toml"
    if name in _loading:
        raise MotionFileError(f"{path}: motions refer to each other in a circle: {' -> '.join([*_loading, name])}")
    _loading = (*_loading, name)
    data = read_motion_file(path)
    if "mirror" in data:
        original = load_motion(str(data["mirror"]), folder, _loading)
        return KeyframeMotion(name, str(data.get("description", f"{original.description}, mirrored")),
                              [_mirrored(k) for k in original.keyframes], original.moves_head)
    frames = data.get("keyframes")
    if not isinstance(frames, list) or not frames:
        raise MotionFileError(f"{path}: needs at least one [[keyframes]] table with duration and joints")
    keyframes = [_keyframe(path, i, frame) for i, frame in enumerate(frames)]
    if "then" in data:
        keyframes += load_motion(str(data["then"]), folder, _loading).keyframes
    return KeyframeMotion(name, str(data.get("description", "")), keyframes, bool(data.get("moves_head", False)))


def _keyframe(path: Path, index: int, frame: object) -> Keyframe:
    where = f"{path}: keyframe {index + 1}"
    if not isinstance(frame, dict):
        raise MotionFileError(f"{where} must be a table")
    duration = frame.get("duration")
    if isinstance(duration, bool) or not isinstance(duration, (int, float)) or not 0.0 < float(duration) <= 30.0:
        raise MotionFileError(f"{where}: duration takes seconds from 0 (exclusive) to 30, got {duration!r}")
    joints = frame.get("joints", {})
    if not isinstance(joints, dict):
        raise MotionFileError(f"{where}: joints must be a table of joint name = angle (rad)")
    targets = {}
    for name, angle in joints.items():
        if name not in JOINT_INDEX:
            from tafel.core.framework.naming import did_you_mean

            raise MotionFileError(f"{where}: unknown joint {name!r}; {did_you_mean(name, JOINT_NAMES)}")
        if isinstance(angle, bool) or not isinstance(angle, (int, float)) or not math.isfinite(angle):
            raise MotionFileError(f"{where}: {name} takes an angle in rad, got {angle!r}")
        low, high = JOINTS_BY_NAME[name].limits
        if not low - 1e-6 <= angle <= high + 1e-6:
            raise MotionFileError(f"{where}: {name} = {angle} is outside its limits {low:.3f} .. {high:.3f} rad")
        targets[JOINT_INDEX[name]] = float(angle)
    abort = frame.get("abort_if_tilted")
    if abort is not None and (isinstance(abort, bool) or not isinstance(abort, (int, float)) or not 0.0 < abort <= math.pi):
        raise MotionFileError(f"{where}: abort_if_tilted takes a tilt in rad from 0 (exclusive) to pi, got {abort!r}")
    return Keyframe(float(duration), targets, _stiffness(where, frame.get("stiffness", 1.0)),
                    None if abort is None else float(abort))


def _stiffness(where: str, value: object) -> np.ndarray:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        values = np.full(JOINT_COUNT, float(value))
    elif isinstance(value, dict):
        values = np.ones(JOINT_COUNT)
        for name, number in value.items():
            if name not in JOINT_INDEX or isinstance(number, bool) or not isinstance(number, (int, float)):
                raise MotionFileError(f"{where}: stiffness.{name} must name a joint and take 0..1")
            values[JOINT_INDEX[name]] = float(number)
    else:
        raise MotionFileError(f"{where}: stiffness takes 0..1, or a table of joint name = 0..1")
    if not np.all((values >= 0.0) & (values <= 1.0)):
        raise MotionFileError(f"{where}: stiffness takes values from 0 to 1")
    return values


def mirror_name(name: str) -> str:
    if name.endswith("HipYawPitch"):
        return "LHipYawPitch"  # one motor for both legs
    return "R" + name[1:] if name.startswith("L") else "L" + name[1:] if name.startswith("R") else name


def _mirrored(keyframe: Keyframe) -> Keyframe:
    targets = {}
    for index, angle in keyframe.targets.items():
        name = mirror_name(JOINT_NAMES[index])
        base = name[1:] if name[0] in "LR" else name
        targets[JOINT_INDEX[name]] = -angle if base in MIRROR_NEGATED else angle
    stiffness = np.array([keyframe.stiffness[JOINT_INDEX[mirror_name(n)]] for n in JOINT_NAMES])
    return Keyframe(keyframe.duration, targets, stiffness, keyframe.abort_if_tilted)
