"""Representations: the data that modules exchange, grouped by area.

Coordinate convention (the only one in Tafel):
- Robot frame: origin on the ground between the feet, x forward, y left, z up (right-handed).
- Field frame: origin at the centre spot, x towards the opponent goal, y left.
- Lengths in millimetres (mm), angles in radians (rad), time in seconds (s) unless a field name says
  otherwise (``time_ns``). Image coordinates in pixels (px), origin at the top-left corner, x right,
  y down.
"""


def load_all() -> None:
    """Import every representation file, so that all of them are registered by name (logs need that)."""
    import importlib
    import pkgutil

    for info in pkgutil.walk_packages(__path__, prefix=__name__ + "."):
        importlib.import_module(info.name)
