"""``urdsl send``, ``state``, ``record``, ``plot`` and ``dashboard``: the robot commands.

Network failures (refused, timed out, dropped) are printed as one message naming
``host:port`` and exit with status 1; usage mistakes exit with 2; never a traceback.
"""

from __future__ import annotations

import argparse
import json
import sys

from .errors import RobotError

__all__ = ["add_commands"]

_FORMATTER = argparse.RawDescriptionHelpFormatter


def _fail(message: str) -> int:
    print(f"urdsl: error: {message}", file=sys.stderr)
    return 1


def _host(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--host", required=True, metavar="HOST",
                        help="the controller's IP address or name (a real robot, e.g. the "
                        "course's 192.168.x.x, or 127.0.0.1 for `urdsl sim`)")


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


# ---- record -------------------------------------------------------------------------------

_RECORD_DESCRIPTION = """\
Record RTDE outputs (port 30004) into a CSV file that UR's record.py and csv_reader.py
understand: space-separated, one header line, vector fields expanded into name_0 ... name_5,
timestamp (s since the controller started) first. RTDE protocol 2 is used, 1 as fallback.

Ctrl-C stops cleanly: every sample received is in the file, each a complete line. A dropped
connection or a controller that stops sending also ends the recording with the file intact.
Text messages the controller sends meanwhile are shown and do not stop it.

Exit status: 0 recorded (stopped by --duration, --samples or Ctrl-C), 1 no connection, a
refused recipe, or the stream ended early (the file keeps what came), 2 usage errors.
"""

_RECORD_EPILOG = """\
examples:
  urdsl record --host 127.0.0.1 -o run.csv                         (Ctrl-C to stop)
  urdsl record --host 127.0.0.1 --duration 10 --frequency 500 -o run.csv
  urdsl record --host 127.0.0.1 --fields actual_q,actual_TCP_pose,speed_scaling -o run.csv
  urdsl plot run.csv -o run.png

common fields: actual_q, actual_qd, target_q, target_qd, actual_TCP_pose, actual_TCP_speed,
actual_TCP_force, actual_current, joint_temperatures, robot_mode, safety_mode,
runtime_state, speed_scaling, actual_digital_input_bits, actual_digital_output_bits
"""


def _progress_display(args: argparse.Namespace):
    """(callback, close) showing samples, rate and missed samples on stderr with rich."""
    from rich.console import Console
    from rich.progress import BarColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    console = Console(stderr=True)
    columns = [SpinnerColumn(), TextColumn("recording {task.fields[samples]:>7} samples"),
               TextColumn("{task.fields[rate]:>6.1f} Hz"),
               TextColumn("{task.fields[missed]} missed"), TimeElapsedColumn()]
    if args.duration:
        columns.insert(1, BarColumn())
    progress = Progress(*columns, console=console, transient=False)
    task = progress.add_task("record", total=args.duration or None, samples=0, rate=0.0,
                             missed=0)
    progress.start()
    shown: set[str] = set()

    def update(state) -> None:
        rate = (state.samples - 1) / state.span if state.span > 0 else 0.0
        progress.update(task, completed=min(state.elapsed, args.duration or state.elapsed),
                        samples=state.samples, rate=rate, missed=state.missed)
        if state.message and state.message not in shown:
            shown.add(state.message)
            progress.console.print(f"controller: {state.message}")

    return update, progress.stop


def cmd_record(args: argparse.Namespace) -> int:
    import os
    import signal
    import threading

    from .._cli import UsageError
    from .recorder import parse_fields, record

    try:
        fields = parse_fields(args.fields)
    except ValueError as error:
        raise UsageError(str(error)) from None
    folder = os.path.dirname(os.path.abspath(args.output))
    if not os.path.isdir(folder):
        raise UsageError(f"cannot write {args.output}: no folder {folder}")
    stop = threading.Event()
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGINT, lambda *_: stop.set())
    update, close = (None, None) if args.quiet else _progress_display(args)
    try:
        result = record(args.host, args.output, fields, frequency=args.frequency,
                        duration=args.duration, samples=args.samples, port=args.port,
                        timeout=args.timeout, stall_timeout=args.stall_timeout, stop=stop,
                        progress=update, delimiter="," if args.comma else " ")
    except RobotError as error:
        return _fail(error.message)
    except OSError as error:
        raise UsageError(f"cannot write {args.output}: {error.strerror}") from None
    finally:
        if close is not None:
            close()
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    rate = (result.samples - 1) / result.span if result.span > 0 else 0.0
    print(f"recorded {result.samples} samples ({result.span:.3f} s of controller time, "
          f"{rate:.1f} Hz, {result.missed} missed by the controller) from "
          f"{args.host}:{args.port} (RTDE v{result.protocol}, controller "
          f"{result.controller_version}) to {result.path}", file=sys.stderr)
    if result.error:
        return _fail(result.error)
    return 0


