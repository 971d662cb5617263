"""Check a program: run it on a simulated robot, sample the trajectory, apply every check.

The steps, each reported as findings at the statement that caused them:

1. parse (syntax errors are URS001 findings; nothing runs);
2. run the program through :class:`urdsl.runtime.Interpreter` with a
   :class:`urdsl.motion.MotionPlanner` as its robot, in robot time — runtime errors (URS2xx,
   an unreachable target as URS301) stop it as they would stop the controller;
3. sample the planned trajectory at the controller rate (:func:`urdsl.motion.trace.sample`);
4. run every check registered in :mod:`urdsl.verify.checks` over the samples.

Reads from outside the controller (devices, inputs, operator answers) are unknown values
(:mod:`urdsl.runtime.unknown`): what depends on them is a URS210 warning, not an error.
Every check ends within its wall-clock bound (``CheckOptions.timeout``): the run stops where
it got to and says so (URS313), and checks left undone are named.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from .._gc import gc_paused
from ..motion.direction import stoppable_moves
from ..motion.planner import MotionPlanner
from ..motion.trace import sample
from ..project.model import from_missing_program
from ..runtime import Environment, Interpreter, RuntimeConfig, ScriptRuntimeError
from ..runtime.errors import beyond_reach
from ..runtime.values import Unknown
from ..script import nodes as n
from ..script.diagnostics import ScriptSyntaxError
from ..script.nodes import NO_SPAN
from ..script.parser import parse
from ..script.urcaps import by_urcap_block, urcap_blocks
from . import checks
from .findings import Finding, nothing_runs
from .report import Loop, Move, Report, Slowed

__all__ = ["CheckOptions", "Progress", "check_text", "check_tree", "check_file", "DEFAULT_START",
           "DEFAULT_TIMEOUT"]

DEFAULT_TIMEOUT = 60.0
"""Wall-clock time (s) one program's check may take by default (``urdsl check --timeout``)."""

RUN_SHARE = 0.6
"""The part of the wall-clock bound the program's run may use; sampling the trajectory and
the trace checks get the rest (see :data:`CHECK_RESERVE`). A cell program stopped by a 60 s
bound after 48 s (80 % here; 573,099 moves, 2,292 s of robot time) needed 4 s more on a
quiet machine and 17 s under load to sample and check, when sampling could not be
interrupted."""

CHECK_RESERVE = 2.0
"""Sampling the trajectory stops once the time it has taken, counted three times, would
pass the end of the bound (less the report's writing): the trace checks, and the work
between them and sampling (joining the windows, speeds), get twice as long as sampling
took, whatever the machine's speed (measured on a toolpath: the checks take 0.4 times as
long as sampling, the work between 0.3 times; twice that under load)."""

OUTPUT_SECONDS_PER_MOVE = 5e-6
"""Wall-clock time (s) kept back per planned move for writing the report after the checks
(a JSON report lists every move: about 3 µs each measured, on a loaded machine; a cell
program stopped at the bound may have planned 900,000)."""

DEFAULT_START = (0.0, -1.5707963267948966, 1.5707963267948966, -1.5707963267948966,
                 -1.5707963267948966, 0.0)
"""Where the simulated arm rests before the program (rad): upper arm up, forearm
horizontal, tool pointing down — a pose every model reaches away from singularities."""


@dataclass
class Progress:
    """How far one program's check got, for the report of a check that overran its bound
    (:func:`urdsl.verify.command.cmd_check`): the ``phase`` under way ("running the
    program", ...) and the ``span`` of the program once parsed."""

    phase: str = "reading the program"
    span: Any = NO_SPAN


def _phase(options: CheckOptions, phase: str) -> None:
    if options.progress is not None:
        options.progress.phase = phase


