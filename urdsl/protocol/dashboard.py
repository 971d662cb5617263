"""The dashboard server's line protocol (port 29999), both sides, without sockets.

The dashboard server speaks ASCII lines: the client sends one command per line
(``"robotmode\\n"``), the server answers each with exactly one line, in order. On connect the
server first sends the welcome line ``Connected: Universal Robots Dashboard Server``.

This module knows every documented command, the replies it can get and what the reply
means (:data:`COMMANDS`), and offers

* :func:`encode_command` / :func:`decode_command` — a command line and back;
* :func:`parse_reply` / :func:`format_reply` — a reply line and its meaning, and back;
* :class:`DashboardClient` — the client's state machine: what to send, which reply answers
  which command (replies come back in order), the welcome line first;
* :class:`DashboardServer` — the virtual controller's side: commands in, reply lines out.

Replies are matched by pattern, not by equality, as UR's own client library does: the
server's texts differ in details between software versions (``Program running: true`` on
3.x/5.x, ``Robot running: True`` on old CB2 controllers).
"""

from __future__ import annotations

import re
from collections import deque
from dataclasses import dataclass, field
from types import MappingProxyType

from .errors import ProtocolError

__all__ = [
    "WELCOME", "PORT", "CommandSpec", "COMMANDS", "DashboardCommand", "DashboardReply",
    "DashboardWelcome", "encode_command", "decode_command", "parse_reply", "format_reply",
    "LineBuffer", "DashboardClient", "DashboardServer", "MAX_LINE", "UNKNOWN_COMMAND",
]

PORT = 29999
WELCOME = "Connected: Universal Robots Dashboard Server"

MAX_LINE = 65536
"""Longest line accepted, in bytes, without its line break.

The longest documented replies carry a file path (``Loaded program: <path>``), and Linux
paths are at most 4096 bytes (PATH_MAX); popup and log texts sent by users are short. 64 KiB
leaves room for anything a controller sends while bounding the memory a peer that never
sends a line break can make us hold (h11 bounds its header buffer the same way).
"""

# Named fields that may appear in reply templates, with the text each one matches.
_FIELD_PATTERNS = {
    "arg": r".*?",
    "name": r".*?",
    "text": r".*?",
    "mode": r"[A-Za-z_0-9]+",
    "bool": r"true|false|True|False",
    "state": r"STOPPED|PLAYING|PAUSED",
    "version": r"[0-9][0-9.]*",
}
_TEMPLATE_FIELD = re.compile(r"\{(\w+)\}")


def _template_regex(template: str) -> re.Pattern[str]:
    """A full-line regex for a reply template such as ``"Loading program: {arg}"``."""
    parts = []
    pos = 0
    for match in _TEMPLATE_FIELD.finditer(template):
        parts.append(re.escape(template[pos:match.start()]))
        name = match.group(1)
        parts.append(f"(?P<{name}>{_FIELD_PATTERNS[name]})")
        pos = match.end()
    parts.append(re.escape(template[pos:]))
    return re.compile("".join(parts) + r"\Z")


