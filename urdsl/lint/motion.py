"""Rules about moves: joint vectors of the wrong length, degrees written where radians are
expected, speeds and accelerations beyond the arm's limits, blends that cannot happen."""

from __future__ import annotations

import math
from collections.abc import Iterator

from ..script import nodes as n
from ..script.diagnostics import Diagnostic
from .context import BLOCKING_CALLS, MOTION_CALLS, LintContext
from .registry import rule
from .scope import Scope

# Parameters that take joint positions [rad] (6 values) when given a list.
_JOINT_POSITIONS: dict[str, tuple[str, ...]] = {
    "movej": ("q",), "servoj": ("q",), "set_pos": ("q",), "get_forward_kin": ("q",),
    "get_inverse_kin": ("qnear",), "get_inverse_kin_has_solution": ("qnear",),
    "get_jacobian": ("q",), "get_jacobian_time_derivative": ("q",), "get_mass_matrix": ("q",),
    "get_coriolis_and_centrifugal_torques": ("q",), "reset_revolution_counter": ("qNear",),
    # Moves whose target is a pose also accept joint positions (then forward kinematics).
    "movel": ("pose",), "movep": ("pose",), "movec": ("pose_via", "pose_to"),
    "optimovej": ("goal",), "optimovel": ("goal",),
}
# Parameters that take one value per joint that is not a position.
_JOINT_OTHER: dict[str, tuple[str, ...]] = {
    "speedj": ("qd",), "direct_torque": ("torques",),
    "get_jacobian_time_derivative": ("qd",), "get_coriolis_and_centrifugal_torques": ("qd",),
}

_TWO_PI = 2.0 * math.pi

# Bounds that client libraries enforce before they send a move (ur_rtde's rtde_control.h:
# joint acceleration 40 rad/s², tool speed 3 m/s, tool acceleration 150 m/s²). Joint speed
# uses the model's own limit (urdsl.kinematics.MODELS[...].qd_max).
_JOINT_ACCELERATION_MAX = 40.0  # rad/s²
_TOOL_SPEED_MAX = 3.0  # m/s
_TOOL_ACCELERATION_MAX = 150.0  # m/s²

_JOINT_SPACE = {"movej", "optimovej"}
_TOOL_SPACE = {"movel", "movep", "movec", "optimovel", "servoc"}


def _joint_lists(ctx: LintContext, table: dict[str, tuple[str, ...]]
                 ) -> Iterator[tuple[str, n.Call, n.Expr, n.Expr]]:
    """``(function, call, argument, literal)`` for every joint-vector argument written as a
    list, directly or through a name assigned a list once."""
    for _scope, call in ctx.calls():
        name = call.func.id  # type: ignore[union-attr]
        if name not in table or ctx.builtin(call) is None:
            continue
        for param in table[name]:
            argument = ctx.builtin_argument(call, param)
            if argument is None:
                continue
            literal = ctx.literal(argument)
            if isinstance(literal, n.List):
                yield name, call, argument, literal


def _via(argument: n.Expr, literal: n.Expr) -> str:
    if argument is literal or isinstance(argument, n.Paren):
        return ""
    return f" ('{getattr(argument, 'id', '?')}' is assigned at line {literal.span.line})"


@rule(
    "URS108", "joint-vector-length", "error",
    "A list of joint values that does not have 6 elements (one per joint).",
    """
Every UR arm has six joints: base, shoulder, elbow, wrist 1, 2 and 3. movej, servoj,
speedj, get_forward_kin and the moves given joint positions need six values, or the
program stops with a runtime error. Lists assigned to a variable once and passed by name are
checked too.""",
    "movej([d2r(0), d2r(-90), d2r(0), d2r(-90), d2r(0)])",
    "movej([d2r(0), d2r(-90), d2r(0), d2r(-90), d2r(0), d2r(0)])",
)
def joint_vector_length(ctx: LintContext) -> Iterator[Diagnostic]:
    seen: set[int] = set()
    for table in (_JOINT_POSITIONS, _JOINT_OTHER):
        for name, _call, argument, literal in _joint_lists(ctx, table):
            count = len(literal.items)  # type: ignore[attr-defined]
            if count == 6 or id(argument) in seen:
                continue
            if count and all(isinstance(item, n.List) for item in literal.items):  # type: ignore[attr-defined]
                continue  # a matrix (a batch of joint vectors): not ours to judge
            seen.add(id(argument))
            yield ctx.diagnostic(
                "URS108", argument, f"{name}() needs 6 joint values, this list has {count}"
                f"{_via(argument, literal)}",
                "one value per joint: base, shoulder, elbow, wrist 1, wrist 2, wrist 3")