@dataclass
class CheckOptions:
    """What to check against.

    ``robot``: model name (``urdsl.kinematics.MODELS``); ``start_joints`` (rad);
    ``tcp``: TCP pose in the flange frame (m, rad) active from the start; ``cell``: path of a
    cell TOML (obstacles, see :mod:`urdsl.kinematics.collision`); ``tcp_speed_limit`` (m/s);
    ``joint_acceleration_limit`` (rad/s², one value or six); ``q_min``/``q_max``: user joint
    limits (rad) replacing the model's; ``singularity_scale``: see
    :func:`urdsl.verify.checks.singularities`; ``max_time``: robot time (s) after which a
    program that runs on is stopped; ``sample_time``: trace step in s (default: the
    controller's, 0.002 e-Series / 0.008 CB3); ``collision_step``: robot time (s) between
    collision samples; ``timeout``: wall-clock time (s) the whole check may take (None: no
    bound); ``environment``: the world the program reads (default: every device unknown,
    see :mod:`urdsl.runtime.unknown`).
    """

    robot: str = "ur5e"
    start_joints: tuple[float, ...] = DEFAULT_START
    tcp: tuple[float, ...] | None = None
    cell: str | Path | None = None
    tcp_speed_limit: float | None = None
    joint_acceleration_limit: float | tuple[float, ...] | None = None
    q_min: tuple[float, ...] | None = None
    q_max: tuple[float, ...] | None = None
    singularity_scale: float | None = None
    max_time: float = 3600.0
    sample_time: float | None = None
    collision_step: float = 0.02
    self_collision: bool = True
    timeout: float | None = DEFAULT_TIMEOUT
    environment: Environment | None = field(default=None, repr=False)
    calibration: Any = None
    """A :class:`urdsl.kinematics.Calibration` of the very arm (a PolyScope program's
    ``<kinematics>``), or None for the model's nominal kinematics."""
    joint_speed_limit: tuple[float, ...] | None = None
    """Joint speed limits [rad/s] set for the cell (a PolyScope installation's), below the
    model's."""
    safety_planes: tuple = ()
    """Safety planes (a PolyScope installation's, :class:`urdsl.polyscope.installation.
    SafetyPlane`: ``name``, ``normal``, ``distance``, ``elbow``) the TCP, and the elbow where
    the plane restricts it, must stay on the allowed side of (``normal·x + distance ≥ 0``)."""
    start_unknown: bool = False
    """Whether the program starts wherever the arm was left (no start pose given with
    ``start_joints`` or inferred from the program): then ``start_joints`` is only where the
    simulated arm stands, and what the program reads of the arm's position before its first
    move to a known target is unknown, as is that move's path."""
    robot_assumed: bool = False
    """Whether ``robot`` is only assumed (neither given nor inferred): a finding that must
    hold on the real arm whatever it is (a relative move that drifts out of every start's
    reach, :mod:`urdsl.motion.drift`) is then judged on the widest UR model."""
    unknown_globals: dict[str, str] = field(default_factory=dict)
    """Globals the program reads that something outside it defines (a URCap node's code):
    name → where the value comes from; each holds an unknown value."""
    hostless: bool = False
    """Whether the file is a fragment that no program of its project includes (a Script-node
    file whose PolyScope program is elsewhere, :attr:`urdsl.project.FileContext.hostless`):
    a name defined nowhere is still an error, with a hint that the program may define it."""
    progress: Progress | None = field(default=None, repr=False, compare=False)
    """Where the check records its phase (see :class:`Progress`), or None."""


def check_text(text: str, filename: str = "<script>", *, robot: str = "ur5e",
               options: CheckOptions | None = None) -> Report:
    """Check URScript ``text``; ``filename`` names it in messages."""
    options = options or CheckOptions(robot=robot)
    started = time.monotonic()
    try:
        module = parse(text, filename=filename)
    except ScriptSyntaxError as error:
        report = Report(filename, options.robot)
        report.findings.append(Finding(error.diagnostic.code or "URS001", "error",
                                       error.diagnostic.message, error.span or NO_SPAN,
                                       None, error.diagnostic.hint))
        return report
    return check_tree(module, filename, options, started)


def check_file(path: str | Path, options: CheckOptions | None = None) -> Report:
    """Check a ``.script`` file, or a DSL program file (``.py``) after compiling it."""
    path = Path(path)
    options = options or CheckOptions()
    if path.suffix == ".py":
        from ..dsl.command import load_program

        program = load_program(path)
        return check_tree(program.tree(), str(path), options)
    return check_text(path.read_text(encoding="utf-8"), str(path), options=options)


