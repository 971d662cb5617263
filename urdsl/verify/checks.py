"""Checks over a sampled trace, one function per rule. Each takes the trace (and what it
needs of the robot model or the cell) and returns findings, at most one per move and rule,
placed at the statement that commanded the move, with its cause (the joint, the
singularity, the colliding pair): the report keeps one finding per statement, rule and
cause, however often a loop runs the statement (:meth:`urdsl.verify.report.Report.sort`).

Each rule registers itself with :func:`trace_check`, as lint rules do with
:func:`urdsl.lint.registry.rule`: its code, severity and explanation go into the one rule
registry (:data:`urdsl.rules.RULES`, ``urdsl rules``), and :func:`urdsl.verify.run.check_tree`
runs every registered check, in code order, over a :class:`TraceContext`. A new check is
one decorated function ``check(ctx) -> list[Finding]`` (and its test).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .._threads import shared_pool
from ..kinematics.models import JOINT_NAMES
from ..motion.planner import JOINT_SPACE
from ..motion.trace import KNOT_TIME, Trace
from ..rules import Rule, register
from .findings import Finding

if TYPE_CHECKING:  # pragma: no cover
    from .run import CheckOptions

__all__ = ["joint_limits", "joint_speeds", "joint_accelerations", "blend_radii",
           "path_continuity", "tcp_speed", "singularities", "collisions", "Continuity",
           "TraceContext", "TraceCheck", "trace_check", "trace_checks"]

JOINTS = JOINT_NAMES


@dataclass
class TraceContext:
    """What a trace check reads: the sampled ``trace``, the ``planner`` that made it (its
    segments), the ``robot`` model, the user's ``options`` and ``excluded``: (N,) bool, the
    samples around jumps and unreachable stretches, and after the point where a move fails,
    that other checks leave out (set by the URS302 check, which runs first)."""

    trace: Trace
    planner: Any
    robot: Any
    options: CheckOptions
    excluded: np.ndarray | None = None
    path_limits: list[Finding] = field(default_factory=list)
    """URS303 findings of the URS302 check: paths that run a joint into its limit."""
    everywhere: dict[int, float] = field(default_factory=dict)
    """Moves whose path no UR model can follow (see :attr:`Continuity.everywhere`)."""
    deadline: float | None = None
    """``time.monotonic()`` after which a long check stops where it got to (None: never)."""
    partial: dict[str, float] = field(default_factory=dict)
    """Checks that stopped at the deadline: their label → the robot time (s) checked up to."""


@dataclass(frozen=True)
class TraceCheck:
    """A registered check: its rule, the ``label`` that names it when it is skipped at the
    wall-clock bound, and ``applies(options)``: whether the user's options ask for it."""

    rule: Rule
    label: str
    applies: Callable[[CheckOptions], bool]

    def run(self, ctx: TraceContext) -> list[Finding]:
        assert self.rule.check is not None
        return self.rule.check(ctx)


_TRACE_CHECKS: dict[str, TraceCheck] = {}


def trace_check(code: str, name: str, severity: str, label: str, summary: str,
                explanation: str, example: str, fixed: str,
                applies: Callable[[CheckOptions], bool] | None = None
                ) -> Callable[[Callable[[TraceContext], list[Finding]]],
                              Callable[[TraceContext], list[Finding]]]:
    """Register the decorated ``check(ctx) -> list[Finding]`` as the check of rule
    ``code`` (``urdsl check`` runs it over every trace for which ``applies(options)``)."""

    def add(check: Callable[[TraceContext], list[Finding]]):
        rule = register(Rule(code, name, severity, summary, explanation, example, fixed,
                             check, stage="check"))
        _TRACE_CHECKS[code] = TraceCheck(rule, label, applies or (lambda options: True))
        return check

    return add


def trace_checks() -> list[TraceCheck]:
    """The registered trace checks in code order (URS302 first: it finds the samples the
    others leave out)."""
    return [_TRACE_CHECKS[code] for code in sorted(_TRACE_CHECKS)]


def _per_segment(trace: Trace, mask: np.ndarray):
    """(segment index, first sample index) for each move with a flagged sample."""
    flagged = np.flatnonzero(mask.any(axis=1) if mask.ndim == 2 else mask)
    segments, first = np.unique(trace.segment[flagged], return_index=True)
    for order in np.argsort(first):  # in time order, one per move
        yield int(segments[order]), int(flagged[first[order]])


def _rows_where(values: np.ndarray, predicate, block: int = 32768) -> np.ndarray:
    """(N,) bool: rows of ``values`` (N, 6) where ``predicate`` (an elementwise test of a
    block of rows) holds for some column; evaluated in cache-sized blocks of rows."""
    flagged = np.empty(len(values), dtype=bool)

    def rows(start: int) -> None:
        predicate(values[start:start + block]).any(axis=1, out=flagged[start:start + block])

    list(shared_pool().map(rows, range(0, len(values), block)))
    return flagged


def _span(trace: Trace, segment: int):
    from ..script.nodes import NO_SPAN

    return trace.segments[segment].span if segment >= 0 else NO_SPAN


def joint_limits(trace: Trace, lower: np.ndarray, upper: np.ndarray,
                 exclude: np.ndarray | None = None) -> list[Finding]:
    """URS303: joint positions outside [lower, upper] (rad); samples in ``exclude`` are left
    out."""
    low, high = lower - 1e-9, upper + 1e-9
    outside = _rows_where(trace.q, lambda q: (q < low) | (q > high))
    if exclude is not None:
        outside &= ~exclude
    findings = []
    for segment, sample in _per_segment(trace, outside):
        joint = int(np.argmax((trace.q[sample] < low) | (trace.q[sample] > high)))
        value = trace.q[sample, joint]
        bound = upper[joint] if value > upper[joint] else lower[joint]
        where = f"at t={trace.times[sample]:.3f} s"
        if segment < 0 and trace.segments:  # at rest before the first move: its start
            segment, where = 0, "where the arm starts, before this first move"
        findings.append(Finding.of(
            "URS303",
            f"{JOINTS[joint]} joint reaches {np.degrees(value):.1f}° "
            f"(limit {np.degrees(bound):.1f}°) {where}",
            _span(trace, segment), float(trace.times[sample]),
            "choose a target closer to the current joints, or another IK solution",
            cause=f"{JOINTS[joint]} {'upper' if value > upper[joint] else 'lower'}"))
    return findings