# ---- plot ----------------------------------------------------------------------------------

_PLOT_DESCRIPTION = """\
Plot a recording (from `urdsl record` or UR's record.py) into a PNG: one panel per field
against time in s, joints named, units on the axes, TCP poses split into position (m) and
rotation (rad). Without --fields: actual_q and actual_qd (or target_q/target_qd).

Exit status: 0 written, 1 the file cannot be read or lacks a field, 2 usage errors.
"""

_PLOT_EPILOG = """\
examples:
  urdsl plot run.csv -o run.png
  urdsl plot run.csv --fields actual_q,actual_TCP_pose -o pose.png
  urdsl plot run.csv --fields actual_qd --degrees -o speeds.png
  urdsl plot robot_data.csv --fields target_q_1 -o q1.png     (UR's example_plotting.py)
"""


def cmd_plot(args: argparse.Namespace) -> int:
    from .csvfile import RecordingFormatError
    from .plot import plot_recording

    fields = [f.strip() for f in args.fields.split(",") if f.strip()] if args.fields else None
    try:
        summary = plot_recording(args.recording, args.output, fields, degrees=args.degrees,
                                 title=args.title)
    except FileNotFoundError:
        return _fail(f"cannot read {args.recording}: no such file")
    except OSError as error:
        return _fail(f"{error.filename or args.recording}: {error.strerror}")
    except RecordingFormatError as error:
        return _fail(str(error))
    except KeyError as error:
        return _fail(str(error.args[0]))
    print(f"plot written to {summary.path} ({', '.join(summary.fields)}; {summary.samples} "
          f"samples over {summary.duration:.3f} s)", file=sys.stderr)
    return 0


# ---- dashboard -----------------------------------------------------------------------------

_DASHBOARD_DESCRIPTION = """\
Send one command to the dashboard server (port 29999) and print its reply. The words after
the options form the command, as the dashboard server spells it (case matters):

"""

_DASHBOARD_EPILOG = """\
On e-Series robots most commands need the robot in Remote Control mode (set on the teach
pendant); otherwise the server answers with an explanation and urdsl exits 1.

Exit status: 0 the reply is the documented success, 1 a failure reply, no reply or no
connection, 2 an unknown command or other usage error.

examples:
  urdsl dashboard --host 127.0.0.1 robotmode
  urdsl dashboard --host 127.0.0.1 power on --wait      (then waits for IDLE)
  urdsl dashboard --host 127.0.0.1 brake release --wait (then waits for RUNNING)
  urdsl dashboard --host 127.0.0.1 load /programs/pick.urp
  urdsl dashboard --host 127.0.0.1 play
  urdsl dashboard --host 127.0.0.1 programState --json
"""

_WAIT_FOR = {"power on": {"IDLE", "RUNNING"}, "brake release": {"RUNNING"},
             "power off": {"POWER_OFF"}}


def _dashboard_description() -> str:
    from ..protocol.dashboard import COMMANDS

    lines = []
    for spec in COMMANDS.values():
        usage = spec.name + (f" <{spec.argument}>" if spec.argument else "")
        lines.append(f"  {usage:<34} {spec.doc}")
    return _DASHBOARD_DESCRIPTION + "\n".join(lines) + "\n"