def _robot_model(name: str, calibration=None):
    from ..kinematics import Robot

    return Robot.model(name, calibration=calibration)


def check_tree(module, filename: str, options: CheckOptions,
               started: float | None = None) -> Report:
    """Run and check a parsed program (:class:`urdsl.script.nodes.Module`); ``started``:
    the ``time.monotonic()`` the wall-clock bound counts from (default: now)."""
    with gc_paused():  # the tree, closures and segments are long-lived and acyclic
        return _check_tree(module, filename, options,
                           time.monotonic() if started is None else started)


def _check_tree(module, filename: str, options: CheckOptions, started: float) -> Report:
    if options.progress is not None:
        options.progress.span = module.span
    _phase(options, "running the program")
    robot = _robot_model(options.robot, options.calibration)
    cb3 = getattr(robot.spec, "generation", "") == "cb3"
    step = 0.008 if cb3 else 0.002
    planner = MotionPlanner(robot, options.start_joints, step_time=step, lazy_ik=True)
    planner.stoppable = stoppable_moves(module)  # Direction nodes: moves until a condition
    if options.start_unknown:
        planner.unknown_position("the program starts (where the arm was left: no start pose "
                                 "given or inferred; --start-joints sets one)", module.span,
                                 still="where the arm stood when the program started")
    planner.model_assumed = options.robot_assumed
    if options.tcp is not None:
        planner.tcp = np.asarray(options.tcp, dtype=float)
    deadline = None if options.timeout is None else started + RUN_SHARE * options.timeout
    config = RuntimeConfig(step_time=step, max_time=options.max_time, deadline=deadline,
                           go_on_after_undefined=True, stop_repeating=True)
    environment = options.environment
    if environment is None:
        environment = Environment(devices="unknown")
    interpreter = Interpreter(module, robot=planner, environment=environment, config=config)
    for name, source in options.unknown_globals.items():
        interpreter.globals.setdefault(name, Unknown(source))
    result = interpreter.run()

    report = Report(filename, options.robot)
    report.events = result.events
    if result.error is None and planner.failure is not None:
        # found when the last moves were solved, after the script had run on: the robot
        # stops at that move, so nothing after it happens
        failure = planner.failure
        result.error = ScriptRuntimeError("ik", f"inverse kinematics failed: {failure}",
                                          failure.span, "the pose is out of reach of this "
                                          "robot with the active TCP", failure.time)
        result.error.beyond = beyond_reach(failure)
    if result.error is not None and result.error.kind == "ik":
        # a target solved in a batch may fail after the script ran on: the robot stops at
        # the move, so nothing after its start happens
        result.time = min(result.time, result.error.time)
        planner.end_time = max([result.time] + [s.end for s in planner.segments])
        report.events = [e for e in result.events if e.time <= result.error.time]
    for error in result.undefined:  # the run went on with the value unknown
        finding = _runtime_finding(error)
        hints = [finding.hint] if finding.hint else []
        if options.hostless and error.name is not None:
            hints.append(from_missing_program(error.name, "check"))
        hints.append("the check went on with its value unknown (what depends on it is not "
                     "checked)")
        report.findings.append(replace(finding, hint="; ".join(hints)))
    if result.error is not None:
        report.findings.append(_runtime_finding(result.error))
    for warning in planner.warnings:  # Overlapping Blends, or a stoppable move's far target
        code = "URS210" if warning.code == "condition" else "URS309"
        report.findings.append(Finding.of(code, warning.message, warning.span, warning.time))
    # threads still running when the check stopped the program (--max-time) are not left
    # running by the program
    running = [] if result.stopped_at_max_time or result.stopped else \
        result.threads_left_running
    blocks = urcap_blocks(module)
    generated = generated_threads(module, blocks) if running else set()
    left = [name for name in running if name not in generated]
    if left:
        names = ", ".join(left)
        report.findings.append(Finding.of(
            "URS311", f"the program ended while thread(s) {names} still ran; the controller "
            "stops them", module.span, result.time, "join or kill threads before the end"))
    for warning in result.warnings:
        report.findings.append(Finding.of("URS210", warning.message, warning.span,
                                          warning.time))
    if result.stopped_early is not None:
        report.findings.append(_stopped_finding(result.stopped_early, options))
    for event in result.events:
        if event.kind == "blocked":  # a thread that waits for ever; the others went on
            report.findings.append(Finding.of(
                "URS313", f"{event.message}; this thread was not checked further",
                event.span, event.time, "give the read a timeout, or make sure something "
                "answers"))
    idle = nothing_runs(module)
    if idle is not None:
        report.findings.append(idle)
    if result.stopped_at_max_time:
        report.findings.append(Finding.of(
            "URS312", f"the program still ran after {options.max_time:g} s of robot time and "
            "was stopped there (a cell program that loops forever?)", module.span,
            options.max_time, "use --max-time to check longer"))

    # sampled while the arm moves (after the last move it rests: nothing to check), and
    # never past --max-time
    last = max((s.end for s in planner.segments), default=0.0)
    # the bound less the time to write the report: sampling leaves the trace checks as
    # long as it took (CHECK_RESERVE), the checks stop at the end of it
    final = None if options.timeout is None else started + options.timeout - \
        OUTPUT_SECONDS_PER_MOVE * len(planner.segments)
    _phase(options, "sampling the motion")
    trace = sample(planner, options.sample_time or step, until=min(last, options.max_time),
                   deadline=final, reserve=CHECK_RESERVE)
    report.trace = trace
    report.cycle_time = float(min(max(result.time, trace.duration), options.max_time))
    report.loop = _forever(result)
    if report.loop is not None:
        report.cycle_time = report.loop.pass_time
    report.moves = [Move(s.kind, s.span, s.start, s.duration, s.params.get("lead"))
                    for s in planner.segments]
    _phase(options, "checking the motion")
    report.findings.extend(_trace_findings(trace, planner, robot, options, final,
                                           module.span))
    report.findings = group_urcap_notes(blocks, report.findings)
    if result.paced is not None:
        report.findings = device_paced(report.findings, result.paced)
    if result.shaped_moves:
        report.findings = device_shaped(report.findings, result.shaped_moves, planner)
    report.slowed = slowed_moves(trace, report.findings, report.loop)
    report.sort()
    return report