def joint_speeds(trace: Trace, limits: np.ndarray, exclude: np.ndarray | None = None,
                 everywhere: dict[int, float] | None = None) -> list[Finding]:
    """URS304: joint speeds above the model's limits (rad/s); samples in ``exclude`` (jumps
    already reported by :func:`path_continuity`) are left out. A speed on the way to where a
    path leaves every UR model's workspace (``everywhere``: move → robot time, s) holds on
    every model: the joints speed up without bound as the arm nears that edge."""
    bound = limits * (1 + 1e-6)
    over = _rows_where(trace.qd, lambda qd: np.abs(qd) > bound)
    if exclude is not None:
        over &= ~exclude
    carried = _carried(trace, over)
    over[carried] = False
    findings = []
    for segment, sample in _per_segment(trace, over):
        ratio = np.abs(trace.qd[sample]) / limits
        joint = int(np.argmax(ratio))
        samples = _samples_of(trace, segment)  # the move's samples, not the whole trace
        inside = np.ones(samples.stop - samples.start, dtype=bool)
        if exclude is not None:
            inside &= ~exclude[samples]
        own = carried[(carried >= samples.start) & (carried < samples.stop)]
        inside[own - samples.start] = False
        peak = float(np.max(np.abs(trace.qd[samples][inside, joint])))
        finding = Finding.of(
            "URS304",
            f"{JOINTS[joint]} joint turns at {peak:.2f} rad/s, over its limit of "
            f"{limits[joint]:.2f} rad/s",
            _span(trace, segment), float(trace.times[sample]), _speed_hint(trace, segment),
            cause=JOINTS[joint])
        move = _slowed(trace, segment, peak / limits[joint], exclude)
        if move is not None:
            fastest = float(np.max(np.abs(trace.qd[samples][inside]) / limits))
            finding = replace(finding, severity="warning", slowed=fastest, message=(
                f"{finding.message}; this {move.kind} mostly turns the tool, and its time is "
                "that turn's at 4·v rad/s, a rate UR does not document (a user's "
                "measurement): the controller may turn the tool slower"
                if move.params.get("turn_timed") else
                f"{finding.message}; the controller slows a program's moves so that no joint "
                f"exceeds its speed limit (UR user manual, safety joint limits): "
                f"{_takes_longer(move)}"))
        if everywhere and segment in everywhere and trace.times[sample] <= everywhere[segment]:
            finding = replace(finding, cause=f"{JOINTS[joint]}, {EVERY_MODEL}", message=(
                f"{finding.message}, on the way to where the path leaves every UR model's "
                "workspace (URS302)"))
        findings.append(finding)
    return findings


SCALED_MARGIN = 2.0
'''A joint speed over its limit by at most this factor on a movej, movel, movep or movec is a
URS304 warning: the controller slows a running program so that no joint exceeds its speed
limit, and stops it only when one does (CB3 user manual 3.4, safety "Joint Limits": "the speed
of the robot arm is automatically adjusted in order to not exceed any of the entered values";
the e-Series' the same [U]), so such a move takes longer rather than stopping. On a movel or
movep timed by its tool turn (:data:`urdsl.motion.planner.ROTATION_PER_METRE`, [U]) the speed
may also come from that undocumented rate. These stay errors: a speed over this factor (a
path near a singularity, where the joints speed up without bound: 30 rad/s in project 135, and
UR's distributor notes say the arm stops [U]), servo and speed commands, and any speed on a
move whose path fails (URS302/URS303).

A move whose time ``t`` the program gives is judged at the speeds its ``a`` and ``v`` alone
give (the segment's ``t_free``, s) when ``t`` is shorter: the joint speeds scale with
``t_free / t``, so what a too short ``t`` adds is time the controller stretches, as for any
move, and what stays is the path's own (a singularity). The manual's sentence covers every
motion of a running program and names no exception for a given time; that the controller
stretches a given ``t`` rather than stop is not documented [U] (project 26 of
bench/realworld: a 0.1 s ``t`` for 0.1-0.7 m lines, run on a UR3 and a UR3e by its author's
account).'''

SCALED_KINDS = frozenset({"movej", "movel", "movep", "movec"})
"""Moves whose speed the controller's trajectory generator scales (:data:`SCALED_MARGIN`)."""


def _samples_of(trace: Trace, segment: int) -> slice:
    """The samples of move ``segment`` (a sample belongs to the latest move started, so a
    move's samples are one run of the trace)."""
    return slice(int(np.searchsorted(trace.segment, segment, side="left")),
                 int(np.searchsorted(trace.segment, segment, side="right")))


def _slowed(trace: Trace, segment: int, ratio: float, exclude: np.ndarray | None,
            margin: float = SCALED_MARGIN):
    """The move ``segment`` when the controller slows it rather than stop at a speed
    ``ratio`` times a limit (up to ``margin`` times, :data:`SCALED_MARGIN` for joints);
    else None."""
    if segment < 0:
        return None
    move = trace.segments[segment]
    if move.kind not in SCALED_KINDS:
        return None
    given = move.params.get("t", 0)
    if given > 0:
        free = move.params.get("t_free")
        if not free:
            return None
        ratio *= min(1.0, given / free)  # the part of the speed a too short t adds
    if ratio > margin:
        return None
    if exclude is not None and bool(exclude[_samples_of(trace, segment)].any()):
        return None  # the move's path fails: the speed is that failure's
    return move


def _takes_longer(move) -> str:
    """What slowing ``move`` (a trace segment) down means for its time, for a message."""
    given, free = move.params.get("t", 0), move.params.get("t_free")
    if given > 0 and free and given < free:
        return (f"this {move.kind} takes longer than the t={given:g} s the program gives it "
                f"(its a and v alone take {free:.2f} s; that the controller stretches a given "
                "time is not documented)")
    return f"this {move.kind} takes longer than planned"


def _carried(trace: Trace, over: np.ndarray) -> np.ndarray:
    """The samples flagged in ``over`` (N,) only because a move's first sample shares its
    central difference with the move before, which was flagged there too: a speed the move
    before still had (a path through a singularity that ends in it, a path drawn from where
    the arm was last known) is that move's, not this one's."""
    first = np.flatnonzero(trace.segment[1:] != trace.segment[:-1]) + 1
    return first[over[first] & over[first - 1]]


def _speed_hint(trace: Trace, segment: int) -> str:
    kind = trace.segments[segment].kind if segment >= 0 else ""
    if kind in JOINT_SPACE:
        return f"lower v (rad/s of the leading joint) or lengthen t of this {kind}"
    return f"lower v (m/s of the TCP) of this {kind}, or move further from singularities"


