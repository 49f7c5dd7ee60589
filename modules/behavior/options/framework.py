"""Behaviour as a graph of options, each a small state machine (XABSL at NaoTH, CABSL at B-Human), in
plain Python.

An option is a class; its states are methods marked ``@state``. A state's method first checks its
transitions (``return "other_state"``) and then does its action: it writes the module's outputs or calls
other options (``self.call(Other, x=1.0)``). Conditions may use ``self.time_in_state`` and
``self.time_in_option`` (s). A method marked ``@common`` holds the transitions every state has; it is
checked first. Every transition and every call is declared (``@state(to=...)``, ``calls = (...)``), so
the graph can be drawn before it runs, and a transition or call that was not declared is an error::

    class Kick(Option["MyBehavior"]):
        '''Walk behind the ball, then kick it.'''

        @state(initial=True, to=("kick",))
        def approach(self, b: MyBehavior) -> Next:
            if b.ball_in_front():
                return "kick"
            b.walk_to_ball()

        @state(final=True, to=("approach",))
        def kick(self, b: MyBehavior) -> Next:
            if self.time_in_state > 2.0 and not b.ball_in_front():
                return "approach"
            b.kick()

An option that was not active in the previous frame starts again in its initial state. A transition
takes effect at once: the new state's method runs in the same frame (so its action, not the old one's,
is what the frame does).
"""

from __future__ import annotations

import dataclasses
import inspect
from collections.abc import Callable, Iterable
from typing import Any, ClassVar, Generic, TypeVar, cast

from tafel.core import TafelError
from tafel.representations.behavior import ActivationGraph, ActiveOption, OptionGraph, OptionInfo, OptionState

B = TypeVar("B")
Next = str | None
"""What a state's method returns: the name of the state to go to, or None to stay."""

StateMethod = Callable[[Any, Any], Next]


class OptionError(TafelError):
    """An option graph that is written wrongly, or an option that did something it did not declare."""


@dataclasses.dataclass(frozen=True)
class StateSpec:
    """What ``@state`` records on a method."""

    name: str
    doc: str
    initial: bool
    final: bool
    to: tuple[str, ...]


def _doc(thing: Any) -> str:
    return inspect.cleandoc(thing.__doc__ or "").split("\n\n")[0].replace("\n", " ")


def state(method: StateMethod | None = None, *, initial: bool = False, final: bool = False,
          to: Iterable[str] = ()) -> Any:
    """Mark an option's method as a state. ``initial``: where the option starts (exactly one state);
    ``final``: the option has done its job there (``call`` tells the caller); ``to``: the states its
    method may return. Usable as ``@state`` or ``@state(initial=True, to=("b",))``."""
    if isinstance(to, str):
        raise OptionError(f"@state(to={to!r}): give a tuple of state names, e.g. to=({to!r},)")

    def mark(function: StateMethod) -> StateMethod:
        function.__tafel_state__ = StateSpec(function.__name__, _doc(function), initial, final, tuple(to))  # type: ignore[attr-defined]
        return function

    return mark(method) if method is not None else mark


def common(*, to: Iterable[str]) -> Callable[[StateMethod], StateMethod]:
    """Mark an option's method as the transitions of every state, checked before the state's own. It
    returns a state name or None; returning the state the option is in changes nothing."""

    def mark(function: StateMethod) -> StateMethod:
        function.__tafel_common__ = tuple(to)  # type: ignore[attr-defined]
        return function

    return mark


