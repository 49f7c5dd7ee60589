"""The SPL field world both simulators build: carpet, lines, marks, goals, the hall around it, the ball.

Everything is generated from ``representations.field`` as engine-neutral ``FieldPart`` pieces (m), so
MuJoCo and PyBullet show the same world. The SPL ball (white with black pentagons, used since 2016) is
a textured sphere: ``paint_ball_texture`` paints the pattern of a truncated icosahedron procedurally and
``ball_mesh`` gives the UV sphere both engines wrap it on. Nothing is downloaded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import cv2
import numpy as np

from tafel.platforms.realism import RealismLevel
from tafel.representations import field
from tafel.representations.field import circle_segments, goal_post_positions, line_segments, mark_centres

M = 0.001  # mm -> m
BALL_COLORS = ("spl", "orange")


@dataclass(frozen=True)
class FieldPart:
    """One piece of the field world (m). ``kind``: plane, box (size = half extents, turned by ``yaw``),
    cylinder (radius, half height), capsule (radius; from ``start`` to ``end``), or sphere (the ball).
    ``texture``: the ball's pattern is painted on it (engines use ``ball_mesh`` and ``ball_texture``).
    ``in_cameras`` False: the robot's cameras do not see it, only the viewers do. ``absorbs``: it takes
    what hits it without a bounce and lets nothing climb it (a net: slippery, overdamped contacts; a
    ball spinning into a gripping wall would roll up it and fly back out of the goal)."""

    name: str
    kind: str
    position: tuple[float, float, float]
    size: tuple[float, ...]
    rgba: tuple[float, float, float, float]
    collides: bool = True
    yaw: float = 0.0
    end: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mass: float = 0.0  # > 0: a free body (the ball)
    texture: bool = False
    in_cameras: bool = True
    absorbs: bool = False
    material: str = ""  # an engine's own look for it, where the engine has one (MuJoCo: the realistic carpet's texture)


CARPET_RGBA = (0.18, 0.55, 0.2, 1.0)
WHITE = (1.0, 1.0, 1.0, 1.0)
ORANGE_BALL_RGBA = (1.0, 0.42, 0.0, 1.0)
HALL_RGBA = (0.42, 0.4, 0.38, 1.0)  # floor and walls around the carpet: neither green nor white
CEILING_RGBA = (0.75, 0.75, 0.78, 1.0)
HALL_MARGIN = 3.0  # m from the carpet's edge to the walls
HALL_HEIGHT = 6.0  # m: above every camera's view from the field
NET_RGBA = (0.92, 0.92, 0.92, 0.35)  # what the viewers show of the nets: a light, see-through grey
NET_HALF_THICKNESS = 0.02  # m: thick enough that the fastest ball (10 m/s, 2 cm a physics step) cannot pass
NET_FRICTION = 0.05  # sliding friction of a net (the ball's own is 0.6)


def _flat_box(name: str, x1: float, y1: float, x2: float, y2: float, half_width: float) -> FieldPart:
    """A painted stripe from (x1, y1) to (x2, y2) (mm), ``half_width`` mm to each side."""
    length = math.hypot(x2 - x1, y2 - y1)
    return FieldPart(name, "box", ((x1 + x2) / 2 * M, (y1 + y2) / 2 * M, 0.0005), ((length / 2 + half_width) * M, half_width * M, 0.0005),
                     WHITE, collides=False, yaw=math.atan2(y2 - y1, x2 - x1))


def field_parts(ball: tuple[float, float] = (1.0, 0.0), ball_color: str = "spl", look: SceneLook | None = None) -> list[FieldPart]:
    """Hall, carpet, lines and marks (visual only), goals and the ball at ``ball`` (m); with a ``look``
    (``--realism``) also the hall's clutter, visible nets and its carpet green."""
    if ball_color not in BALL_COLORS:
        raise ValueError(f"ball colour {ball_color!r}: choose one of {', '.join(BALL_COLORS)}")
    half_x, half_y = field.LENGTH / 2 * M, field.WIDTH / 2 * M
    carpet = (half_x + field.BORDER_STRIP * M, half_y + field.BORDER_STRIP * M, 0.1)
    hall_x, hall_y = carpet[0] + HALL_MARGIN, carpet[1] + HALL_MARGIN
    carpet_rgba = (*look.carpet, 1.0) if look else CARPET_RGBA
    parts = [FieldPart("carpet", "plane", (0.0, 0.0, 0.0), carpet, carpet_rgba, material="carpet" if look and look.texture else "")]
    # the hall's floor: four strips round the carpet, not a plane under it (PyBullet's CPU renderer would
    # draw the hidden part too, at twice the cost of a frame)
    strip_x, strip_y = (hall_x - carpet[0]) / 2, (hall_y - carpet[1]) / 2
    for name, x, y, sx, sy in (("floor_front", carpet[0] + strip_x, 0.0, strip_x, hall_y), ("floor_back", -carpet[0] - strip_x, 0.0, strip_x, hall_y),
                               ("floor_left", 0.0, carpet[1] + strip_y, carpet[0], strip_y), ("floor_right", 0.0, -carpet[1] - strip_y, carpet[0], strip_y)):
        parts.append(FieldPart(name, "box", (x, y, -0.0005), (sx, sy, 0.0005), HALL_RGBA, collides=False))
    for name, x, y, sx, sy in (("wall_front", hall_x, 0.0, 0.05, hall_y), ("wall_back", -hall_x, 0.0, 0.05, hall_y),
                               ("wall_left", 0.0, hall_y, hall_x, 0.05), ("wall_right", 0.0, -hall_y, hall_x, 0.05)):
        parts.append(FieldPart(name, "box", (x, y, HALL_HEIGHT / 2), (sx, sy, HALL_HEIGHT / 2), HALL_RGBA, collides=False))
    parts.append(FieldPart("ceiling", "box", (0.0, 0.0, HALL_HEIGHT), (hall_x, hall_y, 0.05), CEILING_RGBA, collides=False))
    w = field.LINE_WIDTH / 2
    parts += [_flat_box(f"line{i}", *segment, w) for i, segment in enumerate(line_segments() + circle_segments())]
    for i, (x, y) in enumerate(mark_centres()):
        arm = field.MARK_SIZE / 2 - w
        parts += [_flat_box(f"mark{i}_x", x - arm, y, x + arm, y, w), _flat_box(f"mark{i}_y", x, y - arm, x, y + arm, w)]
    r, h = field.GOAL_POST_DIAMETER / 2 * M, field.GOAL_HEIGHT * M
    posts = goal_post_positions()
    for (x, y), name in zip(posts, ("opponent_left", "opponent_right", "own_left", "own_right")):
        parts.append(FieldPart(f"goal_{name}", "cylinder", (x * M, y * M, h / 2), (r, h / 2), WHITE))
    for side, (x, y) in (("opponent", posts[0]), ("own", posts[2])):
        parts.append(FieldPart(f"goal_{side}_bar", "capsule", (x * M, -y * M, h), (r,), WHITE, collides=False, end=(x * M, y * M, h)))
    parts += goal_nets()
    if look and look.nets:
        parts += net_strands()
    if look and look.clutter:
        parts += hall_clutter(look.seed)
    ball_r = field.BALL_RADIUS * M
    rgba = WHITE if ball_color == "spl" else ORANGE_BALL_RGBA
    parts.append(FieldPart("ball", "sphere", (ball[0], ball[1], ball_r), (ball_r,), rgba, mass=field.BALL_MASS,
                           texture=ball_color == "spl"))
    return parts


