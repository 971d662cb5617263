"""What ``urdsl check`` can tell from a PolyScope program about the robot it was taught on.

* **The model.** PolyScope writes each taught waypoint as a pose and joints pair
  (``global Waypoint_1_p=p[...]`` / ``global Waypoint_1_q=[...]``, any name ending in
  ``_p``/``_q``; PolyScope 3.x also inlines them as ``get_inverse_kin(p[...], qnear=[...])``).
  The model whose kinematics maps the joints to the poses is the robot
  (:func:`urdsl.kinematics.identify.identify`).
* **The start joints.** PolyScope makes the arm go to the first move's target before the
  program runs: the joints of the first move's waypoint (its ``_q`` or ``qnear``), or the
  first ``movej``'s joint target. Only for PolyScope programs (waypoint pairs or ``$ N``
  markers): a script sent to the arm starts wherever the arm is.
* **TCP and payload.** The first ``set_tcp``/``set_payload``/``set_target_payload`` with
  constant arguments (the preamble), and the project's ``.installation`` beside the file.

Everything here is read statically from the syntax tree; nothing is run. Command-line
values override (and are then not inferred).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..script import nodes as n
from .checks import EVERY_MODEL
from .run import DEFAULT_START, DRIFT, CheckOptions

__all__ = ["WaypointPair", "Inference", "waypoint_pairs", "static_tcp", "static_tcps",
           "static_payload",
           "first_move_joints", "infer", "apply"]

_MOVES = frozenset({"movej", "movel", "movep", "movec"})


@dataclass(frozen=True)
class WaypointPair:
    """A taught waypoint: ``joints`` (rad) and the TCP ``pose`` (m, rad) PolyScope computed
    from them; ``span`` is where the joints are written."""

    name: str
    joints: tuple[float, ...]
    pose: tuple[float, ...]
    span: n.Span


@dataclass
class Inference:
    """What was inferred (or given) for one program.

    ``robot``: the model checked against; ``robot_source``: ``"given"``, ``"inferred"`` or
    ``"default"``; ``identification``: the fit (``None`` when the robot was given);
    ``start_joints`` (rad) and ``start_source`` (``"given"``, ``"inferred"``, ``"default"``)
    with ``start_from``/``start_span``; ``tcp`` (flange frame, m and rad) and ``tcp_from``;
    ``payload`` (kg, centre of gravity m) and ``payload_from``; ``gravity`` (m/s²) from the
    installation's mounting; ``installation``: its path; ``notes``: other things to tell.
    """

    robot: str
    robot_source: str
    pairs: int = 0
    identification: Any = None
    start_joints: tuple[float, ...] = DEFAULT_START
    start_source: str = "default"
    start_from: str = ""
    start_span: n.Span = n.NO_SPAN
    tcp: tuple[float, ...] | None = None
    tcp_from: str = ""
    payload: tuple[float, tuple[float, ...] | None] | None = None
    payload_from: str = ""
    gravity: tuple[float, float, float] | None = None
    installation: str | None = None
    notes: list[str] = field(default_factory=list)
    polyscope: bool = False  # written by PolyScope (waypoint pairs or `$` labels): taught
    robot_from: str = ""  # where an inferred robot comes from, when not waypoint pairs

    def robot_line(self) -> str:
        """One sentence about the robot model."""
        found = self.identification
        if self.robot_source == "given":
            return f"robot {self.robot} as given"
        if self.robot_from:
            return f"robot {self.robot} from {self.robot_from}"
        if self.robot_source == "inferred":
            share = (f"{found.used} of {found.pairs}" if found.used < found.pairs
                     else str(found.pairs))
            text = (f"robot {self.robot} inferred from {share} waypoint pair(s) (residual "
                    f"{found.residual * 1000:.1f} mm")
            if found.tcp_fitted:
                text += ", with a TCP fitted at " + _pose_text(found.tcp)
            text += ")"
            if found.same_arm:
                text += f"; {', '.join(found.same_arm)} is the same arm"
            return text
        reason = found.reason if found is not None else "no taught waypoint pairs"
        return f"robot {self.robot} by default, not inferred: {reason}"

    def start_line(self) -> str:
        """One sentence about the start joints."""
        if self.start_source == "given":
            return "start joints as given"
        if self.start_source == "inferred":
            where = f" (line {self.start_span.line})" if self.start_span.source else ""
            return f"start joints from {self.start_from}{where}"
        why = self.start_from or "no taught target of a first move found"
        return f"start joints by default ({why})"

    def lines(self) -> list[str]:
        """Everything inferred, one sentence each."""
        out = [self.robot_line() + "; " + self.start_line()]
        if self.tcp is not None and self.tcp_from:
            out.append(f"TCP {_pose_text(self.tcp)} from {self.tcp_from}")
        if self.payload is not None:
            mass, cog = self.payload
            text = f"payload {mass:g} kg"
            if cog is not None:
                text += " at (" + ", ".join(f"{v:g}" for v in cog) + ") m"
            out.append(f"{text} from {self.payload_from}")
        if self.gravity is not None:
            out.append("gravity (" + ", ".join(f"{v:.3g}" for v in self.gravity)
                       + ") m/s² from the installation's mounting")
        out.extend(self.notes)
        return out

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (lengths in m, angles in rad)."""
        found = self.identification
        robot: dict[str, Any] = {"model": self.robot, "source": self.robot_source,
                                 "pairs": self.pairs}
        if found is not None:
            if found.model is not None:
                robot.update(used=found.used, residual=round(found.residual, 6),
                             rotation_residual=round(found.rotation_residual, 6),
                             same_arm=list(found.same_arm), tcp_fitted=found.tcp_fitted)
                if found.tcp_fitted:
                    robot["tcp"] = [round(v, 6) for v in found.tcp]
            if found.runner_up is not None:
                robot["runner_up"] = {"model": found.runner_up[0],
                                      "residual": round(found.runner_up[1], 6)}
            if found.reason and not self.robot_from:
                robot["reason"] = found.reason
        if self.robot_from:
            robot["from"] = self.robot_from
        start: dict[str, Any] = {"joints": [round(v, 9) for v in self.start_joints],
                                 "source": self.start_source}
        if self.start_from and self.start_source == "inferred":
            start["from"] = self.start_from
            if self.start_span.source:
                start["line"] = self.start_span.line
        out: dict[str, Any] = {"robot": robot, "start": start, "text": self.lines()}
        if self.tcp is not None:
            out["tcp"] = {"pose": [round(v, 9) for v in self.tcp], "from": self.tcp_from}
        if self.payload is not None:
            out["payload"] = {"mass": self.payload[0], "from": self.payload_from,
                              "cog": list(self.payload[1]) if self.payload[1] else None}
        if self.gravity is not None:
            out["gravity"] = [round(v, 9) for v in self.gravity]
        if self.installation:
            out["installation"] = self.installation
        return out


