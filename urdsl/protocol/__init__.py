"""Sans-I/O codecs for the controller's interfaces: bytes in, typed messages out, and back.

No sockets, threads or clocks here (the model is h11): :mod:`urdsl.robot` and the virtual
controller are thin socket layers on top. Every malformed input raises :class:`ProtocolError`
with the field, offset or size that is wrong.

* :mod:`.realtime` — the realtime interface (30003/30013), every layout from 1.6 to 5.x;
* :mod:`.primary` — primary/secondary (30001/30002): robot state and robot messages;
* :mod:`.rtde` — RTDE (30004) protocol versions 1 and 2, the client's state machine;
* :mod:`.dashboard` — the dashboard server's line protocol (29999).
"""

from .errors import ProtocolError

__all__ = ["ProtocolError"]
