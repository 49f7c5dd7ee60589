"""The command protocol: parser, formatter, telnet decoding."""

from __future__ import annotations

import socket
import threading

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from tafel.debug.protocol import Command, ParseError, TelnetDecoder, answer_bytes, format_command, parse
from tafel.debug.router import DebugRouter
from tafel.debug.server import DebugServer
from tafel.debug.session import looks_like_http


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


@given(st.text(max_size=200))
def test_random_text_parses_to_a_command_that_round_trips_or_says_what_was_expected(text: str) -> None:
    try:
        command = parse(text)
    except ParseError as exc:
        assert str(exc).startswith(("expected", "argument", "the value of")), str(exc)
        return
    assert parse(format_command(command)) == command


@pytest.fixture(scope="module")
def echo_server():
    """A real debug server whose one command answers its argument: the order of answers is visible."""
    router = DebugRouter()
    router.register("echo", "answers its argument", "echo -n N", lambda command: str(command.args.get("n", "")))
    server = DebugServer(router, "127.0.0.1", 0)
    server.start()
    stop = threading.Event()
    threading.Thread(target=server.dispatch_forever, args=(stop,), daemon=True).start()
    yield server
    stop.set()
    server.stop()


def _answers(server: DebugServer, payload: bytes, count: int) -> list[bytes]:
    with socket.create_connection(server.address, timeout=10) as connection:
        connection.sendall(payload)
        received = b""
        while received.count(b"\0") < count:
            chunk = connection.recv(65536)
            if not chunk:
                return received.split(b"\0")[:-1]  # closed early: the caller checks whether it should have been
            received += chunk
    return received.split(b"\0")[:count]


# lines a fuzzer makes from the protocol's own pieces, well-formed or not
FUZZ_LINE = st.lists(st.sampled_from(["echo", "-n", "+n", " ", '"', "x y", "aGk=", "@", "help", "\t", "é", "-", "+", "zz"]),
                     min_size=1, max_size=8).map("".join)


@given(st.lists(FUZZ_LINE, min_size=1, max_size=15))
@example(["+n +n echo"])  # found by the fuzzer: an unknown command whose base64 argument is no UTF-8 text
def test_every_fuzzed_line_gets_exactly_one_answer_in_order(echo_server: DebugServer, lines: list[str]) -> None:
    lines = [line.replace("\n", " ") for line in lines if line.strip()]
    if not lines:
        return
    payload = b"".join(f"{line}\necho -n {i}\n".encode() for i, line in enumerate(lines))  # a marker after each line
    answers = _answers(echo_server, payload, 2 * len(lines))
    for i, line in enumerate(lines):
        answer, marker = answers[2 * i].decode(), answers[2 * i + 1].decode()
        assert marker == f"{i}\n", (line, answers)  # the pipeline kept its order: one answer per line
        try:  # as the server reads a line: a base64 argument that is no UTF-8 text is malformed too
            parsed = parse(line.strip()).as_text()
        except ParseError as exc:
            assert answer == f"error: {exc}\n", (line, answer)  # malformed: the parser's own message
            continue
        if parsed.name not in ("echo", "help"):
            assert answer.startswith("error: unknown command"), (line, answer)


@given(st.binary(max_size=300))
def test_random_bytes_get_one_answer_per_line_and_errors_for_what_is_not_a_command(echo_server: DebugServer, data: bytes) -> None:
    payload = data + b"\necho -n end\n"
    lines = [line for line in TelnetDecoder().feed(payload) if line is None or line.strip()]
    answers = _answers(echo_server, payload, len(lines))
    if lines and lines[0] is not None and looks_like_http(lines[0]):
        assert answers == [], answers  # what a browser sends is closed at once, unanswered
        return
    assert len(answers) == len(lines), (lines, answers)  # exactly one answer per line
    for line, answer in zip(lines, answers):
        try:
            command = parse(line.decode("utf-8").strip()) if line is not None else None
        except (ParseError, UnicodeDecodeError):
            command = None
        if command is None:
            assert answer.startswith(b"error:"), (line, answer)
        elif command.name == "echo":
            assert answer == f"{command.args.get('n', '')}\n".encode(), (line, answer)


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


