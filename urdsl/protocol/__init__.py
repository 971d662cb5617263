"""Sans-I/O codecs for the controller's interfaces: bytes in, typed messages out, and back.

No sockets, threads or clocks live here (the model is h11): a socket layer feeds received
bytes to a decoder and writes the bytes an encoder returns. Malformed input raises
:class:`ProtocolError` naming the field, offset and size that were wrong.

==========================  =======  ================================================
module                      port     what
==========================  =======  ================================================
:mod:`.dashboard`           29999    dashboard server line protocol (both sides)
:mod:`.realtime`            30003    realtime ("Matlab") interface, every version
:mod:`.primary`             30001/2  primary/secondary: robot state and robot messages,
                                     the controller's side of a connection
:mod:`.script_framing`      30001-3  script text cut into programs as the controller does
:mod:`.rtde`                30004    RTDE protocol v1/v2, client and server machines
:mod:`.rtde_fields`                  the RTDE field/type table, as data
==========================  =======  ================================================
"""

from __future__ import annotations

from .dashboard import DashboardClient, DashboardReply, DashboardServer
from .errors import ProtocolError
from .primary import (
    PrimaryDecoder,
    PrimaryServer,
    RobotState,
    RuntimeExceptionMessage,
    VersionMessage,
)
from .realtime import RealtimeDecoder, RealtimeState, decode_realtime, encode_realtime
from .rtde import DataPackage, Recipe, RtdeClient, RtdeServer

__all__ = [
    "ProtocolError",
    "DashboardClient", "DashboardReply", "DashboardServer",
    "RealtimeDecoder", "RealtimeState", "decode_realtime", "encode_realtime",
    "PrimaryDecoder", "PrimaryServer", "RobotState", "RuntimeExceptionMessage", "VersionMessage",
    "RtdeClient", "RtdeServer", "Recipe", "DataPackage",
]
