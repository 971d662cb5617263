"""``urdsl check``: run programs offline on a simulated robot and report what would go wrong."""

from __future__ import annotations

import argparse
import math
import sys
import time

from ..rules import RULES
from . import checks  # noqa: F401 - registers the trace checks (their rules)
from . import findings as _findings  # noqa: F401 - registers the rules of the run

__all__ = ["add_commands", "cmd_check", "parse_vector"]

_DESCRIPTION = """\
Run each program on a simulated robot, offline, and report every problem the real robot
would stop for, at the line that causes it: unreachable poses (URS301), straight-line moves
that leave the workspace or flip the IK solution (URS302), joint limits (URS303), joint
speeds (URS304), the cell's TCP speed limit (URS306), singularities (URS307), collisions with
the cell or the arm itself (URS308), Overlapping Blends (URS309), runtime errors (URS2xx).
Also prints every move with its duration and the cycle time.

A script file runs in its project's context: a file that a program includes (a PolyScope
"Script: file" node, a subprogram) runs with the definitions it takes from that program,
sibling script files and installation variables (*.variables), and the report says so.

Exit status: 0 no errors (warnings allowed), 1 errors found, 2 usage errors.
"""

_EPILOG = """\
examples:
  urdsl check pick.script --robot ur5e
  urdsl check programs/palletizing.py --robot ur10e --cell cell.toml
  urdsl check pick.script --start-joints-deg 0,-90,90,-90,-90,0 --tcp 0,0,0.15,0,0,0
  urdsl check pick.script --tcp-speed-limit 0.25 --json > report.json
  urdsl check pick.script --plot pick.png

rules ('urdsl rules CODE' explains one, 'urdsl rules URS3' all of the checker's):
  URS2xx  error    runtime errors of the program (urdsl rules URS2)
""" + "\n".join(f"  {rule.code}  {rule.severity:<8} {rule.summary}"
                for rule in sorted(RULES.values(), key=lambda rule: rule.code)
                if rule.stage == "check")


def parse_vector(text: str, count: int, what: str, degrees: bool = False) -> tuple:
    """``"0,-1.57,0,..."`` → a tuple of ``count`` floats (converted from degrees if asked)."""
    try:
        values = tuple(float(v) for v in text.replace(" ", "").strip("[]p").split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} must be {count} comma-separated numbers, "
                                         f"got {text!r}") from None
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"{what} must be {count} finite numbers, got "
                                         f"{len(values)}: {text!r}")
    return tuple(math.radians(v) for v in values) if degrees else values


