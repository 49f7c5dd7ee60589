"""The simulated world, generated from the shared robot and field descriptions.

``mjcf()`` gives MuJoCo XML of the NAO (bodies, joints with limits, masses and inertias, collision
shapes, IMU and foot pressure sites, both cameras, position servos) on an SPL field with a ball.
``urdf()`` gives the same robot as URDF for simulators that read it. Both come from
``representations.nao`` and ``representations.field``; nothing here is a hand-made copy of figures.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from xml.sax.saxutils import quoteattr

import numpy as np

from tafel.platforms.field_world import NET_FRICTION, SceneLook, ball_mesh, ball_texture_png, carpet_texture_png, field_parts
from tafel.representations import field
from tafel.representations.nao import (
    ACCELEROMETER_POSITION,
    CAMERAS,
    COUPLED_JOINTS,
    ELBOW_OFFSET_Y,
    FOOT_HEIGHT,
    GYROSCOPE_POSITION,
    HAND_OFFSET_X,
    HAND_OFFSET_Z,
    HIP_OFFSET_Z,
    JOINTS,
    LOWER_ARM_LENGTH,
    SOLE_BACK,
    SOLE_FRONT,
    SOLE_INSIDE,
    SOLE_OUTSIDE,
    THIGH_LENGTH,
    TIBIA_LENGTH,
    TORSO_MASS,
    UPPER_ARM_LENGTH,
    VERTICAL_FOV,
)

M = 0.001  # mm -> m
#: servo strength at stiffness 1 (N m / rad)
SERVO_GAIN = 120.0
#: what each joint's motor can give: (stall torque N m, no-load speed rad/s), the motor's figures times
#: its gear ratio (Aldebaran's motor tables: legs RE-Max 24, 59.5 mN m and 8000 rpm; arms and head
#: RE-Max 17, 15.1 mN m and 11 900 rpm; wrists A-max 12, 1.52 mN m and 12 300 rpm; ratios 201.3 or
#: 130.85 in the legs, 150.27 or 173.22 in the arms and head, 800 at the wrists)
_LEG_A, _LEG_B = (11.98, 4.16), (7.79, 6.40)  # 201.3: hip yaw-pitch and roll, ankle roll; 130.85: pitch joints
_ARM_A, _ARM_B = (2.27, 8.29), (2.62, 7.19)  # 150.27: shoulder pitch, elbow yaw, head yaw; 173.22: the others
_JOINT_MOTORS = {"HipYawPitch": _LEG_A, "HipRoll": _LEG_A, "AnkleRoll": _LEG_A, "HipPitch": _LEG_B, "KneePitch": _LEG_B,
                 "AnklePitch": _LEG_B, "ShoulderPitch": _ARM_A, "ElbowYaw": _ARM_A, "HeadYaw": _ARM_A, "ShoulderRoll": _ARM_B,
                 "ElbowRoll": _ARM_B, "HeadPitch": _ARM_B, "WristYaw": (1.22, 1.61), "Hand": (0.5, 2.0)}


def joint_motor(name: str) -> tuple[float, float]:
    """(stall torque N m, no-load speed rad/s) of a joint, by its name with or without the side."""
    return _JOINT_MOTORS[name[1:] if name[0] in "LR" and name[1:] in _JOINT_MOTORS else name]


def torque_range(velocity: np.ndarray, stall: np.ndarray, no_load_speed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lowest, highest) torque (N m) the motors can give at joint ``velocity`` (rad/s).

    A DC motor's torque falls in a straight line from its stall torque at rest to nothing at its
    no-load speed; against the motion (braking) it gives up to the stall torque. That line is what
    limits the NAO's joint speeds, so the simulated joints cannot move faster than the real ones.
    """
    share = velocity / no_load_speed
    # np.minimum and np.maximum: the same as np.clip, at a fraction of its overhead (this runs 500 times a second per robot)
    return -stall * np.maximum(np.minimum(1.0 + share, 1.0), 0.0), stall * np.maximum(np.minimum(1.0 - share, 1.0), 0.0)

JOINT_DAMPING = 0.6
JOINT_ARMATURE = 0.01
#: torso height above the ground with straight legs (m): where the robot is placed
STANDING_HEIGHT = (HIP_OFFSET_Z + THIGH_LENGTH + TIBIA_LENGTH + FOOT_HEIGHT) * M
ROBOT_GROUP, WORLD_GROUP = 2, 1  # collision bits: the robot touches the world, not itself