def _pose_text(values) -> str:
    return "p[" + ", ".join(f"{v:.4g}" for v in values) + "]"


# ---- reading constants ---------------------------------------------------------------------


def _number(expr: n.Expr) -> float | None:
    while isinstance(expr, n.Paren):
        expr = expr.expr
    if isinstance(expr, n.Number):
        return float(expr.value)
    if isinstance(expr, n.UnaryOp) and expr.op in ("-", "+"):
        value = _number(expr.operand)
        if value is not None:
            return -value if expr.op == "-" else value
    return None


def _vector(expr: n.Expr | None, kind: type, count: int) -> tuple[float, ...] | None:
    """The numbers of a constant ``p[...]`` (kind Pose) or ``[...]`` (kind List)."""
    while isinstance(expr, n.Paren):
        expr = expr.expr
    if not isinstance(expr, kind) or len(expr.items) != count:  # type: ignore[attr-defined]
        return None
    values = [_number(item) for item in expr.items]  # type: ignore[attr-defined]
    if any(v is None or not math.isfinite(v) for v in values):
        return None
    return tuple(values)  # type: ignore[arg-type]


def _constants(module: n.Module) -> dict[str, tuple[n.Expr, n.Span]]:
    """Each name's first assignment (``global x = ...`` or ``x = ...``) anywhere."""
    found: dict[str, tuple[n.Expr, n.Span]] = {}
    for node in n.walk(module):
        if isinstance(node, n.Declare) and node.value is not None:
            found.setdefault(node.name, (node.value, node.span))
        elif isinstance(node, n.Assign) and isinstance(node.target, n.Name):
            found.setdefault(node.target.id, (node.value, node.span))
    return found


