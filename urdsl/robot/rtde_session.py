"""An RTDE connection (port 30004) over a socket: handshake, recipe, start, stream, pause.

The protocol itself (packages, recipes, which reply answers which request) is
:class:`urdsl.protocol.rtde.RtdeClient`; this module adds the socket and the policy:

* protocol version 2 is asked for first, then version 1 (UR's client library does the
  same; CB3 controllers before 3.5 know only version 1, which has no output frequency and
  streams at the control rate);
* every request waits for its reply at most ``timeout`` seconds;
* data packages and text messages that arrive while a reply is awaited are kept, in order
  (a pause request while streaming is answered after the last samples — none is lost);
* a recipe the controller refuses raises :class:`RtdeSetupError` naming the fields it does
  not know (with the closest names it does know) or that another client uses.
"""

from __future__ import annotations

import difflib
import time
from collections import deque
from collections.abc import Iterable

from ..protocol import rtde as r
from ..protocol.errors import ProtocolError
from ..protocol.rtde_fields import FIELDS
from .connection import Connection
from .errors import ControllerProtocolError, RobotError, RobotTimeout

__all__ = ["RtdeSession", "RtdeSetupError", "PORT", "CB3_MAX_FREQUENCY",
           "E_SERIES_MAX_FREQUENCY", "suggest_fields"]

PORT = r.PORT
CB3_MAX_FREQUENCY = r.CB3_MAX_FREQUENCY
E_SERIES_MAX_FREQUENCY = r.E_SERIES_MAX_FREQUENCY

MAX_QUEUED = 200_000
"""Samples kept while a reply is awaited before the oldest are dropped: 400 s at 500 Hz,
far more than any reply takes; it only bounds memory against a misbehaving peer."""


class RtdeSetupError(RobotError):
    """The controller refused a recipe or a request (unknown field, input in use, start
    refused, frequency out of range)."""


def suggest_fields(name: str, outputs: bool = True) -> list[str]:
    """Known RTDE names close to ``name`` (for "did you mean ...")."""
    names = [f.name for f in FIELDS.values() if (f.output if outputs else f.input)]
    return difflib.get_close_matches(name, names, n=3, cutoff=0.6)


