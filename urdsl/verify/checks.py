"""Checks over a sampled trace, one function per rule. Each takes the trace (and what it
needs of the robot model or the cell) and returns findings, at most one per move and rule,
placed at the statement that commanded the move, with its cause (the joint, the
singularity, the colliding pair): the report keeps one finding per statement, rule and
cause, however often a loop runs the statement (:meth:`urdsl.verify.report.Report.sort`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._threads import shared_pool
from ..motion.planner import JOINT_SPACE
from ..motion.trace import Trace
from .findings import Finding

__all__ = ["joint_limits", "joint_speeds", "joint_accelerations", "blend_radii",
           "path_continuity", "tcp_speed", "singularities", "collisions", "Continuity"]

JOINTS = ("base", "shoulder", "elbow", "wrist 1", "wrist 2", "wrist 3")


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


def joint_limits(trace: Trace, lower: np.ndarray, upper: np.ndarray) -> list[Finding]:
    """URS303: joint positions outside [lower, upper] (rad)."""
    low, high = lower - 1e-9, upper + 1e-9
    outside = _rows_where(trace.q, lambda q: (q < low) | (q > high))
    findings = []
    for segment, sample in _per_segment(trace, outside):
        joint = int(np.argmax((trace.q[sample] < low) | (trace.q[sample] > high)))
        value = trace.q[sample, joint]
        bound = upper[joint] if value > upper[joint] else lower[joint]
        findings.append(Finding.of(
            "URS303",
            f"{JOINTS[joint]} joint reaches {np.degrees(value):.1f}° "
            f"(limit {np.degrees(bound):.1f}°) at t={trace.times[sample]:.3f} s",
            _span(trace, segment), float(trace.times[sample]),
            "choose a target closer to the current joints, or another IK solution",
            cause=f"{JOINTS[joint]} {'upper' if value > upper[joint] else 'lower'}"))
    return findings


def joint_speeds(trace: Trace, limits: np.ndarray, exclude: np.ndarray | None = None
                 ) -> list[Finding]:
    """URS304: joint speeds above the model's limits (rad/s); samples in ``exclude`` (jumps
    already reported by :func:`path_continuity`) are left out."""
    bound = limits * (1 + 1e-6)
    over = _rows_where(trace.qd, lambda qd: np.abs(qd) > bound)
    if exclude is not None:
        over &= ~exclude
    findings = []
    for segment, sample in _per_segment(trace, over):
        ratio = np.abs(trace.qd[sample]) / limits
        joint = int(np.argmax(ratio))
        inside = trace.segment == segment
        if exclude is not None:
            inside &= ~exclude
        peak = float(np.max(np.abs(trace.qd[inside, joint])))
        findings.append(Finding.of(
            "URS304",
            f"{JOINTS[joint]} joint turns at {peak:.2f} rad/s, over its limit of "
            f"{limits[joint]:.2f} rad/s",
            _span(trace, segment), float(trace.times[sample]), _speed_hint(trace, segment),
            cause=JOINTS[joint]))
    return findings


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


JUMP_MIN = 0.25
"""Smallest joint step (rad) between two samples that counts as a jump of the IK branch: at
the fastest joint speed of any UR (π rad/s) a joint moves 0.006 rad in a 2 ms step and
0.025 rad in an 8 ms step; a change of branch moves a joint by about π."""


def path_continuity(trace: Trace, speed_limits: np.ndarray) -> Continuity:
    """URS302: a TCP path (movel/movep/movec) that leaves the workspace between reachable
    ends, or whose joints jump because inverse kinematics must change its branch."""
    count = len(trace.times)
    flagged = np.zeros(count, dtype=bool)
    findings = []
    threshold = np.maximum(JUMP_MIN, 10.0 * speed_limits * trace.dt)
    jumps = np.zeros(count, dtype=bool)
    block = 32768

    def rows(start: int) -> None:  # a step from the sample before over the threshold
        stop = min(start + block, count - 1)
        step = np.abs(trace.q[start + 1:stop + 1] - trace.q[start:stop])
        (step > threshold).any(axis=1, out=jumps[start + 1:stop + 1])

    list(shared_pool().map(rows, range(0, count - 1, block)))
    reported: set[int] = set()
    for segment, sample in _per_segment(trace, trace.unreachable):
        reported.add(segment)
        move = trace.segments[segment]
        inside = np.flatnonzero(trace.unreachable & (trace.segment == segment))
        fraction = (trace.times[inside] - move.start) / max(move.duration, 1e-12)
        findings.append(Finding.of(
            "URS302",
            f"the {move.kind} path leaves the robot's workspace between "
            f"{100 * fraction.min():.0f}% and {100 * fraction.max():.0f}% of the way "
            f"(t={trace.times[sample]:.3f} s), although both ends are reachable",
            _span(trace, segment), float(trace.times[sample]),
            "go round the unreachable region with a waypoint, or use movej", cause="reach"))
    for segment, sample in _per_segment(trace, jumps):
        if segment in reported or segment < 0:
            continue
        move = trace.segments[segment]
        step = np.abs(trace.q[sample] - trace.q[sample - 1])
        joint = int(np.argmax(step / threshold))
        findings.append(Finding.of(
            "URS302",
            f"the {move.kind} path needs a change of IK solution: the {JOINTS[joint]} joint "
            f"jumps by {np.degrees(step[joint]):.0f}° at "
            f"t={trace.times[sample]:.3f} s, which the robot cannot do on a straight line",
            _span(trace, segment), float(trace.times[sample]),
            "split the move, or reach the end with movej", cause=f"jump {JOINTS[joint]}"))
    bad = jumps | trace.unreachable
    for shift in (-2, -1, 1, 2):  # central differences spread a jump to the neighbours
        flagged |= np.roll(bad, shift)
    flagged |= bad
    return Continuity(findings, flagged)


def _tcp_positions(trace: Trace, robot, stride: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """TCP positions (M, 3) in m for every ``stride``-th sample, with the sample indices;
    each sample uses the TCP that was active for its move."""
    from ..motion.trace import tcp_groups

    index = np.arange(0, len(trace.times), stride)
    positions = np.empty((len(index), 3))
    group_of_move, tcps = tcp_groups(trace.segments)
    # samples at rest before the first move (-1) use the first move's TCP
    group = np.append(group_of_move, group_of_move[:1])[trace.segment[index]]
    for number in np.unique(group):
        rows = group == number
        positions[rows] = robot.fk_many(trace.q[index[rows]], tcp=tcps[number])[:, :3, 3]
    return positions, index


def tcp_speed(trace: Trace, robot, limit: float) -> list[Finding]:
    """URS306: the TCP moves faster than the user's limit (m/s), e.g. 0.25 m/s in a
    collaborative cell."""
    positions, _ = _tcp_positions(trace, robot)
    speed = np.linalg.norm(np.gradient(positions, trace.dt, axis=0), axis=1) \
        if len(positions) > 1 else np.zeros(len(positions))
    findings = []
    for segment, sample in _per_segment(trace, speed > limit * (1 + 1e-6)):
        peak = float(np.max(speed[trace.segment == segment]))
        findings.append(Finding.of(
            "URS306", f"the TCP moves at {peak:.3f} m/s, over the cell's limit of {limit:g} m/s",
            _span(trace, segment), float(trace.times[sample]), _speed_hint(trace, segment),
            cause="tcp"))
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


def collisions(trace: Trace, robot, cell, step: float = 0.02,
               self_collision: bool = True) -> list[Finding]:
    """URS308: the arm hits the cell's obstacles (floor, boxes, cylinders, planes) or itself,
    checked every ``step`` s of robot time while it moves, or further apart where it cannot
    come into contact in between (see :meth:`CollisionModel.sweep`). ``cell`` is a path of a
    cell TOML or a ready :class:`urdsl.kinematics.collision.CollisionModel` (None: no
    obstacles)."""
    if cell is None and not self_collision:
        return []
    from ..kinematics.collision import CollisionModel

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
    index, result = model.sweep(trace.q[moving[0]:], tcp=tcp, stride=stride)
    index += moving[0]
    hit = np.zeros(len(trace.times), dtype=bool)
    hit[index] = result.colliding
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
            "move around the obstacle with an extra waypoint", cause=what))
    return findings