@rule(
    "URS109", "degrees-for-radians", "warning",
    "Angles that look like degrees where URScript expects radians.",
    """
URScript angles are radians. A joint position beyond ±2π (±360°, the joint range of every UR
arm) or a rotation-vector component beyond 2π in a pose literal was almost certainly written
in degrees: `movej([0, -90, 0, -90, 0, 0])` asks the shoulder for -90 rad, 14 turns.""",
    "movej([0, -90, 0, -90, 0, 0])",
    "movej([0, d2r(-90), 0, d2r(-90), 0, 0])",
)
def degrees_for_radians(ctx: LintContext) -> Iterator[Diagnostic]:
    for name, _call, argument, literal in _joint_lists(ctx, _JOINT_POSITIONS):
        values = [ctx.number(item) for item in literal.items]  # type: ignore[attr-defined]
        big = [v for v in values if v is not None and abs(v) > _TWO_PI + 1e-9]
        if big:
            shown = ", ".join(_short(v) for v in big[:3])
            yield ctx.diagnostic(
                "URS109", argument, f"joint positions of {name}() look like degrees "
                f"({shown} rad is beyond the ±2π joint range){_via(argument, literal)}",
                "write radians, or convert each value with d2r(): d2r(-90)")
    for node in n.walk(ctx.tree):
        if not isinstance(node, n.Pose):
            continue
        values = [ctx.number(item) for item in node.items[3:]]
        big = [v for v in values if v is not None and abs(v) > _TWO_PI + 1e-9]
        if big:
            shown = ", ".join(_short(v) for v in big[:3])
            yield ctx.diagnostic(
                "URS109", node, f"the rotation vector of this pose looks like degrees "
                f"({shown} rad)", "a pose ends with a rotation vector in radians; from "
                "roll-pitch-yaw in degrees use rpy2rotvec([d2r(r), d2r(p), d2r(y)])")


def _short(value: float) -> str:
    return f"{value:g}"


def _model_limit(ctx: LintContext) -> tuple[float, str]:
    """Fastest joint speed [rad/s] of the target model (or of any UR arm) and its name."""
    from ..kinematics.models import MODELS

    if ctx.model is not None:
        spec = ctx.model
        return float(max(spec.qd_max)), spec.name.upper()  # type: ignore[attr-defined]
    fastest = max(MODELS.values(), key=lambda spec: float(max(spec.qd_max)))
    return float(max(fastest.qd_max)), "any UR arm"


