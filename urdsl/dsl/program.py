"""The :class:`Program` builder: Python calls that append URScript statements to a tree.

Every method builds syntax-tree nodes (:mod:`urdsl.script.nodes`), never text; the program's
text is the one printer's output of :meth:`Program.tree`. Each statement carries a span into
the user's Python file (the line that built it), so the verifier reports its findings there.

Motion methods take the controller's parameter names and defaults; a keyword left out is left
out of the URScript too (the controller's default applies). Arguments are checked where the
user's line calls them: six finite joint angles in rad, non-negative ``a``, ``v``, ``t``,
``r``, a blend radius in metres.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from contextlib import contextmanager

from ..script import nodes as n
from ..script.binder import Signature, first_problem
from ..script.builtins import lookup
from ..script.printer import format as format_tree
from .errors import DslError, caller
from .values import Expr, Joints, Pose, to_node

__all__ = ["Program", "Function", "Thread"]

_MAX_BLEND = 2.0
"""A blend radius above this (m) is beyond every UR's reach: surely millimetres or degrees."""


def _span():
    location = caller()
    return location.span() if location is not None else n.NO_SPAN


def _number(value, name: str, what: str = "") -> None:
    """Check a numeric argument the user gave (expressions are checked by the robot)."""
    if isinstance(value, Expr):
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DslError(f"{name} must be a number, not {type(value).__name__}")
    if not math.isfinite(value):
        raise DslError(f"{name} must be finite, got {value}")
    if value < 0:
        raise DslError(f"{name} must not be negative, got {value:g}{what}")


def _joints(value, what: str, pose_ok: bool = False) -> object:
    """A joint target: Joints, six numbers (checked like Joints), or an expression; a Pose
    only where the controller solves it (``movej``)."""
    if isinstance(value, (Expr, Joints)):
        return value
    if isinstance(value, Pose):
        if pose_ok:
            return value
        raise DslError(f"{what} needs joint angles, not a Pose",
                       "only movej solves a pose by inverse kinematics; for a straight line "
                       "use movel")
    if isinstance(value, (list, tuple)):
        if len(value) != 6:
            raise DslError(f"{what} needs 6 joint angles, got {len(value)}",
                           "a joint vector is [base, shoulder, elbow, wrist1, wrist2, wrist3] "
                           "in rad")
        if any(isinstance(v, Expr) for v in value):
            return value
        return Joints(*value)
    raise DslError(f"{what} needs Joints, a Pose or six numbers, not {type(value).__name__}")


def _pose(value, what: str) -> object:
    if isinstance(value, (Pose, Expr, Joints)):
        return value
    if isinstance(value, (list, tuple)):
        raise DslError(f"{what} needs a Pose (x, y, z in m, rotation vector in rad), not a "
                       f"{type(value).__name__}",
                       "write Pose(x, y, z, rx, ry, rz); a list of six numbers would be joints")
    raise DslError(f"{what} needs a Pose, not {type(value).__name__}")


_STAMPED = (n.Name, n.Call, n.Index, n.Attribute, n.BinOp, n.UnaryOp)


def _stamp(node: n.Expr, span: n.Span) -> n.Expr:
    """``node`` with the statement's span on its operations and names that have none, so
    that a runtime error inside an expression built with operators names the user's line."""
    if span is n.NO_SPAN or not isinstance(node, _STAMPED + (n.Paren, n.List, n.Pose)):
        return node
    changes = {}
    for field in node.__dataclass_fields__:
        value = getattr(node, field)
        if isinstance(value, n.Expr):
            stamped = _stamp(value, span)
        elif isinstance(value, tuple) and value and isinstance(value[0], n.Node):
            stamped = tuple(_stamp(v, span) if isinstance(v, n.Expr) else v for v in value)
        else:
            continue
        if stamped is not value:
            changes[field] = stamped
    if isinstance(node, _STAMPED) and node.span is n.NO_SPAN:
        changes["span"] = span
    return dataclasses.replace(node, **changes) if changes else node


class _Block:
    """Statements being collected for one body."""

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self.items: list[n.Item] = []