def _call_name(node: n.Node) -> str | None:
    if isinstance(node, n.Call) and isinstance(node.func, n.Name):
        return node.func.id
    return None


def _argument(call: n.Call, index: int, keyword: str) -> n.Expr | None:
    for item in call.keywords:
        if item.name == keyword:
            return item.value
    return call.args[index] if len(call.args) > index else None


def waypoint_pairs(module: n.Module) -> list[WaypointPair]:
    """Every taught waypoint of a program with both its joints and its pose, in source order:
    ``NAME_p``/``NAME_q`` constants and ``get_inverse_kin(p[...], qnear=[...])`` with literal
    arguments. A pose without joints (some CB3 waypoints) is skipped."""
    constants = _constants(module)
    pairs: list[WaypointPair] = []
    seen: set[tuple] = set()
    for name, (value, span) in constants.items():
        if not name.endswith("_q"):
            continue
        joints = _vector(value, n.List, 6)
        pose_entry = constants.get(name[:-2] + "_p")
        pose = _vector(pose_entry[0], n.Pose, 6) if pose_entry else None
        if joints is not None and pose is not None and (joints, pose) not in seen:
            seen.add((joints, pose))
            pairs.append(WaypointPair(name[:-2], joints, pose, span))
    for node in n.walk(module):
        if _call_name(node) != "get_inverse_kin":
            continue
        assert isinstance(node, n.Call)
        pose = _vector(_argument(node, 0, "x"), n.Pose, 6)
        near = _argument(node, 1, "qnear")
        joints = _vector(near, n.List, 6)
        if pose is not None and joints is not None and (joints, pose) not in seen:
            seen.add((joints, pose))
            pairs.append(WaypointPair(f"get_inverse_kin at line {node.span.line}", joints,
                                      pose, node.span))
    pairs.sort(key=lambda pair: pair.span.start)
    return pairs


def _first_call(module: n.Module, names: set[str]) -> n.Call | None:
    for node in n.walk(module):
        if _call_name(node) in names:
            return node  # type: ignore[return-value]
    return None


def static_tcps(module: n.Module) -> list[tuple[tuple[float, ...], n.Span]]:
    """Every ``set_tcp`` whose pose is a constant (a literal or a name bound to one), in
    source order, each pose once."""
    constants = _constants(module)
    found: dict[tuple[float, ...], n.Span] = {}
    for node in n.walk(module):
        if _call_name(node) != "set_tcp":
            continue
        assert isinstance(node, n.Call)
        arg = _argument(node, 0, "pose")
        if isinstance(arg, n.Name) and arg.id in constants:
            arg = constants[arg.id][0]
        pose = _vector(arg, n.Pose, 6)
        if pose is not None:
            found.setdefault(pose, node.span)
    return list(found.items())


def static_tcp(module: n.Module) -> tuple[tuple[float, ...], n.Span] | None:
    """The first ``set_tcp`` whose pose is a constant (the preamble's, in an export)."""
    tcps = static_tcps(module)
    return tcps[0] if tcps else None


def static_payload(module: n.Module
                   ) -> tuple[float, tuple[float, ...] | None, n.Span, str] | None:
    """The first ``set_payload``/``set_target_payload``/``set_payload_mass`` with a constant
    mass (kg): the mass, the constant centre of gravity (m) if given, where, and which call."""
    for node in n.walk(module):
        name = _call_name(node)
        if name not in ("set_payload", "set_target_payload", "set_payload_mass"):
            continue
        assert isinstance(node, n.Call)
        mass_expr = _argument(node, 0, "m")
        mass = _number(mass_expr) if mass_expr is not None else None
        if mass is None:
            continue
        cog = _vector(_argument(node, 1, "cog"), n.List, 3) if name != "set_payload_mass" \
            else None
        return mass, cog, node.span, name
    return None