@rule(
    "URS110", "beyond-speed-limit", "warning",
    "A speed or acceleration far beyond what the arm can do.",
    """
movej/optimovej `v` is the speed of the leading joint in rad/s: above the model's fastest
joint (`--robot`; by default the fastest UR arm) the controller cannot follow it. speedj
joint speeds are checked per joint. Tool-space moves are checked against the bounds client
libraries enforce (ur_rtde: 3 m/s, 150 m/s²), joint accelerations against 40 rad/s². Such
values are usually degrees or mm written where radians or metres belong.""",
    "movej(q_home, a=1.4, v=180)",
    "movej(q_home, a=1.4, v=d2r(180))",
)
def beyond_speed_limit(ctx: LintContext) -> Iterator[Diagnostic]:
    joint_speed, model = _model_limit(ctx)
    for _scope, call in ctx.calls():
        name = call.func.id  # type: ignore[union-attr]
        if ctx.builtin(call) is None:
            continue
        if name in _JOINT_SPACE or name in _TOOL_SPACE:
            joint = name in _JOINT_SPACE
            checks = (("v", joint_speed if joint else _TOOL_SPEED_MAX,
                       "rad/s" if joint else "m/s",
                       f"the fastest joint of {model}" if joint else "the tool speed "
                       "client libraries allow"),
                      ("a", _JOINT_ACCELERATION_MAX if joint else _TOOL_ACCELERATION_MAX,
                       "rad/s²" if joint else "m/s²", "the acceleration client libraries "
                       "allow"))
            for param, limit, unit, what in checks:
                argument = ctx.builtin_argument(call, param)
                value = None if argument is None else ctx.number(argument)
                if value is not None and value > limit * 1.001:
                    yield ctx.diagnostic(
                        "URS110", argument, f"{name}() {param}={_short(value)} {unit} is "
                        f"beyond {what} ({_short(round(limit, 3))} {unit})",
                        _unit_hint(joint, param))
        elif name == "speedj":
            argument = ctx.builtin_argument(call, "qd")
            literal = None if argument is None else ctx.literal(argument)
            if isinstance(literal, n.List):
                values = [ctx.number(item) for item in literal.items]
                limits = _per_joint_limits(ctx)
                for index, value in enumerate(values[:6]):
                    if value is not None and abs(value) > limits[index] * 1.001:
                        yield ctx.diagnostic(
                            "URS110", literal.items[index], f"speedj() joint {index + 1} "
                            f"speed {_short(value)} rad/s is beyond {model}'s limit "
                            f"({_short(round(limits[index], 3))} rad/s)",
                            _unit_hint(True, "v"))


def _per_joint_limits(ctx: LintContext) -> list[float]:
    from ..kinematics.models import MODELS

    if ctx.model is not None:
        return [float(v) for v in ctx.model.qd_max]  # type: ignore[attr-defined]
    return [max(float(spec.qd_max[i]) for spec in MODELS.values()) for i in range(6)]


def _unit_hint(joint: bool, param: str) -> str:
    if joint:
        return ("joint speeds are rad/s: convert degrees with d2r()" if param == "v"
                else "joint accelerations are rad/s²: convert degrees with d2r()")
    return "tool speeds are m/s and accelerations m/s²: divide millimetres by 1000"


def _is_move(ctx: LintContext, item: n.Node) -> n.Call | None:
    found = ctx.builtin_call(item) if isinstance(item, n.ExprStmt) else None
    if found and found[0] in ("movej", "movel", "movep", "movec", "optimovej", "optimovel"):
        return found[1]
    return None


def _stops(ctx: LintContext, item: n.Node,
           memo: dict[int, tuple[bool, bool]] | None = None) -> str | None:
    """Why ``item`` makes the arm stop before any further move: a statement that takes time
    without moving (sleep, sync, waiting), or halt. None when it may move or takes no time.
    ``memo`` keeps what each loop and ``if`` holds across calls (see :func:`_waits_moves`)."""
    if isinstance(item, n.Halt):
        return "halt"
    if isinstance(item, n.ExprStmt):
        found = ctx.builtin_call(item)
        if found is not None:
            name = found[0]
            if name in BLOCKING_CALLS and name not in MOTION_CALLS:
                return f"{name}()"
            if name in ("stopj", "stopl"):
                return f"{name}()"
    if isinstance(item, n.While):
        waits = moves = False
        for statement in item.body:
            if isinstance(statement, n.Stmt):
                inner_waits, inner_moves = _waits_moves(ctx, statement, memo
                                                        if memo is not None else {})
                waits, moves = waits or inner_waits, moves or inner_moves
        if waits and not moves:
            return "a waiting loop"
    return None