class RtdeSession:
    """One RTDE connection (see the module docstring). A context manager: leaving it pauses
    the stream (bounded) and closes the socket."""

    def __init__(self, host: str, port: int = PORT, *, timeout: float = 5.0,
                 attempts: int = 1, connection: Connection | None = None) -> None:
        self.host = host
        self.port = port
        self.timeout = timeout
        self.connection = connection or Connection.open(host, port, interface="RTDE",
                                                        timeout=timeout, attempts=attempts)
        self.client = r.RtdeClient()
        self.queued: deque = deque(maxlen=MAX_QUEUED)  # samples and texts, in order
        self.messages: deque[r.RtdeTextMessage] = deque(maxlen=100)  # every text seen
        try:
            self._negotiate()
        except BaseException:
            self.connection.close()
            raise

    # -- properties -----------------------------------------------------------------------

    @property
    def where(self) -> str:
        return self.connection.where

    @property
    def protocol(self) -> int:
        return self.client.protocol

    @property
    def controller_version(self) -> str | None:
        version = self.client.controller_version
        if version is None:
            return None
        return f"{version.major}.{version.minor}.{version.bugfix}.{version.build}"

    @property
    def e_series(self) -> bool:
        version = self.client.controller_version
        return version is not None and version.major >= 5

    @property
    def max_frequency(self) -> float:
        return E_SERIES_MAX_FREQUENCY if self.e_series else CB3_MAX_FREQUENCY

    # -- requests -------------------------------------------------------------------------

    def _place(self) -> dict:
        return {"host": self.host, "port": self.port, "interface": "RTDE"}

    def _feed(self, data: bytes) -> list:
        try:
            return self.client.receive_data(data)
        except ProtocolError as error:
            raise ControllerProtocolError(f"{self.where} sent bytes that are not RTDE: "
                                          f"{error}", **self._place()) from None

    def _sort(self, events: list, reply_type: type | None):
        """Keep samples and messages; return the awaited reply if among ``events``."""
        reply = None
        for event in events:
            if isinstance(event, r.DataPackage):
                self.queued.append(event)
            elif isinstance(event, r.RtdeTextMessage):
                self.queued.append(event)
                self.messages.append(event)
            elif reply_type is not None and isinstance(event, reply_type) and reply is None:
                reply = event
        return reply

    def _request(self, data: bytes, reply_type: type, what: str,
                 timeout: float | None = None):
        timeout = self.timeout if timeout is None else timeout
        self.connection.send(data, timeout)
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise RobotTimeout(f"{self.where} did not answer the {what} request within "
                                   f"{timeout:g} s", **self._place())
            try:
                chunk = self.connection.recv(left)
            except RobotTimeout:
                continue
            reply = self._sort(self._feed(chunk), reply_type)
            if reply is not None:
                return reply

    def _negotiate(self) -> None:
        for version in (2, 1):
            reply = self._request(self.client.request_protocol_version(version),
                                  r.ProtocolVersionReply, f"protocol version {version}")
            if reply.accepted:
                break
        else:
            raise RtdeSetupError(f"{self.where} accepts neither RTDE protocol version 2 nor 1",
                                 **self._place())
        self._request(self.client.get_controller_version(), r.ControllerVersion,
                      "controller version")

    def setup_outputs(self, names: Iterable[str], frequency: float = 125.0) -> r.Recipe:
        """Ask for the output recipe ``names`` at ``frequency`` Hz (protocol 2; protocol 1
        streams at the control rate). Returns the recipe with the controller's types."""
        names = tuple(names)
        if not 0 < frequency <= self.max_frequency:
            series = "e-Series" if self.e_series else "CB3"
            raise RtdeSetupError(f"{self.where}: a {series} controller "
                                 f"({self.controller_version}) streams at 1 to "
                                 f"{self.max_frequency:g} Hz, not {frequency:g} Hz",
                                 **self._place())
        try:
            data = self.client.setup_outputs(names, frequency)
        except ProtocolError as error:
            raise RtdeSetupError(f"RTDE output recipe: {error.message}",
                                 **self._place()) from None
        self._request(data, r.OutputSetupReply, "output setup")
        recipe = self.client.output_recipe
        assert recipe is not None
        if not recipe.valid:
            raise RtdeSetupError(self._refusal(recipe, outputs=True), **self._place())
        return recipe

    def _refusal(self, recipe: r.Recipe, outputs: bool) -> str:
        parts = []
        for name in recipe.not_found:
            close = suggest_fields(name, outputs)
            hint = f" (did you mean {' or '.join(close)}?)" if close else ""
            parts.append(f"{name}{hint}")
        text = ""
        if parts:
            text = (f"{self.where} (controller {self.controller_version}) does not know the "
                    f"{'output' if outputs else 'input'} field(s): {', '.join(parts)}")
        if recipe.in_use:
            text += ("; " if text else f"{self.where}: ") + \
                f"input(s) controlled by another RTDE client: {', '.join(recipe.in_use)}"
        for message in list(self.messages)[-3:]:
            text += f"; controller says: {message.message}"
        return text

    def start(self) -> None:
        """Start streaming; raises :class:`RtdeSetupError` when the controller refuses."""
        try:
            data = self.client.start()
        except ProtocolError as error:
            raise RtdeSetupError(f"cannot start RTDE: {error.message}", **self._place()) \
                from None
        reply = self._request(data, r.StartReply, "start")
        if not reply.accepted:
            raise RtdeSetupError(f"{self.where} refused to start streaming", **self._place())

    def pause(self, timeout: float | None = None) -> None:
        """Pause streaming; samples that arrive before the reply are kept in ``queued``."""
        self._request(self.client.pause(), r.PauseReply, "pause", timeout)

    # -- streaming ------------------------------------------------------------------------

    def receive(self, timeout: float) -> list:
        """Samples (:class:`DataPackage`) and text messages that arrived, oldest first:
        those queued, else whatever comes within ``timeout`` s (maybe nothing)."""
        if self.queued:
            return self._take_queued()
        try:
            chunk = self.connection.recv(timeout)
        except RobotTimeout:
            return []
        return self._seen(self._feed(chunk))

    def _seen(self, events: list) -> list:
        self.messages.extend(e for e in events if isinstance(e, r.RtdeTextMessage))
        return events

    def drain(self) -> list:
        """Everything buffered now (queued first), without waiting."""
        events = self._take_queued()
        data = self.connection.drain()
        if data:
            events.extend(self._seen(self._feed(data)))
        return events

    def feed(self, data: bytes) -> list:
        """Events (samples, texts, replies) completed by ``data`` read elsewhere."""
        return self._seen(self._feed(data))

    def take_queued(self) -> list:
        """Samples and texts kept while replies were awaited, oldest first."""
        return self._take_queued()

    def _take_queued(self) -> list:
        events = list(self.queued)
        self.queued.clear()
        return events

    def close(self, timeout: float = 1.0) -> None:
        """Pause if streaming (waiting at most ``timeout`` s), then close."""
        if not self.connection.closed and self.client.running:
            try:
                self.pause(timeout)
            except (RobotError, ProtocolError, OSError):
                pass
        self.connection.close()

    def __enter__(self) -> RtdeSession:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