def joint_accelerations(trace: Trace, limits: np.ndarray, exclude: np.ndarray | None = None
                        ) -> list[Finding]:
    """URS305: joint accelerations above the user's limits (rad/s²; UR publishes none)."""
    over = np.abs(trace.qdd) > limits * (1 + 1e-6)
    if exclude is not None:
        over &= ~exclude[:, None]
    findings = []
    for segment, sample in _per_segment(trace, over):
        joint = int(np.argmax(np.abs(trace.qdd[sample]) / limits))
        findings.append(Finding.of(
            "URS305",
            f"{JOINTS[joint]} joint accelerates at {abs(trace.qdd[sample, joint]):.1f} "
            f"rad/s², over {limits[joint]:.1f} rad/s²",
            _span(trace, segment), float(trace.times[sample]), "lower a", cause=JOINTS[joint]))
    return findings


def blend_radii(segments) -> list[Finding]:
    """URS310: a blend radius larger than half of the segment before or after it (a
    conservative house rule: UR's own rule is the overlap of blend spheres, URS309)."""
    findings = []
    if len(segments) < 2:
        return findings
    radius = np.array([s.radius for s in segments[:-1]])
    ends = np.array([s.pose_end[:3, 3] for s in segments])
    starts = np.array([s.pose_start[:3, 3] for s in segments])
    lengths = np.sqrt(((ends - starts) ** 2).sum(axis=1))
    shortest_all = np.minimum(lengths[:-1], lengths[1:])
    for index in np.flatnonzero((radius > 0) & (radius > shortest_all / 2 + 1e-9)):
        before, shortest = segments[index], float(shortest_all[index])
        findings.append(Finding.of(
            "URS310",
            f"blend radius {before.radius:g} m is more than half of a neighbouring "
            f"segment ({shortest:.4g} m): the blend may be cut short",
            before.span, before.end, "use at most half the shorter segment"))
    return findings


@dataclass
class Continuity:
    """What :func:`path_continuity` found: its findings, and the samples (N,) around jumps
    and unreachable stretches, which other checks leave out."""

    findings: list[Finding]
    samples: np.ndarray
    limits: list[Finding] = field(default_factory=list)
    """URS303: moves whose path runs a joint into its limit (reported by that check)."""
    everywhere: dict[int, float] = field(default_factory=dict)
    """Moves whose path leaves the workspace of every UR model → the robot time (s) where
    it leaves the assumed model's."""


EVERY_MODEL = "beyond every UR model's workspace"
"""The cause of a URS302 whose path no UR model can follow, and the end of that of a URS304
on the way there: they hold whichever arm runs the program (see
:func:`urdsl.verify.infer.qualify`)."""


JUMP_MIN = 0.25
"""Smallest joint step (rad) between two samples that counts as a jump of the IK branch: at
the fastest joint speed of any UR (π rad/s) a joint moves 0.006 rad in a 2 ms step and
0.025 rad in an 8 ms step; a change of branch moves a joint by about π."""


def path_continuity(trace: Trace, speed_limits: np.ndarray, model=None,
                    every_model: bool = False) -> Continuity:
    """URS302: a TCP path (movel/movep/movec) that leaves the workspace between reachable
    ends, or whose joints jump because inverse kinematics must change its branch; and, with
    the kinematic ``model``, URS303 where the jump is a joint running into its limit
    (:func:`urdsl.motion.planner.branch_path`).

    The controller stops the arm where such a move fails. What the trace draws after that
    point — the rest of the move on another branch, and the jump back to where the next move
    starts — is motion the arm never makes: those samples go into the ``samples`` the other
    checks leave out, and the jump back is not a failure of the next move.

    With ``every_model`` (the arm's model is only assumed) a path that leaves the workspace
    is also tried on every UR model: where none can follow it, the finding's cause says so
    (:data:`EVERY_MODEL`), and so does that of a joint speed on the way there
    (``Continuity.everywhere``)."""
    count = len(trace.times)
    findings: list[Finding] = []
    limits: list[Finding] = []
    everywhere: dict[int, float] = {}
    threshold = np.maximum(JUMP_MIN, 10.0 * speed_limits * trace.dt)
    jumps = np.zeros(count, dtype=bool)
    block = 32768

    def rows(start: int) -> None:  # a step from the sample before over the threshold
        stop = min(start + block, count - 1)
        step = np.abs(trace.q[start + 1:stop + 1] - trace.q[start:stop])
        (step > threshold).any(axis=1, out=jumps[start + 1:stop + 1])

    list(shared_pool().map(rows, range(0, count - 1, block)))
    bad = jumps | trace.unreachable
    failed = np.zeros(count, dtype=bool)  # after the point where a move fails
    for segment, first in _per_segment(trace, bad):
        if segment < 0:
            continue
        samples = _samples_of(trace, segment)
        low, high = samples.start, samples.stop
        if failed[first]:  # the trace coming back from an earlier move's failure
            rest = np.flatnonzero(bad[first:high] & ~failed[first:high])
            if len(rest) == 0:
                continue
            first += int(rest[0])
        move = trace.segments[segment]
        previous = trace.segments[segment - 1] if segment > 0 else None
        start, limit = _failure(trace, move, previous, low, high, first, model)
        if limit is not None and not move.params.get("from_unknown"):
            # (from a start unknown offline, the path is not checked: a URS302 the run
            # drops, see urdsl.verify.run._from_unknown_start)
            sample, joint, bound = limit
            fraction = float(move.profile.position(trace.times[sample] - move.start)
                             / max(move.profile.distance, 1e-12))
            side = "upper" if bound == float(model.q_max[joint]) else "lower"
            limits.append(Finding.of(
                "URS303",
                f"the {move.kind} path takes the {JOINTS[joint]} joint to its limit of "
                f"{np.degrees(bound):.1f}° at {100 * fraction:.0f}% of the way "
                f"(t={trace.times[sample]:.3f} s): the controller stops the arm there",
                _span(trace, segment), float(trace.times[sample]),
                f"turn the {JOINTS[joint]} joint back with a movej before this move, or "
                "split the move", cause=f"{JOINTS[joint]} {side}"))
        else:
            finding = _continuity_finding(trace, segment, first, jumps, threshold)
            if every_model and finding.cause == "reach" and _beyond_every_model(trace, segment):
                finding = replace(finding, cause=EVERY_MODEL,
                                  message=f"{finding.message}; no UR model can follow it")
                everywhere[segment] = finding.time
            findings.append(finding)
        failed[start:high] = True
        failed[high:_end_of_run(bad, high)] = True  # the jump back to the next move's start
    near = bad | failed
    flagged = near.copy()
    for shift in (1, 2):  # central differences spread a jump to the neighbours
        flagged[shift:] |= near[:-shift]
        flagged[:-shift] |= near[shift:]
    return Continuity(findings, flagged, limits, everywhere)


