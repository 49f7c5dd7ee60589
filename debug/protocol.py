"""The NaoTH text command protocol: parsing, formatting, and telnet input.

    Command   = ["+"], CMDName, {Space, Argument}, "\\n";
    Argument  = StringArg | Base64Arg | EmptyArg;
    StringArg = "-", ArgName, Space, ArgValue;
    Base64Arg = "+", ArgName, Space, ArgValue;
    EmptyArg  = ArgName;
    ArgValue  = '"', {CharNoQuote}, '"' | {CharNoSpace};

Example: ``mycommand -arg1 "value1 with space" -arg2 value2 argwithemptyvalue +argwithbase64 aGVsbG8=``.
String arguments arrive as ``str``, base64 arguments decoded as ``bytes``, empty arguments as ``""``.
A ``+`` before the command name asks for the answer in base64. Every answer is UTF-8 text ending with a
newline, followed by a NUL byte.
"""

from __future__ import annotations

import base64
import binascii
import re
from dataclasses import dataclass, field

from tafel.core.framework.errors import TafelError

MAX_LINE = 64 * 1024
EMPTY_VALUE = '""'  # an empty ArgValue must be quoted
IDENTIFIER = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_:./\-]*")


class ParseError(TafelError, ValueError):
    """A line that is not a well-formed command; the message says what was expected."""


#: arguments that stay bytes when sent in base64 (binary data); every other one is text either way
BINARY_ARGUMENTS = frozenset({"data"})


@dataclass(frozen=True)
class Command:
    name: str
    args: dict[str, str | bytes] = field(default_factory=dict)
    base64_answer: bool = False

    def as_text(self) -> Command:
        """The command with every base64 argument decoded to text (UTF-8), as if sent plainly.

        Base64 is a way to send any value (spaces, quotes, line breaks), not another kind of value:
        handlers see text, except for the binary arguments (``BINARY_ARGUMENTS``).
        """
        if not any(isinstance(v, bytes) for v in self.args.values()):
            return self
        args: dict[str, str | bytes] = {}
        for name, value in self.args.items():
            if isinstance(value, bytes) and name not in BINARY_ARGUMENTS:
                try:
                    value = value.decode("utf-8")
                except UnicodeDecodeError as exc:
                    raise ParseError(f"argument +{name} decodes to bytes that are not UTF-8 text (byte {exc.start})") from None
            args[name] = value
        return Command(self.name, args, self.base64_answer)


def parse(line: str) -> Command:
    """Parse one command line (without its newline)."""
    position = 0
    length = len(line)
    base64_answer = line.startswith("+")
    if base64_answer:
        position = 1
    match = IDENTIFIER.match(line, position)
    if not match:
        raise ParseError("expected a command name (letters, digits, _ : . / -) at the start of the line")
    name = match.group()
    position = match.end()
    args: dict[str, str | bytes] = {}
    while position < length:
        if line[position] != " ":
            raise ParseError(f"expected a space before the next argument at column {position + 1}")
        while position < length and line[position] == " ":
            position += 1
        if position >= length:
            break
        kind = line[position]
        if kind in "-+":
            position += 1
        arg = IDENTIFIER.match(line, position)
        if not arg:
            raise ParseError(f"expected an argument name at column {position + 1}")
        arg_name = arg.group()
        position = arg.end()
        if arg_name in args:
            raise ParseError(f"argument {arg_name!r} is given twice")
        if kind not in "-+":
            args[arg_name] = ""
            continue
        if position >= length or line[position] != " ":
            raise ParseError(f"argument {kind}{arg_name} needs a value after a space")
        while position < length and line[position] == " ":
            position += 1
        if position >= length:
            raise ParseError(f"argument {kind}{arg_name} needs a value after a space")
        if line[position] == '"':
            end = line.find('"', position + 1)
            if end < 0:
                raise ParseError(f'the value of {kind}{arg_name} opens a quote (") that is never closed')
            value = line[position + 1 : end]
            position = end + 1
        else:
            end = line.find(" ", position)
            end = length if end < 0 else end
            value = line[position:end]
            position = end
        if kind == "+":
            try:
                args[arg_name] = base64.b64decode(value.encode("ascii"), validate=True)
            except (binascii.Error, UnicodeEncodeError):
                raise ParseError(f"argument +{arg_name} is not valid base64: {value[:40]!r}") from None
        else:
            args[arg_name] = value
    return Command(name, args, base64_answer)


def format_command(command: Command) -> str:
    """The protocol line of a command (without newline); ``parse(format_command(c)) == c``."""
    parts = [("+" if command.base64_answer else "") + command.name]
    for name, value in command.args.items():
        if isinstance(value, bytes):
            parts.append(f"+{name} {base64.b64encode(value).decode('ascii') or EMPTY_VALUE}")
        elif value == "":
            parts.append(name)  # an EmptyArg; parses back as ""
        else:
            parts.append(f"-{name} {quote(value)}")
    return " ".join(parts)


