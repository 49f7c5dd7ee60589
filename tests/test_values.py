"""The one layer that converts and checks values from outside (``tafel.core.framework.values``), and the
places that go through it: parameters, configuration, platform options, the command line's types."""

from __future__ import annotations

import argparse
import enum
import math
import re
from typing import Annotated, Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core.framework.config import ConfigError, check_runtime, context_section
from tafel.core.framework.values import (
    BOOL_WORDS,
    INT_RANGE,
    MAX_MAGNITUDE,
    Range,
    ValueCheckError,
    convert,
    describe,
    refusal,
    shown,
)
from tafel.core.runtime.platform import PlatformOptionError, seed_number
from tafel.platforms.simulated import CARPET_X, number, parse_noise, parse_pair, parse_pose, parse_resolution, switch
from tafel.tools.cli.arguments import parse_speed, port_number, positive, team_number

#: the one wording of every refusal
WORDING = re.compile(r"^(\S.* )?takes .+, got .+$", re.DOTALL)


class Colour(enum.Enum):
    red = 1
    blue = 2


def refused(value: Any, kind: Any, **options: Any) -> str:
    """The message ``convert`` refuses ``value`` with (it must refuse it, in the one wording)."""
    with pytest.raises(ValueCheckError) as error:
        convert(value, kind, where=options.pop("where", "Thing.x"), **options)
    message = str(error.value)
    assert WORDING.match(message), message
    return message


# ------------------------------------------------------------------------- numbers
@given(st.floats(min_value=-1e6, max_value=1e6))
def test_a_number_typed_as_text_is_the_number(x: float) -> None:
    assert convert(repr(x), float, where="Thing.x") == x
    assert convert(x, float, where="Thing.x") == x


@given(st.floats(min_value=-10.0, max_value=10.0), st.floats(min_value=0.0, max_value=5.0))
def test_a_declared_range_takes_what_is_in_it_and_refuses_the_rest_naming_it(x: float, high: float) -> None:
    if -high <= x <= high:
        assert convert(x, float, where="Thing.x", bounds=(-high, high)) == x
    else:
        message = refused(x, float, bounds=(-high, high))
        assert message == f"Thing.x takes a finite number from {-high:g} to {high:g}, got {x:g}"


@given(st.integers())
def test_a_whole_number_fits_64_bits_or_is_refused(n: int) -> None:
    if INT_RANGE[0] <= n <= INT_RANGE[1]:
        assert convert(str(n), int, where="Thing.n") == n == convert(n, int, where="Thing.n")
    else:
        assert "Thing.n takes a whole number that fits in 64 bits, got" in refused(n, int, where="Thing.n")


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, 1e308, "nan", "inf", "1e400", "", "fast"])
def test_numbers_without_a_range_are_finite_and_of_a_sane_size(value: Any) -> None:
    message = refused(value, float)
    assert message == f"Thing.x takes a finite number of at most {MAX_MAGNITUDE:g} in size, got {shown(value)}"


def test_data_is_taken_strictly_and_text_as_typed() -> None:
    assert convert(5.0, int, where="Thing.n") == 5 and convert(3, float, where="Thing.x") == 3.0
    assert convert(" 1_000 ", int, where="Thing.n") == 1000
    assert refused("5", int, text=False) == "Thing.x takes a whole number that fits in 64 bits, got '5'"
    assert "got True" in refused(True, int) and "got 5.5" in refused(5.5, int) and "got 1" in refused(1, bool)
    assert convert(np.float32(0.5), float, where="Thing.x") == 0.5 and convert(np.int64(3), int, where="Thing.n") == 3
    assert convert(np.bool_(True), bool, where="Thing.b") is True


def test_an_open_range_refuses_its_low_end() -> None:
    positive = Range(0.0, 1000.0, low_open=True)
    assert convert("0.5", float, where="rate", bounds=positive) == 0.5
    assert refused("0", float, where="rate", bounds=positive, unit="Hz") == "rate takes a finite number of Hz above 0 and at most 1000, got '0'"
    assert refused(0, int, bounds=Range(0, low_open=True)) == "Thing.x takes a whole number above 0, got 0"
    assert Range(2).words() == "of at least 2" and Range(high=3).words() == "of at most 3" and Range().words() == ""
    with pytest.raises(ValueError, match="low must be at most high"):
        Range(1.0, 0.0)


