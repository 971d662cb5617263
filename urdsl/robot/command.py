"""``urdsl send``, ``state``, ``record``, ``plot`` and ``dashboard``: talking to a robot."""

from __future__ import annotations

import argparse
import json
import sys
import time

__all__ = ["add_commands"]

_HOST_HELP = ("the controller's address (default 127.0.0.1: `urdsl sim` on this machine); "
              "your robot's, such as 192.168.0.10")


def add_commands(commands) -> None:
    p = commands.add_parser(
        "send", help="check a program, send it to a robot and report how it ran",
        description="Check the program offline first (refused on errors unless --no-check), "
        "send its canonical text (a bare list of statements is wrapped in `def "
        "urdsl_program():`), then follow the primary interface (30001) and report whether "
        "it finished or failed; a runtime error is shown at your file's line.\n\nExit "
        "status: 0 finished (or sent, with --no-wait), 1 refused or failed, 2 usage or "
        "connection errors.",
        epilog="examples:\n  urdsl send pick.script --host 127.0.0.1\n"
        "  urdsl send programs/pick_and_place.py --host 127.0.0.1 --robot ur5e\n"
        "  urdsl send sec_io.script --host 127.0.0.1 --port 30003 --no-wait",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file", metavar="FILE|PROGRAM.py")
    p.add_argument("--host", default="127.0.0.1", help=_HOST_HELP)
    p.add_argument("--port", type=int, default=30002,
                   help="script port: 30001 primary, 30002 secondary (default), 30003 "
                   "realtime (or a simulator's shifted port)")
    p.add_argument("--primary-port", type=int, default=30001,
                   help="where to follow the program (default 30001)")
    p.add_argument("--robot", default="ur5e", help="model to check against (default ur5e)")
    p.add_argument("--no-check", action="store_true",
                   help="send without checking first (not recommended)")
    p.add_argument("--no-wait", action="store_true",
                   help="send and return at once, without following the program")
    p.add_argument("--timeout", type=float, default=120.0, metavar="S",
                   help="how long to follow the program (default 120 s)")
    p.set_defaults(run=cmd_send)

    p = commands.add_parser(
        "state", help="read the robot's joints, TCP pose and modes",
        description="Read the newest state (queued older packets are skipped) from the "
        "realtime (30003), primary (30002) or RTDE (30004) interface.",
        epilog="examples:\n  urdsl state --host 127.0.0.1\n"
        "  urdsl state --host 127.0.0.1 --interface rtde --json\n"
        "  urdsl state --host 127.0.0.1 --watch",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--host", default="127.0.0.1", help=_HOST_HELP)
    p.add_argument("--interface", choices=("realtime", "primary", "rtde"), default="realtime")
    p.add_argument("--port", type=int, help="default: 30003, 30002 or 30004 by interface")
    p.add_argument("--watch", action="store_true", help="print the state every 0.5 s until "
                   "Ctrl-C")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--timeout", type=float, default=5.0, metavar="S")
    p.set_defaults(run=cmd_state)

    p = commands.add_parser(
        "record", help="record RTDE outputs to a CSV file",
        description="Record RTDE outputs (protocol 2, falling back to 1) to CSV in the "
        "format of UR's record.py (space-delimited, a header row with timestamp first and "
        "vectors expanded: actual_q_0 … actual_q_5). Ctrl-C stops and keeps what was "
        "recorded.",
        epilog="examples:\n  urdsl record --host 127.0.0.1 --duration 10 -o run.csv\n"
        "  urdsl record --host 127.0.0.1 --fields actual_q,actual_TCP_pose --frequency 500 "
        "-o fast.csv",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--host", default="127.0.0.1", help=_HOST_HELP)
    p.add_argument("--port", type=int, default=30004)
    p.add_argument("--fields", default="actual_q,actual_qd,actual_TCP_pose,runtime_state",
                   help="comma-separated RTDE output names")
    p.add_argument("--frequency", type=float, default=125.0,
                   help="Hz: up to 125 on CB3, 500 on e-Series (default 125)")
    p.add_argument("--duration", type=float, metavar="S", help="seconds (default: Ctrl-C)")
    p.add_argument("-o", "--output", required=True, metavar="CSV")
    p.set_defaults(run=cmd_record)

    p = commands.add_parser("plot", help="plot a recorded CSV file",
                            description="Plot columns of a CSV written by `urdsl record` "
                            "against time (PNG, SVG or PDF by the suffix of -o).",
                            epilog="example:\n  urdsl plot run.csv -o run.png "
                            "--columns actual_q,actual_TCP_pose",
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("csv", metavar="CSV")
    p.add_argument("-o", "--output", required=True, metavar="PNG")
    p.add_argument("--columns", help="names or vector prefixes (default actual_q,actual_qd)")
    p.set_defaults(run=cmd_plot)

    p = commands.add_parser(
        "dashboard", help="send a dashboard server command (power on, play, robotmode, ...)",
        description="Send one command to the dashboard server (29999) and print its reply. "
        "Exit 1 when the reply is not the documented success reply.",
        epilog="examples:\n  urdsl dashboard --host 127.0.0.1 robotmode\n"
        "  urdsl dashboard --host 127.0.0.1 power on\n"
        "  urdsl dashboard --host 127.0.0.1 load pick.urp",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--host", default="127.0.0.1", help=_HOST_HELP)
    p.add_argument("--port", type=int, default=29999)
    p.add_argument("--timeout", type=float, default=5.0, metavar="S")
    p.add_argument("words", nargs="+", metavar="COMMAND")
    p.set_defaults(run=cmd_dashboard)


# ---- send ----------------------------------------------------------------------------------


def _load(name: str):
    """(tree, label) of a .script or DSL program; prints the problem and returns None."""
    from ..cli import read_input
    from ..dsl.command import ProgramFileError, load_program
    from ..dsl.errors import DslError
    from ..script.diagnostics import ScriptError
    from ..script.parser import parse

    if name.endswith(".py"):
        try:
            return load_program(name).tree(), name
        except (DslError, ProgramFileError) as error:
            print(str(error), file=sys.stderr)
            return None
    source = read_input(name)
    try:
        return parse(source.text, source.name), source.name
    except ScriptError as error:
        print(error.diagnostic.render(), file=sys.stderr)
        return None


def program_to_send(tree):
    """The tree as sent: a program as it is; bare statements wrapped in ``def
    urdsl_program():`` (the controller runs one def; UR documents only that form)."""
    from ..script import nodes as n

    body = [item for item in tree.body if not isinstance(item, (n.Comment, n.Blank))]
    if len(body) == 1 and isinstance(body[0], (n.FunctionDef, n.SecDef)):
        return tree
    return n.Module((n.FunctionDef("urdsl_program", (), tree.body),))


def map_back(sent_tree, sent_text: str, line: int, column: int):
    """The span in the user's source of the statement at ``line``:``column`` of the text as
    sent (the printed tree, parsed again, walks in step with the tree that was printed)."""
    from ..script import nodes as n
    from ..script.parser import parse

    printed = parse(sent_text, "<sent>")
    best = None
    for original, again in zip(n.walk(sent_tree), n.walk(printed), strict=False):
        if again.span.line == line and again.span.column <= max(column, 1) \
                and original.span.source is not None:
            if best is None or again.span.column >= best[1]:
                best = (original.span, again.span.column)
        elif again.span.line > line and best is not None:
            break
    return None if best is None else best[0]


def cmd_send(args: argparse.Namespace) -> int:
    from ..cli import EXIT_OK, EXIT_PROBLEMS, EXIT_USAGE
    from ..kinematics import MODELS
    from ..protocol import ProtocolError
    from ..script.diagnostics import Diagnostic
    from ..script.printer import format as format_tree
    from .connection import RobotConnectionError
    from .sender import run_program, send_program

    if args.robot.lower() not in MODELS:
        print(f"urdsl: error: unknown robot model {args.robot!r}", file=sys.stderr)
        return EXIT_USAGE
    loaded = _load(args.file)
    if loaded is None:
        return EXIT_PROBLEMS
    tree, label = loaded
    if not args.no_check:
        from ..verify.run import CheckOptions, check_tree

        report = check_tree(tree, label, CheckOptions(robot=args.robot.lower()))
        if report.has_errors:
            print(report.render_text(moves=False), end="")
            print("not sent: the check found errors (use --no-check to send anyway)",
                  file=sys.stderr)
            return EXIT_PROBLEMS
        print(report.summary(), file=sys.stderr)
    sent_tree = program_to_send(tree)
    text = format_tree(sent_tree)
    try:
        if args.no_wait:
            send_program(text, args.host, args.port, timeout=min(args.timeout, 10.0))
            print(f"sent {label} to {args.host}:{args.port}")
            return EXIT_OK
        result = run_program(text, args.host, args.port, timeout=args.timeout,
                             primary_port=args.primary_port)
    except (RobotConnectionError, ProtocolError) as error:
        print(f"urdsl: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    for message in result.messages:
        print(f"controller: {message}")
    if result.status == "failed":
        error = result.error
        span = map_back(sent_tree, text, error.line, error.column)
        message = f"the controller stopped the program: {error.text}"
        if span is not None:
            print(Diagnostic.at(span, message, code="URS200").render())
        else:
            print(f"{label}: sent line {error.line}:{error.column}: {message}")
        return EXIT_PROBLEMS
    if result.status == "timeout":
        print(f"{label}: still running after {args.timeout:g} s (urdsl stopped following it)")
        return EXIT_OK
    if result.status == "not observed":
        print(f"{label}: sent; no runtime error, and it did not show as running (it "
              "finished within 0.1 s, or the controller did not start it)")
        return EXIT_OK
    print(f"{label}: finished on {args.host}")
    return EXIT_OK


# ---- state, record, plot, dashboard -----------------------------------------------------------


def cmd_state(args: argparse.Namespace) -> int:
    from ..cli import EXIT_OK, EXIT_USAGE
    from ..protocol import ProtocolError
    from .connection import RobotConnectionError
    from .state import read_state

    try:
        while True:
            sample = read_state(args.host, args.interface, args.port, timeout=args.timeout)
            if args.json:
                print(json.dumps(sample.to_dict()))
            else:
                joints = ", ".join(f"{v:8.4f}" for v in sample.joints)
                pose = ", ".join(f"{v:8.4f}" for v in sample.tcp_pose)
                print(f"joints [rad]  {joints}\nTCP pose      p[{pose}]\n"
                      f"robot mode    {sample.robot_mode_name}\n"
                      f"safety mode   {sample.safety_mode_name}\n"
                      f"interface     {sample.interface}")
            if not args.watch:
                return EXIT_OK
            sys.stdout.flush()
            time.sleep(0.5)
    except (RobotConnectionError, ProtocolError) as error:
        print(f"urdsl: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        return EXIT_OK


def cmd_record(args: argparse.Namespace) -> int:
    from ..cli import EXIT_OK, EXIT_USAGE
    from ..protocol import ProtocolError
    from .connection import RobotConnectionError
    from .recorder import record

    fields = [f.strip() for f in args.fields.split(",") if f.strip()]
    messages: list = []

    def progress(rows: int, duration: float) -> None:
        print(f"\rrecorded {rows} samples", end="", file=sys.stderr)

    try:
        rows = record(args.host, args.output, fields, args.frequency, args.duration,
                      args.port, progress=progress, messages=messages)
    except (RobotConnectionError, ProtocolError, ValueError) as error:
        print(f"\nurdsl: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except OSError as error:
        print(f"\nurdsl: error: cannot write {args.output}: {error.strerror}", file=sys.stderr)
        return EXIT_USAGE
    for message in messages:
        print(f"controller: {message.text}", file=sys.stderr)
    print(f"\rrecorded {rows} samples to {args.output}", file=sys.stderr)
    return EXIT_OK


def cmd_plot(args: argparse.Namespace) -> int:
    from ..cli import EXIT_OK, EXIT_USAGE
    from .recorder import plot_csv

    columns = [c.strip() for c in args.columns.split(",")] if args.columns else None
    try:
        drawn = plot_csv(args.csv, args.output, columns)
    except (OSError, ValueError) as error:
        print(f"urdsl: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    print(f"plotted {len(drawn)} columns to {args.output}", file=sys.stderr)
    return EXIT_OK


def cmd_dashboard(args: argparse.Namespace) -> int:
    from ..cli import EXIT_OK, EXIT_PROBLEMS, EXIT_USAGE
    from ..protocol import ProtocolError
    from .connection import RobotConnectionError
    from .dashboard import DashboardClient

    command = " ".join(args.words)
    try:
        with DashboardClient(args.host, args.port, args.timeout) as dashboard:
            reply = dashboard.command(command)
    except (RobotConnectionError, ProtocolError) as error:
        print(f"urdsl: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    print(reply.text)
    return EXIT_OK if reply.ok else EXIT_PROBLEMS