def quote(value: str) -> str:
    """A string value as ArgValue: bare when possible, quoted when it has spaces."""
    if "\n" in value or "\r" in value:
        raise ParseError("string values cannot contain line breaks; send them as base64 (+name)")
    if value and " " not in value and not value.startswith('"'):
        return value
    if '"' in value:
        raise ParseError('a value with spaces cannot contain a quote ("); send it as base64 (+name)')
    return f'"{value}"'


def answer_bytes(text: str | bytes, *, base64_answer: bool = False) -> bytes:
    """The bytes sent for an answer: UTF-8 text ending with a newline, then NUL."""
    if base64_answer:
        payload = text.encode("utf-8") if isinstance(text, str) else text
        body = base64.b64encode(payload).decode("ascii")
    elif isinstance(text, bytes):
        body = base64.b64encode(text).decode("ascii")
    else:
        body = text
    if not body.endswith("\n"):
        body += "\n"
    return body.encode("utf-8") + b"\0"


def encode_answer(command: Command, is_error: bool, payload: str | bytes) -> bytes:
    """The bytes of one answer to ``command``: an error line, base64 for ``+name`` commands, text otherwise."""
    if is_error:
        return answer_bytes(f"error: {payload}")
    if isinstance(payload, bytes) and not command.base64_answer:
        return answer_bytes(f"error: {command.name} answers with bytes; send +{command.name} for base64")
    return answer_bytes(payload, base64_answer=command.base64_answer)


IAC, SB, SE = 255, 250, 240
MAX_SUBNEGOTIATION = 512  # real ones are a few bytes; a longer one is garbage, and reading goes on
_NEGOTIATION = {251, 252, 253, 254}  # WILL, WONT, DO, DONT


class TelnetDecoder:
    """Strips telnet option negotiation from a byte stream and splits it into lines.

    Accepts ``\\n``, ``\\r\\n`` and ``\\r\\0`` line ends; ``IAC IAC`` is a literal 0xFF. State survives
    chunk boundaries. Lines longer than ``MAX_LINE`` are reported (``None`` in the output) and skipped; a
    subnegotiation that does not end within ``MAX_SUBNEGOTIATION`` bytes is given up.

    The input is scanned in bulk (a regular expression finds the next IAC or line end, and the bytes
    between are copied in one piece), never byte by byte in Python: a client streaming garbage costs
    the program little more than the copy, and holds the interpreter lock only briefly.
    """

    def __init__(self, max_line: int = MAX_LINE) -> None:
        self.max_line = max_line
        self.buffer = bytearray()
        self.state = "data"
        self.sub_length = 0
        self.overlong = False
        self.pending_cr = False

    def feed(self, data: bytes) -> list[bytes | None]:
        lines: list[bytes | None] = []
        position, length = 0, len(data)
        while position < length:
            state = self.state
            if state == "data":
                if self.pending_cr:  # \r ends the line at the next data byte; a \n or \0 belongs to it
                    if data[position] == IAC:  # telnet commands in between do not count as data
                        self.state, position = "iac", position + 1
                        continue
                    self.pending_cr = False
                    self._end_line(lines)
                    if data[position] in (0, 10):
                        position += 1
                    continue
                match = _SPECIAL.search(data, position)
                end = match.start() if match else length
                if end > position:
                    self._append(data, position, end)
                if match is None:
                    break
                byte, position = data[end], end + 1
                if byte == IAC:
                    self.state = "iac"
                elif byte == 10:
                    self._end_line(lines)
                else:
                    self.pending_cr = True
                continue
            byte = data[position]
            if state == "iac":
                position += 1
                if byte == IAC:
                    self.state = "data"
                    if self.pending_cr:
                        self.pending_cr = False
                        self._end_line(lines)
                    self._append(b"\xff", 0, 1)
                elif byte in _NEGOTIATION:
                    self.state = "option"
                elif byte == SB:
                    self.state = "sub"
                    self.sub_length = 0
                else:
                    self.state = "data"  # two-byte command (NOP, GA, ...)
            elif state == "option":
                position += 1
                self.state = "data"
            elif state == "sub":
                room = MAX_SUBNEGOTIATION - self.sub_length  # bytes that may still belong to it
                stop = min(length, position + room + 1)
                found = data.find(IAC, position, stop)
                if found >= 0:
                    self.sub_length += found - position + 1
                    self.state, position = "sub-iac", found + 1
                elif stop - position > room:  # no IAC SE came: not a subnegotiation after all
                    self.sub_length = MAX_SUBNEGOTIATION + 1
                    self.state, position = "data", position + room
                else:
                    self.sub_length += stop - position
                    position = stop
            else:  # sub-iac
                position += 1
                self.state = "data" if byte == SE else "sub"
        return lines

    def _append(self, data: bytes, start: int, end: int) -> None:
        if self.overlong:
            return
        self.buffer += data[start:end]
        if len(self.buffer) > self.max_line:
            self.overlong = True
            self.buffer.clear()

    def _end_line(self, lines: list[bytes | None]) -> None:
        lines.append(None if self.overlong else bytes(self.buffer))
        self.buffer.clear()
        self.overlong = False


_SPECIAL = re.compile(rb"[\r\n\xff]")
