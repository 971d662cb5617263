"""Talking to a robot over sockets: sender, state reader, RTDE recorder, dashboard.

=====================  ==================================================================
module                 what
=====================  ==================================================================
:mod:`.connection`     bounded connect (retries, backoff), reads with deadlines, drain
:mod:`.program`        the text that is sent, and the way back from controller lines
:mod:`.sender`         check, send, follow: started / finished / failed at the user's line
:mod:`.state`          latest-sample state reader (realtime, primary, RTDE)
:mod:`.rtde_session`   RTDE handshake, recipe, stream
:mod:`.recorder`       RTDE → CSV (UR's record.py format)
:mod:`.csvfile`        the recording file: writer and reader
:mod:`.plot`           recording → PNG
:mod:`.dashboard`      dashboard server client
:mod:`.api`            :func:`connect`: one object for all of the above
=====================  ==================================================================

The byte formats are :mod:`urdsl.protocol`'s; nothing here decodes bytes by hand.
"""

from __future__ import annotations

from .api import Robot, connect
from .errors import (
    CheckFailedError,
    ConnectError,
    ConnectionLost,
    ControllerProtocolError,
    RobotError,
    RobotTimeout,
)
from .recorder import RecordResult, record
from .sender import SendResult, run_program, send, send_program
from .state import RobotState, StateReader, read_state

__all__ = [
    "Robot", "connect", "send", "send_program", "run_program", "SendResult", "read_state",
    "StateReader", "RobotState", "record", "RecordResult", "RobotError", "ConnectError",
    "ConnectionLost", "RobotTimeout", "ControllerProtocolError", "CheckFailedError",
]
