"""Errors of the module framework. Every message says what is wrong and how to fix it."""

from __future__ import annotations


class TafelError(Exception):
    """Base of all errors raised by Tafel itself."""


class RepresentationDefinitionError(TafelError, TypeError):
    """A representation class cannot be used as written (unsupported field type, duplicate name)."""


class ModuleDefinitionError(TafelError, TypeError):
    """A module class declares something impossible (not a representation, requires what it provides)."""


class ReadOnlyRepresentationError(TafelError, AttributeError):
    """A module wrote to a representation it only requires or uses."""

    def __init__(self, module: str, representation: str, path: str = "") -> None:
        self.module = module
        self.representation = representation
        self.path = path
        where = f"{representation}{path}" if path else representation
        super().__init__(
            f"{module} wrote to {where}, but it only requires or uses {representation}, which is "
            f"read-only for it. Only the module that provides {representation} may change it; "
            f"copy the value into a local variable, or declare @provides({representation}) if this "
            "module is meant to compute it."
        )


class ModuleGraphError(TafelError):
    """The module configuration cannot form a valid frame; raised before anything runs."""


class MissingProviderError(ModuleGraphError):
    """A module requires or uses a representation that nothing provides."""


class DependencyCycleError(ModuleGraphError):
    """The requires-edges form a cycle, so no execution order exists."""

    def __init__(self, message: str, cycle: list[tuple[str, str]]) -> None:
        super().__init__(message)
        #: the cycle as (module, representation it provides to the next module) pairs
        self.cycle = cycle


class ConflictingProvidersError(ModuleGraphError):
    """More than one provider for one representation and no choice was made."""


class UnknownModuleError(ModuleGraphError, KeyError):
    """A name that should denote a module (or representation) denotes none."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""