def generated_threads(module, blocks: list[tuple[str, int, int]]) -> set[str]:
    """Threads PolyScope or a URCap (its code in ``blocks``, see :func:`urcap_blocks`) wrote
    into a program (a step counter, a gripper's communication thread): the program may end
    while they run, the controller stops them, and the user has nothing to change."""
    return {t.name for t in n.walk(module) if type(t) is n.ThreadDef and (
        t.name.startswith("Step_Counter_Thread_")
        or any(first <= t.span.line <= last for _name, first, last in blocks))}


def group_urcap_notes(blocks: list[tuple[str, int, int]],
                      findings: list[Finding]) -> list[Finding]:
    """The URS210 notes (what depends on a value unknown offline) at statements of one
    URCap's code (``blocks``, see :func:`urcap_blocks`), when there are several, as one: the
    user did not write that code, and a Robotiq preamble alone holds some fifty device
    conditions."""
    if not blocks:
        return findings
    kept, grouped = by_urcap_block(blocks, findings, lambda f: f.span.line,
                                   lambda f: f.code == "URS210")
    for (name, first, last), notes in grouped.items():
        if len(notes) == 1:
            kept.extend(notes)
            continue
        notes.sort(key=lambda f: (f.span.line, f.span.column))
        lines = sorted({f.span.line for f in notes})
        shown = ", ".join(str(line) for line in lines[:8]) + (", …" if len(lines) > 8 else "")
        kept.append(Finding.of(
            "URS210", f"{len(notes)} statements of the URCap code of {name} (lines {first}-{last}) "
            f"depend on values unknown offline, the device's replies; the check follows a "
            f"working device through them (lines {shown}; the first: {notes[0].message})",
            notes[0].span, notes[0].time, "the URCap wrote this code: these notes are about "
            "the device, not about your program"))
    return kept