# ------------------------------------------------------------------------- words, names, choices
@given(st.sampled_from(sorted(BOOL_WORDS)), st.booleans())
def test_yes_and_no_are_words_in_any_case(word: str, upper: bool) -> None:
    assert convert(word.upper() if upper else word, bool, where="-on") is BOOL_WORDS[word]


def test_a_bool_refused_says_the_words() -> None:
    assert refused("maybe", bool, where="-enabled") == "-enabled takes on/off or true/false, got 'maybe'"


def test_enums_go_by_name_and_choices_in_any_case() -> None:
    assert convert("blue", Colour, where="Thing.c") is Colour.blue is convert(Colour.blue, Colour, where="Thing.c")
    assert refused("green", Colour) == "Thing.x takes one of red, blue, got 'green'"
    assert refused(2, Colour) == "Thing.x takes one of red, blue, got 2"
    assert convert("ORANGE", str, where="--ball-color", choices=("spl", "orange")) == "orange"
    assert refused("pink", str, choices=("spl", "orange")) == "Thing.x takes one of spl, orange, got 'pink'"
    assert refused(5, str) == "Thing.x takes text, got 5"


# ------------------------------------------------------------------------- lists, tuples, tables
@given(st.lists(st.integers(min_value=-1000, max_value=1000), max_size=8))
def test_a_list_comes_as_json_or_separated_the_same(values: list[int]) -> None:
    assert convert(",".join(map(str, values)), list[int], where="Thing.l") == values
    assert convert(str(values), list[int], where="Thing.l") == values
    assert convert(values, list[float], where="Thing.l") == [float(v) for v in values]


def test_a_misfit_inside_a_list_names_its_place() -> None:
    assert refused("[1, 2, 7]", list[int], bounds=(0, 5)) == "Thing.x[2] takes a whole number from 0 to 5, got 7"
    assert refused("[1, 2", list[int]) == "Thing.x takes a list (a whole number that fits in 64 bits each), got '[1, 2'"
    assert refused(5, list[str], text=False, expected="a list of module names") == "Thing.x takes a list of module names, got 5"


def test_a_tuple_has_its_length_and_its_elements_their_ranges() -> None:
    side = Annotated[int, Range(16, 4096)]
    assert convert("320x240", tuple[side, side], where="--resolution", separator="x") == (320, 240)
    assert refused("8x8", tuple[side, side], separator="x") == "Thing.x[0] takes a whole number from 16 to 4096, got '8'"
    assert refused("1,2,3", tuple[float, float], expected="X,Y") == "Thing.x takes X,Y, got '1,2,3'"
    assert convert([1, 2, 3], tuple[int, ...], where="Thing.t") == (1, 2, 3)


def test_tables_optionals_and_any() -> None:
    assert convert({"a": "x"}, dict[str, str], where="providers") == {"a": "x"}
    assert convert('{"a": 1}', dict[str, int], where="t") == {"a": 1}
    assert refused({"a": 1}, dict[str, str], where="providers") == "providers.a takes text, got 1"
    assert refused("{", dict[str, str]) == "Thing.x takes a table (text each), got '{'"
    assert convert(None, int | None, where="Thing.o") is None and convert("none", int | None, where="Thing.o") is None
    assert convert("4", int | None, where="Thing.o") == 4
    assert describe(int | None) == "a whole number that fits in 64 bits or none"
    assert convert(object, Any, where="Thing.a") is object


def test_a_type_no_value_converts_to_is_a_programming_error() -> None:
    with pytest.raises(TypeError, match="is no type values can be converted to"):
        convert(1, list[int] | str, where="Thing.x")


# ------------------------------------------------------------------------- one wording, the caller's error class
@given(st.one_of(st.text(max_size=200), st.floats(), st.integers(), st.binary(max_size=80), st.none()))
def test_every_refusal_is_worded_one_way_and_short(value: Any) -> None:
    for kind in (int, float, bool, Colour, list[int]):
        try:
            convert(value, kind, where="Thing.x", bounds=(0, 10) if kind in (int, float) else None)
        except ValueCheckError as error:
            assert WORDING.match(str(error)) and len(str(error)) < 300, str(error)


def test_the_caller_chooses_the_error_class() -> None:
    with pytest.raises(PlatformOptionError, match="^-x takes"):
        convert("far", float, where="-x", error=PlatformOptionError)
    assert str(refusal("", "a port number", "x")) == "takes a port number, got 'x'"
    assert shown(10**400).startswith("a number of about 401 digits") and shown("x" * 100).endswith("... (100 long)")


