"""Tafel core: representations, blackboard, modules and the module manager.

Depends on nothing else in the project; everything else depends on it.
"""

from tafel.core.access import ReadOnlyArray
from tafel.core.errors import (
    ConflictingProvidersError,
    DependencyCycleError,
    MissingProviderError,
    ModuleDefinitionError,
    ModuleGraphError,
    ReadOnlyRepresentationError,
    RepresentationDefinitionError,
    TafelError,
    UnknownModuleError,
)
from tafel.core.graph import prune_unsatisfiable
from tafel.core.manager import Blackboard, ModuleManager, ModuleTiming
from tafel.core.module import Module, Requirements, provides, requires, uses
from tafel.core.naming import snake_case
from tafel.core.representation import (
    array,
    bounded,
    fields_of,
    get_representation,
    is_representation,
    is_state,
    registered_representations,
    representation,
    values_equal,
)
from tafel.core.serialization import SerializationError, deserialize, schema_of, serialize

__all__ = [
    "Blackboard",
    "ConflictingProvidersError",
    "DependencyCycleError",
    "MissingProviderError",
    "Module",
    "ModuleDefinitionError",
    "ModuleGraphError",
    "ModuleManager",
    "ModuleTiming",
    "ReadOnlyArray",
    "ReadOnlyRepresentationError",
    "RepresentationDefinitionError",
    "Requirements",
    "SerializationError",
    "TafelError",
    "UnknownModuleError",
    "array",
    "bounded",
    "deserialize",
    "fields_of",
    "get_representation",
    "is_representation",
    "is_state",
    "prune_unsatisfiable",
    "provides",
    "registered_representations",
    "representation",
    "requires",
    "schema_of",
    "serialize",
    "snake_case",
    "uses",
    "values_equal",
]