def goal_nets() -> list[FieldPart]:
    """Back, sides and roof of both goals' nets (m): a scored ball stays in the goal, as on a real field.

    The nets stop the ball and the robots; the robot's cameras do not see them (``in_cameras``), so
    perception sees the goals as it always did, and only the viewers show them.
    """
    t, h = NET_HALF_THICKNESS, field.GOAL_HEIGHT * M
    post_x, post_y = goal_post_positions()[0][0] * M, goal_post_positions()[0][1] * M  # the posts' centres
    back_x = (field.LENGTH / 2 + field.GOAL_DEPTH) * M + t  # the back net's inside on the goal's depth
    outer_y = post_y + field.GOAL_POST_DIAMETER / 2 * M  # the posts' outer edge
    side_x = (post_x + back_x + t) / 2, (back_x + t - post_x) / 2  # from the posts to the back net: centre, half length
    panels = [("back", back_x, 0.0, h / 2, (t, outer_y + t, h / 2 + t)), ("left", side_x[0], post_y, h / 2, (side_x[1], t, h / 2)),
              ("right", side_x[0], -post_y, h / 2, (side_x[1], t, h / 2)), ("roof", side_x[0], 0.0, h + t, (side_x[1], outer_y + t, t))]
    return [FieldPart(f"goal_{side}_net_{name}", "box", (sign * x, y, z), size, NET_RGBA, in_cameras=False, absorbs=True)
            for sign, side in ((1.0, "opponent"), (-1.0, "own")) for name, x, y, z, size in panels]