def cmd_dashboard(args: argparse.Namespace) -> int:
    from .._cli import UsageError
    from .dashboard import Dashboard, parse_command_words, wait_for_mode

    try:
        name, argument = parse_command_words(args.words)
    except ValueError as error:
        raise UsageError(str(error)) from None
    if args.wait and name not in _WAIT_FOR:
        raise UsageError(f"--wait works with {', '.join(_WAIT_FOR)}; not with {name!r}")
    try:
        with Dashboard(args.host, args.port, timeout=args.timeout) as dashboard:
            reply = dashboard.command(name, argument)
            mode = None
            if reply.ok and args.wait:
                mode = wait_for_mode(dashboard, _WAIT_FOR[name], args.wait_timeout)
    except RobotError as error:
        return _fail(error.message)
    if args.json:
        document = {"command": reply.command, "reply": reply.text, "ok": reply.ok,
                    "value": reply.value, "fields": dict(reply.fields)}
        if mode is not None:
            document["robotmode"] = mode
        json.dump(document, sys.stdout)
        sys.stdout.write("\n")
    else:
        print(reply.text)
        if mode is not None:
            print(f"Robotmode: {mode}")
    if not reply.ok:
        hint = ""
        if "remote" in reply.text.lower():
            hint = " (switch the robot to Remote Control on the teach pendant)"
        print(f"urdsl: the dashboard server did not do {reply.command!r}: {reply.text}{hint}",
              file=sys.stderr)
        return 1
    return 0


# ---- send ---------------------------------------------------------------------------------

_SEND_DESCRIPTION = """\
Check a program offline, send it to the controller and follow it until it finishes or
fails. The program is a URScript file or a Python DSL program (PROGRAM.py, compiled as
`urdsl compile` does). What is sent is the canonical printout, wrapped in
`def urdsl_program(): ... end` when the file is bare statements; a running program is
replaced, as UR's controller does with every new program.

urdsl then listens on the primary interface (port 30001) and reports that the program
started, finished, or failed; a runtime exception is shown at the line of YOUR file
(file:line:col with the line), not at the line of the text that was sent.

Exit status: 0 finished (or still running when --timeout ended the wait), 1 the check found
errors (nothing sent), the program failed, or the controller could not be reached,
2 usage errors.
"""

_SEND_EPILOG = """\
examples:
  urdsl send pick.script --host 127.0.0.1
  urdsl send programs/pick_and_place.py --host 127.0.0.1 --robot ur5e
  urdsl send pick.script --host 127.0.0.1 --port 30001 --timeout 120
  urdsl send pick.script --host 127.0.0.1 --dry-run      (check and print, send nothing)

ports: 30001 primary, 30002 secondary (default), 30003 realtime — all three take scripts;
urdsl follows the program on 30001 either way (--monitor-port to change that).
"""


def _load_program(name: str, robot: str):
    """(tree, filename) of a .script file or a DSL .py program; problems as exceptions."""
    from .._cli import UsageError, read_input
    from ..script.parser import parse

    if name.endswith(".py"):
        from ..dsl.command import load_program

        try:
            program = load_program(name)
        except OSError as error:
            raise UsageError(f"cannot read {name}: {error.strerror}") from None
        return program.tree(), name
    source = read_input(name)
    return parse(source.text, source.name), source.name