# ---- the first move ------------------------------------------------------------------------


def _program_body(module: n.Module) -> tuple[n.Item, ...]:
    """The statements that run first: the body of the program's ``def`` when the file is one
    definition (PolyScope's export) or calls one at top level, else the top level."""
    defs = [s for s in module.body if isinstance(s, n.FunctionDef)]
    others = [s for s in module.body if isinstance(s, n.Stmt)
              and not isinstance(s, (n.FunctionDef, n.ThreadDef, n.SecDef))]
    if len(defs) == 1 and not others:
        return defs[0].body
    return module.body


def _moves(body, functions: dict[str, n.Node], depth: int = 0):
    """Move calls in the order the program reaches them: nested blocks in source order, the
    bodies of user functions it calls and of threads it runs (PolyScope 5 runs an If's body
    as a thread), not the definitions it passes."""
    for item in body:
        if isinstance(item, (n.FunctionDef, n.ThreadDef, n.SecDef)):
            continue
        if isinstance(item, n.If):
            blocks = [item.body] + [e.body for e in item.elifs] + [item.orelse or ()]
            for block in blocks:
                yield from _moves(block, functions, depth)
            continue
        if isinstance(item, n.While):
            yield from _moves(item.body, functions, depth)
            continue
        if not isinstance(item, n.Stmt):
            continue
        for node in n.walk(item):
            name = node.thread if isinstance(node, n.Run) else _call_name(node)
            if name in _MOVES:
                yield node
            elif name in functions and depth < 8:
                yield from _moves(functions[name].body, functions,  # type: ignore[attr-defined]
                                  depth + 1)


def first_move_joints(module: n.Module) -> tuple[tuple[float, ...], str, n.Span] | None:
    """The joints (rad) the arm is at when the program starts: the target of its first move
    as taught, with a description and where the joints are written; ``None`` if unknown."""
    constants = _constants(module)
    functions: dict[str, n.Node] = {
        node.name: node for node in n.walk(module)
        if isinstance(node, (n.FunctionDef, n.ThreadDef))}
    for call in _moves(_program_body(module), functions):
        assert isinstance(call, n.Call)
        target = _argument(call, 1 if call.func.id == "movec" else 0,  # type: ignore[attr-defined]
                           "pose_to" if call.func.id == "movec" else "q")  # type: ignore
        return _target_joints(target, constants) if target is not None else None
    return None


_WRAPPERS = frozenset({"get_inverse_kin", "pose_trans", "pose_add"})
"""Calls PolyScope wraps a waypoint in (a feature-relative or IK-solved target)."""


def _joints_ok(joints: tuple[float, ...] | None) -> tuple[float, ...] | None:
    """Joint positions within the controller's ±2π, else ``None`` (degrees, a sentinel)."""
    if joints is None or any(abs(v) > 2.0 * math.pi + 1e-6 for v in joints):
        return None
    return joints


def _target_joints(target: n.Expr, constants) -> tuple[tuple[float, ...], str, n.Span] | None:
    """The taught joints of a move's target as PolyScope writes it: a joint list, a
    ``NAME_q``/``NAME_p`` waypoint, ``get_inverse_kin(.., qnear=..)`` or a waypoint inside
    ``pose_trans``/``pose_add`` (feature-relative). Anything else (a computed target, a
    variable waypoint) is unknown."""
    while isinstance(target, n.Paren):
        target = target.expr
    joints = _joints_ok(_vector(target, n.List, 6))
    if joints is not None:
        return joints, "the first move's joint target", target.span
    if _call_name(target) == "get_inverse_kin":
        assert isinstance(target, n.Call)
        near = _argument(target, 1, "qnear")
        joints = _joints_ok(_vector(near, n.List, 6))
        if joints is not None:
            return joints, "the first move's qnear", near.span  # type: ignore[union-attr]
        if near is not None:
            found = _target_joints(near, constants)
            if found is not None:
                return found
    if _call_name(target) in _WRAPPERS:
        assert isinstance(target, n.Call)
        for arg in reversed(target.args):       # the waypoint comes after the feature
            found = _target_joints(arg, constants)
            if found is not None:
                return found
        return None
    if isinstance(target, n.Name) and target.id.endswith(("_q", "_p")):
        key = target.id[:-2] + "_q"
        if key in constants:
            value, span = constants[key]
            joints = _joints_ok(_vector(value, n.List, 6))
            if joints is not None:
                return joints, key, span
    return None


