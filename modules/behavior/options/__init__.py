"""Behaviour written as options: small state machines that call each other (see ``framework``), and the
soccer behaviour's options (``soccer``)."""

from tafel.modules.behavior.options.framework import Next, Option, OptionError, OptionRunner, common, state

__all__ = ["Next", "Option", "OptionError", "OptionRunner", "common", "state"]