def cmd_send(args: argparse.Namespace) -> int:
    from .._cli import robot_model
    from ..dsl.command import ProgramFileError
    from ..dsl.errors import DslError
    from ..script.diagnostics import ScriptError
    from .errors import CheckFailedError
    from .program import prepare_tree
    from .sender import default_checker, send_prepared

    robot = robot_model(args.robot)
    if args.program.lower().endswith(".urp"):
        from ..polyscope.check import send_check

        loaded = send_check(args.program, robot, args.check)
        if loaded is None:
            return 1
        tree, filename, report = loaded
        robot = report.robot if report is not None else robot
    else:
        try:
            tree, filename = _load_program(args.program, robot)
        except ScriptError as error:
            print(error.diagnostic.render(), file=sys.stderr)
            return 1
        except (DslError, ProgramFileError) as error:
            print(str(error), file=sys.stderr)
            return 1
        report = default_checker(tree, filename, robot) if args.check else None
    prepared = prepare_tree(tree, filename)
    if report is not None:
        if report.has_errors:
            sys.stderr.write(report.render_text(moves=False))
            print(str(CheckFailedError(report, filename)), file=sys.stderr)
            return 1
        warnings = report.count("warning") if hasattr(report, "count") else 0
        if warnings:
            sys.stderr.write(report.render_text(moves=False))
        print(f"checked {filename} on {robot}: no errors"
              + (f", {warnings} warning(s)" if warnings else ""), file=sys.stderr)
    if args.dry_run:
        sys.stdout.write(prepared.text)
        return 0
    def report(kind: str, text: str) -> None:
        prefix = "  controller: " if kind == "message" else ""
        print(prefix + text, file=sys.stderr, flush=True)

    try:
        result = send_prepared(prepared, args.host, args.port, timeout=args.timeout,
                               follow=not args.no_follow, monitor_port=args.monitor_port,
                               connect_timeout=args.connect_timeout, report=report)
    except RobotError as error:
        return _fail(error.message)
    if result.controller_version:
        print(f"  (controller software {result.controller_version})", file=sys.stderr)
    if result.error is not None:
        print(result.error.render(), file=sys.stderr)
    print(result.summary(), file=sys.stderr)
    if result.status == "not observed":
        print("  (no start was seen: a program that runs in under 0.1 s leaves no trace in "
              "the 10 Hz robot state; on e-Series the robot must be in Remote Control)",
              file=sys.stderr)
    return 0 if result.ok else 1


# ---- state --------------------------------------------------------------------------------

_STATE_DESCRIPTION = """\
Show the robot's joints, TCP pose, robot mode and safety mode, read from one of the
controller's interfaces: realtime (port 30003, every control cycle), primary (the secondary
port 30002 by default, 10 Hz) or RTDE (30004). Each sample shown is the newest: urdsl
drains the socket and skips queued packets, so a slow terminal never shows old positions.

Exit status: 0 ok, 1 no connection or no sample, 2 usage errors.
"""

_STATE_EPILOG = """\
examples:
  urdsl state --host 127.0.0.1
  urdsl state --host 127.0.0.1 --interface rtde --json
  urdsl state --host 127.0.0.1 --watch                 (Ctrl-C to stop)
  urdsl state --host 127.0.0.1 --watch --json --duration 10 > states.jsonl
"""


def _vector(values, digits: int = 4) -> str:
    return "  ".join(f"{v:{digits + 4}.{digits}f}" for v in values)


def render_state(state) -> str:
    """A sample as lines of text: modes, joints in rad and degrees, TCP pose."""
    import math

    head = f"{state.host}:{state.port} ({state.interface})"
    if state.version and state.interface == "realtime":
        head += f", packet layout {state.version}"
    elif state.version:
        head += f", controller {state.version}"
    if state.time is not None:
        head += f", time {state.time:.3f} s"
    lines = [head]
    if state.robot_mode is not None:
        lines.append(f"robot mode    {state.robot_mode_name} ({state.robot_mode})")
    if state.safety_mode is not None:
        lines.append(f"safety mode   {state.safety_mode_name} ({state.safety_mode})")
    if state.program_state is not None:
        lines.append(f"program       {state.program_state_name}")
    elif state.program_running is not None:
        lines.append(f"program       {'running' if state.program_running else 'not running'}")
    if state.joints is not None:
        lines.append(f"joints [rad]  {_vector(state.joints)}")
        lines.append(f"joints [deg]  {_vector([math.degrees(v) for v in state.joints], 2)}")
    if state.joint_speeds is not None:
        lines.append(f"speeds [rad/s]{_vector(state.joint_speeds)}")
    if state.tcp_pose is not None:
        pose = state.tcp_pose
        lines.append(f"TCP [m]       x {pose[0]:.4f}  y {pose[1]:.4f}  z {pose[2]:.4f}")
        lines.append(f"TCP [rad]     rx {pose[3]:.4f}  ry {pose[4]:.4f}  rz {pose[5]:.4f}")
    if state.speed_scaling is not None:
        lines.append(f"speed scaling {state.speed_scaling:.2f}")
    return "\n".join(lines)


