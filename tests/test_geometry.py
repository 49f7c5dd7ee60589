"""``Pose2D``: the one way Tafel turns points and poses between frames on the ground."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.representations import Pose2D as ExportedPose2D
from tafel.representations.geometry import Pose2D, normalize_angle
from tafel.representations.modeling import RobotPose
from tafel.representations.motion_control import Odometry

coordinates = st.floats(-20000.0, 20000.0, allow_nan=False)
angles = st.floats(-100.0, 100.0, allow_nan=False)
poses = st.builds(Pose2D, coordinates, coordinates, angles)


def close(a: Pose2D, b: Pose2D, tolerance: float = 1e-6) -> bool:
    """Same place (mm) and heading (rad, either side of the seam at pi)."""
    return (math.isclose(a.x, b.x, abs_tol=tolerance) and math.isclose(a.y, b.y, abs_tol=tolerance)
            and abs(normalize_angle(a.rotation - b.rotation)) <= 1e-9)


def test_a_robot_facing_left_sees_the_field_turned() -> None:
    robot = Pose2D(1000.0, 500.0, math.pi / 2)
    assert robot.to_global(100.0, 0.0) == pytest.approx((1000.0, 600.0))  # ahead of it is +y on the field
    assert robot.to_local(1000.0, 600.0) == pytest.approx((100.0, 0.0))
    assert robot.rotated(100.0, 0.0) == pytest.approx((0.0, 100.0))  # a velocity turns but does not move
    step = Pose2D(200.0, 0.0, math.pi / 2)
    assert tuple(robot * step) == pytest.approx((1000.0, 700.0, math.pi))  # 200 mm ahead, then a quarter turn
    assert tuple((robot * step).relative_to(robot)) == pytest.approx(tuple(step))
    assert tuple(robot.inverse()) == pytest.approx((-500.0, 1000.0, -math.pi / 2))
    assert robot.compose(step) == robot * step
    x, y, rotation = robot
    assert (x, y, rotation) == (1000.0, 500.0, math.pi / 2)
    assert ExportedPose2D is Pose2D  # ``from tafel.representations import Pose2D``


def test_the_angle_is_kept_in_minus_pi_excluded_to_pi() -> None:
    assert Pose2D(rotation=-math.pi).rotation == math.pi
    assert Pose2D(rotation=3 * math.pi).rotation == math.pi
    assert Pose2D(rotation=math.tau + 0.5).rotation == pytest.approx(0.5)
    assert Pose2D(rotation=-0.25).rotation == -0.25
    with pytest.raises(TypeError):
        Pose2D(0.0, 0.0, 0.0) * (1.0, 2.0)  # type: ignore[operator]
    with pytest.raises(AttributeError):  # a value: it cannot change under a module that holds it
        Pose2D().x = 1.0  # type: ignore[misc]


def test_representations_with_a_pose_hand_out_the_same_transforms() -> None:
    pose = RobotPose(x=-2000.0, y=1000.0, rotation=-0.75)
    assert pose.as_pose2d() == Pose2D(-2000.0, 1000.0, -0.75)
    assert pose.to_field(300.0, -40.0) == pose.as_pose2d().to_global(300.0, -40.0)
    assert pose.to_robot(0.0, 0.0) == pose.as_pose2d().to_local(0.0, 0.0)
    before, now = Odometry(x=100.0, y=0.0, rotation=0.5), Odometry(x=100.0, y=300.0, rotation=1.0)
    forward, left, turn = now.as_pose2d().relative_to(before.as_pose2d())
    assert (forward, left, turn) == pytest.approx((300.0 * math.sin(0.5), 300.0 * math.cos(0.5), 0.5))


@given(angles)
def test_every_angle_lands_in_minus_pi_excluded_to_pi_and_means_the_same(angle: float) -> None:
    wrapped = normalize_angle(angle)
    assert -math.pi < wrapped <= math.pi
    assert math.isclose(math.cos(wrapped), math.cos(angle), abs_tol=1e-9)
    assert math.isclose(math.sin(wrapped), math.sin(angle), abs_tol=1e-9)


@given(poses, poses)
def test_composed_poses_keep_their_angle_in_range(a: Pose2D, b: Pose2D) -> None:
    for pose in (a, a * b, a.inverse(), b.relative_to(a)):
        assert -math.pi < pose.rotation <= math.pi


@given(poses)
def test_a_pose_composed_with_its_inverse_is_the_identity(pose: Pose2D) -> None:
    assert close(pose * pose.inverse(), Pose2D(), 1e-6)
    assert close(pose.inverse() * pose, Pose2D(), 1e-6)
    assert close(pose.inverse().inverse(), pose)


@given(poses, coordinates, coordinates)
def test_a_point_taken_into_a_frame_and_back_is_where_it_was(pose: Pose2D, x: float, y: float) -> None:
    assert pose.to_global(*pose.to_local(x, y)) == pytest.approx((x, y), abs=1e-6)
    assert pose.to_local(*pose.to_global(x, y)) == pytest.approx((x, y), abs=1e-6)
    # a vector turned keeps its length; turned by the inverse it comes back
    assert math.hypot(*pose.rotated(x, y)) == pytest.approx(math.hypot(x, y), abs=1e-6)
    assert pose.inverse().rotated(*pose.rotated(x, y)) == pytest.approx((x, y), abs=1e-6)


@given(poses, poses, poses, coordinates, coordinates)
def test_composition_is_applying_one_frame_after_the_other(a: Pose2D, b: Pose2D, c: Pose2D, x: float, y: float) -> None:
    assert (a * b).to_global(x, y) == pytest.approx(a.to_global(*b.to_global(x, y)), abs=1e-5)
    assert close((a * b) * c, a * (b * c), 1e-5)
    assert close(b.relative_to(a), a.inverse() * b, 1e-5)
    assert close(a * b.relative_to(a), b, 1e-5)
