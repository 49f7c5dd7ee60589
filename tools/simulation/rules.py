"""What the SPL rules fix for a simulated match that the command line checks too (standard library only)."""

from __future__ import annotations

#: robots a team may field in ``tafel match`` (the SPL's five)
MAX_PLAYERS_PER_TEAM = 5