# ---------------------------------------------------------------------------------- the realistic hall
@dataclass(frozen=True)
class SceneLook:
    """What ``--realism`` adds to the world: clutter in the hall, nets the cameras see, the carpet's green
    (r, g, b 0..1) and whether it has a texture (``carpet_texture``), all from one seed."""

    seed: int
    carpet: tuple[float, float, float]
    texture: float = 0.0
    clutter: bool = True
    nets: bool = True


NET_STRAND_RGBA = (0.8, 0.8, 0.82, 1.0)
NET_STRAND = 0.004  # m: half the thickness of a net's cord as the cameras see it
NET_MESH = 0.1  # m between cords


def net_strands() -> list[FieldPart]:
    """The nets' cords as the cameras see them: thin boxes over each panel of ``goal_nets``, every
    ``NET_MESH``; they only show (the panels stop the ball)."""
    strands = []
    for panel in goal_nets():
        centre, half = np.array(panel.position), np.array(panel.size)
        thin = int(np.argmin(half))
        u, v = (axis for axis in range(3) if axis != thin)
        for along, across in ((u, v), (v, u)):
            count = int(2 * half[across] / NET_MESH)
            for k in range(count + 1):
                position = centre.copy()
                position[across] += -half[across] + 2 * half[across] * k / max(1, count)
                size = np.full(3, NET_STRAND)
                size[along] = half[along]
                strands.append(FieldPart(f"{panel.name}_cord{len(strands)}", "box", tuple(position), tuple(size), NET_STRAND_RGBA,
                                         collides=False))
    return strands


TROUSERS = ((0.1, 0.12, 0.25), (0.05, 0.05, 0.06), (0.55, 0.5, 0.38), (0.35, 0.36, 0.38), (0.2, 0.25, 0.4))
SHIRTS = ((0.85, 0.85, 0.85), (0.1, 0.1, 0.12), (0.7, 0.15, 0.12), (0.15, 0.3, 0.6), (0.9, 0.75, 0.2), (0.3, 0.5, 0.3))
CASE_RGBA = ((0.06, 0.06, 0.07, 1.0), (0.12, 0.12, 0.13, 1.0), (0.25, 0.25, 0.27, 1.0), (0.7, 0.7, 0.72, 1.0))
TABLE_RGBA = ((0.85, 0.85, 0.83, 1.0), (0.55, 0.4, 0.25, 1.0), (0.3, 0.3, 0.32, 1.0))


