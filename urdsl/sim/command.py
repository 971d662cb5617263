"""``urdsl sim``: run the virtual controller until Ctrl-C (SIGINT) or SIGTERM."""

from __future__ import annotations

import argparse
import math
import signal
import sys
import threading

__all__ = ["add_commands", "cmd_sim"]

_DESCRIPTION = """\
Run a virtual Universal Robots controller on this machine: the dashboard server (29999),
primary/secondary/realtime interfaces (30001-30003, read-only 30011-30013) and RTDE (30004),
serving one simulated arm. URScript sent to 30001-30003 runs in real time (or --speed times
faster) through urdsl's interpreter; RTDE, realtime and primary clients see the arm move.
Controller time advances in lockstep with the program: a machine too slow for --speed makes
the controller run slower in wall time (it says so once), never skip a step.

A new def program replaces the running one, sec programs run beside it, bare lines run as a
one-off program. Syntax and runtime errors are reported on the primary interface (30001)
with line and column. A joint beyond its limit or a link below the floor (z < 0) causes a
protective stop (dashboard: 'safetymode', 'unlock protective stop').
"""

_EPILOG = """\
examples:
  urdsl sim                                   UR5e, software 5.15, standard ports
  urdsl sim --robot ur10 --version 3.15       a CB3 UR10 (125 Hz realtime and RTDE)
  urdsl sim --speed 5 --programs programs/    five times faster; dashboard 'load' reads programs/
  urdsl sim --port-offset 100                 ports 30099, 30101, ... (several sims at once)

then, in another terminal:
  urdsl send programs/course_examples.script  send a program (or any UR client library)
  urdsl record --csv run.csv                  record RTDE while it runs

Stop with Ctrl-C.
"""


def _joints(text: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.replace("[", "").replace("]", "").split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not 6 comma-separated numbers") from None
    if len(values) != 6 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: give 6 finite joint angles in rad")
    return values


def add_commands(commands) -> None:
    """Register ``urdsl sim``."""
    p = commands.add_parser(
        "sim", help="run a virtual UR controller (dashboard, primary, realtime, RTDE) locally",
        description=_DESCRIPTION, epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--robot", default="ur5e", metavar="MODEL",
                   help="arm model, e.g. ur3e, ur5e, ur10e, ur16e, ur20, ur30, ur5 (CB3) "
                   "(default: ur5e)")
    p.add_argument("--version", default=None, metavar="X.Y",
                   help="controller software version: 5.x for e-Series arms (default 5.15), "
                   "3.x for CB3 arms (default 3.15); sets packet layouts and rates")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default: 127.0.0.1, this machine only)")
    p.add_argument("--speed", type=float, default=1.0, metavar="FACTOR",
                   help="run programs FACTOR times faster than real time (default: 1.0)")
    p.add_argument("--start-joints", type=_joints, default=None, metavar="Q",
                   help="joint angles in rad where the arm rests at start, e.g. "
                   "'0,-1.5708,1.5708,-1.5708,-1.5708,0'")
    p.add_argument("--port-offset", type=int, default=0, metavar="N",
                   help="add N to every port (default: 0, the controller's own ports)")
    p.add_argument("--programs", default=None, metavar="DIR",
                   help="folder the dashboard's 'load <file>' reads programs from: URScript "
                   "files, and PolyScope programs (.urp, compiled with their installation "
                   "as urdsl compile does)")
    p.add_argument("--powered-off", action="store_true",
                   help="start powered off, as a real controller boots: use the dashboard's "
                   "'power on' and 'brake release' before sending programs")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="print only the ready line, not the controller's messages")
    p.set_defaults(run=cmd_sim)


def cmd_sim(args: argparse.Namespace) -> int:
    from .._cli import UsageError, robot_model
    from .controller import DEFAULT_START, SimError, VirtualController

    if not 0 <= args.port_offset <= 30000:
        return _usage("--port-offset must be between 0 and 30000")
    try:
        robot = robot_model(args.robot)
    except UsageError as error:
        return _usage(str(error))
    try:
        sim = VirtualController(
            robot=robot, version=args.version, speed=args.speed,
            start_joints=args.start_joints or DEFAULT_START, programs_dir=args.programs,
            powered=not args.powered_off)
    except SimError as error:
        return _usage(str(error))
    stop = threading.Event()

    def on_signal(signum, frame):
        stop.set()

    # The clock thread must get Python's lock every 2 ms: switch threads more often than
    # the default 5 ms (this process only serves the controller).
    sys.setswitchinterval(min(sys.getswitchinterval(), 0.0005))
    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        with sim:
            try:
                servers = sim.serve(host=args.host, port_offset=args.port_offset)
            except OSError as error:
                print(f"urdsl: error: {error}", file=sys.stderr)
                return 1
            with servers:
                if not args.quiet:
                    sim.subscribe_messages(_printer(sim))
                ports = ", ".join(f"{k} {v}" for k, v in servers.ports.items())
                print(f"urdsl sim: {args.robot} software {sim.version} at {args.host} "
                      f"({ports}); {sim.frequency:g} Hz, speed x{sim.speed:g}. "
                      "Ctrl-C stops.", flush=True)
                while not stop.wait(0.2):
                    pass
        print("urdsl sim: stopped", flush=True)
        return 0
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _usage(message: str) -> int:
    print(f"urdsl: error: {message}", file=sys.stderr)
    return 2


def _printer(sim):
    def show(message) -> None:
        print(f"[{message.time:9.3f} s] {message.kind}: {message.text}", flush=True)

    return show