@dataclass(frozen=True)
class Shape:
    """A collision and visual shape of a link, in the link frame (m)."""

    kind: str  # "box" (size = half extents), "capsule" (from, to, radius), "sphere" (center, radius)
    size: tuple[float, ...]
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)
    end: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rgba: str = "0.85 0.85 0.88 1"


def _foot(side: str) -> Shape:
    outward = SOLE_OUTSIDE if side == "L" else -SOLE_OUTSIDE
    inward = -SOLE_INSIDE if side == "L" else SOLE_INSIDE
    half = ((SOLE_FRONT + SOLE_BACK) / 2 * M, abs(outward - inward) / 2 * M, 0.012)
    center = ((SOLE_FRONT - SOLE_BACK) / 2 * M, (outward + inward) / 2 * M, -FOOT_HEIGHT * M + half[2])
    return Shape("box", half, center, rgba="0.75 0.75 0.8 1")


def shapes(link: str) -> list[Shape]:
    """The simple shapes of each link; limbs are capsules, feet boxes with the sole's size."""
    side = link[0] if link[0] in "LR" and link != "torso" else ""
    s = 1.0 if side == "L" else -1.0
    name = link[1:] if side else link
    table: dict[str, list[Shape]] = {
        "torso": [Shape("box", (0.045, 0.065, 0.095), (-0.008, 0.0, 0.035))],
        "Neck": [],
        "Head": [Shape("sphere", (0.062,), (0.0, 0.0, 0.055), rgba="0.9 0.9 0.92 1")],
        "Shoulder": [],
        "Biceps": [Shape("capsule", (0.024,), (0.0, 0.0, 0.0), (UPPER_ARM_LENGTH * M, s * ELBOW_OFFSET_Y * M, 0.0))],
        "Elbow": [],
        "ForeArm": [Shape("capsule", (0.021,), (0.0, 0.0, 0.0), (LOWER_ARM_LENGTH * M, 0.0, 0.0))],
        "Wrist": [Shape("capsule", (0.02,), (0.0, 0.0, 0.0), (HAND_OFFSET_X * M, 0.0, -HAND_OFFSET_Z * M))],
        "Fingers": [],
        "Pelvis": [],
        "Hip": [],
        "Thigh": [Shape("capsule", (0.033,), (0.0, 0.0, -0.015), (0.0, 0.0, -(THIGH_LENGTH - 15) * M))],
        "Tibia": [Shape("capsule", (0.03,), (0.0, 0.0, -0.015), (0.0, 0.0, -(TIBIA_LENGTH - 15) * M))],
        "Ankle": [],
        "Foot": [_foot(side)] if side else [],
    }
    return table[name]