def cmd_state(args: argparse.Namespace) -> int:
    from .state import StateReader

    try:
        with StateReader(args.host, args.interface, args.port, timeout=args.timeout) as reader:
            if not args.watch:
                state = reader.read()
                if args.json:
                    print(json.dumps(state.to_dict()))
                else:
                    print(render_state(state))
                return 0
            return _watch(reader, args)
    except RobotError as error:
        return _fail(error.message)


def _watch(reader, args: argparse.Namespace) -> int:
    import time

    from .errors import ConnectionLost

    period = 1.0 / args.rate
    end = None if args.duration is None else time.monotonic() + args.duration
    live = None
    if not args.json and sys.stdout.isatty():
        from rich.console import Console
        from rich.live import Live
        from rich.text import Text

        live = Live(Text("connecting"), console=Console(), auto_refresh=False)
        live.start()
    try:
        while end is None or time.monotonic() < end:
            tick = time.monotonic()
            try:
                state = reader.read()
            except ConnectionLost as error:
                print(f"urdsl: {error.message}; reconnecting", file=sys.stderr)
                reader.reconnect()
                continue
            if args.json:
                print(json.dumps(state.to_dict()), flush=True)
            elif live is not None:
                from rich.text import Text

                live.update(Text(render_state(state) + "\n(Ctrl-C to stop)"), refresh=True)
            else:
                print(render_state(state) + "\n", flush=True)
            rest = period - (time.monotonic() - tick)
            if rest > 0:
                time.sleep(rest if end is None else min(rest, max(end - time.monotonic(), 0)))
    except KeyboardInterrupt:
        pass
    finally:
        if live is not None:
            live.stop()
    return 0


# ---- registration --------------------------------------------------------------------------