class Function:
    """A user function of the program: ``f(args)`` is a call expression, ``f.call(args)``
    appends it as a statement; ``f.p`` (or ``f["p"]``) is parameter ``p`` inside the body."""

    def __init__(self, program: Program, name: str, params: tuple[str, ...]) -> None:
        self._program = program
        self.name = name
        self.params = params

    def __getattr__(self, name: str) -> Expr:
        if name in self.params:
            return Expr(n.Name(name))
        raise AttributeError(f"function {self.name} has no parameter {name!r}")

    def __getitem__(self, name: str) -> Expr:
        return self.__getattr__(name)

    def __call__(self, *args, **keywords) -> Expr:
        return Expr(_call(self.name, args, keywords))

    def call(self, *args, **keywords) -> None:
        span = _span()
        self._program._append(n.ExprStmt(_call(self.name, args, keywords, span), span))


class Thread:
    """A thread of the program; ``program.run(thread)`` starts it."""

    def __init__(self, name: str) -> None:
        self.name = name


def _call(name: str, args: tuple, keywords: dict, span: n.Span = n.NO_SPAN) -> n.Call:
    return n.Call(n.Name(name, span), tuple(to_node(a) for a in args),
                  tuple(n.Keyword(k, to_node(v)) for k, v in keywords.items()), span)