class Option(Generic[B]):
    """Base class of options. ``B`` is what every state's method gets: the behaviour module, with its
    blackboard, parameters and helpers. ``calls``: the options its states may call. ``Args``: a dataclass
    of the parameters a caller gives (``self.args`` in the states; None when the option takes none)."""

    calls: ClassVar[tuple[type[Option[Any]], ...]] = ()
    Args: ClassVar[type | None] = None

    #: filled by the class definition: state name -> (spec, method)
    states: ClassVar[dict[str, tuple[StateSpec, StateMethod]]]
    initial_state: ClassVar[str]
    common_transitions: ClassVar[tuple[StateMethod, tuple[str, ...]] | None]

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls.states = {}
        commons: list[tuple[StateMethod, tuple[str, ...]]] = []
        for _, member in inspect.getmembers(cls, callable):
            spec = getattr(member, "__tafel_state__", None)
            if spec is not None:  # marked by @state, which takes state methods only
                cls.states[spec.name] = (spec, cast(StateMethod, member))
            if hasattr(member, "__tafel_common__"):
                commons.append((cast(StateMethod, member), member.__tafel_common__))
        where = f"option {cls.__name__}"
        if not cls.states:
            raise OptionError(f"{where} has no state: mark at least one method with @state(initial=True)")
        initial = [name for name, (spec, _) in cls.states.items() if spec.initial]
        if len(initial) != 1:
            raise OptionError(f"{where} needs exactly one initial state, has {len(initial)} ({', '.join(initial) or 'none'}): "
                              "mark one with @state(initial=True)")
        if len(commons) > 1:
            raise OptionError(f"{where} has {len(commons)} @common methods; put the common transitions into one")
        cls.initial_state, cls.common_transitions = initial[0], commons[0] if commons else None
        for name, targets in [(n, spec.to) for n, (spec, _) in cls.states.items()] + [("@common", c[1]) for c in commons]:
            unknown = [t for t in targets if t not in cls.states]
            if unknown:
                raise OptionError(f"{where}: {name} may go to {', '.join(unknown)}, which is no state; it has "
                                  f"{', '.join(cls.states)}")
        if cls.Args is not None and not dataclasses.is_dataclass(cls.Args):
            raise OptionError(f"{where}: Args must be a @dataclass of the option's parameters")

    def __init__(self) -> None:
        self.state = self.initial_state
        self.args: Any = None
        self.option_start = 0.0
        self.state_start = 0.0
        self.now = 0.0
        self.runner: OptionRunner[B] | None = None

    @property
    def time_in_state(self) -> float:
        """s since the option entered the state it is in."""
        return self.now - self.state_start

    @property
    def time_in_option(self) -> float:
        """s since the option became active."""
        return self.now - self.option_start

    @property
    def done(self) -> bool:
        """Whether the option is in a final state."""
        return self.states[self.state][0].final

    def call(self, option: type[Option[B]], **args: Any) -> bool:
        """Run ``option`` this frame, below this one, with ``args`` as its ``Args``; whether it is done
        (in a final state) afterwards."""
        if option not in self.calls:
            raise OptionError(f"option {type(self).__name__} (state {self.state}) calls {option.__name__}, which it does not "
                              f"declare: add it to {type(self).__name__}.calls")
        assert self.runner is not None, "an option runs only inside an OptionRunner"
        return self.runner.execute(option, args)

    @classmethod
    def describe(cls) -> OptionInfo:
        """The option as written, for the drawn graph."""
        return OptionInfo(name=cls.__name__, doc=_doc(cls),
                          states=[OptionState(name=s.name, doc=s.doc, initial=s.initial, final=s.final, to=list(s.to))
                                  for s, _ in sorted(cls.states.values(), key=lambda item: _line(item[1]))],
                          common=list(cls.common_transitions[1]) if cls.common_transitions else [],
                          calls=[o.__name__ for o in cls.calls])


def _line(method: StateMethod) -> int:
    """Where a method is written, so that states are listed in the order of the source."""
    return method.__code__.co_firstlineno


def format_args(args: Any) -> str:
    """``name=value`` of each field of an option's Args, numbers rounded for reading."""
    if args is None:
        return ""
    parts = []
    for item in dataclasses.fields(args):
        value = getattr(args, item.name)
        text = f"{value:.4g}" if isinstance(value, float) else value.name if hasattr(value, "name") and hasattr(value, "value") else str(value)
        parts.append(f"{item.name}={text}")
    return " ".join(parts)