def _seconds(text: str) -> float:
    """A positive, finite number of seconds (``--timeout``)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds, got {text!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {text!r}")
    return value


def add_commands(commands) -> None:
    p = commands.add_parser(
        "check", help="run programs offline on a simulated robot and report problems",
        description=_DESCRIPTION, epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="+", metavar="FILE",
                   help="a URScript file (.script), a DSL program (.py; a .py file is run "
                   "as Python, with your permissions, to build its program) or a PolyScope "
                   "program (.urp: compiled, checked on its arm with its installation), "
                   "or a folder of them (a .urp with PolyScope's .script beside it is left "
                   "out for that .script)")
    p.add_argument("--robot", metavar="MODEL",
                   help="robot model: ur3, ur5, ur10, ur3e, ur5e, ur10e, ur16e, ur20, ur30, "
                   "ur7e, ur12e, ur15, ur18, ur8long (default: the model whose kinematics "
                   "maps the program's taught waypoint joints to their poses, else ur5e)")
    start = p.add_mutually_exclusive_group()
    start.add_argument("--start-joints", metavar="Q", type=lambda t: parse_vector(
        t, 6, "--start-joints"), help="joint positions in rad where the arm starts, "
        "comma-separated (default: the joints of the first move's taught target, as "
        "PolyScope starts there, else 0,-pi/2,pi/2,-pi/2,-pi/2,0)")
    start.add_argument("--start-joints-deg", metavar="Q", type=lambda t: parse_vector(
        t, 6, "--start-joints-deg", degrees=True), help="the same in degrees")
    p.add_argument("--tcp", metavar="POSE", type=lambda t: parse_vector(t, 6, "--tcp"),
                   help="TCP offset from the flange: x,y,z in m and a rotation vector in rad "
                   "(default: the flange; a script's set_tcp() changes it)")
    p.add_argument("--q-min", metavar="Q", type=lambda t: parse_vector(t, 6, "--q-min"),
                   help="lower joint limits in rad set for the cell (default: the model's)")
    p.add_argument("--q-max", metavar="Q", type=lambda t: parse_vector(t, 6, "--q-max"),
                   help="upper joint limits in rad set for the cell (default: the model's)")
    p.add_argument("--cell", metavar="TOML",
                   help="cell description with the floor, boxes and cylinders to avoid")
    p.add_argument("--tcp-speed-limit", type=float, metavar="M_PER_S",
                   help="maximum TCP speed in m/s, e.g. 0.25 for a collaborative cell")
    p.add_argument("--joint-acceleration-limit", type=float, metavar="RAD_PER_S2",
                   help="maximum joint acceleration in rad/s² (UR publishes none; off "
                   "by default)")
    p.add_argument("--singularity-scale", type=float, metavar="F",
                   help="scale the distances at which URS307 warns (default 1: shoulder "
                   "0.05 m, elbow 0.02 m, wrist 0.05 rad); 0 turns the warning off")
    p.add_argument("--no-self-collision", action="store_true",
                   help="do not check the arm against itself")
    p.add_argument("--max-time", type=float, default=3600.0, metavar="S",
                   help="stop a program that runs longer than this robot time (default 3600)")
    p.add_argument("--timeout", type=_seconds, default=60.0, metavar="S",
                   help="wall-clock time in s each program's check may take (default 60); "
                   "a check that reaches it stops and says how far it got (URS313)")
    p.add_argument("--json", action="store_true",
                   help="print the report as one JSON document on stdout (one per file, in "
                   "a list when several files are given)")
    p.add_argument("--plot", metavar="PNG",
                   help="write a plot of joint positions, speeds and the TCP path")
    p.add_argument("--all-moves", action="store_true",
                   help="list every move in the text report (default: the first 20)")
    p.add_argument("--include", action="append", default=[], metavar="FILE",
                   help="another file of the project whose definitions the program uses "
                   "(a script file, a .variables file, or a folder of them); repeatable")
    p.add_argument("--no-project", action="store_true",
                   help="check the file alone, not in the context of its project (host "
                   "program, sibling script files, installation variables)")
    p.add_argument("--nominal", action="store_true",
                   help="a PolyScope program (.urp), or its export with the .urp beside "
                   "it: check on the model's nominal kinematics, not the arm's calibration "
                   "stored in the program")
    p.set_defaults(run=cmd_check)


def cmd_check(args: argparse.Namespace) -> int:
    from .._cli import EXIT_OK, EXIT_PROBLEMS, UsageError, load_cell, read_input, robot_model
    from .run import DEFAULT_START, CheckOptions

    robot = robot_model(args.robot or "ur5e")
    if args.plot and len(args.files) > 1:
        raise UsageError("--plot takes one file at a time")
    options = CheckOptions(
        robot=robot,
        start_joints=args.start_joints or args.start_joints_deg or DEFAULT_START,
        tcp=args.tcp, cell=args.cell, q_min=args.q_min, q_max=args.q_max,
        tcp_speed_limit=args.tcp_speed_limit,
        joint_acceleration_limit=args.joint_acceleration_limit,
        singularity_scale=args.singularity_scale, max_time=args.max_time,
        timeout=args.timeout,
        self_collision=not args.no_self_collision)
    if args.cell:
        options.cell = load_cell(robot, args.cell)
    from ..dsl.command import ProgramFileError
    from ..dsl.errors import DslError
    from ..polyscope.urp import is_text_file

    reports = []
    failed = False
    for name in _expand_folders(args.files):
        if name.endswith(".py"):
            try:
                report = _bounded(name, options, lambda o, n=name: _check_program(n, o))
            except (DslError, ProgramFileError) as error:
                print(str(error), file=sys.stderr)
                failed = True
                continue
        elif name.lower().endswith(".urp") and not is_text_file(name):
            report = _bounded(name, options, lambda o, n=name: _check_urp(n, args, o))
            failed = failed or not report.checked
        else:
            source = read_input(name)
            report = _bounded(name, options, lambda o, s=source: _check_script(s, args, o))
            if name.lower().endswith(".urp"):  # a script file given the extension
                from ..lint.command import _TEXT_URP
                from ..script.nodes import Source, Span
                from .findings import Finding

                span = Span(Source(source.text, source.name), 0, 0)
                report.findings.insert(0, Finding("URS001", "info", _TEXT_URP, span))
        reports.append(report)
        if not args.json:
            _print(report, args.all_moves)
    if args.json and reports:
        from .report import dumps

        documents = [r.to_dict() for r in reports]
        sys.stdout.write(dumps(documents[0] if len(documents) == 1 else documents) + "\n")
    if args.plot and reports:
        reports[0].plot(args.plot)
        print(f"plot written to {args.plot}", file=sys.stderr)
    return EXIT_PROBLEMS if failed or any(r.has_errors for r in reports) else EXIT_OK


def _expand_folders(names: list[str]) -> list[str]:
    """The files named, a folder standing for its programs (see
    :func:`urdsl.polyscope.command.expand_folders`)."""
    from ..polyscope.command import expand_folders

    return [file for file, _folder in expand_folders(names, "checked")]


GRACE = 1.5
"""Seconds past a program's wall-clock bound after which ``urdsl check`` stops waiting for
a check that did not stop by itself (a phase that does not look at the bound, such as
reading a very large project) and reports it as stopped there (URS313)."""


def _bounded(name: str, options, check):
    """``check(options)`` for the program ``name``, on a thread of its own, awaited until
    ``options.timeout`` + :data:`GRACE` s: a check still running then is left behind (it
    ends with the process) and its report says in which phase it was (URS313)."""
    import threading
    from dataclasses import replace

    from .._deep import STACK_BYTES
    from .findings import Finding
    from .report import Report
    from .run import Progress

    if options.timeout is None:
        return check(options)
    started = time.monotonic()
    progress = Progress()
    options = replace(options, progress=progress)
    outcome: dict = {}

    def work() -> None:
        try:
            outcome["report"] = check(options)
        except BaseException as error:  # noqa: BLE001 - re-raised in the caller's thread
            outcome["error"] = error

    previous = threading.stack_size()
    threading.stack_size(STACK_BYTES)  # as deep as the thread that runs the command
    try:
        worker = threading.Thread(target=work, name=f"urdsl-check {name}", daemon=True)
        worker.start()
    finally:
        threading.stack_size(previous)
    worker.join(max(0.0, started + options.timeout + GRACE - time.monotonic()))
    if worker.is_alive():
        report = Report(name, options.robot)
        report.findings.append(Finding.of(
            "URS313", f"the check reached its wall-clock bound of {options.timeout:g} s while "
            f"{progress.phase} and was abandoned there; nothing of the program was reported",
            progress.span, None, "use --timeout to allow more time"))
        return report
    if "error" in outcome:
        raise outcome["error"]
    return outcome["report"]


def _check_script(source, args: argparse.Namespace, options):
    """Check a script file in its project's context (a fragment runs with the definitions
    it takes from its host program, sibling files and installation variables), with what can
    be inferred from it (robot model, start joints, TCP and payload; see
    :mod:`urdsl.verify.infer`) where the command line leaves it open."""
    import os

    from .._cli import UsageError, load_cell
    from ..project import ProjectError
    from ..project.check import in_context
    from ..script.diagnostics import ScriptError
    from ..script.parser import parse
    from .infer import apply, infer, qualify_report
    from .run import check_text, check_tree

    started = time.monotonic()  # the wall-clock bound covers the parse and inference too
    try:
        module = parse(source.text, source.name)
    except ScriptError:
        return check_text(source.text, source.name, options=options)  # reports the syntax
    if options.progress is not None:
        options.progress.span = module.span
        options.progress.phase = "reading the program's project"
    context = None
    if not args.no_project and source.path is not None:
        missing = [extra for extra in args.include if not os.path.exists(extra)]
        if missing:
            raise UsageError(f"--include {missing[0]}: no such file")
        try:
            context = in_context(source.path, source.text, module, source.name, args.include)
        except ProjectError as error:
            raise UsageError(str(error)) from None
    if context is not None:
        module = context.module
    if options.progress is not None:
        options.progress.phase = "inferring the robot"
    inference = infer(module, source.path, robot=options.robot if args.robot else None,
                      start_joints=args.start_joints or args.start_joints_deg, tcp=args.tcp,
                      default_robot=options.robot)
    export = _export_kinematics(source.path)
    if export is not None and inference.robot_source == "default":
        # no taught waypoint pairs: the arm whose factory table the PolyScope program of this
        # export keeps is the robot the program was written on
        inference.robot, inference.robot_source = export[1], "inferred"
        inference.robot_from = f"the <kinematics> of {export[2]} (the arm's calibration)"
    file_options = apply(options, inference, tcp_given=args.tcp is not None)
    file_options.hostless = context is not None and context.hostless
    if args.cell and file_options.robot != options.robot:
        file_options.cell = load_cell(file_options.robot, args.cell)
    if context is not None and context.hosts:
        inference.polyscope = True  # a fragment of a program PolyScope runs: taught on an arm
    calibrated = None
    if export is not None and not args.nominal and export[1] == file_options.robot:
        file_options.calibration = export[0]
        calibrated = f"on this very arm: the {export[1]} calibration of {export[2]}'s <kinematics>"
    report = check_tree(module, source.name, file_options, started=started)
    report.inferred = inference
    qualify_report(report, inference, calibrated=file_options.calibration is not None)
    notes = [context.note] if context is not None and context.note else []
    if calibrated:
        notes.append(calibrated)
    if notes:
        report.context = "; ".join(notes)
    return report


def _export_kinematics(path: str | None):
    """For an export (``X.script`` with PolyScope's ``X.urp`` beside it, whose ``<kinematics>``
    is the arm's factory calibration): ``(calibration, model, "X.urp")``, the arm ``urdsl
    check X.urp`` checks on; None when there is no such program or block, or it matches no
    model."""
    from pathlib import Path

    from ..polyscope.check import calibration_of
    from ..polyscope.urp import UrpError, read_urp

    if path is None:
        return None
    program_path = Path(path).with_suffix(".urp")
    if not program_path.is_file():
        return None
    try:
        program = read_urp(program_path)
    except (UrpError, OSError):
        return None
    calibration, model = calibration_of(program)
    if calibration is None or model is None:
        return None
    return calibration, model, program_path.name


def _check_urp(name: str, args: argparse.Namespace, options):
    """A PolyScope program: compiled, then checked (see :mod:`urdsl.polyscope.check`); when
    it cannot be compiled, the report of :func:`_not_compiled`."""
    from pathlib import Path

    from .._cli import UsageError
    from ..polyscope.check import check_urp
    from ..polyscope.compile import CompileError
    from ..polyscope.urp import UnsupportedProgram, UrpError

    if not Path(name).is_file():
        raise UsageError(f"cannot read {name}: No such file")
    try:
        report = check_urp(name, options, robot_given=bool(args.robot),
                           start_joints=args.start_joints or args.start_joints_deg,
                           tcp=args.tcp, nominal=args.nominal, cell_path=args.cell)
    except UnsupportedProgram as error:  # urdsl's limit, not the program's mistake
        return _not_compiled(name, options, "warning", "not checked: ", str(error))
    except (UrpError, CompileError) as error:
        return _not_compiled(name, options, "error", "", str(error))
    return report


def _not_compiled(name: str, options, severity: str, prefix: str, text: str):
    """The report of a PolyScope program that cannot be compiled: one URS001 finding at the
    program's first line with the compiler's message (which names the node and its place
    in the file), as ``urdsl lint X.urp`` gives it; not checked, so the command fails."""
    from ..script.nodes import Source, Span
    from .findings import Finding
    from .report import Report

    message = text.split(": error: ", 1)[1] if ": error: " in text else text
    if message.startswith(f"{name}: "):  # the finding names the file already
        message = message[len(name) + 2:]
    report = Report(name, options.robot, checked=False)
    report.findings.append(Finding("URS001", severity, prefix + message,
                                   Span(Source("", name), 0, 0)))
    return report


def _check_program(name: str, options):
    from .._cli import UsageError
    from .run import check_file

    try:
        return check_file(name, options)
    except OSError as error:
        raise UsageError(f"cannot read {name}: {error.strerror}") from None


def _print(report, all_moves: bool) -> None:
    from rich.console import Console

    console = Console(highlight=False, soft_wrap=True)
    report.print_rich(console, max_moves=len(report.moves) if all_moves else 20)
