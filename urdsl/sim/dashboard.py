"""The dashboard server's commands and replies (port 29999), without sockets.

One line in, one line out, with the replies of docs/controller-facts.md §13. The virtual
controller is always in remote control. ``load`` reads URScript files (``.script``,
``.urscript``, ``.txt``) and PolyScope programs (``.urp``, compiled with their installation
as ``urdsl compile`` does) from the controller's programs folder; a file that cannot be read
or compiled answers ``Error while loading program``.
"""

from __future__ import annotations

from typing import Any

from ..protocol.dashboard import MAX_LINE, WELCOME, LineBuffer
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
        """The reply to one command line."""
        lower = line.lower()
        if lower.startswith("load installation "):
            return f"Loading installation: {line[18:].strip()}"
        if lower.startswith("load "):
            return self._load(line[5:].strip())
        if lower.startswith("popup "):
            return "showing popup"
        if lower.startswith("addtolog "):
            return "Added log message"
        if lower.startswith("setuserrole "):
            return f"Setting user role: {line[12:].strip()}"
        if lower.startswith("set operational mode "):
            self._operational_mode = line[21:].strip().upper()
            return f"Operational mode '{self._operational_mode.lower()}' is set"
        simple = _COMMANDS.get(lower)
        if simple is not None:
            return simple(self)
        return f"could not understand: '{line}'"

    # ---- commands --------------------------------------------------------------------------

    def _load(self, name: str) -> str:
        try:
            loaded = self.sim.load_program(name)
        except FileNotFoundError:
            return f"File not found: {name}"
        except SimError:
            return f"Error while loading program: {name}"
        return f"Loading program: {loaded}"

    def _play(self) -> str:
        return "Starting program" if self.sim.play() else "Failed to execute: play"

    def _stop(self) -> str:
        self.sim.stop_program()
        return "Stopped"

    def _pause(self) -> str:
        return "Pausing program" if self.sim.pause_program() else "Failed to execute: pause"

    def _quit(self) -> str:
        self.closed = True
        return "Disconnected"

    def _running(self) -> str:
        running = self.sim.program_state != ProgramState.STOPPED
        return f"Program running: {'true' if running else 'false'}"

    def _robotmode(self) -> str:
        return f"Robotmode: {self.sim.robot_mode.name}"

    def _safetymode(self) -> str:
        return f"Safetymode: {self.sim.safety_mode.name}"

    def _safetystatus(self) -> str:
        return f"Safetystatus: {self.sim.safety_mode.name}"

    def _program_state(self) -> str:
        state = self.sim.program_state
        shown = {ProgramState.STOPPING: "STOPPED", ProgramState.PAUSING: "PAUSED",
                 ProgramState.RESUMING: "PLAYING"}.get(state, state.name)
        name = self.sim.loaded_program or self.sim.program_name or "<unnamed>"
        return f"{shown} {name}"

    def _loaded(self) -> str:
        name = self.sim.loaded_program
        return f"Loaded program: {name}" if name else "No program loaded"

    def _power_on(self) -> str:
        self.sim.power_on()
        return "Powering on"

    def _power_off(self) -> str:
        self.sim.power_off()
        return "Powering off"

    def _brake_release(self) -> str:
        self.sim.brake_release()
        return "Brake releasing"

    def _unlock(self) -> str:
        if self.sim.unlock_protective_stop():
            return "Protective stop releasing"
        return ("Cannot unlock protective stop until 5s after occurrence. Always inspect cause "
                "of protective stop before unlocking")

    def _saved(self) -> str:
        name = self.sim.loaded_program or "<unnamed>"
        return f"true {name}"

    def _polyscope(self) -> str:
        return f"URSoftware {self.sim.version} (urdsl virtual controller)"

    def _model(self) -> str:
        name = self.sim.robot_name.upper()
        return name[:-1] if name.endswith("E") else name

    def _operational(self) -> str:
        return self._operational_mode or "NONE"

    def _clear_operational(self) -> str:
        self._operational_mode = None
        return ("No longer controlling the operational mode. Current operational mode: "
                "'none'.")


_COMMANDS = {
    "play": DashboardSession._play,
    "stop": DashboardSession._stop,
    "pause": DashboardSession._pause,
    "quit": DashboardSession._quit,
    "shutdown": lambda s: (s.sim.power_off(), "Shutting down")[1],
    "running": DashboardSession._running,
    "robotmode": DashboardSession._robotmode,
    "safetymode": DashboardSession._safetymode,
    "safetystatus": DashboardSession._safetystatus,
    "programstate": DashboardSession._program_state,
    "get loaded program": DashboardSession._loaded,
    "power on": DashboardSession._power_on,
    "power off": DashboardSession._power_off,
    "brake release": DashboardSession._brake_release,
    "unlock protective stop": DashboardSession._unlock,
    "close safety popup": lambda s: "closing safety popup",
    "restart safety": lambda s: (s.sim.restart_safety(), "Restarting safety")[1],
    "close popup": lambda s: "closing popup",
    "isprogramsaved": DashboardSession._saved,
    "polyscopeversion": DashboardSession._polyscope,
    "version": lambda s: str(s.sim.version),
    "get robot model": DashboardSession._model,
    "get serial number": lambda s: s.sim.serial_number,
    "get operational mode": DashboardSession._operational,
    "clear operational mode": DashboardSession._clear_operational,
    "is in remote control": lambda s: "true",
    "getuserrole": lambda s: "PROGRAMMER",
    "savelog": lambda s: "Log saved to disk",
}