def _end_of_run(flags: np.ndarray, start: int, chunk: int = 4096) -> int:
    """The first index from ``start`` on where ``flags`` is False (its length if none), in
    time proportional to the run's length."""
    stop = start
    while stop < len(flags):
        clear = np.flatnonzero(~flags[stop:stop + chunk])
        if len(clear):
            return stop + int(clear[0])
        stop += chunk
    return len(flags)


def _continuity_finding(trace: Trace, segment: int, sample: int, jumps: np.ndarray,
                        threshold: np.ndarray) -> Finding:
    """URS302 for the move ``segment`` that fails at ``sample``: its path leaves the
    workspace (some sample of it is out of reach) or its joints jump there."""
    move = trace.segments[segment]
    samples = _samples_of(trace, segment)
    inside = samples.start + np.flatnonzero(trace.unreachable[samples])
    if len(inside):
        fraction = (trace.times[inside] - move.start) / max(move.duration, 1e-12)
        return Finding.of(
            "URS302",
            f"the {move.kind} path leaves the robot's workspace between "
            f"{100 * fraction.min():.0f}% and {100 * fraction.max():.0f}% of the way "
            f"(t={trace.times[inside[0]]:.3f} s), although both ends are reachable",
            _span(trace, segment), float(trace.times[inside[0]]),
            "go round the unreachable region with a waypoint, or use movej", cause="reach")
    step = np.abs(trace.q[sample] - trace.q[sample - 1])
    joint = int(np.argmax(step / threshold))
    return Finding.of(
        "URS302",
        f"the {move.kind} path needs a change of IK solution: the {JOINTS[joint]} joint "
        f"jumps by {np.degrees(step[joint]):.0f}° at "
        f"t={trace.times[sample]:.3f} s, which the robot cannot do on a straight line",
        _span(trace, segment), float(trace.times[sample]),
        "split the move, or reach the end with movej", cause=f"jump {JOINTS[joint]}")


DEPARTURE = 0.05
"""Joint difference (rad, 2.9°) at which the trace of a failing move has left the path its
joints take on the IK branch it starts on. Away from singularities the trace's cubics are
within a micro-radian of that path (:data:`urdsl.motion.trace.KNOT_TIME`); near one, where
the joints swing at tens of rad/s, measured up to 0.006 rad (project 135); a jump to another
branch moves a joint by a large fraction of a turn. The trace has left the path from where
that difference starts to grow towards it (down to :data:`DEPARTURE_FLOOR`)."""

DEPARTURE_FLOOR = 1e-5
"""Joint difference (rad) below which the trace of a failing move is still on its path."""


BEYOND_SAMPLES = 256
"""Points of a path, evenly spaced, at which :func:`_beyond_every_model` tries each model,
besides the samples where the assumed model could not follow it."""


def _beyond_every_model(trace: Trace, segment: int) -> bool:
    """Whether some point of the path of the Cartesian move ``segment`` lies outside the
    workspace of every UR model with the move's TCP, whatever the joint limits (a straight
    line that passes the base's vertical axis closer than any arm's shoulder offset)."""
    from ..kinematics import MODELS, Robot

    move = trace.segments[segment]
    samples = _samples_of(trace, segment)
    inside = samples.start + np.flatnonzero(trace.unreachable[samples])
    local = np.clip(trace.times[inside] - move.start, 0.0, move.duration)
    covered = move.profile.position(local) / max(move.profile.distance, 1e-12)
    poses = move.path_poses(np.concatenate([np.linspace(0.0, 1.0, BEYOND_SAMPLES), covered]))
    for name in MODELS:
        solutions, _ = Robot.model(name).ik_all_many(poses, tcp=move.tcp)
        if not np.isnan(solutions).all(axis=(1, 2)).any():
            return False  # this model reaches every point
    return True


def _failure(trace: Trace, move, previous, low: int, high: int, first: int, model
             ) -> tuple[int, tuple[int, int, float] | None]:
    """Where the Cartesian ``move`` (samples ``low`` to ``high`` − 1 of the trace, flagged
    first at ``first``) fails: the sample from which its trace is no longer the arm's motion,
    and ``(sample, joint, bound in rad)`` when the reason is a joint running into its limit
    (:func:`urdsl.motion.planner.branch_path`), else None.

    A jump between two knots of the trace is drawn over the samples between them (up to
    :data:`urdsl.motion.trace.KNOT_TIME`, or 8 mm of a slow path): the trace leaves the
    branch before the jump is flagged. Samples in a blend from ``previous`` (the move
    before) are not compared: both moves add up there."""
    fallback = max(low, first - int(np.ceil(KNOT_TIME / trace.dt))), None
    if model is None or move.kind in JOINT_SPACE or move.profile.distance <= 0.0:
        return fallback
    from ..motion.planner import branch_path

    local = np.clip(trace.times[low:high] - move.start, 0.0, move.duration)
    path = branch_path(model, move, move.profile.position(local) / move.profile.distance)
    if path is None:
        return fallback
    valid = int(np.argmax(np.isnan(path).any(axis=1))) if np.isnan(path).any() \
        else len(path)
    blended = 0 if previous is None else \
        int(np.searchsorted(trace.times[low:high], previous.end, side="left"))
    apart = np.abs(trace.q[low + blended:low + valid] - path[blended:valid]).max(axis=1) \
        if valid > blended else np.zeros(0)
    left = np.flatnonzero(apart > DEPARTURE)
    departure = first
    if len(left):
        row = int(left[0])
        while row > 0 and DEPARTURE_FLOOR < apart[row - 1] < apart[row]:
            row -= 1  # back to where the difference starts to grow
        departure = low + blended + row
    departure = min(departure, first)
    low_limit = np.asarray(model.q_min, dtype=float)
    high_limit = np.asarray(model.q_max, dtype=float)
    outside = (path[:valid] < low_limit - 1e-9) | (path[:valid] > high_limit + 1e-9)
    rows = np.flatnonzero(outside.any(axis=1))
    if len(rows) == 0 or low + int(rows[0]) < departure:
        return departure, None
    row = int(rows[0])
    joint = int(np.argmax(outside[row]))
    bound = high_limit[joint] if path[row, joint] > high_limit[joint] else low_limit[joint]
    return departure, (low + row, joint, float(bound))