def _waits_moves(ctx: LintContext, node: n.Node, memo: dict[int, tuple[bool, bool]]
                 ) -> tuple[bool, bool]:
    """Whether running ``node`` may wait (sleep, sync) and whether it may move (a move, a
    user function, a method), from every call in it. The answer for each ``while`` and
    ``if`` is kept in ``memo`` (by ``id``): nested loops are read once, not once per loop
    around them (that was quadratic in the nesting depth)."""
    if isinstance(node, (n.While, n.If)) and id(node) in memo:
        return memo[id(node)]
    waits = moves = False
    if isinstance(node, (n.While, n.If)):
        if isinstance(node, n.While):
            tests: list[n.Node] = [node.test]
            blocks = [node.body]
        else:
            tests = [node.test, *(branch.test for branch in node.elifs)]
            blocks = [node.body, *(branch.body for branch in node.elifs)]
            if node.orelse:
                blocks.append(node.orelse)
        parts = [(test, False) for test in tests] + [
            (statement, True) for block in blocks for statement in block
            if isinstance(statement, n.Stmt)]
    else:
        parts = [(node, False)]
    for part, nested in parts:
        if nested:
            inner_waits, inner_moves = _waits_moves(ctx, part, memo)
            waits, moves = waits or inner_waits, moves or inner_moves
            continue
        for inner in n.walk(part):
            if isinstance(inner, n.Call):
                found = ctx.builtin_call(inner)
                if found is None:
                    moves = True  # a user function or a method: it may move
                elif found[0] in ("sleep", "sync"):
                    waits = True
                elif found[0] in MOTION_CALLS:
                    moves = True
    if isinstance(node, (n.While, n.If)):
        memo[id(node)] = (waits, moves)
    return waits, moves


def _executable(items: tuple) -> list[n.Stmt]:
    return [item for item in items if isinstance(item, n.Stmt)
            and not isinstance(item, (n.FunctionDef, n.ThreadDef, n.SecDef))]


@rule(
    "URS111", "blend-without-next-move", "warning",
    "A blend radius on a move after which the arm stops anyway.",
    """
A move with `r > 0` blends into the next move, which the controller must know when the arm
reaches the blend. If the program ends, halts, or waits (sleep, sync, a waiting loop,
stopj) right after the move, there is nothing to blend into: the robot stops at the target
and the radius only misleads. Statements that take no time (assignments, set_*_out, textmsg)
between two blended moves are fine: the controller runs them during the approach.""",
    "movel(p_above, r=0.05)\nsleep(1.0)\nmovel(p_pick)",
    "movel(p_above)\nsleep(1.0)\nmovel(p_pick)",
)
def blend_without_next_move(ctx: LintContext) -> Iterator[Diagnostic]:
    memo: dict[int, tuple[bool, bool]] = {}  # what each loop and if holds (_waits_moves)

    def check_block(items: tuple, tail: str | None, scope: Scope) -> Iterator[Diagnostic]:
        executable = _executable(items)
        for index, item in enumerate(executable):
            if isinstance(item, n.If):
                follow = _follow(executable[index + 1:], tail)
                yield from check_block(item.body, follow, scope)
                for branch in item.elifs:
                    yield from check_block(branch.body, follow, scope)
                if item.orelse:
                    yield from check_block(item.orelse, follow, scope)
            elif isinstance(item, n.While):
                yield from check_block(item.body, None, scope)
            call = _is_move(ctx, item)
            if call is None:
                continue
            radius = ctx.builtin_argument(call, "r")
            value = None if radius is None else ctx.number(radius)
            if not value or value <= 0:
                continue
            reason = _follow(executable[index + 1:], tail)
            if reason is not None:
                yield ctx.diagnostic(
                    "URS111", radius, f"blend radius r={_short(value)} m, but {reason} follows:"
                    " the arm stops at this target", "set r=0 (or leave r out) here")

    def _follow(rest: list[n.Stmt], tail: str | None) -> str | None:
        for item in rest:
            reason = _stops(ctx, item, memo)
            if reason is not None:
                return reason
            if not isinstance(item, (n.Assign, n.Declare)) and not (
                isinstance(item, n.ExprStmt) and isinstance(item.expr, n.Call)
                and ctx.builtin_call(item) and not _is_move(ctx, item)
            ):
                return None  # a move, a user function, a branch: it may move next
        return tail

    top = ctx.analysis.top
    end = "the end of the program" if ctx.analysis.program is not None else None
    yield from check_block(top.body, end, top)
    for scope in ctx.analysis.scopes:
        if scope is not top:
            yield from check_block(scope.body, None, scope)
