"""The defaults of a run that the command line shows in its help: standard library only, so that
building the parser (``tafel --help``) stays cheap."""

from __future__ import annotations

from pathlib import Path

#: the default configuration, shipped inside the package (the repository's config/ folder)
DEFAULT_CONFIG = Path(__file__).resolve().parent.parent.parent / "config"
FALLBACK_PLATFORM = "dummy"
DEFAULT_DEBUG_PORT = 5401
DEFAULT_FOXGLOVE_PORT = 8765
DEFAULT_WEB_PORT = 5480