def hall_clutter(seed: int) -> list[FieldPart]:
    """Tables, equipment cases, people's legs, robots waiting at the carpet's edge and boards on the walls,
    placed round the carpet from ``seed``; they only show (nothing collides with them)."""
    rng = np.random.default_rng([seed, 53])
    carpet_x, carpet_y = field.LENGTH / 2 * M + field.BORDER_STRIP * M, field.WIDTH / 2 * M + field.BORDER_STRIP * M
    hall_x, hall_y = carpet_x + HALL_MARGIN, carpet_y + HALL_MARGIN
    parts: list[FieldPart] = []

    def place(near: float, far: float) -> tuple[float, float, float]:
        """A point on the hall floor ``near`` to ``far`` m beyond the carpet's edge, facing the field."""
        side = rng.integers(4)
        gap = rng.uniform(near, far)
        if side < 2:
            x, y = (carpet_x + gap) * (1 if side == 0 else -1), rng.uniform(-carpet_y, carpet_y)
        else:
            x, y = rng.uniform(-carpet_x, carpet_x), (carpet_y + gap) * (1 if side == 2 else -1)
        return float(x), float(y), float(math.atan2(-y, -x))

    def box(name: str, x: float, y: float, z: float, size: tuple[float, float, float], rgba: tuple[float, ...], yaw: float) -> None:
        parts.append(FieldPart(name, "box", (x, y, z), size, (*rgba[:3], 1.0), collides=False, yaw=yaw))

    for i in range(4):  # tables, some with a case or a laptop-grey box on them
        x, y, yaw = place(0.8, 2.2)
        rgba = TABLE_RGBA[rng.integers(len(TABLE_RGBA))]
        box(f"hall_table{i}", x, y, 0.73, (0.8, 0.4, 0.02), rgba, yaw)
        c, s = math.cos(yaw), math.sin(yaw)
        for j, (lx, ly) in enumerate(((0.75, 0.35), (0.75, -0.35), (-0.75, 0.35), (-0.75, -0.35))):
            box(f"hall_table{i}_leg{j}", x + c * lx - s * ly, y + s * lx + c * ly, 0.355, (0.02, 0.02, 0.355), (0.3, 0.3, 0.3), yaw)
        if rng.random() < 0.6:
            box(f"hall_table{i}_case", x + rng.uniform(-0.4, 0.4), y, 0.9, (0.25, 0.18, 0.15), CASE_RGBA[rng.integers(len(CASE_RGBA))], yaw)
    for i in range(7):  # equipment cases on the floor: dark, as in real halls
        x, y, yaw = place(0.2, 2.5)
        size = (rng.uniform(0.2, 0.45), rng.uniform(0.15, 0.3), rng.uniform(0.12, 0.3))
        box(f"hall_case{i}", x, y, size[2], size, CASE_RGBA[rng.integers(len(CASE_RGBA))], yaw + rng.normal(0.0, 0.3))
    for i in range(8):  # people: two legs, shoes and the lower body of a shirt
        x, y, yaw = place(0.15, 2.5)
        trousers, shirt = TROUSERS[rng.integers(len(TROUSERS))], SHIRTS[rng.integers(len(SHIRTS))]
        c, s = math.cos(yaw), math.sin(yaw)
        for j, side in enumerate((-0.1, 0.1)):
            lx, ly = x - s * side, y + c * side
            parts.append(FieldPart(f"hall_person{i}_leg{j}", "cylinder", (lx, ly, 0.47), (0.07, 0.4), (*trousers, 1.0), collides=False))
            box(f"hall_person{i}_shoe{j}", lx + c * 0.05, ly + s * 0.05, 0.04, (0.14, 0.05, 0.04), (0.1, 0.1, 0.1) if rng.random() < 0.6 else (0.9, 0.9, 0.9), yaw)
        box(f"hall_person{i}_body", x, y, 1.2, (0.12, 0.22, 0.35), shirt, yaw)
    for i in range(3):  # robots waiting beside the field, sitting: white and grey
        x, y, yaw = place(0.1, 0.6)
        c, s = math.cos(yaw), math.sin(yaw)
        box(f"hall_robot{i}_legs", x + c * 0.08, y + s * 0.08, 0.05, (0.12, 0.08, 0.05), (0.85, 0.85, 0.85), yaw)
        box(f"hall_robot{i}_torso", x, y, 0.2, (0.05, 0.08, 0.1), (0.9, 0.9, 0.9), yaw)
        box(f"hall_robot{i}_head", x, y, 0.35, (0.06, 0.065, 0.06), (0.88, 0.88, 0.88), yaw)
        box(f"hall_robot{i}_arms", x, y, 0.2, (0.03, 0.11, 0.08), (0.35, 0.35, 0.37), yaw)
    for i in range(6):  # boards, doors and banners on the walls
        width, height = rng.uniform(0.5, 1.5), rng.uniform(0.5, 1.2)
        colour = tuple(rng.uniform(0.1, 0.9, 3))
        along = rng.uniform(-0.8, 0.8)
        if i % 2:
            box(f"hall_board{i}", (hall_x - 0.06) * (1 if i % 4 == 1 else -1), along * hall_y, height + rng.uniform(0.0, 0.8),
                (0.01, width, height), colour, 0.0)
        else:
            box(f"hall_board{i}", along * hall_x, (hall_y - 0.06) * (1 if i % 4 == 0 else -1), height + rng.uniform(0.0, 0.8),
                (width, 0.01, height), colour, 0.0)
    return parts


def scene_look(seed: int, greens: list[tuple[float, float, float]], texture: float, clutter: bool, nets: bool) -> SceneLook:
    """The scene of run ``seed``: one of ``greens`` for the carpet, the rest as the level says."""
    green = greens[int(np.random.default_rng([seed, 59]).integers(len(greens)))]
    return SceneLook(seed=seed, carpet=tuple(float(c) for c in green), texture=texture, clutter=clutter, nets=nets)  # type: ignore[arg-type]


def level_look(seed: int, level: RealismLevel | None) -> SceneLook | None:
    """The scene of run ``seed`` at a ``--realism`` level (None: the plain scene)."""
    if level is None:
        return None
    return scene_look(seed, level.carpet_greens, level.carpet_texture, level.hall_clutter, level.goal_nets)


