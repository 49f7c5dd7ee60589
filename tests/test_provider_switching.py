"""Provider switching can always be undone: a hypothesis state machine over enable, disable and switch."""

from __future__ import annotations

from hypothesis import settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, invariant, rule

from tafel.core import Module, ModuleGraphError, ModuleManager, provides, representation, requires


@representation
class SwitchInput:
    value: float = 0.0


@representation
class SwitchModel:
    value: float = 0.0


@representation
class SwitchDecision:
    value: float = 0.0


@requires(SwitchInput)
@provides(SwitchModel)
class SwitchFirst(Module):
    def execute(self) -> None:
        self.switch_model.value = 1.0


@requires(SwitchInput)
@provides(SwitchModel)
class SwitchSecond(Module):
    def execute(self) -> None:
        self.switch_model.value = 2.0


@requires(SwitchInput)
@provides(SwitchModel)
class SwitchThird(Module):
    def execute(self) -> None:
        self.switch_model.value = 3.0


@requires(SwitchModel)
@provides(SwitchDecision)
class SwitchUser(Module):
    def execute(self) -> None:
        self.switch_decision.value = self.switch_model.value


PROVIDERS = ["SwitchFirst", "SwitchSecond", "SwitchThird"]
MODULES = [*PROVIDERS, "SwitchUser"]
VALUES = {"SwitchFirst": 1.0, "SwitchSecond": 2.0, "SwitchThird": 3.0}


def make_manager() -> ModuleManager:
    return ModuleManager([SwitchFirst, SwitchSecond, SwitchThird, SwitchUser], external=[SwitchInput],
                         providers={"SwitchModel": "SwitchFirst"})


def test_disabling_the_chosen_provider_and_enabling_it_again_brings_the_choice_back() -> None:
    manager = make_manager()
    manager.set_enabled("SwitchThird", False)
    manager.set_provider("SwitchModel", "SwitchSecond")
    manager.set_enabled("SwitchSecond", False)  # the one provider left takes over meanwhile
    manager.execute()
    assert manager.blackboard[SwitchDecision].value == 1.0
    manager.set_enabled("SwitchSecond", True)  # before the fix the choice was gone, and this failed
    manager.execute()
    assert manager.providers["SwitchModel"] == "SwitchSecond"
    assert manager.blackboard[SwitchDecision].value == 2.0
    manager.set_provider("SwitchModel", "SwitchThird")  # switching to a disabled module enables it
    manager.execute()
    assert manager.blackboard[SwitchDecision].value == 3.0 and "SwitchThird" not in manager.disabled


class Switching(RuleBasedStateMachine):
    """The model: the user's choice and the disabled set; the manager must follow it exactly."""

    def __init__(self) -> None:
        super().__init__()
        self.manager = make_manager()
        self.choice = "SwitchFirst"
        self.disabled: set[str] = set()
        self.history: list[tuple[str, frozenset[str], list[str]]] = []

    def expected_provider(self, choice: str, disabled: set[str]) -> str | None:
        if choice not in disabled:
            return choice
        running = [m for m in PROVIDERS if m not in disabled]
        return running[0] if len(running) == 1 else None  # several left and none chosen: ambiguous

    def attempt(self, change, choice: str, disabled: set[str]) -> None:
        before = (self.manager.order, self.manager.providers, self.manager.disabled)
        try:
            change()
        except ModuleGraphError:
            assert (self.manager.order, self.manager.providers, self.manager.disabled) == before  # nothing changed
            return
        self.choice, self.disabled = choice, disabled

    @rule(module=st.sampled_from(PROVIDERS))
    def switch(self, module: str) -> None:
        self.attempt(lambda: self.manager.set_provider("SwitchModel", module), module, self.disabled - {module})

    @rule(module=st.sampled_from(MODULES), enabled=st.booleans())
    def enable(self, module: str, enabled: bool) -> None:
        disabled = self.disabled - {module} if enabled else self.disabled | {module}
        self.attempt(lambda: self.manager.set_enabled(module, enabled), self.choice, disabled)

    @rule(module=st.sampled_from(MODULES))
    def disable_then_enable(self, module: str) -> None:
        """A disable followed by an enable leaves everything as it was."""
        if module in self.disabled:
            return
        before = (self.manager.order, self.manager.providers, self.manager.disabled)
        try:
            self.manager.set_enabled(module, False)
        except ModuleGraphError:
            return
        self.manager.set_enabled(module, True)
        assert (self.manager.order, self.manager.providers, self.manager.disabled) == before

    @invariant()
    def follows_the_model(self) -> None:
        assert self.manager.providers.get("SwitchModel") == self.choice
        assert self.manager.disabled == self.disabled
        self.manager.execute()
        if "SwitchUser" not in self.disabled:
            provider = self.expected_provider(self.choice, self.disabled)
            assert self.manager.blackboard[SwitchDecision].value == VALUES[provider]


TestSwitching = Switching.TestCase
TestSwitching.settings = settings(max_examples=60, stateful_step_count=25)
