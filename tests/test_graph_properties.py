"""Properties of the module graph over random configurations."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core import DependencyCycleError, Module, ModuleGraphError, ModuleManager, provides, representation, requires

POOL = [representation(type(f"PropRep{i}", (), {"__annotations__": {"v": int}, "__module__": __name__})) for i in range(8)]


@st.composite
def random_graphs(draw) -> list[type]:
    """Modules M0..Mn-1; Mi provides PropRep i and requires a random subset of the others."""
    n = draw(st.integers(2, len(POOL)))
    modules = []
    for i in range(n):
        others = [j for j in range(n) if j != i]
        needs = draw(st.lists(st.sampled_from(others), unique=True, max_size=3)) if others else []
        cls = type(f"PropModule{i}", (Module,), {"execute": lambda self: None})
        cls = provides(POOL[i])(cls)
        if needs:
            cls = requires(*(POOL[j] for j in needs))(cls)
        modules.append(cls)
    order = draw(st.permutations(modules))
    return list(order)


def edges(modules: list[type]) -> list[tuple[str, str, str]]:
    """(provider, representation, requirer) for every requires edge."""
    provider = {m.requirements().provides[0]: m.__name__ for m in modules}
    return [
        (provider[rep], rep.__name__, m.__name__)
        for m in modules
        for rep in m.requirements().requires
    ]


@settings(max_examples=200, deadline=None)
@given(random_graphs())
def test_order_respects_every_requires_edge_or_a_real_cycle_is_reported(modules: list[type]) -> None:
    try:
        manager = ModuleManager(modules)
    except DependencyCycleError as error:
        cycle = error.cycle
        assert len(cycle) >= 2
        known = set(edges(modules))
        for (module, rep), (next_module, _) in zip(cycle, cycle[1:] + cycle[:1]):
            assert (module, rep, next_module) in known, f"{module}.{rep} -> {next_module} is no edge"
        assert " -> ".join(f"{m}.{r}" for m, r in cycle) in str(error)
        return
    position = {name: i for i, name in enumerate(manager.order)}
    assert sorted(manager.order) == sorted(m.__name__ for m in modules)
    for source, _rep, target in edges(modules):
        assert position[source] < position[target]


@settings(max_examples=200, deadline=None)
@given(random_graphs(), st.data())
def test_failed_reconfiguration_changes_nothing(modules: list[type], data) -> None:
    try:
        manager = ModuleManager(modules)
    except ModuleGraphError:
        return
    manager.execute()
    for _ in range(4):
        name = data.draw(st.sampled_from([m.__name__ for m in modules]))
        enabled = data.draw(st.booleans())
        state = (manager.order, manager.disabled, manager.providers, [id(manager.module(n)) for n in manager.order])
        try:
            manager.set_enabled(name, enabled)
        except ModuleGraphError:
            after = (manager.order, manager.disabled, manager.providers, [id(manager.module(n)) for n in manager.order])
            assert after == state
        manager.execute()
