"""The dashboard server's commands and replies (port 29999), without sockets.

One line in, one line out, with the replies of docs/controller-facts.md §13 — their texts are
the protocol's (:data:`urdsl.protocol.dashboard.COMMANDS`), written once. The virtual
controller is always in remote control. ``load`` reads URScript files (``.script``,
``.urscript``, ``.txt``) and PolyScope programs (``.urp``, compiled with their installation
as ``urdsl compile`` does) from the controller's programs folder; a file that cannot be read
or compiled answers ``Error while loading program``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..protocol.dashboard import (
    COMMANDS,
    MAX_LINE,
    UNKNOWN_COMMAND,
    WELCOME,
    DashboardCommand,
    LineBuffer,
    decode_command,
    format_reply,
)
from ..protocol.errors import ProtocolError
from .state import ProgramState, SimError

__all__ = ["WELCOME", "DashboardSession", "MAX_LINE"]


class DashboardSession:
    """Answers one client's dashboard commands against a :class:`VirtualController`.

    Lines are cut by the protocol's :class:`~urdsl.protocol.dashboard.LineBuffer`, with its
    one line limit (:data:`~urdsl.protocol.dashboard.MAX_LINE` bytes): a longer line is
    answered as not understood and the connection lives on.
    """

    def __init__(self, controller: Any) -> None:
        self.sim = controller
        self._lines = LineBuffer()
        self.closed = False
        self._operational_mode: str | None = None

    @property
    def pending(self) -> int:
        """Bytes of an unfinished command line held back (at most :data:`MAX_LINE`)."""
        return self._lines.pending

    def receive(self, data: bytes) -> list[str]:
        """Feed bytes; return the reply lines (without line breaks)."""
        try:
            lines = self._lines.feed(data)
        except ProtocolError:
            self._lines = LineBuffer()
            return [] if self.closed else ["could not understand: '<line too long>'"]
        replies = []
        for line in lines:
            if self.closed:
                break
            replies.append(self.command(line.strip("\r ")))
        return replies

    def command(self, line: str) -> str:
        """The reply to one command line. The words are matched in any case; the reply texts
        are the protocol's (:func:`urdsl.protocol.dashboard.format_reply`)."""
        command = decode_command(line, ignore_case=True)
        spec = COMMANDS.get(command.name)
        if spec is None or (spec.argument is not None and not command.argument):
            return UNKNOWN_COMMAND.format(text=line)
        if command.argument is not None:
            command = DashboardCommand(command.name, command.argument.strip())
        ok, variant, fields = _HANDLERS[spec.name](self, command)
        try:
            return format_reply(command, ok, variant, **fields)
        except ProtocolError:  # a reply the line protocol cannot carry (too long)
            return UNKNOWN_COMMAND.format(text=line[:200])

    # ---- commands: (ok, reply variant, the reply's fields) ---------------------------------

    def _load(self, command: DashboardCommand) -> Reply:
        name = command.argument or ""
        try:
            loaded = self.sim.load_program(name)
        except FileNotFoundError:
            return False, 0, {}
        except SimError:
            return False, 1, {}
        return True, 0, {"arg": loaded}

    def _play(self, command: DashboardCommand) -> Reply:
        return bool(self.sim.play()), 0, {}

    def _stop(self, command: DashboardCommand) -> Reply:
        self.sim.stop_program()
        return True, 0, {}

    def _pause(self, command: DashboardCommand) -> Reply:
        return bool(self.sim.pause_program()), 0, {}

    def _quit(self, command: DashboardCommand) -> Reply:
        self.closed = True
        return True, 0, {}

    def _shutdown(self, command: DashboardCommand) -> Reply:
        self.sim.power_off()
        return True, 0, {}

    def _running(self, command: DashboardCommand) -> Reply:
        return True, 0, {"bool": self.sim.program_state != ProgramState.STOPPED}

    def _robotmode(self, command: DashboardCommand) -> Reply:
        return True, 0, {"mode": self.sim.robot_mode.name}

    def _safetymode(self, command: DashboardCommand) -> Reply:
        return True, 0, {"mode": self.sim.safety_mode.name}

    def _program_state(self, command: DashboardCommand) -> Reply:
        state = self.sim.program_state
        shown = {ProgramState.STOPPING: "STOPPED", ProgramState.PAUSING: "PAUSED",
                 ProgramState.RESUMING: "PLAYING"}.get(state, state.name)
        name = self.sim.loaded_program or self.sim.program_name or "<unnamed>"
        return True, 0, {"state": shown, "name": name}

    def _loaded(self, command: DashboardCommand) -> Reply:
        name = self.sim.loaded_program
        return (True, 0, {"name": name}) if name else (True, 1, {})

    def _power_on(self, command: DashboardCommand) -> Reply:
        self.sim.power_on()
        return True, 0, {}

    def _power_off(self, command: DashboardCommand) -> Reply:
        self.sim.power_off()
        return True, 0, {}

    def _brake_release(self, command: DashboardCommand) -> Reply:
        self.sim.brake_release()
        return True, 0, {}

    def _unlock(self, command: DashboardCommand) -> Reply:
        if self.sim.unlock_protective_stop():
            return True, 0, {}
        return False, 0, {"text": "Always inspect cause of protective stop before unlocking"}

    def _restart_safety(self, command: DashboardCommand) -> Reply:
        self.sim.restart_safety()
        return True, 0, {}

    def _saved(self, command: DashboardCommand) -> Reply:
        return True, 0, {"bool": True, "name": self.sim.loaded_program or "<unnamed>"}

    def _polyscope(self, command: DashboardCommand) -> Reply:
        return True, 0, {"version": self.sim.version, "text": " (urdsl virtual controller)"}

    def _version(self, command: DashboardCommand) -> Reply:
        return True, 0, {"version": self.sim.version}

    def _model(self, command: DashboardCommand) -> Reply:
        name = self.sim.robot_name.upper()
        return True, 0, {"mode": name[:-1] if name.endswith("E") else name}

    def _serial(self, command: DashboardCommand) -> Reply:
        return True, 0, {"name": self.sim.serial_number}

    def _set_operational(self, command: DashboardCommand) -> Reply:
        self._operational_mode = (command.argument or "").upper()
        return True, 0, {"arg": self._operational_mode.lower()}

    def _operational(self, command: DashboardCommand) -> Reply:
        return True, 0, {"mode": self._operational_mode or "NONE"}

    def _clear_operational(self, command: DashboardCommand) -> Reply:
        self._operational_mode = None
        return True, 0, {"text": "Current operational mode: 'none'."}

    def _remote(self, command: DashboardCommand) -> Reply:
        return True, 0, {"bool": True}  # the virtual controller is always in remote control

    def _user_role(self, command: DashboardCommand) -> Reply:
        return True, 0, {"mode": "PROGRAMMER"}

    def _done(self, command: DashboardCommand) -> Reply:
        """Commands whose answer is their one fixed text (popup, log, user role, …)."""
        return True, 0, {}