# ---- putting it together -------------------------------------------------------------------


def infer(module: n.Module, filename: str | None = None, *, robot: str | None = None,
          start_joints: tuple[float, ...] | None = None, tcp: tuple[float, ...] | None = None,
          default_robot: str = "ur5e", installation: bool = True) -> Inference:
    """Infer the robot, start joints, TCP and payload of a parsed program.

    ``robot``, ``start_joints``, ``tcp``: given on the command line (then not inferred);
    ``filename``: the program's path, whose folder is searched for an ``.installation``
    (``installation=False`` skips that). A corrupt installation becomes a note, not an error.
    """
    from ..kinematics.identify import identify
    from ..polyscope.installation import InstallationError, find_installation, read_installation

    notes: list[str] = []
    setup = None
    if installation and filename and Path(filename).is_file():
        path = find_installation(filename)
        if path is not None:
            try:
                setup = read_installation(path)
            except InstallationError as error:
                notes.append(f"installation not used: {error}")

    # the TCP at the start: the flag, the preamble, the installation's active TCP
    fit_tcp = tcp
    tcp_from = "--tcp" if tcp is not None else ""
    program_tcps = static_tcps(module)
    if fit_tcp is None:
        if program_tcps:
            fit_tcp, span = program_tcps[0]
            tcp_from = f"set_tcp at line {span.line}"
        elif setup is not None and setup.tcp is not None:
            fit_tcp = setup.tcp.offset
            tcp_from = f"TCP {setup.tcp.name!r} of {Path(setup.path).name}"
    # the waypoints may have been taught with any TCP the program or installation names
    candidates = [fit_tcp] if fit_tcp is not None else []
    candidates += [pose for pose, _ in program_tcps]
    candidates += [t.offset for t in setup.tcps] if setup is not None else []
    candidates.append((0.0,) * 6)
    candidates = list(dict.fromkeys(tuple(float(v) for v in c) for c in candidates))
    result = Inference(robot=(robot or default_robot), robot_source="given" if robot
                       else "default", tcp=fit_tcp, tcp_from=tcp_from)
    if setup is not None:
        result.installation = setup.path
        result.gravity = setup.gravity
    payload = static_payload(module)
    if payload is not None:
        result.payload = (payload[0], payload[1])
        result.payload_from = f"{payload[3]} at line {payload[2].line}"
    elif setup is not None and setup.payload is not None:
        result.payload = (setup.payload.mass, setup.payload.cog)
        result.payload_from = Path(setup.path).name

    pairs = waypoint_pairs(module)
    result.pairs = len(pairs)
    if robot is None:
        found = identify([p.joints for p in pairs], [p.pose for p in pairs], candidates)
        result.identification = found
        if found.model is not None:
            result.robot = found.model
            result.robot_source = "inferred"
    result.polyscope = bool(pairs) or any(isinstance(node, n.Marker) for node in n.walk(module))
    if start_joints is not None:
        result.start_joints, result.start_source = tuple(start_joints), "given"
    elif not result.polyscope:
        result.start_from = "not a PolyScope program"
    else:
        first = first_move_joints(module)
        if first is not None:
            result.start_joints, result.start_from, result.start_span = first
            result.start_source = "inferred"
    result.notes = notes
    return result