def carpet_texture_png(look: SceneLook) -> bytes:
    """``carpet_texture`` as a PNG file, as the engines load it."""
    ok, png = cv2.imencode(".png", cv2.cvtColor(carpet_texture(look), cv2.COLOR_RGB2BGR))
    if not ok:
        raise RuntimeError("OpenCV could not encode the carpet's texture")
    return png.tobytes()


def carpet_texture(look: SceneLook, size: int = 256) -> np.ndarray:
    """One metre of the carpet (``size`` x ``size`` RGB, tiling without seams): its green with fibre
    noise and soft worn patches, seeded; ``look.texture`` is the pattern's strength."""
    rng = np.random.default_rng([look.seed, 61])
    fibres = rng.standard_normal((size, size))
    patches = np.fft.ifft2(np.fft.fft2(rng.standard_normal((size, size))) * _low_pass(size, 10.0)).real
    patches /= max(1e-9, float(patches.std()))
    pattern = 1.0 + look.texture * (0.6 * fibres + 0.4 * patches)
    rgb = np.clip(np.array(look.carpet)[None, None, :] * pattern[:, :, None], 0.0, 1.0)
    return np.round(rgb * 255).astype(np.uint8)


def _low_pass(size: int, wavelength: float) -> np.ndarray:
    """A Gaussian low-pass in the frequency domain keeping patterns longer than ``wavelength`` texels."""
    f = np.fft.fftfreq(size)
    fx, fy = np.meshgrid(f, f)
    return np.exp(-(fx**2 + fy**2) * (wavelength**2) / 2.0)


# ------------------------------------------------------------------------------------- the SPL ball
PENTAGON_RADIUS = math.radians(20.1)  # angular circumradius of a truncated icosahedron's pentagons
BALL_BLACK = 25  # the patches' grey level (0..255): printed black, not a light trap
BALL_WHITE = 240


@cache
def _icosahedron() -> tuple[np.ndarray, np.ndarray]:
    """The 12 vertices (unit vectors) and, for each, the direction to one neighbour in its tangent plane."""
    g = (1 + math.sqrt(5)) / 2
    vertices = np.array([(0, s1, s2 * g) for s1 in (-1, 1) for s2 in (-1, 1)]
                        + [(s1, s2 * g, 0) for s1 in (-1, 1) for s2 in (-1, 1)]
                        + [(s2 * g, 0, s1) for s1 in (-1, 1) for s2 in (-1, 1)], dtype=float)
    vertices /= np.linalg.norm(vertices, axis=1, keepdims=True)
    towards = np.empty_like(vertices)
    for i, v in enumerate(vertices):
        dots = vertices @ v
        dots[i] = -2.0
        neighbour = vertices[int(np.argmax(dots))]
        tangent = neighbour - (neighbour @ v) * v
        towards[i] = tangent / np.linalg.norm(tangent)
    return vertices, towards


def ball_is_black(directions: np.ndarray) -> np.ndarray:
    """Whether each unit direction (..., 3) from the ball's centre hits a black pentagon.

    The pentagons sit at the icosahedron's vertices with their corners towards the neighbouring
    vertices, as on a truncated icosahedron (the classic football): 12 patches, 28 % of the surface.
    """
    vertices, towards = _icosahedron()
    flat = directions.reshape(-1, 3)
    nearest = np.argmax(flat @ vertices.T, axis=1)
    v, e1 = vertices[nearest], towards[nearest]
    e2 = np.cross(v, e1)
    along = np.einsum("ij,ij->i", flat, v)
    # gnomonic projection onto the tangent plane at the pentagon's centre: polygons stay polygons
    px, py = np.einsum("ij,ij->i", flat, e1) / along, np.einsum("ij,ij->i", flat, e2) / along
    radius, angle = np.hypot(px, py), np.arctan2(py, px)
    sector = np.mod(angle + math.pi / 5, 2 * math.pi / 5) - math.pi / 5  # angle from the nearest corner
    inside = radius * np.cos(np.abs(sector) - math.pi / 5) <= math.tan(PENTAGON_RADIUS) * math.cos(math.pi / 5)
    return inside.reshape(directions.shape[:-1])