class ByteByByteDecoder:
    """The telnet rules written the slow, obvious way, one byte at a time: the reference for the bulk decoder."""

    def __init__(self, max_line: int) -> None:
        self.max_line, self.buffer, self.state, self.sub, self.overlong, self.cr = max_line, bytearray(), "data", 0, False, False

    def feed(self, data: bytes) -> list[bytes | None]:
        lines: list[bytes | None] = []
        for byte in data:
            if self.state == "data":
                if byte == 255:
                    self.state = "iac"
                else:
                    self.data(byte, lines)
            elif self.state == "iac":
                self.state = "data"
                if byte == 255:
                    self.data(255, lines)
                elif byte in (251, 252, 253, 254):
                    self.state = "option"
                elif byte == 250:
                    self.state, self.sub = "sub", 0
            elif self.state == "option":
                self.state = "data"
            elif self.state == "sub":
                self.sub += 1
                if byte == 255:
                    self.state = "sub-iac"
                elif self.sub > 512:
                    self.state = "data"
                    self.data(byte, lines)
            else:
                self.state = "data" if byte == 240 else "sub"
        return lines

    def data(self, byte: int, lines: list[bytes | None]) -> None:
        if self.cr:
            self.cr = False
            self.end(lines)
            if byte in (0, 10):
                return
        if byte == 13:
            self.cr = True
        elif byte == 10:
            self.end(lines)
        elif not self.overlong:
            self.buffer.append(byte)
            if len(self.buffer) > self.max_line:
                self.overlong, self.buffer = True, bytearray()

    def end(self, lines: list[bytes | None]) -> None:
        lines.append(None if self.overlong else bytes(self.buffer))
        self.buffer, self.overlong = bytearray(), False


# bytes that matter to telnet, so that random streams hit every state often
TELNET_BYTES = st.sampled_from([0, 10, 13, 240, 250, 251, 253, 255, 65, 66])


@given(st.lists(st.one_of(TELNET_BYTES, st.integers(0, 255)), max_size=1500), st.lists(st.integers(1, 200), max_size=20),
       st.sampled_from([5, 40, 1000]))
def test_the_bulk_decoder_splits_lines_exactly_as_the_byte_rules_say(data: list[int], cuts: list[int], max_line: int) -> None:
    stream = bytes(data)
    reference, bulk = ByteByByteDecoder(max_line), TelnetDecoder(max_line)
    expected = reference.feed(stream)
    got: list[bytes | None] = []
    position = 0
    for cut in [*cuts, len(stream)]:  # the same stream, arriving in chunks of any size
        got += bulk.feed(stream[position:position + cut])
        position += cut
    got += bulk.feed(stream[position:])
    assert got == expected


def test_a_long_subnegotiation_without_end_gives_way_to_data_at_the_same_byte_as_byte_rules() -> None:
    stream = bytes([255, 250]) + b"y" * 512 + b"ping\n"
    assert TelnetDecoder().feed(stream) == ByteByByteDecoder(64 * 1024).feed(stream) == [b"ping"]


@pytest.fixture
def aliased(tmp_path):
    """The program-wide commands with the shipped aliases, and a stand-in for the context command they run."""
    import tomllib

    from tafel.tools.launch.debugging import ProgramDebug
    from tests.test_cli_runtime import REPO

    debug = ProgramDebug(host="127.0.0.1", port=0, token=None, config_dir=tmp_path, recorder=None)
    ran: list = []

    class Recording:
        def start(self, commands):
            ran.extend(commands)
            return [("ok", "done")] * len(commands)

        def finish(self, started):
            return started

    debug.router.add_context("motion", Recording())
    debug.add_aliases(tomllib.loads((REPO / "config" / "general.toml").read_text())["debug"]["aliases"])
    return debug, ran


@pytest.mark.parametrize(("line", "message"), [
    ("motion:walk -x abc", "motion:walk: -x takes a finite number of at most 1e+12 in size, got 'abc'"),
    ("motion:walk -x inf", "motion:walk: -x takes a finite number of at most 1e+12 in size, got 'inf'"),
    ("motion:kick -foot Left", "motion:kick: -foot takes left or right, got 'Left'"),
    ("motion:walk -context Motion", "motion:walk: -context takes cognition or motion, got 'Motion'"),  # was ignored
    ("motion:walk -context cognition", "motion:walk runs in motion: leave -context out or give -context motion"),  # was ignored
])
def test_alias_arguments_are_refused_in_the_one_wording(aliased, line: str, message: str) -> None:
    debug, ran = aliased
    assert debug.router.handle_batch([parse(line)]) == [(True, message)]
    assert ran == []


def test_an_alias_runs_its_command_with_the_numbers_and_the_context_given(aliased) -> None:
    debug, ran = aliased
    assert debug.router.handle_batch([parse("motion:walk -x 200 -context motion")]) == [(False, "done")]
    [command] = ran
    assert command.args["context"] == "motion" and '"walk_x":200.0' in command.args["fields"]


def test_replay_stepping_takes_whole_numbers() -> None:
    from tafel.debug.commands import CommandError
    from tafel.tools.launch.debugging import ProgramDebug

    class Replay:
        def step(self, count):
            self.count = count

    replay = Replay()
    assert ProgramDebug._replay_step(replay, parse("log:step -count -3")) == "stepping -3" and replay.count == -3
    with pytest.raises(CommandError, match=r"^-count takes a whole number that fits in 64 bits, got '1.5'$"):
        ProgramDebug._replay_step(replay, parse("log:step -count 1.5"))
    with pytest.raises(CommandError, match=r"^-frame takes a whole number that fits in 64 bits, got 'x'$"):
        ProgramDebug._replay_goto(replay, parse("log:goto -frame x"))