def inertia(mass: float, link_shapes: list[Shape]) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Centre of mass and diagonal inertia (kg m^2) of a link, from its main shape (a small sphere if none)."""
    if not link_shapes:
        r = 0.015
        return (0.0, 0.0, 0.0), (0.4 * mass * r * r,) * 3
    shape = link_shapes[0]
    if shape.kind == "box":
        x, y, z = (2 * h for h in shape.size)
        return shape.center, (mass / 12 * (y * y + z * z), mass / 12 * (x * x + z * z), mass / 12 * (x * x + y * y))
    if shape.kind == "sphere":
        r = shape.size[0]
        return shape.center, (0.4 * mass * r * r,) * 3
    start, end = np.array(shape.center), np.array(shape.end)
    length = float(np.linalg.norm(end - start))
    r = shape.size[0]
    axial = 0.5 * mass * r * r
    transverse = mass * (3 * r * r + length * length) / 12
    axis = int(np.argmax(np.abs(end - start)))
    diagonal = [transverse] * 3
    diagonal[axis] = axial
    center = tuple((start + end) / 2)
    return center, tuple(diagonal)  # type: ignore[return-value]


def fsr_sites(side: str) -> list[tuple[str, tuple[float, float, float]]]:
    """Four pressure sensors per sole: front-left, front-right, rear-left, rear-right (m, foot frame).

    Centred on the sole's corners, where a flat sole's contacts with the ground are.
    """
    left = (SOLE_OUTSIDE if side == "L" else SOLE_INSIDE) * M
    right = -(SOLE_INSIDE if side == "L" else SOLE_OUTSIDE) * M
    front, rear = SOLE_FRONT * M, -SOLE_BACK * M
    z = -FOOT_HEIGHT * M
    return [(f"{side}FsrFrontLeft", (front, left, z)), (f"{side}FsrFrontRight", (front, right, z)),
            (f"{side}FsrRearLeft", (rear, left, z)), (f"{side}FsrRearRight", (rear, right, z))]


def _vec(values: tuple[float, ...] | np.ndarray) -> str:
    return " ".join(f"{v:.6g}" for v in values)


def _geom_xml(shape: Shape, name: str) -> str:
    common = f'name="{name}" contype="{ROBOT_GROUP}" conaffinity="{WORLD_GROUP}" rgba="{shape.rgba}" group="1"'
    if shape.kind == "box":
        return f'<geom {common} type="box" size="{_vec(shape.size)}" pos="{_vec(shape.center)}" friction="1.0 0.02 0.001"/>'
    if shape.kind == "sphere":
        return f'<geom {common} type="sphere" size="{shape.size[0]:.6g}" pos="{_vec(shape.center)}"/>'
    return f'<geom {common} type="capsule" size="{shape.size[0]:.6g}" fromto="{_vec(shape.center)} {_vec(shape.end)}"/>'


def _camera_xml(link: str) -> list[str]:
    if link != "Head":
        return []
    lines = []
    for camera in CAMERAS:
        # MuJoCo cameras look along -z with y up: x_cam = right (-y), y_cam = up tilted forward by the tilt.
        up = (math.sin(camera.tilt), 0.0, math.cos(camera.tilt))
        lines.append(f'<camera name="{camera.name}_camera" pos="{_vec(np.array(camera.position) * M)}" '
                     f'xyaxes="0 -1 0 {_vec(up)}" fovy="{math.degrees(VERTICAL_FOV):.4f}"/>')
    return lines


def _body_xml(link: str, children: dict[str, list], indent: str) -> list[str]:
    lines = []
    for joint in children.get(link, []):
        link_shapes = shapes(joint.link)
        center, diagonal = inertia(joint.mass, link_shapes)
        lines.append(f'{indent}<body name="{joint.link}" pos="{_vec(np.array(joint.offset) * M)}">')
        inner = indent + "  "
        lines.append(f'{inner}<inertial pos="{_vec(center)}" mass="{joint.mass:.6g}" diaginertia="{_vec(diagonal)}"/>')
        low, high = joint.limits
        lines.append(f'{inner}<joint name="{joint.name}" type="hinge" axis="{_vec(joint.axis)}" range="{low:.6g} {high:.6g}" '
                     f'limited="true" damping="{JOINT_DAMPING}" armature="{JOINT_ARMATURE}"/>')
        for i, shape in enumerate(link_shapes):
            lines.append(inner + _geom_xml(shape, f"{joint.link}_geom{i}"))
        if joint.link.endswith("Foot"):
            for name, position in fsr_sites(joint.link[0]):
                lines.append(f'{inner}<site name="{name}" type="box" size="0.02 0.02 0.008" pos="{_vec(position)}" rgba="1 0 0 0"/>')
        lines += [inner + c for c in _camera_xml(joint.link)]
        lines += _body_xml(joint.link, children, inner)
        lines.append(f"{indent}</body>")
    return lines


#: geom group the renderers of the cameras leave out (MuJoCo shows groups 0 to 2 by default); the viewer shows it
VIEWER_ONLY_GROUP = 3


def _field_xml(ball_color: str, robot_bits: int = ROBOT_GROUP, look: SceneLook | None = None) -> list[str]:
    lines = []
    for part in field_parts(ball_color=ball_color, look=look):
        rgba = _vec(part.rgba)
        if part.material:
            rgba = f'1 1 1 1" material="{part.material}'  # the material's texture gives the colour
        groups = f'contype="{WORLD_GROUP}" conaffinity="{WORLD_GROUP | robot_bits}"' if part.collides else 'contype="0" conaffinity="0"'
        groups += "" if part.in_cameras else f' group="{VIEWER_ONLY_GROUP}"'
        groups += f' priority="1" friction="{NET_FRICTION} 0.005 0.0001" solref="0.004 2"' if part.absorbs else ""  # its friction wins
        if part.kind == "plane":
            lines.append(f'<geom name="{part.name}" type="plane" size="{_vec(part.size)}" pos="{_vec(part.position)}" rgba="{rgba}" '
                         f'{groups} friction="1.0 0.02 0.002"/>')
        elif part.kind == "box":
            lines.append(f'<geom name="{part.name}" type="box" size="{_vec(part.size)}" pos="{_vec(part.position)}" '
                         f'euler="0 0 {part.yaw:.6g}" rgba="{rgba}" {groups}/>')
        elif part.kind == "cylinder":
            lines.append(f'<geom name="{part.name}" type="cylinder" size="{_vec(part.size)}" pos="{_vec(part.position)}" rgba="{rgba}" {groups}/>')
        elif part.kind == "capsule":
            lines.append(f'<geom name="{part.name}" type="capsule" size="{_vec(part.size)}" fromto="{_vec(part.position)} {_vec(part.end)}" rgba="{rgba}" {groups}/>')
        elif part.kind == "sphere":
            # with a texture the sphere only collides; a textured mesh of the same size shows the ball
            shown = "0 0 0 0" if part.texture else rgba
            lines += [f'<body name="{part.name}" pos="{_vec(part.position)}">', f'  <freejoint name="{part.name}"/>',
                      f'  <geom name="{part.name}" type="sphere" size="{_vec(part.size)}" mass="{part.mass}" rgba="{shown}" '
                      f'{groups} condim="6" friction="{BALL_FRICTION}"/>']
            if part.texture:
                lines.append(f'  <geom name="{part.name}_look" type="mesh" mesh="{part.name}" material="{part.name}" density="0" '
                             'contype="0" conaffinity="0"/>')
            lines.append("</body>")
    return lines


def _ball_assets(ball_color: str) -> list[str]:
    """The textured ball's mesh, texture and material (the texture's pixels come with ``mjcf_assets``)."""
    if ball_color != "spl":
        return []
    vertices, normals, uvs, triangles = ball_mesh(field.BALL_RADIUS * M)
    return [f'<mesh name="ball" vertex="{_vec(vertices.ravel())}" normal="{_vec(normals.ravel())}" '
            f'texcoord="{_vec(uvs.ravel())}" face="{" ".join(map(str, triangles.ravel()))}"/>',
            f'<texture name="ball" type="2d" file="{BALL_TEXTURE_FILE}"/>',
            '<material name="ball" texture="ball" specular="0.1" shininess="0.1"/>']


BALL_TEXTURE_FILE = "spl_ball.png"
CARPET_TEXTURE_FILE = "carpet.png"


def _carpet_assets(look: SceneLook | None) -> list[str]:
    """The realistic carpet's texture and material: one seeded metre, repeated over the carpet."""
    if not (look and look.texture):
        return []
    return [f'<texture name="carpet" type="2d" file="{CARPET_TEXTURE_FILE}"/>',
            '<material name="carpet" texture="carpet" texuniform="true" texrepeat="1 1" specular="0" shininess="0"/>']