def _forever(result) -> Loop | None:
    """The loop the program runs forever (:class:`~urdsl.verify.report.Loop`), when the run
    stopped inside it only because the check stopped (``--max-time``, the wall-clock bound)
    after at least one complete pass; otherwise None."""
    passes = result.forever
    stopped = result.stopped_at_max_time or result.stopped or (
        result.stopped_early is not None and result.stopped_early.kind in ("deadline",
                                                                           "repeats"))
    if passes is None or not stopped or passes.pass_time is None:
        return None
    later = passes.count - 2  # complete passes after the first
    shortest = passes.shortest if later > 0 else passes.first_pass
    longest = passes.longest if later > 0 else passes.first_pass
    averaged = (passes.second, passes.last, later) if later > 0 else \
        (passes.first, passes.second, 1)
    return Loop(passes.span, passes.count - 1, passes.first_pass, passes.pass_time,
                shortest, longest, averaged)


def slowed_moves(trace, findings: list[Finding], loop: Loop | None) -> Slowed | None:
    """The moves the controller slows (warnings with :attr:`Finding.slowed`; before
    :meth:`Report.sort` merges a loop's passes), and at most how much longer they take: in
    the whole run, or on average in one of the passes ``loop``'s pass time averages. None
    when no move is slowed."""
    factors: dict[int, float] = {}
    for finding in findings:
        if finding.slowed is None or finding.severity != "warning" or finding.time is None:
            continue
        sample = min(int(np.searchsorted(trace.times, finding.time - 1e-9)),
                     len(trace.times) - 1)
        segment = int(trace.segment[sample])
        if segment >= 0:
            factors[segment] = max(factors.get(segment, 1.0), finding.slowed)
    begin, end, passes = (-np.inf, np.inf, 1) if loop is None or loop.averaged is None \
        else loop.averaged
    inside = [(trace.segments[segment], factor) for segment, factor in factors.items()
              if begin - 1e-9 <= trace.segments[segment].start < end - 1e-9]
    if not inside:
        return None
    extra = sum(move.duration * (factor - 1.0) for move, factor in inside)
    return Slowed(max(1, round(len(inside) / passes)), extra / passes)


def _stopped_finding(event, options: CheckOptions) -> Finding:
    """URS313 for a run that stopped early: it names the robot time and the statement;
    URS312 (info) for a loop that repeats itself (nothing is left unchecked)."""
    if event.kind == "repeats":
        return Finding.of("URS312", f"{event.message}; the check stops here at robot time "
                          f"{event.time:.3f} s", event.span, event.time)
    if event.kind == "deadline":
        message = (f"the check reached its wall-clock bound of {options.timeout:g} s and "
                   f"{event.message}, here; what follows was not checked")
        hint = "use --timeout to allow more time"
    else:
        message = f"{event.message}; the check stops here at robot time {event.time:.3f} s"
        hint = "give the read a timeout, or make sure something answers"
    return Finding.of("URS313", message, event.span, event.time, hint)


def _runtime_finding(error) -> Finding:
    diagnostic = error.diagnostic
    if error.kind == "ik":
        # a target that drifted out of every start's reach holds for every start (and, when
        # the model is only assumed, every model): the cause says so (see infer.qualify)
        cause = DRIFT if getattr(error, "drift", False) else None
        return replace(Finding.of("URS301", diagnostic.message, error.span, error.time,
                                  diagnostic.hint, cause), beyond=getattr(error, "beyond", None))
    return Finding(diagnostic.code, "error", diagnostic.message, error.span, error.time,
                   diagnostic.hint)


DRIFT = "drift out of every start's reach"
"""The cause of a URS301 for a move relative to an unknown start that no start makes
reachable (:mod:`urdsl.motion.drift`): it was judged for every model the arm may be."""


PATH_CODES = frozenset({"URS302", "URS304", "URS305", "URS306", "URS307", "URS308"})
"""Findings about the way a move goes (not its target), which depend on where it starts.
A joint position limit (URS303) is not among them: a movej interpolates the joints, so only
its ends can pass a limit, and the target's joints are what the controller would command."""


PACED_CODES = PATH_CODES | {"URS301", "URS303"}
"""Where the arm goes (its targets, paths, joints): what a device-paced loop accumulates moves
it (a counter that picks the next tray place). A loop that spins once the device is idle
(URS207) and the program's own mistakes are not about how many passes the device drives."""