def add_commands(commands) -> None:
    from ..protocol.dashboard import PORT

    p = commands.add_parser("record", help="record RTDE data (joints, TCP, …) into a CSV file",
                            description=_RECORD_DESCRIPTION, epilog=_RECORD_EPILOG,
                            formatter_class=_FORMATTER)
    _host(p)
    p.add_argument("-o", "--output", required=True, metavar="OUT.csv", help="the file to write")
    p.add_argument("--fields", metavar="F1,F2",
                   help="RTDE output fields, comma-separated (default: actual_q,actual_qd,"
                   "actual_TCP_pose); timestamp is always recorded, first")
    p.add_argument("--frequency", type=_positive, default=125.0, metavar="HZ",
                   help="samples per second: up to 125 on CB3, 500 on e-Series (default 125)")
    p.add_argument("--duration", type=_positive, metavar="S",
                   help="stop after S seconds (default: at Ctrl-C)")
    p.add_argument("--samples", type=int, metavar="N",
                   help="stop after N samples")
    p.add_argument("--port", type=int, default=30004, help="RTDE port (default 30004)")
    p.add_argument("--timeout", type=_positive, default=5.0, metavar="S",
                   help="seconds to wait for the connection and each setup reply (default 5)")
    p.add_argument("--stall-timeout", type=_positive, default=10.0, metavar="S",
                   help="end the recording when no sample came for S seconds (default 10)")
    p.add_argument("--comma", action="store_true",
                   help="separate columns with commas instead of spaces (record.py uses "
                   "spaces)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress display")
    p.set_defaults(run=cmd_record)

    p = commands.add_parser("plot", help="plot a recording (CSV) into a PNG",
                            description=_PLOT_DESCRIPTION, epilog=_PLOT_EPILOG,
                            formatter_class=_FORMATTER)
    p.add_argument("recording", metavar="RECORDING.csv",
                   help="a file written by `urdsl record` or UR's record.py")
    p.add_argument("-o", "--output", required=True, metavar="OUT.png", help="the PNG to write")
    p.add_argument("--fields", metavar="F1,F2",
                   help="comma-separated fields (actual_q, actual_TCP_pose, speed_scaling) or "
                   "single columns (actual_q_1); default: actual_q,actual_qd")
    p.add_argument("--degrees", action="store_true",
                   help="show joint angles and speeds in degrees (default: rad)")
    p.add_argument("--title", help="title of the figure (default: file, samples, rate)")
    p.set_defaults(run=cmd_plot)

    from .state import INTERFACES

    p = commands.add_parser("send", help="check a program, send it to the robot and report "
                            "how it ends", description=_SEND_DESCRIPTION, epilog=_SEND_EPILOG,
                            formatter_class=_FORMATTER)
    p.add_argument("program", metavar="FILE|PROGRAM.py",
                   help="a URScript file ('-' reads stdin), a Python DSL program (a .py "
                   "file is run as Python, with your permissions, also with --dry-run) or a "
                   "PolyScope program (.urp, compiled and checked as urdsl compile and "
                   "urdsl check do)")
    _host(p)
    p.add_argument("--port", type=int, default=30002, metavar="PORT",
                   help="where to send: 30001, 30002 (default) or 30003")
    p.add_argument("--robot", default="ur5e", metavar="MODEL",
                   help="robot model the check uses (default: ur5e)")
    p.add_argument("--no-check", dest="check", action="store_false",
                   help="send without checking first (not recommended)")
    p.add_argument("--timeout", type=_positive, default=60.0, metavar="S",
                   help="seconds to wait for the program to finish (default 60); it keeps "
                   "running on the robot after that")
    p.add_argument("--connect-timeout", type=_positive, default=5.0, metavar="S",
                   help="seconds to wait for each connection and the first state (default 5)")
    p.add_argument("--monitor-port", type=int, metavar="PORT",
                   help="primary-interface port to follow the program on (default 30001)")
    p.add_argument("--no-follow", action="store_true",
                   help="send and return at once, without waiting for the outcome")
    p.add_argument("--dry-run", action="store_true",
                   help="check and print the text that would be sent; send nothing")
    p.set_defaults(run=cmd_send)


    p = commands.add_parser("state", help="show joints, TCP pose, robot and safety mode",
                            description=_STATE_DESCRIPTION, epilog=_STATE_EPILOG,
                            formatter_class=_FORMATTER)
    _host(p)
    p.add_argument("--interface", choices=INTERFACES, default="realtime",
                   help="where to read: realtime (default, port 30003), primary (port 30002) "
                   "or rtde (port 30004)")
    p.add_argument("--port", type=int, metavar="P",
                   help="port (default: 30003 / 30002 / 30004 by interface)")
    p.add_argument("--watch", action="store_true",
                   help="keep showing the newest state until Ctrl-C (or --duration)")
    p.add_argument("--rate", type=_positive, default=10.0, metavar="HZ",
                   help="samples shown per second with --watch (default 10)")
    p.add_argument("--duration", type=_positive, metavar="S",
                   help="stop watching after S seconds")
    p.add_argument("--json", action="store_true",
                   help="print each sample as one JSON object per line (joints in rad, pose "
                   "in m and rad, mode numbers and names)")
    p.add_argument("--timeout", type=_positive, default=5.0, metavar="S",
                   help="seconds to wait for the connection and for a sample (default 5)")
    p.set_defaults(run=cmd_state)

    p = commands.add_parser("dashboard", help="send a dashboard command (play, stop, power "
                            "on, …) and print the reply", description=_dashboard_description(),
                            epilog=_DASHBOARD_EPILOG, formatter_class=_FORMATTER)
    _host(p)
    p.add_argument("words", nargs="+", metavar="COMMAND",
                   help="the command and its argument, e.g. `robotmode` or `load pick.urp`")
    p.add_argument("--port", type=int, default=PORT, help=f"dashboard port (default {PORT})")
    p.add_argument("--timeout", type=_positive, default=5.0, metavar="S",
                   help="seconds to wait for the connection and the reply (default 5; "
                   "`load` waits at least 30)")
    p.add_argument("--wait", action="store_true",
                   help="after `power on`, `brake release` or `power off`: wait until the "
                   "robot mode is IDLE, RUNNING or POWER_OFF")
    p.add_argument("--wait-timeout", type=_positive, default=60.0, metavar="S",
                   help="seconds --wait waits (default 60)")
    p.add_argument("--json", action="store_true",
                   help="print {command, reply, ok, value, fields} as JSON")
    p.set_defaults(run=cmd_dashboard)