MODEL_DEPENDENT = frozenset({"URS301", "URS302", "URS303", "URS304", "URS305", "URS308"})
"""Checks whose verdict depends on the arm's kinematics (reach, joint solutions, speeds,
links), so on which UR model the program runs."""

def qualify(report, inference: Inference) -> None:
    """When neither ``--robot`` nor the program's taught waypoints say which arm it runs on,
    findings that hold only for the assumed model (``MODEL_DEPENDENT``) are not certain: they
    become warnings that say so (a program written for a UR10 is not wrong because a UR5e
    cannot reach its poses). A target that no UR model reaches (farther from the shoulder
    than the longest arm's reach plus the TCP), and a path that none can follow
    (:data:`urdsl.verify.checks.EVERY_MODEL`), stay errors."""
    if inference.robot_source != "default":
        return
    why = ("the robot this program was taught on is not known" if inference.polyscope
           else "the program does not say which arm it runs on")
    from ..kinematics import MODELS

    tcp_length = float(np.linalg.norm(inference.tcp[:3])) if inference.tcp else 0.0
    qualified = []
    for finding in report.findings:
        if finding.cause == DRIFT or (finding.cause or "").endswith(EVERY_MODEL):
            qualified.append(finding)  # judged on every UR model already
            continue
        if finding.severity == "error" and finding.code in MODEL_DEPENDENT:
            beyond = finding.beyond if finding.code == "URS301" else None
            if beyond is not None:
                point = np.array(beyond[0])
                reachable = any(
                    np.linalg.norm(point - (0.0, 0.0, spec.d1)) <= spec.reach + tcp_length
                    for spec in MODELS.values())
                if not reachable:
                    qualified.append(finding)
                    continue
            finding = replace(
                finding, severity="warning",
                message=f"{finding.message} (on the assumed {inference.robot}: {why})",
                hint="give the robot with --robot MODEL to make this certain")
        qualified.append(finding)
    report.findings = qualified


def qualify_report(report, inference: Inference, calibrated: bool) -> None:
    """What the check of a script or a ``.urp`` assumed, said in its findings' severities:
    :func:`qualify` (the model assumed), and unless the check ran on the arm's own
    calibration (``calibrated``), :func:`within_nominal_accuracy`."""
    qualify(report, inference)
    if not calibrated:
        within_nominal_accuracy(report)


def within_nominal_accuracy(report) -> None:
    """Errors that a target is out of reach (URS301) by less than
    :data:`~urdsl.kinematics.models.NOMINAL_ACCURACY`,
    on the nominal model (not the arm's calibration), become warnings that say so: a
    waypoint taught with the arm stretched out is where the arm was, a fraction of a
    millimetre beyond the nominal reach. Farther out stays an error."""
    from ..kinematics.models import NOMINAL_ACCURACY

    kept = []
    for finding in report.findings:
        if finding.severity == "error" and finding.code == "URS301":
            if finding.beyond is not None and finding.beyond[1] < NOMINAL_ACCURACY:
                finding = replace(
                    finding, severity="warning",
                    message=f"{finding.message}, within the {NOMINAL_ACCURACY * 1000:g} mm by "
                    "which a real arm differs from the nominal model: the arm's calibration "
                    "decides (the check stopped at this move)",
                    hint="check on the arm's calibration: urdsl check the PolyScope program "
                    "(.urp) beside this file")
        kept.append(finding)
    report.findings = kept


def apply(options: CheckOptions, inference: Inference, tcp_given: bool) -> CheckOptions:
    """``options`` with the inferred robot and start joints (and the installation's TCP as the
    TCP before the program sets one, unless ``--tcp`` was given)."""
    changes: dict[str, Any] = {"robot": inference.robot,
                               "robot_assumed": inference.robot_source == "default",
                               "start_joints": inference.start_joints,
                               "start_unknown": inference.start_source == "default"}
    if not tcp_given and inference.tcp is not None and inference.tcp_from.startswith("TCP "):
        changes["tcp"] = inference.tcp
    return replace(options, **changes)