def mjcf_assets(ball_color: str = "spl", look: SceneLook | None = None) -> dict[str, bytes]:
    """The files ``mjcf`` refers to, for ``MjModel.from_xml_string(xml, assets)``: made here, never read from disk."""
    assets = {BALL_TEXTURE_FILE: ball_texture_png()} if ball_color == "spl" else {}
    if look and look.texture:
        assets[CARPET_TEXTURE_FILE] = carpet_texture_png(look)
    return assets


def sun_direction(seed: int) -> tuple[float, float, float]:
    """Where the hall's main light shines (a unit vector down and a little aside), seeded: shadows fall
    a different way in each run with ``--realism``."""
    rng = np.random.default_rng([seed, 67])
    tilt, heading = rng.uniform(0.2, 0.6), rng.uniform(-math.pi, math.pi)
    return math.sin(tilt) * math.cos(heading), math.sin(tilt) * math.sin(heading), -math.cos(tilt)


#: sliding, torsional and rolling friction of the ball (MuJoCo's three coefficients)
BALL_FRICTION = "0.6 0.01 0.002"


def robot_prefix(index: int, robots: int) -> str:
    """The names of robot ``index``'s bodies, joints, sites, cameras, actuators and sensors start with this:
    nothing when it is alone (``torso``, ``top_camera``), ``r3_`` for the fourth of several."""
    return "" if robots == 1 else f"r{index}_"