# ------------------------------------------------------------------------- the places that go through it
def test_platform_options_say_what_would_be_right() -> None:
    assert parse_pair("1000,300", "--ball") == (1000.0, 300.0) and parse_resolution("640X480") == (640, 480)
    with pytest.raises(PlatformOptionError, match=r"^--ball takes X,Y in mm on the carpet .*, got '9000,0'$"):
        parse_pair("9000,0", "--ball")
    with pytest.raises(PlatformOptionError, match=r"^--start takes X,Y,ROT .*, got '1,2'$"):
        parse_pose("1,2")
    assert parse_pose("0,0,7")[2] == pytest.approx(7 - 2 * math.pi)
    with pytest.raises(PlatformOptionError, match=r"^--resolution takes WIDTHxHEIGHT with 16 to 4096 pixels a side, e.g. 320x240, or TOP,BOTTOM: 640x480,320x240, got '8x8'$"):
        parse_resolution("8x8")
    assert parse_noise(None) == 1.0 and parse_noise("0") == 0.0
    assert number({"x": "12.5"}, "x") == 12.5 and number({}, "x", default=3.0) == 3.0
    with pytest.raises(PlatformOptionError, match=f"^-x takes a finite number from {-CARPET_X:g} to {CARPET_X:g}, got '9000'$"):
        number({"x": "9000"}, "x", limit=CARPET_X)
    assert switch({"reset": ""}, "reset") is True and switch({"reset": "off"}, "reset") is False and switch({}, "reset") is False


@pytest.mark.parametrize(("parse", "text", "message"), [
    (positive(int), "0", "takes a whole number above 0, got '0'"),
    (positive(float), "nan", "takes a finite number above 0, got 'nan'"),
    (port_number, "70000", "takes a port number from 0 to 65535 (0: any free one), got '70000'"),
    (team_number, "x", "takes a team number from 1 to 254 (the GameController's), got 'x'"),
    (parse_speed, "fast", "--speed takes a factor from 0.001 to 1000 or 'max', got 'fast'"),
    (seed_number, "-1", "--seed takes a whole number from 0 to 4294967295, got '-1'"),
])
def test_command_line_types_refuse_in_the_one_wording(parse: Any, text: str, message: str) -> None:
    with pytest.raises(argparse.ArgumentTypeError) as error:
        parse(text)
    assert str(error.value) == message


def test_command_line_types_take_good_words() -> None:
    assert positive(int)("3") == 3 and port_number("0") == 0 and team_number("254") == 254
    assert parse_speed("max") is None and parse_speed("2") == 2.0 and seed_number("7") == 7


@pytest.mark.parametrize(("runtime", "message"), [
    ({"motion_hz": "100"}, "runtime.motion_hz takes a finite number of Hz above 0 and at most 1000, got '100'"),
    ({"cognition_hz": 0}, "runtime.cognition_hz takes a finite number of Hz above 0 and at most 1000, got 0"),
    ({"stall_timeout_s": True}, "runtime.stall_timeout_s takes a finite number of seconds above 0, got True"),
    ({"default_platform": 5}, "runtime.default_platform takes text, got 5"),
    ({"default_platform": ""}, "runtime.default_platform takes a name, got ''"),
])
def test_configuration_is_taken_as_data_and_refused_in_the_one_wording(runtime: dict[str, Any], message: str) -> None:
    with pytest.raises(ConfigError) as error:
        check_runtime({"runtime": runtime})
    assert str(error.value) == message
    check_runtime({"runtime": {"motion_hz": 100, "cognition_hz": 30.0, "default_platform": "dummy"}})


def test_a_context_section_is_checked_as_lists_and_a_table() -> None:
    assert context_section({"cognition": {"modules": ["A"], "providers": {"X": "A"}}}, "cognition") == \
        {"modules": ["A"], "disabled": [], "providers": {"X": "A"}}
    with pytest.raises(ConfigError, match=r"^cognition.disabled takes a list of module names, got \['A', 1\]$"):
        context_section({"cognition": {"disabled": ["A", 1]}}, "cognition")
    with pytest.raises(ConfigError, match=r"^\[motion\] takes a table, got 5$"):
        context_section({"motion": 5}, "motion")