def device_paced(findings: list[Finding], paced) -> list[Finding]:
    """Errors about where the arm goes (:data:`PACED_CODES`) that first happen in a pass of
    the main loop whose state every device reply before it changed
    (:class:`~urdsl.runtime.interpreter.DevicePaced`: pass 3 on, while every pass decided
    something on a device's reply) follow from how many times the device answers, which
    nothing offline says: warnings that say so, once per statement and cause as before. An
    error of the first two passes stays an error (a pass that begins as an earlier one did
    is not run: the check stops there)."""
    out = []
    for finding in findings:
        moment = finding.time
        if finding.severity != "error" or finding.code not in PACED_CODES or moment is None \
                or moment < paced.since - 1e-9 \
                or (paced.until is not None and moment >= paced.until - 1e-9):
            out.append(finding)
            continue
        why = (f"first in pass 3 or later of the loop at line {paced.span.line}, every pass "
               f"of which went on with a reply of {paced.source} (the check follows a working "
               "device): whether the program gets here depends on how many times that "
               "device answers")
        out.append(replace(finding, severity="warning", message=f"{finding.message}; {why}"))
    return out


def device_shaped(findings: list[Finding], moves: dict, planner) -> list[Finding]:
    """Errors about where the arm goes (:data:`PACED_CODES`) at a move whose target the run
    computed on a path it chose for a device (``moves``: the move's span -> that reply's
    source; see :mod:`urdsl.runtime.shaped`), and about the path (:data:`PATH_CODES`) of the
    move that starts where such a move ends, are warnings that say so: the check followed a
    working device, whose real reply puts the target elsewhere."""
    after: dict = {}
    segments = planner.segments
    for previous, segment in zip(segments, segments[1:], strict=False):
        if previous.span in moves and segment.span not in moves:
            after.setdefault(segment.span, moves[previous.span])
    out = []
    for finding in findings:
        if finding.severity == "error":
            source = moves.get(finding.span) if finding.code in PACED_CODES else None
            if source is not None:
                why = (f"this target was computed on the path the check chose for {source}, "
                       "which is unknown offline (the check follows a working device): with "
                       "the device's real reply the arm may go elsewhere")
                if finding.code == "URS301":
                    why += "; the check stopped at this move"
            elif finding.code in PATH_CODES and finding.span in after:
                source = after[finding.span]
                why = (f"this move starts at the target of the move before it, which was "
                       f"computed on the path the check chose for {source}, unknown offline")
            if source is not None:
                finding = replace(finding, severity="warning",
                                  message=f"{finding.message}; {why}")
        out.append(finding)
    return out


def _from_unknown_start(findings: list[Finding], planner) -> list[Finding]:
    """Path findings of moves that start where the arm's position is unknown offline (after
    a move a condition stopped, freedrive, a move to an unknown target) are not errors: the
    planner drew that path from where the arm was last known. One URS210 note per such move
    says so; its target is still checked (URS301)."""
    starts = [s for s in planner.segments if s.params.get("from_unknown")]
    if not starts:
        return findings
    kept: list[Finding] = []
    noted: set = set()
    for finding in findings:
        moment = finding.time
        segment = None if finding.code not in PATH_CODES or moment is None else next(
            (s for s in starts if s.start - 1e-9 <= moment <= s.end + 1e-9), None)
        if segment is None:
            kept.append(finding)
            continue
        if segment.span not in noted:
            noted.add(segment.span)
            kept.append(Finding.of(
                "URS210", "this move starts from the arm's position after "
                f"{segment.params['from_unknown']}, which is unknown offline: its path is not "
                f"checked, its target is ({finding.code} on the path drawn from where the arm "
                "was last known is not reported)", segment.span, segment.start))
    return kept


