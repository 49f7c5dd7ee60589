"""The ``tafel`` command line (``python -m tafel.tools.cli``): its arguments (``arguments.py``), the
dispatch to each subcommand's code (``dispatch.py``), and the listings of platforms and modules."""

from tafel.tools.cli.dispatch import main

__all__ = ["main"]
