"""The program's two contexts as an enum: every name of a context that comes from outside (a debug
command's ``-context``, a configuration section, a recorded topic's prefix, a black-box trigger, a
``tafel`` option) is converted through ``Context.of``, so that a misspelt one (``Motion``) is an error
instead of a context that silently matches nothing."""

from __future__ import annotations

import enum

from tafel.core.framework.values import ValueCheckError, convert

__all__ = ["CONTEXT_NAMES", "Context"]


class Context(enum.StrEnum):
    """Cognition (the images, the world model, behavior; 30 Hz) and motion (the joints; 100 Hz).

    A ``StrEnum``: ``Context.motion == "motion"``, it formats as ``motion`` and keys dicts like the
    string. Names are taken as written, like cameras' (``"Motion"`` is refused, not guessed)."""

    cognition = "cognition"
    motion = "motion"

    @classmethod
    def of(cls, name: object, where: str = "context", error: type[Exception] = ValueCheckError) -> Context:
        """``name`` as a ``Context``, else ``error``: ``<where> takes cognition or motion, got 'Motion'``."""
        context: Context = convert(name, cls, where=where, text=False, expected=" or ".join(cls.__members__), error=error)
        return context

    @property
    def other(self) -> Context:
        """The other context (motion's is cognition)."""
        return Context.cognition if self is Context.motion else Context.motion


#: the contexts' names, in the order of the configuration's sections
CONTEXT_NAMES: tuple[str, ...] = tuple(c.value for c in Context)