def _before_its_condition(findings: list[Finding], planner) -> list[Finding]:
    """What a move that a condition stops (a Direction node's Until, see
    :mod:`urdsl.motion.direction`) hits on its way (URS308: an obstacle, a safety plane) is a
    warning: such moves are made to go until they touch something (tool contact on a table)
    or a signal says so, which offline is not known to come first."""
    if not planner.stoppable:
        return findings
    moves = [s for s in planner.segments if s.span in planner.stoppable]
    out = []
    for finding in findings:
        moment = finding.time
        if finding.code == "URS308" and finding.severity == "error" and moment is not None \
                and any(s.start - 1e-9 <= moment <= s.end + 1e-9 for s in moves):
            finding = replace(finding, severity="warning", message=(
                f"{finding.message}, on a move its condition stops (Until): unless the "
                "condition holds first"))
        out.append(finding)
    return out


def _after_a_failed_path(findings: list[Finding], stops: list[Finding], planner
                         ) -> list[Finding]:
    """Errors about a move's way (:data:`PATH_CODES`, URS303) at a statement that had run
    before the first path the arm could not follow (``stops``: URS302, a line into a joint
    limit), first met after it: warnings. The controller stops the program at that path;
    the check goes on from the failing move's target, with joints its own IK chose, so what
    a later pass of an earlier statement meets depends on how the failure is mended (seen:
    a wrist wound to its limit in a loop's second pass, San28-cardenas/RBTC_MANIPULACION).
    Statements first run after the failure keep their errors (the move after a failing one
    starts where the program wanted the arm), and so do findings after a ``movej`` to given
    joints since the failure: the arm's joints are the program's again there."""
    timed = [f for f in stops if f.severity == "error" and f.time is not None]
    if not timed:
        return findings
    stop = min(timed, key=lambda f: f.time)
    moment = float(stop.time)
    before = {s.span for s in planner.segments if s.start < moment - 1e-9}
    anchors = [s.end for s in planner.segments if s.kind == "movej" and s.start > moment
               and not s.params.get("solved")]
    anchored = min(anchors, default=math.inf)  # from here the joints are the program's
    out = []
    for finding in findings:
        if finding.severity == "error" and finding.code in PATH_CODES | {"URS303"} \
                and finding.time is not None and moment + 1e-9 < finding.time <= anchored \
                and finding.span in before:
            finding = replace(finding, severity="warning", message=(
                f"{finding.message}; met only after the path at line {stop.span.line} failed "
                f"(t={moment:.3f} s), where the controller stops the program: it follows from "
                "where the check went on, which depends on how that failure is mended"))
        out.append(finding)
    return out


def _trace_findings(trace, planner, robot, options: CheckOptions, deadline: float | None,
                    span) -> list[Finding]:
    """The trace checks, in order; once ``deadline`` (``time.monotonic()``) has passed the
    remaining ones are skipped and a URS313 finding names them."""
    findings: list[Finding] = []
    if trace.cut is not None:
        # the first move not sampled: what the program did from there on was not checked
        where = next((s for s in planner.segments if s.start >= trace.cut), None)
        findings.append(Finding.of(
            "URS313", f"the check reached its wall-clock bound of {options.timeout:g} s while "
            f"sampling the motion: the moves from robot time {trace.cut:.3f} s on were not "
            "checked", where.span if where is not None else span, trace.cut,
            "use --timeout to allow more time"))
    if len(trace.times) == 0 or not planner.segments:
        return findings
    ctx = checks.TraceContext(trace, planner, robot, options, deadline=deadline)
    steps = [check for check in checks.trace_checks() if check.applies(options)]
    for index, check in enumerate(steps):
        if deadline is not None and time.monotonic() > deadline:
            skipped = ", ".join(step.label for step in steps[index:])
            findings.append(Finding.of(
                "URS313", f"the check reached its wall-clock bound of {options.timeout:g} s; "
                f"not checked: {skipped}", span, None, "use --timeout to allow more time"))
            break
        findings += check.run(ctx)
    findings = _from_unknown_start(findings, planner)
    findings = _before_its_condition(findings, planner)
    findings = _after_a_failed_path(
        findings, [f for f in findings if f.code == "URS302"] + ctx.path_limits, planner)
    for label, reached in ctx.partial.items():
        findings.append(Finding.of(
            "URS313", f"the check reached its wall-clock bound of {options.timeout:g} s; "
            f"{label} checked up to robot time {reached:.3f} s only", span, reached,
            "use --timeout to allow more time"))
    return findings