class Program:
    """A URScript program built from Python: ``Program("pick")`` prints as
    ``def pick(): ... end``, which the controller runs when it receives it."""

    def __init__(self, name: str = "program") -> None:
        if not name.isidentifier():
            raise DslError(f"{name!r} is not a URScript name")
        self.name = name
        self._blocks: list[_Block] = [_Block("def")]
        self._functions: dict[str, Signature] = {}
        self._threads: set[str] = set()
        self._variables: set[str] = set()
        self._span = _span()

    # ---- output ----------------------------------------------------------------------------

    def tree(self) -> n.Module:
        """The program as a syntax tree (a module holding one ``def``)."""
        if len(self._blocks) != 1:
            raise DslError(f"the {self._blocks[-1].kind} block is still open")
        body = tuple(self._blocks[0].items)
        return n.Module((n.FunctionDef(self.name, (), body, self._span),), self._span)

    def script(self, indent: str = "  ") -> str:
        """The URScript text: the printer's output of :meth:`tree`."""
        return format_tree(self.tree(), indent=indent)

    def __str__(self) -> str:
        return self.script()

    # ---- plumbing --------------------------------------------------------------------------

    def _append(self, item: n.Item) -> None:
        self._blocks[-1].items.append(item)

    def _statement_call(self, name: str, args: tuple, keywords: dict) -> None:
        span = _span()
        self._append(n.ExprStmt(_call(name, args, keywords, span), span))

    @staticmethod
    def _given(**keywords) -> dict:
        return {k: v for k, v in keywords.items() if v is not None}

    # ---- motion ----------------------------------------------------------------------------

    def _check_motion(self, name: str, a=None, v=None, t=None, r=None) -> None:
        for key, value in (("a", a), ("v", v), ("t", t), ("r", r)):
            if value is not None:
                _number(value, f"{name} {key}")
        if r is not None and not isinstance(r, Expr) and r > _MAX_BLEND:
            raise DslError(f"{name} blend radius r={r:g} m is beyond any UR's reach",
                           "r is in metres: 5 mm is r=0.005")

    def movej(self, q, a=None, v=None, t=None, r=None) -> None:
        """Move in joint space to ``q`` (Joints, or a Pose solved by IK closest to the current
        joints): ``a`` rad/s² (1.4), ``v`` rad/s (1.05), ``t`` s, ``r`` blend radius m."""
        target = _joints(q, "movej", pose_ok=True)
        self._check_motion("movej", a, v, t, r)
        self._statement_call("movej", (target,), self._given(a=a, v=v, t=t, r=r))

    def movel(self, pose, a=None, v=None, t=None, r=None) -> None:
        """Straight TCP line to ``pose``: ``a`` m/s² (1.2), ``v`` m/s (0.25), ``t`` s, ``r`` m."""
        target = _pose(pose, "movel")
        self._check_motion("movel", a, v, t, r)
        self._statement_call("movel", (target,), self._given(a=a, v=v, t=t, r=r))

    def movep(self, pose, a=None, v=None, r=None) -> None:
        """Process move to ``pose`` at constant tool speed ``v`` m/s (0.25), blend ``r`` m."""
        target = _pose(pose, "movep")
        self._check_motion("movep", a, v, None, r)
        self._statement_call("movep", (target,), self._given(a=a, v=v, r=r))

    def movec(self, via, to, a=None, v=None, r=None, mode=None) -> None:
        """Circular move through ``via``'s position to ``to``; ``mode`` 0 unconstrained, 1
        fixed orientation."""
        points = (_pose(via, "movec via"), _pose(to, "movec target"))
        self._check_motion("movec", a, v, None, r)
        if mode is not None and mode not in (0, 1):
            raise DslError(f"movec mode must be 0 or 1, got {mode!r}")
        self._statement_call("movec", points, self._given(a=a, v=v, r=r, mode=mode))

    def servoj(self, q, t=None, lookahead_time=None, gain=None) -> None:
        """Servo to ``q`` in ``t`` s (one controller step by default)."""
        target = _joints(q, "servoj")
        self._check_motion("servoj", t=t)
        if lookahead_time is not None and not isinstance(lookahead_time, Expr) \
                and not 0.03 <= lookahead_time <= 0.2:
            raise DslError(f"servoj lookahead_time must be in [0.03, 0.2] s, got "
                           f"{lookahead_time:g}")
        if gain is not None and not isinstance(gain, Expr) and not 100 <= gain <= 2000:
            raise DslError(f"servoj gain must be in [100, 2000], got {gain:g}")
        self._statement_call("servoj", (target,),
                             self._given(t=t, lookahead_time=lookahead_time, gain=gain))

    def speedj(self, qd, a, t=None) -> None:
        """Joint speeds ``qd`` (rad/s) reached with ``a`` rad/s², kept for ``t`` s."""
        if isinstance(qd, (list, tuple)) and len(qd) != 6:
            raise DslError(f"speedj needs 6 joint speeds, got {len(qd)}")
        self._check_motion("speedj", a=a, t=t)
        self._statement_call("speedj", (list(qd) if isinstance(qd, tuple) else qd, a),
                             self._given(t=t))

    def speedl(self, xd, a, t=None) -> None:
        """Tool speed ``xd`` (m/s, rad/s) reached with ``a`` m/s², kept for ``t`` s."""
        if isinstance(xd, (list, tuple)) and len(xd) != 6:
            raise DslError(f"speedl needs 6 speeds (3 linear, 3 angular), got {len(xd)}")
        self._check_motion("speedl", a=a, t=t)
        self._statement_call("speedl", (list(xd) if isinstance(xd, tuple) else xd, a),
                             self._given(t=t))

    def stopj(self, a) -> None:
        """Decelerate the joints with ``a`` rad/s²."""
        self._check_motion("stopj", a=a)
        self._statement_call("stopj", (a,), {})

    def stopl(self, a) -> None:
        """Decelerate the tool with ``a`` m/s²."""
        self._check_motion("stopl", a=a)
        self._statement_call("stopl", (a,), {})

    # ---- robot set-up and I/O ----------------------------------------------------------------

    def set_tcp(self, pose) -> None:
        """The TCP as a pose in the flange frame (m, rad)."""
        self._statement_call("set_tcp", (_pose(pose, "set_tcp"),), {})

    def set_payload(self, mass, cog=None) -> None:
        """Payload ``mass`` in kg, centre of gravity ``cog`` (x, y, z in m, flange frame)."""
        _number(mass, "payload mass", " kg")
        args = (mass,) if cog is None else (mass, list(cog))
        self._statement_call("set_payload", args, {})

    def set_digital_out(self, n_: int, value) -> None:
        self._io("set_standard_digital_out", n_, value, 8)

    def set_configurable_digital_out(self, n_: int, value) -> None:
        self._io("set_configurable_digital_out", n_, value, 8)

    def set_tool_digital_out(self, n_: int, value) -> None:
        self._io("set_tool_digital_out", n_, value, 2)

    def set_analog_out(self, n_: int, value) -> None:
        self._io("set_standard_analog_out", n_, value, 2)
        if not isinstance(value, Expr) and not 0.0 <= value <= 1.0:
            raise DslError(f"analog output {value:g} is outside 0..1 (a fraction of the range)")

    def _io(self, name: str, index, value, count: int) -> None:
        if not isinstance(index, Expr) and not (isinstance(index, int) and 0 <= index < count):
            raise DslError(f"{name}: output {index!r} does not exist (0..{count - 1})")
        self._statement_call(name, (index, value), {})

    def digital_in(self, n_: int) -> Expr:
        """``get_standard_digital_in(n)``."""
        return self.expr("get_standard_digital_in", n_)

    def tool_digital_in(self, n_: int) -> Expr:
        return self.expr("get_tool_digital_in", n_)

    def analog_in(self, n_: int) -> Expr:
        return self.expr("get_standard_analog_in", n_)

    def sleep(self, seconds) -> None:
        _number(seconds, "sleep time", " s")
        self._statement_call("sleep", (seconds,), {})

    def sync(self) -> None:
        self._statement_call("sync", (), {})

    def textmsg(self, *parts) -> None:
        """``textmsg(a, b)``: up to two values, shown in the log."""
        if not 1 <= len(parts) <= 2:
            raise DslError(f"textmsg takes 1 or 2 values, got {len(parts)}")
        self._statement_call("textmsg", parts, {})

    def popup(self, message, title=None, warning=None, error=None, blocking=None) -> None:
        self._statement_call("popup", (message,), self._given(
            title=title, warning=warning, error=error, blocking=blocking))

    # ---- any builtin -----------------------------------------------------------------------

    def call(self, name: str, *args, **keywords) -> None:
        """Append a call of builtin (or program function) ``name`` as a statement, checked
        against the builtin catalog: unknown name, arity and keywords."""
        self._check_call(name, args, keywords)
        self._statement_call(name, args, keywords)

    def expr(self, name: str, *args, **keywords) -> Expr:
        """A call of builtin ``name`` as an expression (``program.expr("get_actual_tcp_pose")``),
        checked like :meth:`call`."""
        self._check_call(name, args, keywords)
        return Expr(_call(name, args, keywords, _span()))

    def _check_call(self, name: str, args: tuple, keywords: dict) -> None:
        if name in self._functions:
            problem = first_problem(self._functions[name], len(args), tuple(keywords))
            if problem is not None:
                raise DslError(problem.message, problem.hint)
            return
        row = lookup(name)
        if row is None:
            import difflib

            from ..script.builtins import catalog

            close = difflib.get_close_matches(name, list(catalog()) + sorted(self._functions))
            raise DslError(f"{name!r} is not a URScript builtin or a function of this program",
                           f"did you mean {', '.join(close)}?" if close else None)
        if not row.callable:
            raise DslError(f"'{name}' is a command of the interpreter socket (port 30020), "
                           "not a function")
        problem = row.argument_problem(len(args), tuple(keywords))
        if problem is not None:
            raise DslError(problem.message, problem.hint)

    # ---- variables -------------------------------------------------------------------------

    def var(self, name: str, value, scope: str | None = None) -> Expr:
        """``name = value`` (``scope`` "global" or "local" declares it so); returns the
        variable as an expression."""
        if not name.isidentifier():
            raise DslError(f"{name!r} is not a URScript name")
        if lookup(name) is not None:
            raise DslError(f"{name!r} is the name of a builtin", "choose another name")
        span = _span()
        if scope is None:
            self._append(n.Assign(n.Name(name, span), _stamp(to_node(value), span), span))
        elif scope in ("global", "local"):
            self._append(n.Declare(scope, name, _stamp(to_node(value), span), span))
        else:
            raise DslError(f"scope must be 'global' or 'local', not {scope!r}")
        self._variables.add(name)
        return Expr(n.Name(name))

    def set(self, target: Expr, value) -> None:
        """``target = value`` for a variable, a list element or a struct member."""
        if not isinstance(target, Expr) or not isinstance(
                target.node, (n.Name, n.Index, n.Attribute)):
            raise DslError("set() needs a variable, an element v[i] or a member v.field(...)")
        span = _span()
        self._append(n.Assign(_stamp(target.node, span), _stamp(to_node(value), span), span))

    def pose(self, x, y, z, rx, ry, rz) -> Expr:
        """A pose literal whose parts may be expressions (``p[x, y, z + dz, ...]``)."""
        return Expr(n.Pose(tuple(to_node(v) for v in (x, y, z, rx, ry, rz))))

    # ---- control flow ----------------------------------------------------------------------

    @contextmanager
    def _body(self, kind: str) -> Iterator[_Block]:
        block = _Block(kind)
        self._blocks.append(block)
        try:
            yield block
        finally:
            if self._blocks[-1] is block:
                self._blocks.pop()

    @contextmanager
    def if_(self, condition) -> Iterator[None]:
        """``if condition:`` … ``end``."""
        span = _span()
        with self._body("if") as block:
            yield
        self._append(n.If(to_node(condition), tuple(block.items), (), None, span))

    @contextmanager
    def elif_(self, condition) -> Iterator[None]:
        """``elif condition:`` after an ``if_`` block."""
        last = self._last_if("elif_")
        span = _span()
        with self._body("elif") as block:
            yield
        self._blocks[-1].items[-1] = n.If(
            last.test, last.body, last.elifs + (n.Elif(to_node(condition), tuple(block.items),
                                                       span),), None, last.span)

    @contextmanager
    def else_(self) -> Iterator[None]:
        """``else:`` after an ``if_`` (or ``elif_``) block."""
        last = self._last_if("else_")
        with self._body("else") as block:
            yield
        self._blocks[-1].items[-1] = n.If(last.test, last.body, last.elifs,
                                          tuple(block.items), last.span)

    def _last_if(self, what: str) -> n.If:
        items = self._blocks[-1].items
        if not items or not isinstance(items[-1], n.If) or items[-1].orelse is not None:
            raise DslError(f"{what}() must follow an if_() block (or an elif_() after one)")
        return items[-1]

    @contextmanager
    def while_(self, condition) -> Iterator[None]:
        """``while condition:`` … ``end``."""
        span = _span()
        with self._body("while") as block:
            yield
        self._append(n.While(to_node(condition), tuple(block.items), span))

    def break_(self) -> None:
        self._append(n.Break(_span()))

    def continue_(self) -> None:
        self._append(n.Continue(_span()))

    def return_(self, value=None) -> None:
        self._append(n.Return(None if value is None else to_node(value), _span()))

    def halt(self) -> None:
        self._append(n.Halt(_span()))

    @contextmanager
    def function(self, name: str, *params: str, **defaults) -> Iterator[Function]:
        """``def name(params):`` … ``end``; yields a :class:`Function` whose attributes are the
        parameters. Keyword arguments are parameters with default values."""
        for param in (*params, *defaults):
            if not param.isidentifier():
                raise DslError(f"{param!r} is not a URScript name")
        if lookup(name) is not None:
            raise DslError(f"{name!r} is the name of a builtin", "choose another name")
        span = _span()
        self._functions[name] = Signature(
            name, (*params, *defaults), (True,) * len(params) + (False,) * len(defaults))
        handle = Function(self, name, (*params, *defaults))
        with self._body("def") as block:
            yield handle
        nodes = tuple(n.Param(p) for p in params) + tuple(
            n.Param(k, to_node(v)) for k, v in defaults.items())
        self._append(n.FunctionDef(name, nodes, tuple(block.items), span))

    @contextmanager
    def thread(self, name: str) -> Iterator[Thread]:
        """``thread name():`` … ``end``; start it with :meth:`run`."""
        span = _span()
        self._threads.add(name)
        with self._body("thread") as block:
            yield Thread(name)
        self._append(n.ThreadDef(name, tuple(block.items), span))

    def run(self, thread: Thread, handle: str) -> Expr:
        """``handle = run thread()``; returns the handle for :meth:`join` and :meth:`kill`."""
        if thread.name not in self._threads:
            raise DslError(f"thread {thread.name} is not defined in this program")
        self._append(n.Assign(n.Name(handle), n.Run(thread.name), _span()))
        return Expr(n.Name(handle))

    def join(self, handle: Expr) -> None:
        self._append(n.Join(to_node(handle), _span()))

    def kill(self, handle: Expr) -> None:
        self._append(n.Kill(to_node(handle), _span()))

    @contextmanager
    def critical(self) -> Iterator[None]:
        """``enter_critical`` … ``exit_critical``."""
        self._append(n.EnterCritical(_span()))
        yield
        self._append(n.ExitCritical(_span()))

    # ---- comments and labels ---------------------------------------------------------------

    def comment(self, text: str) -> None:
        """``# text`` (one line per line of ``text``)."""
        for line in text.splitlines() or [""]:
            self._append(n.Comment(" " + line if line else ""))

    def blank(self) -> None:
        """An empty line."""
        self._append(n.Blank())

    def marker(self, number: int, text: str, flag: str | None = None) -> None:
        """A PolyScope label ``$ number "text"`` (``flag``: "breakAfter" or "noBreak")."""
        if flag not in (None, "breakAfter", "noBreak"):
            raise DslError(f"marker flag must be 'breakAfter' or 'noBreak', not {flag!r}")
        if '"' in text:
            raise DslError("a marker text cannot contain '\"'")
        self._append(n.Marker(number, text, flag))
