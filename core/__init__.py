"""Tafel core: representations, blackboard, modules and the module manager.

Depends on nothing else in the project; everything else depends on it. Its wings: ``framework``
(representations, modules, the manager, parameters, configuration), ``runtime`` (the runtimes,
platforms, clock, hand-overs), ``logs`` (serialization, MCAP logs, recording, the black box) and
``testing`` (the module harness and the pytest plugin). Names a module author needs are here.
"""

from tafel.core import _moved  # noqa: F401 - first: old import paths (tafel.core.manager, ...) keep working
from tafel.core.framework.access import ReadOnlyArray
from tafel.core.framework.errors import (
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
from tafel.core.framework.graph import prune_unsatisfiable
from tafel.core.framework.manager import Blackboard, ModuleManager, ModuleTiming
from tafel.core.framework.module import Module, Requirements, provides, requires, uses
from tafel.core.framework.naming import snake_case
from tafel.core.framework.representation import (
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
from tafel.core.logs.serialization import SerializationError, deserialize, schema_of, serialize

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