class OptionRunner(Generic[B]):
    """Runs an option graph from ``root`` once a frame and says which options were active.

    One instance of each option class; an option runs at most once a frame. The whole graph is checked
    when the runner is made (every option reachable through ``calls``)."""

    MAX_TRANSITIONS = 16  # per option and frame: more is a loop of transitions

    def __init__(self, root: type[Option[B]]) -> None:
        self.root = root
        self.instances: dict[type[Option[Any]], Option[Any]] = {}
        pending = [root]
        while pending:
            option = pending.pop()
            if option in self.instances:
                continue
            if not (isinstance(option, type) and issubclass(option, Option)):
                raise OptionError(f"{option!r} is called as an option but is no Option subclass")
            self.instances[option] = option()
            self.instances[option].runner = self
            pending.extend(option.calls)
        self.behaviour: Any = None
        self.now = 0.0
        self.active: list[ActiveOption] = []
        self.active_classes: list[type[Option[Any]]] = []
        self.last_active: set[type[Option[Any]]] = set()
        self.depth = 0

    def graph(self) -> OptionGraph:
        """The static graph, every option reachable from the root (in the order they are first called)."""
        order: list[type[Option[Any]]] = []
        pending = [self.root]
        while pending:
            option = pending.pop(0)
            if option not in order:
                order.append(option)
                pending.extend(option.calls)
        return OptionGraph(root=self.root.__name__, options=[option.describe() for option in order])

    def run(self, behaviour: B, now: float, out: ActivationGraph | None = None) -> ActivationGraph:
        """One frame: run the root with ``behaviour`` at ``now`` (s); the active options, root first, in
        ``out`` (or a new ``ActivationGraph``)."""
        self.behaviour, self.now = behaviour, now
        self.active, self.active_classes = [], []
        self.execute(self.root, {})
        self.last_active = set(self.active_classes)
        graph = out if out is not None else ActivationGraph()
        graph.options = self.active
        return graph

    def execute(self, option_class: type[Option[Any]], args: dict[str, Any]) -> bool:
        """Run one option (called by ``Option.call``)."""
        name = option_class.__name__
        if option_class in self.active_classes:
            raise OptionError(f"option {name} is called twice in one frame (the second time by "
                              f"{self.active_classes[-1].__name__}); an option is active once at most")
        option = self.instances[option_class]
        option.args = self.make_args(option_class, args)
        option.now = self.now
        if option_class not in self.last_active:  # (re)activated: from the start
            option.state, option.option_start, option.state_start = option.initial_state, self.now, self.now
        depth = self.depth
        record = ActiveOption(name=name, depth=depth, parameters=format_args(option.args))
        self.active.append(record)
        self.active_classes.append(option_class)
        first_child = len(self.active)
        self.depth = depth + 1
        try:
            for _ in range(self.MAX_TRANSITIONS):
                target = self.transition(option)
                if target is None:
                    break
                # a state left this frame: what it called before returning is not part of the frame
                del self.active[first_child:], self.active_classes[first_child:]
                option.state, option.state_start = target, self.now
            else:
                raise OptionError(f"option {name} changed state {self.MAX_TRANSITIONS} times in one frame (now {option.state}): "
                                  "its transitions go round in a loop")
        finally:
            self.depth = depth
        record.state = option.state
        record.time_in_option, record.time_in_state = option.time_in_option, option.time_in_state
        return option.done

    def transition(self, option: Option[Any]) -> str | None:
        """Check the common transitions, then run the state's method: the state to go to, or None."""
        spec, method = option.states[option.state]
        if option.common_transitions is not None:
            common_method, allowed = option.common_transitions
            target = common_method(option, self.behaviour)
            if target is not None and target != option.state:
                return self.checked(option, target, allowed, "@common")
        target = method(option, self.behaviour)
        return None if target is None else self.checked(option, target, spec.to, f"state {spec.name}")

    @staticmethod
    def checked(option: Option[Any], target: Any, allowed: tuple[str, ...], where: str) -> str:
        if target not in allowed:
            declared = ", ".join(allowed) or "nothing"
            raise OptionError(f"option {type(option).__name__}, {where}, returned {target!r}, which it does not declare "
                              f"(to: {declared}); add it to to=(...) or return None to stay")
        return str(target)

    @staticmethod
    def make_args(option_class: type[Option[Any]], args: dict[str, Any]) -> Any:
        if option_class.Args is None:
            if args:
                raise OptionError(f"option {option_class.__name__} takes no parameters, was given {', '.join(args)}")
            return None
        try:
            return option_class.Args(**args)
        except TypeError as error:
            expected = ", ".join(f.name for f in dataclasses.fields(option_class.Args))
            raise OptionError(f"option {option_class.__name__} takes {expected}; was given {', '.join(args) or 'nothing'} "
                              f"({error})") from None
