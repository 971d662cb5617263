"""The world a URScript program touches besides the arm: I/O, registers, sockets, messages.

The verifier uses an :class:`Environment` with everything at rest (inputs low, registers
zero, sockets that connect but never answer); tests and users script it (set inputs, queue
socket replies). The virtual controller shares one environment between the program and its
network interfaces, so that RTDE clients see the registers a script writes.

Nothing here touches the real world: a script's ``socket_open`` never opens a socket.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

__all__ = ["Environment", "SocketModel"]


@dataclass
class SocketModel:
    """A socket a script opened by name. ``incoming`` holds what reads will return, in
    order; ``sent`` collects what the script sent."""

    host: str
    port: int
    connected: bool = True
    incoming: deque = field(default_factory=deque)
    sent: list = field(default_factory=list)


@dataclass
class Environment:
    """I/O and register state, in the controller's numbering (counts as on e-Series; boolean
    registers 0-127, 64-127 since 3.9/5.3).

    ``unsupported``: what a call of a builtin that urdsl does not simulate does:
    ``"default"`` returns a neutral value of its return type and records an event;
    ``"error"`` stops the program with URS209.
    ``devices``: what reads from outside the controller give (inputs, input registers, socket
    and XML-RPC replies, fieldbus and Modbus signals, operator answers): ``"quiet"`` the
    values held here (inputs low, registers zero, sockets that never answer: a read with
    timeout 0 waits for ever); ``"unknown"`` an unknown value that the checker follows as a
    working device would answer (see :mod:`urdsl.runtime.unknown`; ``urdsl check`` uses it).
    ``connectable``: hosts (as strings, with or without ``:port``) a script's
    ``socket_open`` may "connect" to; ``None`` means every host (nothing is opened either way).
    ``foreign_sockets``: code the script does not hold (a URCap's preamble, which urdsl
    cannot generate for a ``.urp``) may have opened sockets: with unknown devices, a socket
    the script uses without opening it is taken as open, to a device that answers.
    """

    standard_digital_in: list[bool] = field(default_factory=lambda: [False] * 8)
    standard_digital_out: list[bool] = field(default_factory=lambda: [False] * 8)
    configurable_digital_in: list[bool] = field(default_factory=lambda: [False] * 8)
    configurable_digital_out: list[bool] = field(default_factory=lambda: [False] * 8)
    tool_digital_in: list[bool] = field(default_factory=lambda: [False] * 2)
    tool_digital_out: list[bool] = field(default_factory=lambda: [False] * 2)
    standard_analog_in: list[float] = field(default_factory=lambda: [0.0] * 2)
    standard_analog_out: list[float] = field(default_factory=lambda: [0.0] * 2)
    tool_analog_in: list[float] = field(default_factory=lambda: [0.0] * 2)
    input_int_registers: list[int] = field(default_factory=lambda: [0] * 48)
    output_int_registers: list[int] = field(default_factory=lambda: [0] * 48)
    input_float_registers: list[float] = field(default_factory=lambda: [0.0] * 48)
    output_float_registers: list[float] = field(default_factory=lambda: [0.0] * 48)
    input_bool_registers: list[bool] = field(default_factory=lambda: [False] * 128)
    output_bool_registers: list[bool] = field(default_factory=lambda: [False] * 128)
    flags: list[bool] = field(default_factory=lambda: [False] * 32)
    sockets: dict[str, SocketModel] = field(default_factory=dict)
    socket_replies: dict[str, list[str]] = field(default_factory=dict)
    unsupported: str = "default"
    devices: str = "quiet"
    connectable: set[str] | None = None
    foreign_sockets: bool = False
    messages: list[tuple[float, str, str]] = field(default_factory=list)
