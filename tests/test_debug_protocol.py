"""The command protocol: parser, formatter, telnet decoding."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.debug.protocol import Command, ParseError, TelnetDecoder, answer_bytes, format_command, parse


def test_the_example_from_the_protocol() -> None:
    command = parse('mycommand -arg1 "value1 with space" -arg2 value2 argwithemptyvalue +argwithbase64 aGVsbG8=')
    assert command == Command("mycommand", {"arg1": "value1 with space", "arg2": "value2", "argwithemptyvalue": "",
                                            "argwithbase64": b"hello"})
    assert not command.base64_answer


def test_plus_asks_for_base64_and_names_may_hold_colons() -> None:
    command = parse("+representation:get -name BallModel")
    assert command.name == "representation:get" and command.base64_answer and command.args == {"name": "BallModel"}


def test_several_spaces_separate_arguments() -> None:
    assert parse("cmd    -a   1    b").args == {"a": "1", "b": ""}


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("", "expected a command name"),
        ("-x", "expected a command name"),
        ("cmd -a", "needs a value"),
        ("cmd -a ", "needs a value"),
        ('cmd -a "open', "never closed"),
        ("cmd +a !!!", "not valid base64"),
        ("cmd -a 1 -a 2", "given twice"),
        ("cmd -", "expected an argument name"),
        ('cmd -a "x"y', "expected a space"),
    ],
)
def test_malformed_lines_say_what_was_expected(line: str, message: str) -> None:
    with pytest.raises(ParseError, match=message):
        parse(line)


identifiers = st.from_regex(r"[A-Za-z0-9_][A-Za-z0-9_:./\-]{0,12}", fullmatch=True)
string_values = st.text(st.characters(blacklist_characters='"\n\r', blacklist_categories=("Cs",)), max_size=20)
commands = st.builds(
    Command,
    name=identifiers,
    args=st.dictionaries(identifiers, st.one_of(string_values, st.binary(max_size=20)), max_size=5),
    base64_answer=st.booleans(),
)


@given(commands)
def test_well_formed_commands_round_trip(command: Command) -> None:
    assert parse(format_command(command)) == command


@given(st.binary(max_size=300))
def test_random_bytes_never_raise_anything_but_parse_errors(data: bytes) -> None:
    for line in TelnetDecoder().feed(data + b"\n"):
        if line is None:
            continue
        try:
            text = line.decode("utf-8")
        except UnicodeDecodeError:
            continue
        try:
            parse(text.strip())
        except ParseError:
            pass


@given(st.text(max_size=200))
def test_random_text_never_raises_anything_but_parse_errors(text: str) -> None:
    try:
        parse(text)
    except ParseError:
        pass


def test_telnet_negotiation_and_line_ends_are_stripped() -> None:
    decoder = TelnetDecoder()
    data = bytes([255, 253, 1, 255, 251, 3]) + b"ping\r\n" + bytes([255, 250, 24, 1, 255, 240]) + b"help\r\0" + b"a\xff\xffb\n"
    assert decoder.feed(data) == [b"ping", b"help", b"a\xffb"]


def test_telnet_state_survives_chunk_boundaries() -> None:
    decoder = TelnetDecoder()
    lines = []
    for byte in bytes([255, 253, 1]) + b"pi" + bytes([255]) + bytes([254, 5]) + b"ng\r" + b"\n":
        lines += decoder.feed(bytes([byte]))
    assert lines == [b"ping"]


def test_overlong_lines_are_reported_once_and_skipped() -> None:
    decoder = TelnetDecoder(max_line=10)
    assert decoder.feed(b"x" * 25 + b"\nok\n") == [None, b"ok"]


def test_answers_end_with_newline_and_nul() -> None:
    assert answer_bytes("pong") == b"pong\n\0"
    assert answer_bytes("pong", base64_answer=True) == b"cG9uZw==\n\0"
    assert answer_bytes(b"\x00\x01") == b"AAE=\n\0"


def test_an_endless_subnegotiation_is_given_up_and_lines_follow() -> None:
    decoder = TelnetDecoder()
    lines = decoder.feed(bytes([255, 250]) + b"x" * 600 + b"\nping\n")
    assert lines[-1] == b"ping"
