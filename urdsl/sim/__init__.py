"""Virtual UR controller serving the controller's protocols on loopback.

>>> from urdsl.sim import VirtualController
>>> with VirtualController(robot="ur5e", speed=2.0) as sim, sim.serve(port_offset=100) as net:
...     sim.submit("def p():\\n  movej([0.5, -1.57, 1.57, -1.57, -1.57, 0])\\nend\\n")
...     snapshot = sim.wait_snapshot(lambda s: abs(s.q[0] - 0.5) < 1e-9, timeout=10)

``urdsl sim`` runs the same from the command line (see :mod:`urdsl.sim.command`).
"""

from __future__ import annotations

from .controller import DEFAULT_START, ControllerMessage, SimError, VirtualController
from .state import ControllerVersion, JointMode, ProgramState, RobotMode, SafetyMode, Snapshot

__all__ = [
    "VirtualController", "ControllerMessage", "SimError", "DEFAULT_START", "Snapshot",
    "RobotMode", "SafetyMode", "ProgramState", "JointMode", "ControllerVersion",
    "STANDARD_PORTS", "demo_story",
]


def __getattr__(name: str):
    if name == "STANDARD_PORTS":
        from .servers import STANDARD_PORTS

        return STANDARD_PORTS
    if name == "demo_story":
        from .story import demo_story

        return demo_story
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