Reply = tuple[bool, int, dict[str, Any]]
"""A command's answer: ok, which of its documented texts, and the text's fields."""

_HANDLERS: dict[str, Callable[[DashboardSession, DashboardCommand], Reply]] = {
    "load": DashboardSession._load,
    "load installation": DashboardSession._done,
    "play": DashboardSession._play,
    "stop": DashboardSession._stop,
    "pause": DashboardSession._pause,
    "quit": DashboardSession._quit,
    "shutdown": DashboardSession._shutdown,
    "running": DashboardSession._running,
    "robotmode": DashboardSession._robotmode,
    "safetymode": DashboardSession._safetymode,
    "safetystatus": DashboardSession._safetymode,
    "programState": DashboardSession._program_state,
    "get loaded program": DashboardSession._loaded,
    "power on": DashboardSession._power_on,
    "power off": DashboardSession._power_off,
    "brake release": DashboardSession._brake_release,
    "unlock protective stop": DashboardSession._unlock,
    "close safety popup": DashboardSession._done,
    "restart safety": DashboardSession._restart_safety,
    "popup": DashboardSession._done,
    "close popup": DashboardSession._done,
    "addToLog": DashboardSession._done,
    "isProgramSaved": DashboardSession._saved,
    "PolyscopeVersion": DashboardSession._polyscope,
    "version": DashboardSession._version,
    "setUserRole": DashboardSession._done,
    "getUserRole": DashboardSession._user_role,
    "set operational mode": DashboardSession._set_operational,
    "get operational mode": DashboardSession._operational,
    "clear operational mode": DashboardSession._clear_operational,
    "is in remote control": DashboardSession._remote,
    "get serial number": DashboardSession._serial,
    "get robot model": DashboardSession._model,
    "saveLog": DashboardSession._done,
}
"""What the virtual controller does for each documented command (every key of
:data:`urdsl.protocol.dashboard.COMMANDS`)."""
assert set(_HANDLERS) == set(COMMANDS), set(COMMANDS) ^ set(_HANDLERS)