def robot_collision_bits(index: int, robots: int) -> tuple[int, int]:
    """(contype, conaffinity) of robot ``index``'s geoms: it touches the world and the other robots,
    never itself (its links overlap at the joints)."""
    if robots == 1:
        return ROBOT_GROUP, WORLD_GROUP
    own = ROBOT_GROUP << (index + 1)
    every = sum(ROBOT_GROUP << (k + 1) for k in range(robots))
    return own, WORLD_GROUP | (every & ~own)


_NAMED = re.compile(r'\b(name|joint|site|joint1|joint2)="([^"]+)"')


def _robot_xml(index: int, robots: int, position: tuple[float, float]) -> tuple[list[str], list[str], list[str], list[str]]:
    """Robot ``index``'s body, actuators, equalities and sensors, its names prefixed (``robot_prefix``)."""
    children: dict[str, list] = {}
    for joint in JOINTS:
        children.setdefault(joint.parent, []).append(joint)
    torso_shapes = shapes("torso")
    center, diagonal = inertia(TORSO_MASS, torso_shapes)
    body = [
        f'<body name="torso" pos="{position[0]:.6g} {position[1]:.6g} {STANDING_HEIGHT + 0.002:.7g}">',
        '  <freejoint name="root"/>',
        f'  <inertial pos="{_vec(center)}" mass="{TORSO_MASS}" diaginertia="{_vec(diagonal)}"/>',
        "  " + _geom_xml(torso_shapes[0], "torso_geom0"),
        f'  <site name="accelerometer" pos="{_vec(np.array(ACCELEROMETER_POSITION) * M)}" size="0.005"/>',
        f'  <site name="gyroscope" pos="{_vec(np.array(GYROSCOPE_POSITION) * M)}" size="0.005"/>',
        *_body_xml("torso", children, "  "),
        "</body>",
    ]
    actuated = [j for j in JOINTS if j.name not in COUPLED_JOINTS]
    actuators = [f'<position name="{j.name}" joint="{j.name}" kp="{SERVO_GAIN}" kv="0" ctrlrange="{j.limits[0]:.6g} {j.limits[1]:.6g}" '
                 f'forcerange="{-joint_motor(j.name)[0]} {joint_motor(j.name)[0]}"/>' for j in actuated]
    equalities = [f'<joint joint1="{follower}" joint2="{leader}" polycoef="0 1 0 0 0"/>' for follower, leader in COUPLED_JOINTS.items()]
    sensors = ['<accelerometer name="accelerometer" site="accelerometer"/>', '<gyro name="gyroscope" site="gyroscope"/>']
    sensors += [f'<touch name="{name}" site="{name}"/>' for side in "LR" for name, _ in fsr_sites(side)]
    prefix = robot_prefix(index, robots)
    contype, conaffinity = robot_collision_bits(index, robots)
    groups = f'contype="{ROBOT_GROUP}" conaffinity="{WORLD_GROUP}"'

    def named(lines: list[str]) -> list[str]:
        return [_NAMED.sub(lambda m: f'{m.group(1)}="{prefix}{m.group(2)}"', line).replace(groups, f'contype="{contype}" conaffinity="{conaffinity}"')
                for line in lines]

    return named(body), named(actuators), named(equalities), named(sensors)


