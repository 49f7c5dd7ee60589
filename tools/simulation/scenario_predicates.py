"""The predicates a scenario's success condition is built from, over ground truth and representations.

Each ``[[success]]`` entry of a scenario file names one predicate and its parameters. A predicate of
kind *eventually* must hold at some moment between ``after_s`` and ``within_s`` (for ``for_s`` without
a break, if given); one of kind *always* must hold at every tick from ``after_s`` until ``within_s``
or the run's end.
A run succeeds, and ends, when every *eventually* predicate has held; it fails, and ends, when an
*always* predicate breaks or a deadline passes.

Ground truth comes from the simulator (where the robot and the ball really are, the torso's posture);
representations come from the program's blackboards. All positions are field coordinates (mm, origin
at the centre spot, x towards the opponent goal), angles in degrees.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from tafel.representations import field as pitch
from tafel.representations.geometry import Pose2D

#: mm of torso height above which an upright torso counts as standing (the NAO stands at about 330)
STANDING_TORSO_MM = 250.0


class World(Protocol):
    """What a predicate may look at: the simulator's truth and the program's blackboards."""

    def ball(self) -> tuple[float, float]: ...
    def robot(self) -> tuple[float, float, float]: ...  # x mm, y mm, heading rad
    def posture(self) -> str: ...
    def torso_height(self) -> float: ...
    def representation(self, name: str, context: str) -> Any: ...


#: the default of a parameter a file must give
REQUIRED: Any = object()


@dataclass(frozen=True)
class Parameter:
    """One parameter of a predicate: its kind (as in scenario files), meaning and default (None: may be left out)."""

    kind: str
    meaning: str
    default: Any = REQUIRED


@dataclass(frozen=True)
class PredicateKind:
    summary: str
    when: str  # "eventually" or "always"
    parameters: Mapping[str, Parameter]
    test: Callable[[World, Mapping[str, Any]], bool]


def _robot_near(world: World, p: Mapping[str, Any]) -> bool:
    x, y, heading = world.robot()
    if math.hypot(x - p["x_mm"], y - p["y_mm"]) > p["within_mm"]:
        return False
    if p.get("rotation_deg") is None:
        return True
    return abs(math.degrees(math.remainder(heading - math.radians(p["rotation_deg"]), math.tau))) <= p["within_deg"]


def _robot_near_ball(world: World, p: Mapping[str, Any]) -> bool:
    (x, y, _), (bx, by) = world.robot(), world.ball()
    return math.hypot(bx - x, by - y) <= p["within_mm"]


def _ball_model_accurate(world: World, p: Mapping[str, Any]) -> bool:
    model = world.representation("BallModel", "cognition")
    if not model.valid:
        return False
    robot, (bx, by) = world.robot(), world.ball()
    seen_x, seen_y = Pose2D(*robot).to_global(model.x, model.y)
    return math.hypot(seen_x - bx, seen_y - by) <= p["within_mm"]


def _representation(world: World, p: Mapping[str, Any]) -> bool:
    value: Any = world.representation(p["name"], p["context"])
    for part in p["field"].split("."):
        value = getattr(value, part)
    value = getattr(value, "name", value)  # enums compare by their names, as files write them
    if p.get("equals") is not None and value != p["equals"]:
        return False
    if p.get("at_least") is not None and not value >= p["at_least"]:
        return False
    return not (p.get("at_most") is not None and not value <= p["at_most"])


def _upright(world: World, _p: Mapping[str, Any]) -> bool:
    return world.posture() == "upright" and world.torso_height() > STANDING_TORSO_MM


def _in_range(value: float, bounds: tuple[float, float]) -> bool:
    return bounds[0] <= value <= bounds[1]


PREDICATES: dict[str, PredicateKind] = {
    "ball_in_goal": PredicateKind(
        "the ball is wholly over the goal line between the posts", "eventually",
        {"goal": Parameter("string", "'opponent' (at +x) or 'own'", "opponent")},
        lambda w, p: pitch.goal_of(*w.ball()) == (1 if p["goal"] == "opponent" else -1)),
    "ball_in_area": PredicateKind(
        "the ball lies in a rectangle of the field", "eventually",
        {"x_mm": Parameter("range", "[low, high] of x"), "y_mm": Parameter("range", "[low, high] of y")},
        lambda w, p: _in_range(w.ball()[0], p["x_mm"]) and _in_range(w.ball()[1], p["y_mm"])),
    "robot_near": PredicateKind(
        "the robot stands within within_mm of (x_mm, y_mm), and within within_deg of rotation_deg if given", "eventually",
        {"x_mm": Parameter("number", "x of the place"), "y_mm": Parameter("number", "y of the place"),
         "within_mm": Parameter("number", "how near", 200.0), "rotation_deg": Parameter("number", "heading, if it matters", None),
         "within_deg": Parameter("number", "how near the heading", 15.0)},
        _robot_near),
    "robot_near_ball": PredicateKind(
        "the robot's torso is within within_mm of the ball", "eventually",
        {"within_mm": Parameter("number", "how near", 250.0)}, _robot_near_ball),
    "ball_model_accurate": PredicateKind(
        "BallModel is valid and places the ball within within_mm of where it really is", "eventually",
        {"within_mm": Parameter("number", "how near", 300.0)}, _ball_model_accurate),
    "representation": PredicateKind(
        "a representation's field equals a value, or is at least or at most one", "eventually",
        {"name": Parameter("string", "the representation, e.g. 'BallModel'"),
         "field": Parameter("string", "its field, e.g. 'valid' (dots reach into nested fields)"),
         "context": Parameter("string", "'cognition' or 'motion'", "cognition"),
         "equals": Parameter("value", "the value it must have (an enum by its name)", None),
         "at_least": Parameter("number", "the least it may be", None), "at_most": Parameter("number", "the most it may be", None)},
        _representation),
    "upright": PredicateKind("the robot stands: torso upright and above 250 mm (ground truth)", "eventually", {}, _upright),
    "fallen": PredicateKind("the robot is down: its torso is not upright (ground truth)", "eventually", {},
                            lambda w, p: w.posture() != "upright"),
    "no_fall": PredicateKind("the torso stays upright (ground truth) at every tick", "always", {},
                             lambda w, p: w.posture() == "upright"),
}
#: parameters every predicate takes: when it is checked (s of the run)
TIMING = {
    "after_s": Parameter("number", "checked from this time on", 0.0),
    "within_s": Parameter("number", "an 'eventually' predicate's deadline, an 'always' one's end (default: the duration)", math.inf),
    "for_s": Parameter("number", "how long it must hold without a break", 0.0),
}