def _sphere_direction(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Texture coordinates (0..1) -> unit directions; u goes round the equator, v from pole to pole."""
    longitude, latitude = u * 2 * math.pi, (v - 0.5) * math.pi
    return np.stack([np.cos(latitude) * np.cos(longitude), np.cos(latitude) * np.sin(longitude), np.sin(latitude)], axis=-1)


def paint_ball_texture(width: int = 512, height: int = 256) -> np.ndarray:
    """The SPL ball's pattern as an equirectangular RGB image (row 0 at v = 0), 4x4 supersampled.

    Painting takes about a second, so the simulators load the copy shipped in ``assets/`` instead
    (``ball_texture``); a test checks that the copy is what this paints. After a change here, write
    it anew with ``python -m tafel.platforms.field_world``.
    """
    samples = 4
    u = (np.arange(width * samples) + 0.5) / (width * samples)
    v = (np.arange(height * samples) + 0.5) / (height * samples)
    black = ball_is_black(_sphere_direction(*np.meshgrid(u, v)))
    share = black.reshape(height, samples, width, samples).mean(axis=(1, 3))
    grey = np.round(BALL_WHITE + (BALL_BLACK - BALL_WHITE) * share).astype(np.uint8)
    return np.repeat(grey[:, :, None], 3, axis=2)


#: the painted ball texture as shipped (a PNG, RGB)
BALL_TEXTURE_PATH = Path(__file__).resolve().parent / "assets" / "ball_texture.png"


@cache
def ball_texture_png() -> bytes:
    """The shipped ball texture's PNG file, as the engines load it."""
    return BALL_TEXTURE_PATH.read_bytes()


@cache
def ball_texture() -> np.ndarray:
    """The shipped ball texture as an RGB image (what ``paint_ball_texture`` paints)."""
    image = cv2.imdecode(np.frombuffer(ball_texture_png(), np.uint8), cv2.IMREAD_COLOR)
    return cv2.cvtColor(image, cv2.COLOR_BGR2RGB)


@cache
def ball_mesh(radius: float, rings: int = 24, segments: int = 48) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A UV sphere: vertices (m), unit normals, texture coordinates (u, v) and triangles (vertex indices).

    The seam's vertices are doubled (u = 0 and u = 1) so that the texture does not wrap backwards.
    """
    u, v = np.meshgrid(np.linspace(0.0, 1.0, segments + 1), np.linspace(0.0, 1.0, rings + 1))
    normals = _sphere_direction(u, v).reshape(-1, 3)
    uvs = np.stack([u.ravel(), v.ravel()], axis=1)
    triangles = []
    for ring in range(rings):
        for segment in range(segments):
            a = ring * (segments + 1) + segment
            b, c, d = a + 1, a + segments + 1, a + segments + 2
            if ring > 0:
                triangles.append((a, b, d))
            if ring < rings - 1:
                triangles.append((a, d, c))
    return normals * radius, normals, uvs, np.array(triangles, dtype=np.int64)


@cache
def cylinder_mesh(radius: float, half_height: float, segments: int = 24) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A closed cylinder along z: vertices (m), unit normals and triangles. The side has its own
    vertices with outward normals (PyBullet's built-in cylinder shades flat grey in its CPU renderer)."""
    angles = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    ring = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(segments)])
    side = np.vstack([ring * radius + [0, 0, -half_height], ring * radius + [0, 0, half_height]])
    caps = np.vstack([side, [[0, 0, -half_height], [0, 0, half_height]]])
    vertices = np.vstack([side, caps])
    normals = np.vstack([ring, ring, np.tile([0, 0, -1.0], (segments, 1)), np.tile([0, 0, 1.0], (segments, 1)), [[0, 0, -1.0], [0, 0, 1.0]]])
    triangles = []
    for i in range(segments):
        j = (i + 1) % segments
        triangles += [(i, j, segments + j), (i, segments + j, segments + i)]  # the side, counter-clockwise from outside
        base, bottom, top = 2 * segments, 4 * segments, 4 * segments + 1
        triangles += [(bottom, base + j, base + i), (top, base + segments + i, base + segments + j)]
    return vertices, normals, np.array(triangles, dtype=np.int64)


if __name__ == "__main__":  # python -m tafel.platforms.field_world: paint the ball texture anew into assets/
    BALL_TEXTURE_PATH.parent.mkdir(exist_ok=True)
    ok, png = cv2.imencode(".png", cv2.cvtColor(paint_ball_texture(), cv2.COLOR_RGB2BGR), [cv2.IMWRITE_PNG_COMPRESSION, 9])
    assert ok, "OpenCV could not encode the ball texture"
    BALL_TEXTURE_PATH.write_bytes(png.tobytes())
    print(f"wrote {BALL_TEXTURE_PATH} ({len(png)} bytes)")