def _tcp_positions(trace: Trace, robot, stride: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """TCP positions (M, 3) in m for every ``stride``-th sample, with the sample indices;
    each sample uses the TCP that was active for its move."""
    index = np.arange(0, len(trace.times), stride)
    positions = np.empty((len(index), 3))
    group, tcps = _tcp_group_of_samples(trace, index)
    for number in np.unique(group):
        rows = group == number
        positions[rows] = robot.fk_many(trace.q[index[rows]], tcp=tcps[number])[:, :3, 3]
    return positions, index


def _tcp_group_of_samples(trace: Trace, index: np.ndarray) -> tuple[np.ndarray, list]:
    """For the samples ``index``, the number of the TCP active in their move, and the TCPs."""
    from ..motion.trace import tcp_groups

    group_of_move, tcps = tcp_groups(trace.segments)
    # samples at rest before the first move (-1) use the first move's TCP
    return np.append(group_of_move, group_of_move[:1])[trace.segment[index]], tcps


def tcp_speed(trace: Trace, robot, limit: float, exclude: np.ndarray | None = None
              ) -> list[Finding]:
    """URS306: the TCP moves faster than the user's limit (m/s), e.g. 0.25 m/s in a
    collaborative cell. Where the program changed its TCP (``set_tcp``) between two samples,
    the TCP point jumps without the arm moving: each side is differentiated on its own.
    Samples in ``exclude`` are left out.

    On a movej, movel, movep or movec whose path does not fail the controller slows the move
    to the limit, however far over it (a warning; "the robot controller prevents violations
    by making a robot stop or by reducing the speed", UR user manual, software safety
    limits). The TCP speed a program asks for is bounded (it is ``v`` on a line), so the
    argument that keeps a joint speed over :data:`SCALED_MARGIN` an error, joint speeds
    without bound near a singularity, does not hold for it; and a cell whose safety system
    switches from 1 m/s to Reduced mode's 0.25 m/s mid-move slows the running program, it does
    not stop it (UR forum, "Smoother transition to reduced mode", topic 944). Which stops
    the safety system makes for a program's own moves is not documented [U]. Servo and
    speed commands stay errors."""
    positions, index = _tcp_positions(trace, robot)
    if len(positions) < 2:
        speed = np.zeros(len(positions))
    else:
        velocity = np.gradient(positions, trace.dt, axis=0)
        group, _tcps = _tcp_group_of_samples(trace, index)
        for last in np.flatnonzero(group[1:] != group[:-1]):  # the TCP changes after it
            first = last + 1
            before = last >= 1 and group[last - 1] == group[last]
            velocity[last] = (positions[last] - positions[last - 1]) / trace.dt if before \
                else 0.0
            after = first + 1 < len(positions) and group[first + 1] == group[first]
            velocity[first] = (positions[first + 1] - positions[first]) / trace.dt if after \
                else 0.0
        speed = np.linalg.norm(velocity, axis=1)
    over = speed > limit * (1 + 1e-6)  # every sample (stride 1): one row a sample
    if exclude is not None:
        over &= ~exclude
    over[_carried(trace, over)] = False
    findings = []
    for segment, sample in _per_segment(trace, over):
        samples = _samples_of(trace, segment)
        peak = float(np.max(speed[samples][over[samples]]))
        finding = Finding.of(
            "URS306", f"the TCP moves at {peak:.3f} m/s, over the cell's limit of {limit:g} m/s",
            _span(trace, segment), float(trace.times[sample]), _speed_hint(trace, segment),
            cause="tcp")
        move = _slowed(trace, segment, peak / limit, exclude, margin=np.inf)
        if move is not None:  # the controller reduces the speed to the safety limit
            finding = replace(finding, severity="warning", slowed=peak / limit, message=(
                f"{finding.message}; the controller slows a program's moves to keep the TCP "
                f"within the safety limit (UR user manual, software safety limits): "
                f"{_takes_longer(move)}"))
        findings.append(finding)
    return findings


SINGULARITY_MARGINS = {"shoulder": 0.05, "elbow": 0.02, "wrist": 0.05}
"""Distances to a singularity below which URS307 warns, in the units of
:meth:`urdsl.kinematics.Robot.singularity`: the wrist centre 5 cm from the vertical plane
through the base axis (shoulder), the arm 2 cm from fully stretched or folded (elbow), the
wrist-1 and wrist-3 axes 0.05 rad (2.9°) from parallel (wrist)."""

_UNITS = {"shoulder": "m", "elbow": "m", "wrist": "rad"}


def singularities(trace: Trace, robot, scale: float | None = None,
                  step: float = 0.01) -> list[Finding]:
    """URS307: on a TCP path (also inside blends) the arm comes closer to a shoulder, elbow or
    wrist singularity than :data:`SINGULARITY_MARGINS` times ``scale`` (default 1), checked
    every ``step`` s of robot time."""
    stride = max(1, int(round(step / trace.dt)))
    index = np.arange(0, len(trace.times), stride)
    if len(index) == 0:
        return []
    joints = trace.q[index]
    blocks = list(shared_pool().map(robot.singularity, [joints[start:start + 32768] for start
                                                       in range(0, len(joints), 32768)]))
    measures = {name: np.concatenate([block[name] for block in blocks]) for name in blocks[0]}
    # Joint moves pass singular configurations harmlessly; on a TCP path (and in blends into
    # one) the joint speeds needed near them grow without bound.
    kinds = np.array([s.kind not in JOINT_SPACE for s in trace.segments] + [False])
    cartesian = kinds[trace.segment]
    findings = []
    for kind, default in SINGULARITY_MARGINS.items():
        limit = default * (1.0 if scale is None else scale)
        close = np.zeros(len(trace.times), dtype=bool)
        close[index] = np.abs(np.asarray(measures[kind])) < limit
        close &= cartesian
        for segment, sample in _per_segment(trace, close):
            move = trace.segments[segment]
            distance = abs(float(measures[kind][sample // stride]))
            distance = 0.0 if distance < 1e-12 else distance  # rounding: on the singularity
            findings.append(Finding.of(
                "URS307",
                f"{kind} singularity: the {move.kind} passes within "
                f"{distance:.3g} {_UNITS[kind]} of it at "
                f"t={trace.times[sample]:.3f} s (joint speeds grow without bound there)",
                _span(trace, segment), float(trace.times[sample]),
                _SINGULARITY_HINTS[kind], cause=kind))
    return findings


_SINGULARITY_HINTS = {
    "shoulder": "keep the wrist away from the base's vertical axis",
    "elbow": "do not stretch the arm fully (stay inside the reach)",
    "wrist": "avoid wrist 2 near 0° or 180° (wrist 1 and wrist 3 axes aligned): tilt the tool",
}


SELF_OVERLAP_TOLERANCE = 0.005
"""Overlap (m) between two of the arm's own links below which no self-collision is reported:
the links are convex hulls or capsules scaled from the UR5's ROS description, not UR's
shapes, and arms taught on the real robot pass poses where these overlap by 1-2 mm
(bench/realworld 117). A real self-collision goes deeper as the move goes on. Obstacles of
the cell file are the user's own shapes: any overlap with them is reported."""


def collisions(trace: Trace, robot, cell, step: float = 0.02,
               self_collision: bool = True, deadline: float | None = None,
               partial: dict[str, float] | None = None,
               exclude: np.ndarray | None = None) -> list[Finding]:
    """URS308: the arm hits the cell's obstacles (floor, boxes, cylinders, planes) or itself,
    checked every ``step`` s of robot time while it moves, or further apart where it cannot
    come into contact in between (see :meth:`CollisionModel.sweep`). ``cell`` is a path of a
    cell TOML or a ready :class:`urdsl.kinematics.collision.CollisionModel` (None: no
    obstacles). With a ``deadline`` (``time.monotonic()``) the sweep stops once it has
    passed; ``partial["collisions"]`` then holds the robot time (s) checked up to. Samples
    in ``exclude`` are left out."""
    if cell is None and not self_collision:
        return []
    from ..kinematics.collision import LINKS, CollisionModel

    if isinstance(cell, CollisionModel):
        model = cell
    else:
        model = CollisionModel(robot)
        if cell is not None:
            model.load_cell(cell)
    stride = max(1, int(round(step / trace.dt)))
    moving = np.flatnonzero(trace.segment >= 0)  # from the first move on
    if len(moving) == 0:
        return []
    tcp = trace.segments[-1].tcp if trace.segments else None
    index, result = model.sweep(trace.q[moving[0]:], tcp=tcp, stride=stride,
                                deadline=deadline)
    index += moving[0]
    if result.stopped is not None and partial is not None:
        partial["collisions"] = float(trace.times[result.stopped + moving[0]])
    colliding = np.array(result.colliding, dtype=bool)
    for i in np.flatnonzero(colliding):
        pairs = result.pairs.get(int(i)) or [result.closest[int(i)]]
        if (all(a in LINKS and b in LINKS for a, b in pairs)
                and -float(result.distance[i]) < SELF_OVERLAP_TOLERANCE):
            colliding[i] = False  # within what the approximate link shapes can tell
    hit = np.zeros(len(trace.times), dtype=bool)
    hit[index] = colliding
    if exclude is not None:
        hit &= ~exclude
    position = {int(sample): i for i, sample in enumerate(index)}
    findings = []
    for segment, sample in _per_segment(trace, hit):
        where = position[sample]
        pairs = result.pairs.get(where) or [result.closest[where]]
        what = ", ".join(" and ".join(pair) for pair in pairs[:3])
        depth = -float(result.distance[where])
        findings.append(Finding.of(
            "URS308", f"collision: {what} (overlap {depth * 1000:.0f} mm) at "
            f"t={trace.times[sample]:.3f} s",
            _span(trace, segment), float(trace.times[sample]),
            "move around the obstacle with an extra waypoint",
            cause=_collision_cause(pairs, LINKS)))
    return findings


def _collision_cause(pairs, links) -> str:
    """What a collision hits, as one cause per statement: the cell's obstacles by name, or
    the arm itself — a loop's later pass that folds the arm onto itself at other link pairs
    (the path differs by a millimetre) is the same problem, reported once."""
    obstacles = sorted({name for pair in pairs for name in pair if name not in links})
    return "obstacle " + ", ".join(obstacles) if obstacles else "self"


SAFETY_PLANE_TOLERANCE = 0.005
"""How far (m) the TCP or elbow may be beyond a safety plane before URS308 reports it (as two
link shapes may overlap, :data:`SELF_OVERLAP_TOLERANCE`): a
waypoint taught on the plane's boundary is where the arm was."""


def past_plane(points: np.ndarray, plane) -> np.ndarray:
    """How far (m) ``points`` (..., 3) lie beyond a safety plane (``normal·x + distance < 0``
    is its forbidden side; its normal need not be a unit vector): positive beyond it."""
    normal = np.asarray(plane.normal, dtype=float)
    normal = normal / np.linalg.norm(normal)
    return -(np.asarray(points, dtype=float) @ normal + float(plane.distance))


def safety_planes(trace: Trace, robot, planes, step: float = 0.02,
                  exclude: np.ndarray | None = None) -> list[Finding]:
    """URS308: the TCP, and the elbow where a plane restricts it, passes beyond a safety plane
    of the installation (``normal·x + distance < 0``), checked every ``step`` s of robot time
    from the first move on, but not at samples in ``exclude``. The controller's safety
    system watches these points of the arm (and the tool's spheres), not its links: a
    forearm that reaches over a plane is allowed."""
    if not planes or not trace.segments:
        return []
    from ..kinematics import Robot

    stride = max(1, int(round(step / trace.dt)))
    tcp, index = _tcp_positions(trace, robot, stride)
    moving = trace.segment[index] >= 0
    tcp, index = tcp[moving], index[moving]
    elbow = None
    if any(plane.elbow for plane in planes):
        # the elbow joint, on the nominal arm of the model (within a calibration's millimetres;
        # a factory table's frames on the parallel axes may lie metres along them)
        nominal = Robot.model(robot.spec.name)
        elbow = nominal.frames_many(trace.q[index])[:, 2, :3, 3]
    beyond = np.zeros(len(index), dtype=bool)
    depth = np.zeros(len(index))
    what = np.empty(len(index), dtype=object)
    for plane in planes:
        points = [("TCP", tcp)] + ([("elbow", elbow)] if plane.elbow and elbow is not None
                                   else [])
        for part, where in points:
            past = past_plane(where, plane)
            new = (past > SAFETY_PLANE_TOLERANCE) & ~beyond
            beyond |= new
            depth[new] = past[new]
            what[new] = f"the {part} passes the safety plane {plane.name}"
    hit = np.zeros(len(trace.times), dtype=bool)
    hit[index[beyond]] = True
    if exclude is not None:
        hit &= ~exclude
    position = {int(sample): i for i, sample in enumerate(index)}
    findings = []
    for segment, sample in _per_segment(trace, hit):
        i = position[sample]
        findings.append(Finding.of(
            "URS308", f"{what[i]} by {depth[i] * 1000:.0f} mm at t={trace.times[sample]:.3f} s "
            "(the controller stops the arm there)",
            _span(trace, segment), float(trace.times[sample]),
            "keep the TCP on the allowed side of the plane, or change the installation's "
            "safety planes", cause=str(what[i])))
    return findings


# ---- the registered checks, in code order ----------------------------------------------------

_READY = "movej([0, -1.9, 1.9, -1.57, -1.57, 0])  # tool down, in front of the robot"
_START = "0,-1.9,1.9,-1.57,-1.57,0"


@trace_check(
    "URS302", "path-leaves-workspace", "error", "path continuity",
    summary="A movel/movep/movec path leaves the workspace or needs an IK branch flip.",
    explanation="""
Both ends of a straight-line (or circular) move are reachable, but a point between them is
not, or the joints would have to jump to another inverse-kinematics solution on the way.
The controller computes the path in Cartesian space and stops the program with a protective
stop when it cannot follow it. urdsl samples the path at the controller rate and reports the
move with the fraction of the way where it fails, or the joint that jumps. The rest of the
move after that point, and the way back to where the next move starts, are motion the arm
never makes: the checks of joint limits, speeds, TCP speed and collisions leave them out
(singularity warnings do not: a singular pose is often why the move fails). Where the
continuous solution runs a joint into its limit, the finding is URS303.""",
    example="movej(get_inverse_kin(p[0.35, -0.2, 0.3, 0, 3.1416, 0]))\n"
            "movel(p[-0.35, 0.2, 0.3, 0, 3.1416, 0])  # through the base's axis",
    fixed="movej(get_inverse_kin(p[0.35, -0.2, 0.3, 0, 3.1416, 0]))\n"
          "movej(get_inverse_kin(p[-0.35, 0.2, 0.3, 0, 3.1416, 0]))",
)
def _continuity(ctx: TraceContext) -> list[Finding]:
    result = path_continuity(ctx.trace, np.asarray(ctx.robot.qd_max), ctx.planner.kinematics,
                             every_model=ctx.options.robot_assumed)
    ctx.excluded = result.samples
    ctx.path_limits = result.limits
    ctx.everywhere = result.everywhere
    return result.findings


@trace_check(
    "URS303", "joint-position-limit", "error", "joint limits",
    summary="A joint goes beyond its position limit.",
    explanation="""
Every UR joint turns at most ±360° (±2π rad) from zero (the UR3/UR3e wrist 3 without
limit); a cell may set tighter limits in the safety configuration (urdsl check --q-min,
--q-max). A movej target outside them, or a linear move whose inverse kinematics lead a
joint there, stops the robot. On a straight line the joints follow one solution
continuously; where that runs a joint into the model's limit (wrist 3 wound to -350° by an
earlier move, then turned on), the finding says how far along the move the arm stops [U].
The finding names the joint, the angle and the limit.""",
    example=f"{_READY}\nmovej([0, -1.9, 1.9, -1.57, -1.57, 6.5])",
    fixed=f"{_READY}\nmovej([0, -1.9, 1.9, -1.57, -1.57, 0.2168])  # 6.5 - 2*pi",
)
def _joint_limits(ctx: TraceContext) -> list[Finding]:
    options, robot = ctx.options, ctx.robot
    q_min = np.asarray(options.q_min if options.q_min is not None else robot.q_min)
    q_max = np.asarray(options.q_max if options.q_max is not None else robot.q_max)
    unknown = _unknown_starts(ctx)
    if ctx.excluded is not None:
        unknown = ctx.excluded if unknown is None else unknown | ctx.excluded
    return ctx.path_limits + joint_limits(ctx.trace, q_min, q_max, unknown)


def _unknown_starts(ctx: TraceContext) -> np.ndarray | None:
    """The samples where the simulated arm stands in for a position unknown offline: at rest
    before the first move when the program starts wherever the arm was left, and every
    sample but the last of a move from such a position (a movej interpolates the joints, so
    only its ends can pass a limit, and its start is the unknown one)."""
    trace = ctx.trace
    segment = trace.segment
    unknown = [index for index, move in enumerate(trace.segments)
               if move.params.get("from_unknown")]
    if not unknown and not ctx.options.start_unknown:
        return None
    mask = np.isin(segment, unknown)
    ends = np.flatnonzero(mask[:-1] & (segment[1:] != segment[:-1]))
    mask[ends] = False
    if len(mask) and mask[-1]:
        mask[-1] = False
    if ctx.options.start_unknown:
        mask |= segment < 0
    return mask


@trace_check(
    "URS304", "joint-speed-limit", "error", "joint speeds",
    summary="A joint turns faster than the robot model allows.",
    explanation="""
Each joint of a UR model has a top speed (e.g. 180 °/s for every joint of a UR5e, 120 °/s
for the base and shoulder of a UR10; see 'urdsl models'). urdsl samples the planned motion at
the controller rate (2 ms e-Series, 8 ms CB3) and reports the first move in which a joint is
faster than its limit, with the joint and its peak speed. A linear move near a singularity,
where the joints must turn fast for a slow TCP, causes it (the robot speeds up and stops with
a joint limit violation [U: UR distributor Zacobria's notes on singularities]). A movej with
a v over a joint's top speed is not: it is timed at the fastest speed the joints allow [U],
and 'urdsl lint' warns about the v (URS110). The controller slows a running program so that
no joint exceeds its speed limit (the user manual's safety joint limits): a joint over its
limit by at most 2x on a movej, movel, movep or movec is a warning that the move takes longer
than planned. A move given a time t shorter than its own a and v take is judged at the
speeds a and v give: what the short t adds is time the controller stretches (the warning
names t; UR documents no exception for a given time, nor that it stretches one [U]).
Faster, near a singularity, the arm stops. A movel or movep that mostly turns the tool is
timed by its turn at 4·v rad/s, a rate a user measured and UR does not document [U]: its
warning says so.""",
    example=f"{_READY}\nmovel(p[-0.35, -0.14, 0.465, 2.2206, 2.2206, 0])\n"
            "movel(p[0.35, -0.14, 0.465, 2.2206, 2.2206, 0], v=1.0)  # 5 cm from the "
            "shoulder singularity",
    fixed=f"{_READY}\nmovel(p[-0.35, -0.14, 0.465, 2.2206, 2.2206, 0])\n"
          "movel(p[0.35, -0.14, 0.465, 2.2206, 2.2206, 0], v=0.25)  # slower near it",
)
def _joint_speeds(ctx: TraceContext) -> list[Finding]:
    qd_max = np.asarray(ctx.robot.qd_max, dtype=float)
    limit = getattr(ctx.options, "joint_speed_limit", None)
    if limit is not None:  # the installation's safety limits, lower than the arm's
        qd_max = np.minimum(qd_max, np.asarray(limit, dtype=float))
    return joint_speeds(ctx.trace, qd_max, exclude=ctx.excluded, everywhere=ctx.everywhere)


@trace_check(
    "URS305", "joint-acceleration-limit", "warning", "joint accelerations",
    summary="A joint accelerates harder than the limit given for the cell.",
    explanation="""
UR publishes no joint acceleration limits, so this check runs only when the user gives one
(urdsl check --joint-acceleration-limit, rad/s², one value or six). It reports the first
move in which a joint accelerates harder, with the joint and the acceleration.""",
    example=f"# urdsl check --joint-acceleration-limit 5\n{_READY}\n"
            "movej([1, -1.9, 1.9, -1.57, -1.57, 0], a=20, v=1)",
    fixed=f"# urdsl check --joint-acceleration-limit 5\n{_READY}\n"
          "movej([1, -1.9, 1.9, -1.57, -1.57, 0], a=4, v=1)",
    applies=lambda options: options.joint_acceleration_limit is not None,
)
def _joint_accelerations(ctx: TraceContext) -> list[Finding]:
    limits = np.broadcast_to(np.asarray(ctx.options.joint_acceleration_limit, float), (6,))
    return joint_accelerations(ctx.trace, limits, exclude=ctx.excluded)


@trace_check(
    "URS306", "tcp-speed-limit", "error", "TCP speed",
    summary="The TCP moves faster than the speed limit set for the cell.",
    explanation="""
A collaborative cell limits the TCP speed in its safety configuration (often 0.25 m/s
where people work); the controller then slows the robot to the limit or stops it ("the robot
controller prevents violations by making a robot stop or by reducing the speed", UR user
manual). This check runs when the limit is given (urdsl check --tcp-speed-limit, m/s, or the
installation of a .urp) and reports each move over it, with its peak TCP speed. On a
movej/movel/movep/movec whose path does not fail it is a warning that the move takes longer
(however far over: a program's TCP speed is bounded, and a running program that Reduced mode
slows from 1 m/s to 0.25 m/s goes on, UR forum topic 944); on servo and speed commands, and
on a path that fails, an error. How the safety system chooses between slowing and stopping
is not documented [U].""",
    example=f"# urdsl check --tcp-speed-limit 0.25 --start-joints {_START}\n"
            "speedl([0, 0, -0.4, 0, 0, 0], a=2.0, t=0.5)  # a speed command: an error\n"
            "stopl(2.0)",
    fixed=f"# urdsl check --tcp-speed-limit 0.25 --start-joints {_START}\n"
          "speedl([0, 0, -0.2, 0, 0, 0], a=2.0, t=0.5)\nstopl(2.0)",
    applies=lambda options: options.tcp_speed_limit is not None,
)
def _tcp_speed(ctx: TraceContext) -> list[Finding]:
    return tcp_speed(ctx.trace, ctx.robot, ctx.options.tcp_speed_limit, ctx.excluded)


@trace_check(
    "URS307", "near-singularity", "warning", "singularities",
    summary="On a TCP path the arm passes close to a shoulder, elbow or wrist singularity.",
    explanation="""
Near a singularity a linear or circular move needs joint speeds that grow without bound:
the wrist centre near the vertical axis through the base (shoulder), the arm stretched out
or folded (elbow), wrist 2 near 0° or 180° so that the wrist 1 and wrist 3 axes line up
(wrist). The controller slows down or stops with "joint speed limit" there. Joint moves
(movej) pass singular poses harmlessly and are not reported. --singularity-scale widens or
narrows the margins.""",
    example="movej([0.3, -1.6, 1.6, -1.57, -0.25, 0])\nb = get_actual_tcp_pose()\n"
            "movej([0.3, -1.6, 1.6, -1.57, 0.25, 0])\nmovel(b)  # wrist 2 passes 0",
    fixed="movej([0.3, -1.6, 1.6, -1.57, -0.25, 0])\nb = get_actual_tcp_pose()\n"
          "movej([0.3, -1.6, 1.6, -1.57, 0.25, 0])\nmovej(get_inverse_kin(b))",
)
def _singularities(ctx: TraceContext) -> list[Finding]:
    return singularities(ctx.trace, ctx.robot, ctx.options.singularity_scale)


@trace_check(
    "URS308", "collision", "error", "collisions",
    summary="The arm hits the cell (floor, boxes, cylinders, planes) or itself.",
    explanation="""
The arm's links (the meshes of the robot description, or capsules around its DH links) are
swept along the planned motion against the obstacles of the cell file (urdsl check --cell
cell.toml) and against each other. The finding names the colliding pair and the overlap.""",
    example=f"# cell.toml: [floor] height = 0.0\n{_READY}\nhome = get_actual_tcp_pose()\n"
            "movel(pose_add(home, p[0, 0, -1.0, 0, 0, 0]))",
    fixed=f"# cell.toml: [floor] height = 0.0\n{_READY}\nhome = get_actual_tcp_pose()\n"
          "movel(pose_add(home, p[0, 0, -0.2, 0, 0, 0]))",
    applies=lambda options: options.cell is not None or options.self_collision,
)
def _collisions(ctx: TraceContext) -> list[Finding]:
    options = ctx.options
    return collisions(ctx.trace, ctx.robot, options.cell, options.collision_step,
                      options.self_collision, ctx.deadline, ctx.partial, ctx.excluded) + \
        safety_planes(ctx.trace, ctx.robot, options.safety_planes, options.collision_step,
                      ctx.excluded)


@trace_check(
    "URS310", "blend-radius-too-large", "warning", "blend radii",
    summary="A blend radius is larger than half of a neighbouring segment.",
    explanation="""
A house rule, stricter than the controller's: when a blend radius is more than half of the
segment before or after it, the blend of the next waypoint may cut it short, and the path
differs from what the radius suggests. (When the blend spheres really overlap the
controller skips the move: that is URS309.)""",
    example=f"{_READY}\nhome = get_actual_tcp_pose()\n"
            "movel(pose_add(home, p[0.2, 0, 0, 0, 0, 0]), r=0.03)\n"
            "movel(pose_add(home, p[0.2, 0.05, 0, 0, 0, 0]), r=0.01)\nmovel(home)",
    fixed=f"{_READY}\nhome = get_actual_tcp_pose()\n"
          "movel(pose_add(home, p[0.2, 0, 0, 0, 0, 0]), r=0.02)\n"
          "movel(pose_add(home, p[0.2, 0.05, 0, 0, 0, 0]), r=0.01)\nmovel(home)",
)
def _blend_radii(ctx: TraceContext) -> list[Finding]:
    return blend_radii(ctx.planner.segments)
