"""The RoboCup SPL field in numbers (mm, field frame: origin at the centre spot, x towards the
opponent goal, y left). Shared by modules and the simulated worlds."""

from __future__ import annotations

LENGTH = 9000.0
WIDTH = 6000.0
LINE_WIDTH = 50.0
BORDER_STRIP = 700.0
CENTER_CIRCLE_DIAMETER = 1500.0
PENALTY_AREA_LENGTH = 1650.0
PENALTY_AREA_WIDTH = 4000.0
GOAL_AREA_LENGTH = 600.0
GOAL_AREA_WIDTH = 2200.0
PENALTY_MARK_DISTANCE = 1300.0
GOAL_INNER_WIDTH = 1500.0
GOAL_POST_DIAMETER = 100.0
GOAL_HEIGHT = 800.0
GOAL_DEPTH = 500.0
BALL_RADIUS = 50.0
BALL_MASS = 0.044  # kg