def mjcf(*, offscreen: tuple[int, int] = (640, 480), timestep: float = 0.002, ball_color: str = "spl",
         robots: list[tuple[float, float]] | None = None, look: SceneLook | None = None, shadows: bool = False) -> str:
    """MuJoCo XML of the field with the ball (``ball_color`` spl or orange; see ``mjcf_assets``) and one
    robot at the centre spot, or several at the given places (m) named by ``robot_prefix``; ``look`` and
    ``shadows``: the realistic hall (``--realism``), its sun casting shadows from a seeded direction."""
    places = robots or [(0.0, 0.0)]
    parts = [_robot_xml(index, len(places), place) for index, place in enumerate(places)]
    every_robot = sum(robot_collision_bits(k, len(places))[0] for k in range(len(places)))
    width, height = offscreen
    return "\n".join([
        '<mujoco model="tafel-nao-spl">',
        f'  <option timestep="{timestep}" integrator="implicitfast" cone="elliptic"/>',
        '  <compiler angle="radian" autolimits="true"/>',
        f'  <visual><global offwidth="{width}" offheight="{height}"/><quality shadowsize="{1024 if shadows else 0}" offsamples="0"/>'
        '<headlight ambient="0.45 0.45 0.45" diffuse="0.5 0.5 0.5" specular="0 0 0"/></visual>',
        "  <asset>", *("    " + a for a in _ball_assets(ball_color) + _carpet_assets(look)), "  </asset>",
        "  <worldbody>",
        f'    <light name="sun" pos="0 0 6" dir="{_vec(sun_direction(look.seed) if shadows and look else (0, 0, -1))}" '
        f'directional="true" diffuse="0.6 0.6 0.6" castshadow="{"true" if shadows else "false"}"/>',
        *("    " + line for line in _field_xml(ball_color, every_robot, look)),
        *("    " + line for body, _, _, _ in parts for line in body),
        "  </worldbody>",
        "  <equality>", *("    " + e for _, _, equalities, _ in parts for e in equalities), "  </equality>",
        "  <actuator>", *("    " + a for _, actuators, _, _ in parts for a in actuators), "  </actuator>",
        "  <sensor>", *("    " + s for _, _, _, sensors in parts for s in sensors), "  </sensor>",
        "</mujoco>",
    ]) + "\n"


def urdf() -> str:
    """The robot alone as URDF (links, joints, limits, masses, inertias, collision shapes), in metres."""
    out = ['<?xml version="1.0"?>', '<robot name="tafel-nao">']

    def link_xml(name: str, mass: float, link_shapes: list[Shape]) -> None:
        center, diagonal = inertia(mass, link_shapes)
        out.append(f'  <link name={quoteattr(name)}>')
        out.append(f'    <inertial><origin xyz="{_vec(center)}"/><mass value="{mass:.6g}"/>'
                   f'<inertia ixx="{diagonal[0]:.6g}" iyy="{diagonal[1]:.6g}" izz="{diagonal[2]:.6g}" ixy="0" ixz="0" iyz="0"/></inertial>')
        for shape in link_shapes:
            geometry, origin = _urdf_geometry(shape)
            for tag in ("collision", "visual"):
                out.append(f"    <{tag}>{origin}<geometry>{geometry}</geometry></{tag}>")
        out.append("  </link>")

    link_xml("torso", TORSO_MASS, shapes("torso"))
    for joint in JOINTS:
        link_xml(joint.link, joint.mass, shapes(joint.link))
        low, high = joint.limits
        out.append(f'  <joint name={quoteattr(joint.name)} type="revolute"><parent link="{joint.parent}"/><child link="{joint.link}"/>'
                   f'<origin xyz="{_vec(np.array(joint.offset) * M)}"/><axis xyz="{_vec(joint.axis)}"/>'
                   f'<limit lower="{low:.6g}" upper="{high:.6g}" effort="{joint_motor(joint.name)[0]}" velocity="{joint_motor(joint.name)[1]}"/>'
                   f'<dynamics damping="{JOINT_DAMPING}"/></joint>')
    out.append("</robot>")
    return "\n".join(out) + "\n"


def _urdf_geometry(shape: Shape) -> tuple[str, str]:
    if shape.kind == "box":
        return f'<box size="{_vec(tuple(2 * h for h in shape.size))}"/>', f'<origin xyz="{_vec(shape.center)}"/>'
    if shape.kind == "sphere":
        return f'<sphere radius="{shape.size[0]:.6g}"/>', f'<origin xyz="{_vec(shape.center)}"/>'
    start, end = np.array(shape.center), np.array(shape.end)
    direction = end - start
    length = float(np.linalg.norm(direction))
    # URDF cylinders lie along z: tilt z onto the capsule's direction
    pitch = math.atan2(math.hypot(direction[0], direction[1]), direction[2])
    yaw = math.atan2(direction[1], direction[0])
    origin = f'<origin xyz="{_vec((start + end) / 2)}" rpy="0 {pitch:.6g} {yaw:.6g}"/>'
    return f'<capsule radius="{shape.size[0]:.6g}" length="{length:.6g}"/>', origin