@dataclass(frozen=True)
class CommandSpec:
    """What the dashboard server documents about one command.

    ``ok`` and ``fail`` are reply templates: literal text with named fields in braces
    (``{arg}`` echoes the command's argument, ``{mode}``, ``{bool}``, ``{state}``, ``{name}``,
    ``{text}``, ``{version}`` are values). The first ``ok`` template is the normal answer.
    ``value`` names the field whose text becomes :attr:`DashboardReply.value` (``bool``
    fields become ``True``/``False``). ``since`` is the first CB3/e-Series software version
    that knows the command.
    """

    name: str
    ok: tuple[str, ...]
    fail: tuple[str, ...] = ()
    argument: str | None = None
    value: str | None = None
    since: str = "1.4"
    doc: str = ""
    _ok_res: tuple[re.Pattern[str], ...] = field(init=False, repr=False, compare=False)
    _fail_res: tuple[re.Pattern[str], ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_ok_res", tuple(_template_regex(t) for t in self.ok))
        object.__setattr__(self, "_fail_res", tuple(_template_regex(t) for t in self.fail))


_SPECS = (
    CommandSpec("load", ("Loading program: {arg}",),
                ("File not found: {arg}", "Error while loading program: {arg}"),
                argument="program.urp", doc="load a program file (waits until loaded, 3.3+)"),
    CommandSpec("play", ("Starting program",), ("Failed to execute: play",),
                doc="start the loaded program"),
    CommandSpec("stop", ("Stopped",), ("Failed to execute: stop",), doc="stop the program"),
    CommandSpec("pause", ("Pausing program",), ("Failed to execute: pause",),
                doc="pause the program"),
    CommandSpec("quit", ("Disconnected",), doc="close the connection"),
    CommandSpec("shutdown", ("Shutting down",), doc="shut the controller down"),
    CommandSpec("running", ("Program running: {bool}", "Robot running: {bool}"), value="bool",
                since="1.6", doc="is a program running"),
    CommandSpec("robotmode", ("Robotmode: {mode}",), value="mode", since="1.6",
                doc="robot mode (NO_CONTROLLER … RUNNING)"),
    CommandSpec("get loaded program", ("Loaded program: {name}", "No program loaded"),
                value="name", since="1.6", doc="path of the loaded program"),
    CommandSpec("popup", ("showing popup",), argument="text", since="1.6",
                doc="show a popup on the teach pendant"),
    CommandSpec("close popup", ("closing popup",), since="1.6", doc="close the popup"),
    CommandSpec("addToLog", ("Added log message",), ("No log message to add",),
                argument="text", since="1.8", doc="add a line to the log"),
    CommandSpec("isProgramSaved", ("{bool} {name}", "{bool}"), value="bool", since="1.8",
                doc="is the loaded program saved"),
    CommandSpec("programState", ("{state} {name}", "{state}"), value="state", since="1.8",
                doc="STOPPED, PLAYING or PAUSED, and the program name"),
    CommandSpec("PolyscopeVersion", ("URSoftware {version}{text}",), value="version",
                since="1.8", doc="software version and build date"),
    CommandSpec("version", ("{version}",), value="version", since="5.0",
                doc="software version (e-Series)"),
    CommandSpec("setUserRole", ("Setting user role: {arg}",), ("Failed setting user role: {arg}",),
                argument="role", since="3.1", doc="CB3 only"),
    CommandSpec("getUserRole", ("{mode}",), value="mode", since="3.1", doc="CB3 only"),
    CommandSpec("set operational mode", ("Operational mode '{arg}' is set",),
                ("Failed setting operational mode: {arg}",), argument="mode", since="5.6",
                doc="MANUAL or AUTOMATIC"),
    CommandSpec("get operational mode", ("{mode}",), value="mode", since="5.6",
                doc="MANUAL, AUTOMATIC or NONE"),
    CommandSpec("clear operational mode",
                ("No longer controlling the operational mode. {text}",), since="5.6",
                doc="hand the operational mode back to the pendant"),
    CommandSpec("power on", ("Powering on",), since="3.0", doc="power the arm on (then IDLE)"),
    CommandSpec("power off", ("Powering off",), since="3.0", doc="power the arm off"),
    CommandSpec("brake release", ("Brake releasing",), since="3.0",
                doc="release the brakes (then RUNNING)"),
    CommandSpec("safetymode", ("Safetymode: {mode}",), value="mode", since="3.0",
                doc="safety mode (NORMAL, PROTECTIVE_STOP, …)"),
    CommandSpec("safetystatus", ("Safetystatus: {mode}",), value="mode", since="5.4",
                doc="safety status (5.4+)"),
    CommandSpec("unlock protective stop", ("Protective stop releasing",),
                ("Cannot unlock protective stop until 5s after occurrence. {text}",),
                since="3.1", doc="release a protective stop (refused within 5 s of it)"),
    CommandSpec("close safety popup", ("closing safety popup",), since="3.1",
                doc="close the safety popup"),
    CommandSpec("load installation", ("Loading installation: {arg}",),
                ("File not found: {arg}", "Failed to load installation: {arg}"),
                argument="file.installation", since="3.2", doc="load an installation file"),
    CommandSpec("restart safety", ("Restarting safety",), since="3.7",
                doc="restart the safety system (then POWER_OFF)"),
    CommandSpec("is in remote control", ("{bool}",), value="bool", since="5.6",
                doc="is the robot in remote control (e-Series)"),
    CommandSpec("get serial number", ("{name}",), value="name", since="3.12",
                doc="serial number of the robot"),
    CommandSpec("get robot model", ("{mode}",), value="mode", since="3.12",
                doc="UR3, UR5, UR10, UR16, …"),
    CommandSpec("saveLog", ("Log saved to disk",), since="3.13", doc="save the log"),
)

COMMANDS: MappingProxyType[str, CommandSpec] = MappingProxyType({s.name: s for s in _SPECS})
"""Every documented command by its exact text (the server is case-sensitive)."""

# Longest command names first, so that "load installation x" is not read as "load".
_BY_LENGTH = sorted(COMMANDS.values(), key=lambda s: -len(s.name))

UNKNOWN_COMMAND = "could not understand: '{text}'"
"""The reply to a line the server does not know [U: widely reported, not in UR's docs]."""
_UNKNOWN_RE = _template_regex(UNKNOWN_COMMAND)


@dataclass(frozen=True)
class DashboardCommand:
    """A command line: ``name`` is a key of :data:`COMMANDS` (or the unknown word the client
    sent), ``argument`` the text after it, if the command takes one."""

    name: str
    argument: str | None = None

    @property
    def known(self) -> bool:
        """Is this a documented command?"""
        return self.name in COMMANDS

    @property
    def line(self) -> str:
        """The command as sent, without the line break."""
        return self.name if self.argument is None else f"{self.name} {self.argument}"


@dataclass(frozen=True)
class DashboardReply:
    """The server's answer to one command.

    ``ok`` is true when the text is one of the command's success replies; ``value`` is the
    reply's meaning (``"RUNNING"`` for ``robotmode``, ``True`` for ``running``, the path for
    ``get loaded program`` or ``None`` if no program is loaded); ``fields`` holds every
    named part of the reply (``{"state": "PLAYING", "name": "pick.urp"}``).
    """

    command: str
    text: str
    ok: bool
    value: object = None
    fields: tuple[tuple[str, str], ...] = ()

    def field(self, name: str) -> str | None:
        """A named part of the reply, e.g. ``field("name")`` of ``programState``."""
        return dict(self.fields).get(name)


@dataclass(frozen=True)
class DashboardWelcome:
    """The welcome line the server sends first."""

    text: str


def _check_text(text: str, what: str, breaks: str = "\r\n") -> None:
    if any(c in text for c in breaks):
        raise ProtocolError(f"{what} {text!r} contains a line break; a dashboard command is "
                            "one line", interface="dashboard")
    if len(text.encode("utf-8")) > MAX_LINE:
        raise ProtocolError(f"{what} is {len(text.encode('utf-8'))} bytes long; the limit is "
                            f"{MAX_LINE}", interface="dashboard")


def encode_command(name: str, argument: str | None = None) -> bytes:
    """The bytes of one command line, e.g. ``encode_command("load", "pick.urp")``.

    Raises :class:`ProtocolError` for an unknown command, a missing or unexpected argument
    or a line break inside the text.
    """
    spec = COMMANDS.get(name)
    if spec is None:
        close = [n for n in COMMANDS if n.lower() == name.lower()]
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ProtocolError(f"unknown command {name!r}{hint}", interface="dashboard")
    if spec.argument is not None and not argument:
        raise ProtocolError(f"{name!r} needs an argument <{spec.argument}>", interface="dashboard")
    if spec.argument is None and argument is not None:
        raise ProtocolError(f"{name!r} takes no argument", interface="dashboard")
    line = name if argument is None else f"{name} {argument}"
    _check_text(line, "command")
    return (line + "\n").encode("utf-8")


def decode_command(line: str, ignore_case: bool = False) -> DashboardCommand:
    """What a received command line asks for (the server's side).

    Unknown lines give a :class:`DashboardCommand` whose ``known`` is false; the server
    answers those with :data:`UNKNOWN_COMMAND`, it does not drop the connection.
    ``ignore_case`` matches the command words in any case (``PROGRAMSTATE``) — the virtual
    controller is lenient so — and still returns the documented name; the argument keeps
    its case.
    """
    text = line.rstrip("\r\n")
    key = text.lower() if ignore_case else text
    for spec in _BY_LENGTH:
        name = spec.name.lower() if ignore_case else spec.name
        if key == name:
            return DashboardCommand(spec.name, None)
        if spec.argument is not None and key.startswith(name + " "):
            return DashboardCommand(spec.name, text[len(name) + 1:])
    return DashboardCommand(text, None)


def _value(spec: CommandSpec, groups: dict[str, str]) -> object:
    if spec.value is None:
        return None
    raw = groups.get(spec.value)
    if raw is None:
        return None
    if spec.value == "bool":
        return raw.lower() == "true"
    return raw


def parse_reply(command: str, text: str) -> DashboardReply:
    """The meaning of the server's reply ``text`` to ``command`` (a key of :data:`COMMANDS`).

    A reply that is none of the command's documented texts is returned with ``ok=False``
    (e-Series answers most commands with an explanation when the robot is not in remote
    control); it is not an exception, because the server did answer.
    """
    spec = COMMANDS.get(command)
    text = text.rstrip("\r\n")
    if spec is None:
        raise ProtocolError(f"unknown command {command!r}", interface="dashboard")
    for regex in spec._ok_res:
        match = regex.match(text)
        if match:
            groups = {k: v for k, v in match.groupdict().items() if v is not None}
            return DashboardReply(command, text, True, _value(spec, groups),
                                  tuple(sorted(groups.items())))
    for regex in spec._fail_res:
        match = regex.match(text)
        if match:
            groups = {k: v for k, v in match.groupdict().items() if v is not None}
            return DashboardReply(command, text, False, None, tuple(sorted(groups.items())))
    return DashboardReply(command, text, False)


def format_reply(command: DashboardCommand | str, ok: bool = True, variant: int = 0,
                 **fields: object) -> str:
    """The reply text the server sends (the virtual controller's side), without line break.

    ``fields`` fill the template's named parts; ``arg`` defaults to the command's argument,
    ``bool`` values print as ``true``/``false``. ``variant`` picks among the documented
    texts (``ok=False`` picks among the failure texts). An unknown command gets
    :data:`UNKNOWN_COMMAND`.
    """
    if isinstance(command, str):
        command = decode_command(command)
    spec = COMMANDS.get(command.name)
    if spec is None:
        return UNKNOWN_COMMAND.format(text=command.line)
    templates = spec.ok if ok else spec.fail
    if not templates:
        raise ProtocolError(f"{spec.name!r} has no documented failure reply",
                            interface="dashboard")
    if not 0 <= variant < len(templates):
        raise ProtocolError(f"{spec.name!r} has {len(templates)} reply texts, not {variant + 1}",
                            interface="dashboard")
    values = {"arg": command.argument or ""}
    for key, value in fields.items():
        values[key] = ("true" if value else "false") if isinstance(value, bool) else str(value)
    try:
        text = templates[variant].format(**values)
    except KeyError as exc:
        raise ProtocolError(f"reply to {spec.name!r} needs a value for {exc.args[0]!r}",
                            interface="dashboard") from None
    _check_text(text, "reply", "\n")  # a received argument may hold a lone "\r"; echo it
    return text


class LineBuffer:
    """Cuts a byte stream into lines (``\\n``-terminated, a trailing ``\\r`` dropped).

    ``feed`` returns the complete lines received so far; a partial line waits for the rest.
    A line longer than :data:`MAX_LINE` raises :class:`ProtocolError` instead of growing
    the buffer without bound.
    """

    def __init__(self) -> None:
        self._buffer = bytearray()

    def feed(self, data: bytes) -> list[str]:
        """Add received bytes; return the lines they complete, decoded as UTF-8."""
        self._buffer += data
        lines = []
        while True:
            end = self._buffer.find(b"\n")
            if end < 0:
                break
            raw = bytes(self._buffer[:end])
            del self._buffer[:end + 1]
            if len(raw) > MAX_LINE:
                raise ProtocolError(f"line of {len(raw)} bytes; the limit is {MAX_LINE}",
                                    interface="dashboard")
            lines.append(raw.decode("utf-8", errors="replace").rstrip("\r"))
        if len(self._buffer) > MAX_LINE:
            raise ProtocolError(f"{len(self._buffer)} bytes without a line break; the limit is "
                                f"{MAX_LINE}", interface="dashboard")
        return lines

    @property
    def pending(self) -> int:
        """Bytes of an incomplete line held back."""
        return len(self._buffer)


class DashboardClient:
    """The client's side of a dashboard connection, without the socket.

    ``send(name, argument)`` gives the bytes to write and remembers that a reply is due;
    ``receive_data(bytes)`` gives the events the received bytes complete: first a
    :class:`DashboardWelcome`, then one :class:`DashboardReply` per command, in the order the
    commands were sent. A line that arrives when no reply is due raises
    :class:`ProtocolError` (the protocol has no unsolicited lines).
    """

    def __init__(self) -> None:
        self._lines = LineBuffer()
        self._pending: deque[str] = deque()
        self.welcomed = False

    @property
    def awaiting(self) -> tuple[str, ...]:
        """Commands sent whose replies have not arrived, oldest first."""
        return tuple(self._pending)

    def send(self, name: str, argument: str | None = None) -> bytes:
        """The bytes of a command; its reply is expected after those already awaited."""
        data = encode_command(name, argument)
        self._pending.append(name)
        return data

    def receive_data(self, data: bytes) -> list[DashboardWelcome | DashboardReply]:
        """Events completed by ``data``."""
        events: list[DashboardWelcome | DashboardReply] = []
        for line in self._lines.feed(data):
            if not self.welcomed:
                if not line.startswith("Connected: "):
                    raise ProtocolError(f"expected the welcome line {WELCOME!r}, got {line!r}",
                                        interface="dashboard")
                self.welcomed = True
                events.append(DashboardWelcome(line))
                continue
            if not self._pending:
                raise ProtocolError(f"reply {line!r} arrived but no command was sent",
                                    interface="dashboard")
            events.append(parse_reply(self._pending.popleft(), line))
        return events


class DashboardServer:
    """The server's side (the virtual controller), without the socket.

    ``greeting()`` gives the welcome bytes; ``receive_data(bytes)`` gives the commands the
    bytes complete; ``reply(command, ...)`` gives the bytes of the answer
    (see :func:`format_reply`). ``closed`` turns true after ``quit`` has been answered.
    """

    def __init__(self) -> None:
        self._lines = LineBuffer()
        self.closed = False

    @staticmethod
    def greeting() -> bytes:
        """The welcome line, sent on connect."""
        return (WELCOME + "\n").encode("utf-8")

    def receive_data(self, data: bytes) -> list[DashboardCommand]:
        """Commands completed by ``data`` (empty lines are ignored, as the controller does)."""
        return [decode_command(line) for line in self._lines.feed(data) if line.strip()]

    def reply(self, command: DashboardCommand, ok: bool = True, variant: int = 0,
              **fields: object) -> bytes:
        """The bytes answering ``command``."""
        if command.name == "quit" and ok:
            self.closed = True
        return (format_reply(command, ok, variant, **fields) + "\n").encode("utf-8")
