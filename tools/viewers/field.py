"""The field's geometry as the pages draw it (the web view and TeamControl ask ``field:geometry``)."""

from __future__ import annotations

from typing import Any

from tafel.representations import field


def field_geometry() -> dict[str, Any]:
    """What a view needs to draw the field to scale (``tafel.representations.field``)."""
    return {"length": field.LENGTH, "width": field.WIDTH, "border": field.BORDER_STRIP, "line_width": field.LINE_WIDTH,
            "lines": [list(s) for s in field.line_segments()],
            "circle": {"x": 0.0, "y": 0.0, "radius": field.CENTER_CIRCLE_DIAMETER / 2},
            "marks": [list(c) for c in field.mark_centres()], "mark_size": field.MARK_SIZE,
            "posts": [list(p) for p in field.goal_post_positions()], "post_radius": field.GOAL_POST_DIAMETER / 2,
            "goal_depth": field.GOAL_DEPTH, "ball_radius": field.BALL_RADIUS}
