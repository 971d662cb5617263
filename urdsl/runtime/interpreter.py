"""The URScript interpreter: runs a syntax tree against a robot, in robot time.

The tree is compiled once into Python closures (one per node), which then run fast without
walking the tree again. Each URScript thread runs in a greenlet; a builtin that uses physical
time (a move, ``sleep``, ``sync``) switches back to the scheduler with the robot time at which
the thread wants to go on. The scheduler always resumes the thread that is due first (round
robin among equals), so robot time jumps from event to event instead of ticking every
controller frame: checking a long program takes a fraction of the time the robot needs.

Scoping follows the controller (docs/controller-facts.md §8.3): variables at
the first level of the program are global, even when written ``local``; inside functions
and threads a free name is the global if one exists, else a local; ``local`` forces a new
local and ``global`` a global. Arguments and assignments copy values.

The interpreter never evaluates Python, opens files or reaches the network: everything a
script does to the outside world goes through the :class:`~urdsl.runtime.environment.Environment`.
"""

from __future__ import annotations

import math
import time as _clock
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import greenlet

from ..script import nodes as n
from ..script.binder import Binding, Signature
from ..script.nodes import NO_SPAN, Span
from .errors import ScriptRuntimeError
from .repeat import detached_threads, inert_names, pass_state
from .shaped import MOTION_CALLS, Shaping, assigned_in, reads, root_name
from .unknown import (
    DEVICE_READS,
    IDLE_AFTER_PASSES,
    UNKNOWN_LOOP_PASSES,
    ends_program,
    first_unknown,
    idle_truth,
    polls_devices,
    stops_motion,
    unknown_call,
)
from .values import (
    LIST_LIMIT,
    ListValue,
    PoseValue,
    StructValue,
    ThreadHandle,
    Unknown,
    copy_value,
    has_unknown,
    is_number,
    type_name,
)

__all__ = ["Interpreter", "RuntimeConfig", "RunResult", "Event", "MAX_THREADS",
           "LIST_LIMIT", "EVENT_LIMIT"]

MAX_THREADS = 128
"""Threads that may run at once; starting one more stops the program (URS208). The
controller documents no limit [U]: a program that starts a thread per command and never
ends them is what this stops."""

EVENT_LIMIT = 10_000
"""Events (and environment messages) an unpaced run keeps; later ones are counted, not kept
(``RunResult.events_dropped``): a cell program's ``textmsg`` at every pass would otherwise
fill the checker's memory. A paced run (the virtual controller) keeps all."""

BREAK, CONTINUE, RETURN = 1, 2, 3


@dataclass(frozen=True)
class RuntimeConfig:
    """How the interpreter behaves.

    ``step_time``: controller frame in s (0.002 e-Series, 0.008 CB3).
    ``runaway_limit``: loop turns a thread may make without using physical time before the
    program is stopped as the controller would ("Runtime is too much behind").
    ``max_time``: robot time in s after which a program that runs on (a ``while True`` cell
    program) is stopped; the result says so.
    ``max_call_depth``: nested user function calls before the program is stopped.
    ``deadline``: a ``time.monotonic()`` value (s of wall-clock time) after which the run
    stops and says how far it got (``RunResult.stopped_early``); ``None``: no bound.
    ``max_threads``: threads that may run at once (:data:`MAX_THREADS`).
    ``go_on_after_undefined``: a name or function that is not defined is recorded once per
    name (``RunResult.undefined``) and read as an unknown value, so the run goes on and one
    missing name does not hide the rest of the program (the verifier); ``False`` (the virtual
    controller): it stops the program as the controller does.
    """

    step_time: float = 0.002
    runaway_limit: int = 50_000
    max_time: float = 3600.0
    max_call_depth: int = 200
    deadline: float | None = None
    max_threads: int = MAX_THREADS
    go_on_after_undefined: bool = False
    stop_repeating: bool = False
    """Stop the run when a pass of a ``while True`` loop of the main thread begins in a state
    an earlier pass began in (:mod:`urdsl.runtime.repeat`): every later pass repeats those
    (the verifier; the virtual controller runs on, as the robot does)."""
    pace: Callable[[float], None] | None = None
    """Called with the robot time (s) the program is about to advance to, before it does:
    the virtual controller sleeps there to run in real time. ``None`` (the verifier): robot
    time jumps from event to event."""


@dataclass(frozen=True)
class Event:
    """Something a program did that a user may want to see: ``textmsg``, ``popup``, a thread
    left running, a builtin modelled as a no-op. ``time`` is robot time in s."""

    time: float
    kind: str
    message: str
    span: Span = NO_SPAN


@dataclass
class RunResult:
    """The outcome of running a program: final robot time (s), events, and the error that
    stopped it (None when it ended normally)."""

    time: float
    events: list[Event] = field(default_factory=list)
    error: ScriptRuntimeError | None = None
    stopped_at_max_time: bool = False
    stopped: bool = False
    threads_left_running: list[str] = field(default_factory=list)
    globals: dict[str, Any] = field(default_factory=dict)
    warnings: list[Event] = field(default_factory=list)
    """What depends on a value from outside that is unknown offline (kind ``"unknown"``),
    once per statement."""
    events_dropped: int = 0
    """Events not kept beyond :data:`EVENT_LIMIT`."""
    undefined: list[ScriptRuntimeError] = field(default_factory=list)
    """Names and functions found not defined, the first use of each, when the run went on
    past them (``RuntimeConfig.go_on_after_undefined``)."""
    forever: LoopPasses | None = None
    """The innermost ``while True`` loop of the main thread that was still running when the
    run stopped (at ``max_time``, the wall-clock bound or a stop), with its pass times."""
    paced: DevicePaced | None = None
    """When the main thread's ``while True`` loop (the innermost still running, also after an
    error) had every pass paced by a device's replies: which passes (see
    :class:`DevicePaced`); None otherwise."""
    shaped_moves: dict = field(default_factory=dict)
    """Motion calls (their span) whose target the run computed on a path it chose for a
    device, with that device reply's source (see :mod:`urdsl.runtime.shaped`)."""
    stopped_early: Event | None = None
    """Why the run stopped before the program's end without an error: ``"blocked"`` (the
    program waits forever, e.g. a read with timeout 0 that nothing answers) or
    ``"deadline"`` (the wall-clock bound); its time and span say how far it got."""


REPEAT_EVERY_PASS = 256
"""Passes of a ``while True`` loop whose begin state is compared, each; after them, every
:data:`REPEAT_STRIDE`-th (see :meth:`Interpreter.stop_if_repeating`)."""
REPEAT_STRIDE = 64
REPEAT_STATES = 512
"""Begin states of one loop kept for comparison (a loop of a longer period runs on)."""


@dataclass
class DevicePaced:
    """A ``while True`` loop of the main thread (``span``) every pass of which so far went
    where it went because the check followed a working device (it decided a condition or a
    loop on a value read from outside, ``source``): from pass 3 on (robot time ``since``, s),
    until ``until`` (the first pass that decided nothing so, or None), the state a pass
    begins in has changed with every device reply before it. What happens there first depends
    on how many times the device answers — a PC that sends a game's nine moves, a PLC that
    stops when the pallet is full — which nothing offline says."""

    span: Span
    since: float
    until: float | None
    source: str


class LoopPasses:
    """The passes of a ``while True`` loop of the main thread: how many began, and when (robot
    time, s). A pass runs from one start of the loop's body to the next."""

    __slots__ = ("span", "count", "first", "second", "last", "shortest", "longest", "states",
                 "repeats", "_decided", "paced_since", "paced_until", "_chain", "source")

    def __init__(self, span: Span) -> None:
        self.span = span
        self.count = 0
        # the state passes began in -> the first such pass (1-based) and its robot time (s)
        self.states: dict = {}
        self.repeats: int | None = None  # the earlier pass the last one began as, if any
        self.first = self.second = self.last = 0.0
        self.shortest = math.inf
        self.longest = 0.0
        self._decided = 0  # device decisions made before this pass began
        self._chain = True  # every pass so far decided something on a device's reply
        self.paced_since: float | None = None
        self.paced_until: float | None = None
        self.source = ""  # the reply the first pass decided on last

    def begin(self, time: float, decided: int = 0, source: str = "") -> None:
        """A pass begins at robot time ``time`` (s); ``decided``: the device decisions the
        run has made so far, ``source`` the last one's reply (see :class:`DevicePaced`)."""
        if self.count >= 1 and self._chain and decided <= self._decided:
            self._chain = False  # the pass that ended decided nothing on a device
            if self.paced_since is not None:
                self.paced_until = time
        if self.count == 1:
            self.source = source
        self._decided = decided
        self.count += 1
        if self.count == 3 and self._chain:
            self.paced_since = time
        if self.count == 1:
            self.first = time
        else:
            if self.count == 2:
                self.second = time
            else:
                took = time - self.last
                self.shortest = min(self.shortest, took)
                self.longest = max(self.longest, took)
        self.last = time

    @property
    def first_pass(self) -> float | None:
        """How long the first pass took (s; it includes the way from where the arm stood),
        or None before a second pass began."""
        return self.second - self.first if self.count >= 2 else None

    @property
    def pass_time(self) -> float | None:
        """The mean time (s) of the complete passes after the first (the first when it is the
        only complete one); None before a second pass began."""
        if self.count >= 3:
            return (self.last - self.second) / (self.count - 2)
        return self.first_pass


_ORDERINGS = frozenset({"<", ">", "<=", ">="})


def _likely_operands(a: Any, b: Any) -> tuple[float, float] | None:
    """The operands of a comparison with the :attr:`Unknown.likely` value of the unknown
    one in its place, when one is such a value and the other a number; else None."""
    if type(a) is Unknown and a.likely is not None and is_number(b):
        return a.likely, b
    if type(b) is Unknown and b.likely is not None and is_number(a):
        return a, b.likely
    return None


class _StopRun(Exception):
    """Ends a run early without a program error (see :attr:`RunResult.stopped_early`)."""

    def __init__(self, event: Event) -> None:
        super().__init__(event.message)
        self.event = event


class Frame:
    """The variables of one function call (or the program's first level, ``top``)."""

    __slots__ = ("vars", "local_names", "global_names", "top", "retval")

    def __init__(self, variables: dict, top: bool) -> None:
        self.vars = variables
        self.local_names: set[str] = set()
        self.global_names: set[str] = set()
        self.top = top
        self.retval: Any = None


class Thread:
    """A running URScript thread (the main program is one too)."""

    __slots__ = ("name", "glet", "wake", "order", "done", "parent", "children", "joiners",
                 "span", "handle", "blocked")

    def __init__(self, name: str, parent: Thread | None, span: Span) -> None:
        self.name = name
        self.glet: greenlet.greenlet | None = None
        self.wake = 0.0
        self.order = 0
        self.done = False
        self.parent = parent
        self.children: list[Thread] = []
        self.joiners: list[Thread] = []
        self.span = span
        self.handle = ThreadHandle(self)
        self.blocked: Event | None = None  # why it waits forever, when it does


class _Function:
    __slots__ = ("name", "params", "body", "node", "defaults", "signature")

    def __init__(self, node: n.FunctionDef, body: Callable, defaults: list) -> None:
        self.name = node.name
        self.params = [p.name for p in node.params]
        self.defaults = defaults
        self.body = body
        self.node = node
        self.signature = Signature(node.name, tuple(self.params),
                                   tuple(p.default is None for p in node.params))


class Interpreter:
    """Runs one program (a :class:`~urdsl.script.nodes.Module`).

    ``robot`` provides motion and robot state, ``environment`` everything else a script
    touches (I/O, registers, sockets, messages); see :mod:`urdsl.runtime.environment`.
    """

    def __init__(self, module: n.Module, robot: Any = None, environment: Any = None,
                 config: RuntimeConfig | None = None) -> None:
        from .builtins import BuiltinTable
        from .environment import Environment

        self.module = module
        self.config = config or RuntimeConfig()
        self.robot = robot
        self.env = environment or Environment()
        self.globals: dict[str, Any] = {}
        self.functions: dict[str, _Function] = {}
        self.threads_defs: dict[str, Callable] = {}
        self.events: list[Event] = []
        self.time = 0.0
        self.steps = 0
        self._steps_time = 0.0  # robot time (s) when the runaway counter was last reset
        self._waits = 0
        self.calls = 0  # user function calls so far
        self.loop_node: n.Node | None = None  # the loop last entered (for "how far")
        # the main thread's ``while True`` loops that are running, outermost first
        self.forever: list[LoopPasses] = []
        # decisions taken on a device's unknown reply (a condition, a loop's test), and the
        # last one's reply: see DevicePaced
        self.device_decisions = 0
        self.device_source = ""
        self.shaping = Shaping()  # values computed on a path chosen for a device
        self.unknown = getattr(self.env, "devices", "quiet") == "unknown"
        # replies taken for device reads compared with constants (see _device_reply)
        self.device_replies: dict[str, object] = {}
        self.warnings: list[Event] = []
        self.undefined: dict[str, ScriptRuntimeError] = {}
        self._undefined_sources: set[str] = set()
        self._dead = 0
        self.events_dropped = 0
        self.depth = 0
        self.current: Thread | None = None
        self.critical: Thread | None = None
        self.halted = False
        self.stop_requested = False
        self._once: set = set()
        self._inert: frozenset[str] | None = None  # see stop_if_repeating
        self._detached: frozenset[str] = frozenset()
        self._threads: list[Thread] = []
        self._order = 0
        self._scheduler: greenlet.greenlet | None = None
        self.builtins = BuiltinTable(self)
        self._compiler = _Compiler(self)
        self.entry = self._compiler.program(module)

    # ---- running ---------------------------------------------------------------------------

    def run(self) -> RunResult:
        """Run the program to its end (or its first runtime error, or ``max_time``)."""
        result = RunResult(0.0)
        self._scheduler = greenlet.getcurrent()
        main = self._spawn("main", self.entry, None, self.module.span)
        try:
            self._schedule(main, result)
        except ScriptRuntimeError as error:
            if error.time is None:
                error.time = self.time
            result.error = error
        except _StopRun as stop:
            result.stopped_early = stop.event
        finally:
            for thread in self._threads:
                if thread.glet is not None and not thread.glet.dead:
                    thread.glet.throw(greenlet.GreenletExit)
        if result.error is None and self.forever:
            result.forever = self.forever[-1]
        if self.forever and self.forever[-1].paced_since is not None:
            passes = self.forever[-1]
            result.paced = DevicePaced(passes.span, passes.paced_since, passes.paced_until,
                                       passes.source)
        if self.robot is not None:
            self.robot.finish(self.time)
            self.time = max(self.time, getattr(self.robot, "end_time", self.time))
        result.time = self.time
        result.events = self.events
        result.globals = self.globals
        result.warnings = self.warnings
        result.undefined = list(self.undefined.values())
        result.shaped_moves = dict(self.shaping.moves)
        result.events_dropped = self.events_dropped
        if self.events_dropped:
            self.events.append(Event(self.time, "dropped", f"{self.events_dropped:,} more "
                                     f"events after the first {EVENT_LIMIT:,} were not kept"))
        return result

    def _schedule(self, main: Thread, result: RunResult) -> None:
        threads = self._threads
        turns = 0
        while not main.done and not self.halted:
            turns += 1
            if not turns & 255:
                self.check_deadline(None)
            if self._dead > 16 and self._dead * 2 > len(threads):
                self._prune()
            if self.critical is not None and not self.critical.done:
                thread = self.critical
            elif len(threads) == 1:  # the main thread alone (most programs)
                thread = main
            else:
                thread = min((t for t in threads if not t.done),
                             key=lambda t: (t.wake, t.order))
            if thread.wake == math.inf:
                if thread.blocked is not None:
                    raise _StopRun(thread.blocked)
                raise ScriptRuntimeError(
                    "call", "every thread waits for another one: the program can never go on",
                    thread.span)
            if thread.wake > self.config.max_time:
                result.stopped_at_max_time = True
                self.time = self.config.max_time
                break
            if thread.wake > self.time and self.config.pace is not None:
                self.config.pace(thread.wake)
            if self.stop_requested:
                result.stopped = True
                break
            self.time = max(self.time, thread.wake)
            self.current = thread
            thread.glet.switch()
        left = [t.name for t in threads if not t.done and t is not main]
        for thread in threads:
            thread.done = True
        result.threads_left_running = left
        for name in left:
            self.event("thread", f"the program ended while thread {name} was still running")

    def _prune(self) -> None:
        """Forget finished threads (the scheduler looks at live ones only); called by the
        scheduler alone, which may end the greenlets of threads killed while waiting."""
        live = []
        for thread in self._threads:
            if not thread.done:
                live.append(thread)
            elif thread.glet is not None and not thread.glet.dead:
                thread.glet.throw(greenlet.GreenletExit)  # killed while it waited
        self._threads[:] = live
        self._dead = 0

    def _spawn(self, name: str, body: Callable, parent: Thread | None, span: Span) -> Thread:
        thread = Thread(name, parent, span)
        thread.wake = self.time
        self._order += 1
        thread.order = self._order

        def run() -> None:
            try:
                body()
            except _Halt:
                self.halted = True
            finally:
                self._finish(thread)

        thread.glet = greenlet.greenlet(run, parent=self._scheduler)
        if parent is not None:
            parent.children.append(thread)
        self._threads.append(thread)
        return thread

    def _finish(self, thread: Thread) -> None:
        if not thread.done:
            self._dead += 1
        thread.done = True
        if self.critical is thread:
            self.critical = None
        for joiner in thread.joiners:
            joiner.wake = self.time
        if thread.parent is not None:  # the main thread's end is the scheduler's business
            for child in thread.children:
                self._kill(child)

    def _kill(self, thread: Thread) -> None:
        if thread.done:
            return
        thread.done = True
        self._dead += 1
        for joiner in thread.joiners:
            joiner.wake = self.time
        for child in thread.children:
            self._kill(child)

    def request_stop(self) -> None:
        """Stop the program at its next step in time (a dashboard ``stop``, a new program
        replacing it); safe to call from the ``pace`` callback or another thread."""
        self.stop_requested = True

    # ---- what builtins and statements call -------------------------------------------------

    def wait_until(self, when: float) -> None:
        """Block the current thread until robot time ``when`` (s)."""
        thread = self.current
        if self.config.deadline is not None:
            self._waits += 1
            if not self._waits & 255:
                self.check_deadline(None)
        if (len(self._threads) == 1 and self.config.pace is None and not self.stop_requested
                and when <= self.config.max_time):
            # the main thread alone, unpaced: the scheduler would only move the clock on
            thread.wake = self.time = max(when, self.time)
            return
        thread.wake = max(when, self.time)
        self._order += 1
        thread.order = self._order
        self._scheduler.switch()
        if thread.done:  # killed while waiting
            raise greenlet.GreenletExit

    def wait_forever(self, message: str, node: n.Node) -> None:
        """Block the current thread for good (a read with timeout 0 that nothing will answer):
        the checker stops there and says so; a paced run (the virtual controller) waits
        until the program is stopped."""
        event = Event(self.time, "blocked", message, node.span)
        if self.config.pace is not None:
            self.wait_until(self.config.max_time)
            return
        if len(self._threads) == 1 or self.current.parent is None:
            raise _StopRun(event)
        self.current.blocked = event
        self.event("blocked", message, node.span)
        self.wait_until(math.inf)

    def stop_if_repeating(self, passes: LoopPasses, frame: Frame, node: n.Node,
                          loop_state: Any = None) -> None:
        """Stop the run (``"repeats"``) when the pass of ``passes`` now beginning begins in the
        state an earlier one began in (:func:`urdsl.runtime.repeat.pass_state`): the passes
        from that one on repeat for ever, and all of them have been run. The state is taken
        at every pass up to :data:`REPEAT_EVERY_PASS`, then at every
        :data:`REPEAT_STRIDE`-th, and at most :data:`REPEAT_STATES` are kept: a loop of very
        short passes (a poll each controller frame) costs little more than before.
        ``loop_state``: what else of the loop decides what its next pass does."""
        count = passes.count
        if count > REPEAT_EVERY_PASS and count % REPEAT_STRIDE:
            return
        if self._inert is None:
            self._inert = inert_names(self.module)
            self._detached = detached_threads(
                self.module, DEVICE_READS if self.unknown else frozenset())
        state = pass_state(self, frame, self._inert, self._detached)
        if state is None:
            return
        state = (state, loop_state, len(self.device_replies))
        seen = passes.states.get(state)
        if seen is None:
            if len(passes.states) < REPEAT_STATES:
                passes.states[state] = (count, self.time)
            return
        earlier, then = seen
        if self.time <= then:
            return  # passes that take no robot time: the controller stops the program as
            # runaway (URS207), which the run must go on to find
        passes.repeats = earlier
        if earlier == count - 1:
            same, repeated = "the one before", f"pass {earlier}, which was checked"
        else:
            same = f"pass {earlier}"
            repeated = f"passes {earlier} to {count - 1}, which were checked"
        raise _StopRun(Event(self.time, "repeats",
                             f"pass {count} of this loop begins in the same state as {same} "
                             f"(variables, arm, I/O, threads): every later pass repeats "
                             f"{repeated}", node.span))

    def check_deadline(self, node: n.Node | None) -> None:
        """Stop the run if the wall-clock bound (``config.deadline``) has passed."""
        deadline = self.config.deadline
        if deadline is None or _clock.monotonic() < deadline:
            return
        if node is None:
            node = self.loop_node
        span = node.span if node is not None else (
            self.current.span if self.current is not None else NO_SPAN)
        where = f" in thread {self.current.name}" if self.current is not None and \
            self.current.name != "main" else ""
        raise _StopRun(Event(self.time, "deadline",
                             f"stopped at robot time {self.time:.3f} s{where}", span))

    def decided_on(self, value: Unknown) -> None:
        """The run took a path on a device's unknown reply ``value`` (see
        :class:`DevicePaced`); only the main thread's decisions pace its loop (a thread that
        polls a gripper all along does not)."""
        if self.current is not None and self.current.parent is not None:
            return
        self.device_decisions += 1
        self.device_source = value.source

    def warn_once(self, message: str, node: Any, unknown: Unknown | None = None) -> None:
        """A warning about what depends on a value unknown offline, once per statement.
        None when ``unknown`` stands for a name that is not defined: its error says that the
        check went on with the value unknown, and what follows is not about a device."""
        if unknown is not None and unknown.source in self._undefined_sources:
            return
        span = node.span if node is not None and hasattr(node, "span") else NO_SPAN
        key = ("unknown", span)
        if key in self._once:
            return
        self._once.add(key)
        self.warnings.append(Event(self.time, "unknown", message, span))

    def wait(self, seconds: float) -> None:
        """Block the current thread for ``seconds`` of robot time."""
        self.wait_until(self.time + max(seconds, 0.0))

    def sync(self) -> None:
        """Give up the rest of the current controller frame."""
        step = self.config.step_time
        frames = math.floor(self.time / step + 1e-9) + 1
        self.wait_until(frames * step)

    def event(self, kind: str, message: str, span: Span = NO_SPAN) -> None:
        if len(self.events) >= EVENT_LIMIT and self.config.pace is None:
            self.events_dropped += 1
            return
        self.events.append(Event(self.time, kind, message, span))

    def message(self, kind: str, text: str) -> None:
        """A message for the environment (``textmsg``, ``popup``), kept up to
        :data:`EVENT_LIMIT` in an unpaced run."""
        messages = self.env.messages
        if len(messages) < EVENT_LIMIT or self.config.pace is not None:
            messages.append((self.time, kind, text))

    def event_once(self, kind: str, message: str, span: Span = NO_SPAN) -> None:
        """An event recorded only the first time this statement causes it (a builtin that is
        not simulated, called in a loop, is reported once, not at every turn)."""
        key = (kind, span)
        if key not in self._once:
            self._once.add(key)
            self.event(kind, message, span)

    def error(self, kind: str, message: str, node: Any = None, hint: str | None = None):
        span = node.span if node is not None and hasattr(node, "span") else NO_SPAN
        return ScriptRuntimeError(kind, message, span, hint, self.time)

    def not_defined(self, name: str, what: str, node: Any, hint: str | None) -> Unknown:
        """A name or function ``name`` that nothing defined: the error that stops the
        program, or, when the run goes on past such names (the verifier), the error recorded
        once per name and an unknown value in its place."""
        error = self.error("undefined", f"{what} '{name}' is not defined", node, hint)
        error.name = name
        if not self.config.go_on_after_undefined:
            raise error
        if name not in self.undefined:
            self.undefined[name] = error
        source = f"'{name}' (not defined)"
        self._undefined_sources.add(source)
        return Unknown(source, error.span)

    def start_thread(self, name: str, node: n.Node) -> ThreadHandle:
        body = self.threads_defs.get(name)
        if body is None:
            raise self.error("undefined", f"thread '{name}' is not defined", node)
        self.steps += 1  # a thread that starts threads without using time runs away too
        if self.steps > self.config.runaway_limit:
            self.count_step(node)
        if len(self._threads) - self._dead >= self.config.max_threads:
            # (no pruning here: only the scheduler may end suspended greenlets)
            if sum(1 for t in self._threads if not t.done) >= self.config.max_threads:
                raise self.error(
                    "call", f"more than {self.config.max_threads} threads would run at once",
                    node, "join or kill threads that are done with their work")
        thread = self._spawn(name, body, self.current, node.span)
        return thread.handle

    def join(self, handle: Any, node: n.Node) -> None:
        if _no_thread(handle):
            return
        if type(handle) is not ThreadHandle:
            raise self.error("type", f"join needs a thread handle, not a {type_name(handle)}",
                             node)
        target = handle.thread
        if target is self.current:
            raise self.error("call", "a thread cannot join itself", node)
        if not target.done:
            target.joiners.append(self.current)
            self.wait_until(math.inf)

    def kill(self, handle: Any, node: n.Node) -> None:
        if _no_thread(handle):
            return
        if type(handle) is not ThreadHandle:
            raise self.error("type", f"kill needs a thread handle, not a {type_name(handle)}",
                             node)
        target = handle.thread
        self._kill(target)
        if target is self.current:
            raise greenlet.GreenletExit

    def count_step(self, node: n.Node) -> None:
        """Called when the loop-turn counter passes ``runaway_limit``: stop a program whose
        threads keep looping without robot time advancing (the counter restarts only when
        it does), and check the wall-clock bound."""
        self.check_deadline(node)
        if self.time != self._steps_time:
            self._steps_time = self.time
            self.steps = 0
            return
        self.steps += 1
        if self.steps > self.config.runaway_limit:
            self.steps = 0
            raise self.error(
                "runaway",
                f"thread {self.current.name} looped {self.config.runaway_limit:,} times "
                "without using physical time: the controller stops the program "
                "(\"Runtime is too much behind\")",
                node, "call sync() in a loop that only waits or computes")


# ---- the compiler --------------------------------------------------------------------------


def _constants(items) -> list | None:
    """The values of literal numbers (``1``, ``-0.5``), or None if any item is not one."""
    values = []
    for item in items:
        if type(item) is n.Number:
            values.append(item.value)
        elif (type(item) is n.UnaryOp and item.op == "-" and type(item.operand) is n.Number):
            values.append(-item.operand.value)
        else:
            return None
    return values


def _truth(value: Any, rt: Interpreter, node: n.Node) -> bool:
    kind = type(value)
    if kind is bool:
        return value
    if kind is int or kind is float:
        return value != 0
    raise rt.error("type", f"a condition must be a bool, not a {type_name(value)}", node)


def _index(value: Any) -> int:
    kind = type(value)
    if kind is int:
        return value
    if kind is float and value.is_integer():
        return int(value)
    raise TypeError(type_name(value))


class _Compiler:
    """Turns tree nodes into closures bound to one :class:`Interpreter`."""

    def __init__(self, rt: Interpreter) -> None:
        self.rt = rt
        # the polling loop (see polls_devices) whose body is being compiled: its pass count
        self._polling: list[int] | None = None
        self._assigned: frozenset[str] = frozenset()  # names the program assigns anywhere

    # -- program -----------------------------------------------------------------------------

    def program(self, module: n.Module) -> Callable[[], None]:
        """The program's entry: a single top-level ``def`` (with nothing else but
        definitions, comments and labels) is run; otherwise the top-level statements are."""
        rt = self.rt
        self._assigned = assigned_names(module)
        defs = [s for s in module.body if isinstance(s, n.FunctionDef)]
        statements = [s for s in module.body if isinstance(s, n.Stmt)
                      and not isinstance(s, (n.FunctionDef, n.ThreadDef, n.SecDef))]
        self.collect(module.body)
        if len(defs) == 1 and not defs[0].params and (not statements or (
                len(statements) == 1 and n.calls_itself(defs[0], statements[0]))):
            # the program's def, alone or followed by its call: its first-level names are
            # the program's globals, which its nested functions see
            body = rt.functions[defs[0].name].body  # compiled once, by collect()
        elif not statements and not defs:
            secs = [s for s in module.body if isinstance(s, n.SecDef)]
            body = self.block(secs[0].body) if secs else self.block(())
        else:
            body = self.block(module.body)

        def entry() -> None:
            frame = Frame(rt.globals, top=True)
            body(frame)

        return entry

    def collect(self, items) -> None:
        """Register every function and thread definition (nested ones too: all are global)."""
        for item in items:
            if isinstance(item, n.FunctionDef):
                defaults = [None if p.default is None else self.expr(p.default)
                            for p in item.params]
                function = _Function(item, None, defaults)
                self.rt.functions[item.name] = function
                self.collect(item.body)
                function.body = self.block(item.body)
            elif isinstance(item, n.ThreadDef):
                self.collect(item.body)
                self.rt.threads_defs[item.name] = self.thread_body(item)
            elif isinstance(item, (n.If, n.While)):
                self.collect(item.body)
                if isinstance(item, n.If):
                    for branch in item.elifs:
                        self.collect(branch.body)
                    if item.orelse:
                        self.collect(item.orelse)

    def thread_body(self, node: n.ThreadDef) -> Callable[[], None]:
        body = self.block(node.body)
        rt = self.rt

        def run() -> None:
            body(Frame({}, top=False))

        run.__name__ = node.name
        del rt  # threads take no arguments; nothing else to bind
        return run

    # -- statements --------------------------------------------------------------------------

    def block(self, items) -> Callable[[Frame], int | None]:
        statements = [self.statement(item) for item in items
                      if isinstance(item, n.Stmt)
                      and not isinstance(item, (n.FunctionDef, n.ThreadDef, n.SecDef))]
        if not statements:
            return lambda frame: None
        if len(statements) == 1:
            return statements[0]

        def run(frame: Frame) -> int | None:
            for statement in statements:
                signal = statement(frame)
                if signal:
                    return signal
            return None

        return run

    def statement(self, node: n.Stmt) -> Callable[[Frame], int | None]:
        method = getattr(self, "s_" + type(node).__name__)
        return method(node)

    def s_ExprStmt(self, node: n.ExprStmt):
        evaluate = self.expr(node.expr)

        def run(frame):
            evaluate(frame)

        return run

    def s_Assign(self, node: n.Assign):
        store = self.target(node.target)
        value = self.expr(node.value)
        shaping = self.rt.shaping
        name, whole = root_name(node.target), type(node.target) is n.Name
        names = reads(node.value)

        def run(frame):
            if not shaping.names:
                store(frame, copy_value(value(frame)))
                return
            shaping.returned = None
            store(frame, copy_value(value(frame)))
            shaping.assigned(name, _shaped_value(shaping, names), whole)

        return run

    def s_Declare(self, node: n.Declare):
        rt = self.rt
        name = node.name
        value = self.expr(node.value) if node.value is not None else None
        shaping = rt.shaping
        names = reads(node.value)

        def evaluate(frame):
            if not shaping.names:
                return copy_value(value(frame))  # type: ignore[misc]
            shaping.returned = None
            result = copy_value(value(frame))  # type: ignore[misc]
            shaping.assigned(name, _shaped_value(shaping, names), True)
            return result

        if node.scope == "global":
            def run(frame):
                frame.global_names.add(name)
                frame.local_names.discard(name)
                if value is not None:
                    rt.globals[name] = evaluate(frame)
            return run

        def run_local(frame):
            if frame.top:  # the program's first level: global even when written local
                if value is not None:
                    rt.globals[name] = evaluate(frame)
                return
            frame.local_names.add(name)
            frame.global_names.discard(name)
            if value is not None:
                frame.vars[name] = evaluate(frame)
            else:
                frame.vars.pop(name, None)

        return run_local

    def s_Return(self, node: n.Return):
        value = self.expr(node.value) if node.value is not None else None
        shaping = self.rt.shaping
        names = reads(node.value)

        def run(frame):
            if not shaping.names:
                frame.retval = None if value is None else value(frame)
                return RETURN
            shaping.returned = None
            frame.retval = None if value is None else value(frame)
            shaping.returned = _shaped_value(shaping, names)
            return RETURN

        return run

    def s_Halt(self, node):
        def run(frame):
            raise _Halt

        return run

    def s_Break(self, node):
        return lambda frame: BREAK

    def s_Continue(self, node):
        return lambda frame: CONTINUE

    def s_EnterCritical(self, node):
        rt = self.rt

        def run(frame):
            rt.critical = rt.current

        return run

    def s_ExitCritical(self, node):
        rt = self.rt

        def run(frame):
            if rt.critical is rt.current:
                rt.critical = None

        return run

    def s_Join(self, node: n.Join):
        rt = self.rt
        handle = self.expr(node.thread)
        return lambda frame: rt.join(handle(frame), node)

    def s_Kill(self, node: n.Kill):
        rt = self.rt
        handle = self.expr(node.thread)
        return lambda frame: rt.kill(handle(frame), node)

    def s_If(self, node: n.If):
        rt = self.rt
        branches = [(self.expr(node.test), self.block(node.body), node.test,
                     ends_program(node.body), stops_motion(node.body))]
        branches += [(self.expr(b.test), self.block(b.body), b.test, ends_program(b.body),
                      stops_motion(b.body)) for b in node.elifs]
        orelse = self.block(node.orelse) if node.orelse is not None else None
        # branch -> [robot time of its first unknown test, tests at that time]
        first_seen: dict[int, list] = {}
        polling = self._polling  # [passes] of the polling loop this statement is in, or None
        shaping = rt.shaping
        assigned = assigned_in(node.body, *(b.body for b in node.elifs), node.orelse)
        tests = [reads(node.test)] + [reads(b.test) for b in node.elifs]
        taken = ("it takes this branch for the loop's first "
                 f"{IDLE_AFTER_PASSES} passes, then skips it (an idle device)"
                 if polling is not None else "it takes this branch")
        at_rest = [idle_truth(node.test)] + [idle_truth(b.test) for b in node.elifs]
        taken_idle = (f"it takes this branch, also after the loop's first {IDLE_AFTER_PASSES} "
                      "passes (an idle device reads at rest: False, 0)")

        def run(frame):
            source = None  # the device reply a test depended on: the rest is shaped
            for index, (test, body, test_node, ending, stopping) in enumerate(branches):
                value = test(frame)
                if type(value) is Unknown:
                    if source is None:
                        source = value.source
                        shaping.decide(assigned, source)
                    rt.decided_on(value)
                    # follow a working device: not into an error branch (it ends the
                    # program), not against the reply the program expects, else in
                    working = take = not ending and value.lean is not False
                    idle = polling is not None and polling[0] > IDLE_AFTER_PASSES
                    if idle:
                        # the device has gone idle: its reads are at rest (False, 0)
                        take = not ending and at_rest[index]
                    elif take and stopping:
                        # a sensor that stops a move (PolyScope's Until: tool contact, an
                        # input) fires once the move has come as far as it can go (the arm
                        # at rest) and robot time has passed since it was first tested; a
                        # loop that tests it again without time passing (no move to wait
                        # for) sees it fire on its second test
                        seen = first_seen.setdefault(index, [rt.time, 0])
                        if rt.time > seen[0]:
                            seen[1] = 2
                        else:
                            seen[1] += 1
                        free_at = getattr(rt.robot, "free_at", rt.time)
                        take = seen[1] >= 2 and free_at <= rt.time + 1e-9
                    rt.warn_once(
                        f"this condition depends on {value.source}, which is unknown "
                        "offline; the check follows a working device: "
                        + ("it skips this branch, which ends the program" if ending
                           else "it takes this branch once the move it stops has come as "
                           "far as it can" if stopping and value.lean is not False
                           else (taken_idle if polling is not None and at_rest[index]
                                 else taken) if working
                           else "it skips this branch (a working device's reply does not "
                           "lead here)"),
                        test_node, value)
                    if not take:
                        continue
                    return body(frame)
                if source is None and shaping.names:
                    source = shaping.source(tests[index])
                    if source is not None:
                        shaping.decide(assigned, source)
                if _truth(value, rt, test_node):
                    return body(frame)
            if orelse is not None:
                return orelse(frame)
            return None

        return run

    def s_While(self, node: n.While):
        rt = self.rt
        test = self.expr(node.test)
        outer, polling = self._polling, ([0] if polls_devices(node.body) else None)
        self._polling = polling
        try:
            body = self.block(node.body)
        finally:
            self._polling = outer
        test_node = node.test
        shaping = rt.shaping
        assigned, tested = assigned_in(node.body), reads(node.test)
        literal = test_node
        while type(literal) is n.Paren:
            literal = literal.expr
        forever = type(literal) is n.Bool and literal.value  # PolyScope's ``while (True):``

        def run(frame):
            rt.loop_node = node
            if polling is not None:
                polling[0] = 0
            passes = None
            if forever and rt.current is not None and rt.current.parent is None:
                passes = LoopPasses(node.span)  # the main thread's: its passes are timed
                rt.forever.append(passes)
            signal = _loop(frame, passes)
            if passes is not None:  # left (an error, or the run's end, leaves it on the list)
                rt.forever.remove(passes)
            return signal

        def _loop(frame, passes):
            unknown_passes = 0
            source = None  # the device reply the loop's test depended on: passes are shaped
            while True:
                if passes is not None:
                    passes.begin(rt.time, rt.device_decisions, rt.device_source)
                    if rt.config.stop_repeating:
                        # the polling loop's pass count decides its device branches until
                        # the device is taken as idle
                        rt.stop_if_repeating(passes, frame, node, None if polling is None
                                             else min(polling[0], IDLE_AFTER_PASSES + 1))
                if polling is not None:
                    polling[0] += 1
                value = test(frame)
                if source is None and (type(value) is Unknown or shaping.names):
                    source = value.source if type(value) is Unknown else \
                        shaping.source(tested)
                    if source is not None:
                        shaping.decide(assigned, source)
                if type(value) is Unknown:
                    rt.decided_on(value)
                    unknown_passes += 1
                    if value.lean is False:  # the expected reply came at once
                        rt.warn_once(
                            f"this loop's condition depends on {value.source}, which is "
                            "unknown offline; the check follows a working device, whose "
                            "reply ends the loop", test_node, value)
                        break
                    if unknown_passes == 1:
                        rt.warn_once(
                            f"this loop's condition depends on {value.source}, which is "
                            "unknown offline; the check follows a working device and leaves "
                            f"the loop after at most {UNKNOWN_LOOP_PASSES} passes", test_node,
                            value)
                    if unknown_passes > UNKNOWN_LOOP_PASSES:
                        break
                elif not _truth(value, rt, test_node):
                    break
                signal = body(frame)
                if signal == BREAK:
                    break
                if signal == RETURN:
                    return RETURN
                rt.steps += 1
                if rt.steps > rt.config.runaway_limit:
                    rt.count_step(node)
            return None

        return run

    def s_FunctionDef(self, node):  # definitions are collected beforehand
        return lambda frame: None

    s_ThreadDef = s_SecDef = s_FunctionDef

    # -- assignment targets ------------------------------------------------------------------

    def target(self, node: n.Expr) -> Callable[[Frame, Any], None]:
        rt = self.rt
        if isinstance(node, n.Name):
            name = node.id

            def store(frame, value):
                if frame.top or name in frame.global_names:
                    rt.globals[name] = value
                elif name in frame.local_names:
                    frame.vars[name] = value
                elif name in rt.globals:
                    rt.globals[name] = value
                else:
                    frame.local_names.add(name)
                    frame.vars[name] = value

            return store
        if isinstance(node, n.Index):
            container = self.expr(node.value)
            store_container = self.target(node.value)
            indices = [self.expr(i) for i in node.indices]

            def store_item(frame, value):
                target = container(frame)
                keys = [idx(frame) for idx in indices]
                kind = type(target)
                if kind is Unknown:  # an element of an unknown value: still unknown
                    return
                try:
                    positions = [_index(k) for k in keys]
                except TypeError as error:
                    found = _first_unknown_key(keys)
                    if found is not None:  # which element changed is unknown
                        store_container(frame, found.plain())
                        return
                    raise rt.error("type", f"an index must be an int, not a {error}", node) \
                        from None
                try:
                    if kind is ListValue:
                        if len(positions) == 2:
                            target[positions[0]][positions[1]] = value
                        else:
                            _check_bounds(positions[0], len(target), rt, node)
                            target[positions[0]] = value
                    elif kind is PoseValue:
                        _check_bounds(positions[0], 6, rt, node)
                        if type(value) is Unknown:
                            store_container(frame, value.plain())
                            return
                        if not is_number(value):
                            raise rt.error("type", f"a pose holds numbers, not a "
                                           f"{type_name(value)}", node)
                        store_container(frame, target.replace(positions[0], value))
                    elif kind is StructValue:
                        member = list(target.members)[positions[0]]
                        target.members[member] = value
                    else:
                        raise rt.error("type", f"cannot assign to an element of a "
                                       f"{type_name(target)}", node)
                except IndexError:
                    raise rt.error("index", f"index {keys} is out of range", node) from None

            return store_item
        if isinstance(node, n.Attribute):
            container = self.expr(node.value)
            attr = node.attr

            def store_field(frame, value):
                target = container(frame)
                if type(target) is Unknown:
                    return
                if type(target) is not StructValue:
                    raise rt.error("type", f"a {type_name(target)} has no field '{attr}'", node)
                if attr not in target.members:
                    raise rt.error("undefined", f"the struct has no member '{attr}'", node,
                                   "a struct's members are fixed when it is made")
                target.members[attr] = value

            return store_field
        raise rt.error("type", "cannot assign to this expression", node)

    # -- expressions -------------------------------------------------------------------------

    def expr(self, node: n.Expr) -> Callable[[Frame], Any]:
        return getattr(self, "e_" + type(node).__name__)(node)

    def e_Number(self, node):
        value = node.value
        return lambda frame: value

    e_String = e_Bool = e_Number

    def e_NoneLit(self, node):
        return lambda frame: None

    def e_Opaque(self, node: n.Opaque):
        """A value from another file of the project that is not known here: unknown."""
        value = Unknown(node.source, node.span)
        return lambda frame: value

    def e_Paren(self, node):
        return self.expr(node.expr)

    def e_Name(self, node: n.Name):
        rt = self.rt
        name = node.id
        globals_ = rt.globals
        assigned = self._assigned

        def read(frame):
            if name in frame.local_names:
                try:
                    return frame.vars[name]
                except KeyError:
                    pass
            elif name in globals_:
                return globals_[name]
            if rt.warnings and name in assigned:
                # the program gives the name a value on a path the check did not follow
                # because it decided on a device's or operator's reply: not certain
                first = rt.warnings[0].span.line
                rt.warn_once(
                    f"name '{name}' is not defined here, on the path the check followed; the "
                    f"program assigns '{name}' on others, so this depends on the replies the "
                    f"check assumed (the first at line {first}); the check goes on with its "
                    "value unknown", node)
                return Unknown(f"'{name}' (not assigned on the path the check followed)",
                               node.span)
            return rt.not_defined(name, "name", node, _name_hint(name, frame, rt))

        return read

    def e_List(self, node: n.List):
        rt = self.rt
        constants = _constants(node.items)
        if constants is not None:  # a literal list: copy it, as every evaluation must
            return lambda frame: ListValue(constants)
        items = [self.expr(i) for i in node.items]

        def make(frame):
            values = [copy_value(item(frame)) for item in items]
            rows = 0
            for value in values:
                if type(value) is ListValue:
                    if value and type(value[0]) is ListValue:
                        raise rt.error("type", "a list cannot hold a matrix: lists have at "
                                       "most two levels (a matrix)", node)
                    rows += len(value)
            if rows > LIST_LIMIT:
                raise rt.error("index", f"a matrix of more than {LIST_LIMIT:,} values", node)
            return ListValue(values)

        return make

    def e_Pose(self, node: n.Pose):
        rt = self.rt
        constants = _constants(node.items)
        if constants is not None:  # a literal pose (the bulk of a toolpath) is made once
            pose = PoseValue(constants)
            return lambda frame: pose
        items = [self.expr(i) for i in node.items]

        def make(frame):
            values = [item(frame) for item in items]
            for value, item in zip(values, node.items, strict=True):
                if not is_number(value):
                    if type(value) is Unknown:  # a pose with an unknown part is unknown
                        return value.plain()
                    raise rt.error("type", f"a pose holds numbers, not a {type_name(value)}",
                                   item)
            return PoseValue(values)

        return make

    def e_UnaryOp(self, node: n.UnaryOp):
        rt = self.rt
        operand = self.expr(node.operand)
        if node.op in ("not", "!"):
            def negate(frame):
                value = operand(frame)
                if type(value) is not bool:
                    if type(value) is Unknown:
                        return value.leaning(None if value.lean is None else not value.lean)
                    raise rt.error("type", f"'{node.op}' needs a bool, not a "
                                   f"{type_name(value)}", node)
                return not value
            return negate
        sign = -1 if node.op == "-" else 1

        def minus(frame):
            value = operand(frame)
            kind = type(value)
            if kind is int or kind is float:
                return sign * value
            if kind is ListValue and all(is_number(v) for v in value):
                return ListValue([sign * v for v in value])
            if has_unknown(value) is not None:
                return has_unknown(value).leaning(None)
            raise rt.error("type", f"unary '{node.op}' needs a number, not a "
                           f"{type_name(value)}", node)

        return minus

    def e_BinOp(self, node: n.BinOp):
        from .operators import binary

        rt = self.rt
        left = self.expr(node.left)
        right = self.expr(node.right)
        op = node.op
        if op == "and":
            def conj(frame):
                a = left(frame)
                if type(a) is Unknown:  # unknown, unless the right side is false
                    b = right(frame)
                    if b is False:
                        return b
                    if type(b) is not Unknown:
                        _bool_operand(b, rt, node)  # a known operand must be a bool
                    else:
                        return a.leaning(False if False in (a.lean, b.lean) else
                                         a.lean and b.lean)
                    return a.plain()
                if not _bool_operand(a, rt, node):
                    return False
                b = right(frame)
                return b.plain() if type(b) is Unknown else _bool_operand(b, rt, node)
            return conj
        if op == "or":
            def disj(frame):
                a = left(frame)
                if type(a) is Unknown:  # unknown, unless the right side is true
                    b = right(frame)
                    if b is True:
                        return b
                    if type(b) is not Unknown:
                        _bool_operand(b, rt, node)  # a known operand must be a bool
                    else:
                        return a.leaning(True if True in (a.lean, b.lean) else
                                         None if None in (a.lean, b.lean) else False)
                    return a.plain()
                if _bool_operand(a, rt, node):
                    return True
                b = right(frame)
                return b.plain() if type(b) is Unknown else _bool_operand(b, rt, node)
            return disj
        operation = binary(op)
        if op in ("==", "!="):
            lean = op == "=="  # a working device answers what the program expects
            reply = _device_reply(node)  # (the read as text, the constant compared with)

            def compare(frame):
                a = left(frame)
                b = right(frame)
                found = has_unknown(a) or has_unknown(b)
                if found is not None:
                    likely = _likely_operands(a, b)
                    if likely is not None:
                        return found.leaning(operation(*likely))
                    if reply is not None:
                        # one device, one reply: the first constant a read is compared with
                        # is the reply taken; `JOB == 2` then `JOB == 7` is not both true
                        taken = rt.device_replies.setdefault(reply[0], reply[1])
                        return found.leaning((taken == reply[1]) is lean)
                    return found.leaning(lean)
                return operation(a, b)
            return compare

        def apply(frame):
            a = left(frame)
            b = right(frame)
            try:
                return operation(a, b)
            except ZeroDivisionError:
                raise rt.error("arithmetic", "division by zero", node) from None
            except (TypeError, ValueError) as error:
                found = has_unknown(a) or has_unknown(b)
                likely = _likely_operands(a, b) if op in _ORDERINGS else None
                if likely is not None:
                    return found.leaning(operation(*likely))
                # xor of an unknown needs the other side a bool or unknown too (two device
                # reads, e.g. RTDE boolean registers, are a valid xor)
                other = b if found is a else a
                if found is not None and not (op == "xor" and type(other) is not bool
                                              and has_unknown(other) is None):
                    return found.leaning(None)
                raise rt.error("type", f"'{op}' cannot combine a {type_name(a)} and a "
                               f"{type_name(b)}" + (f": {error}" if str(error) else ""),
                               node, _operator_hint(op, a, b)) from None

        return apply

    def e_Index(self, node: n.Index):
        rt = self.rt
        container = self.expr(node.value)
        indices = [self.expr(i) for i in node.indices]

        def get(frame):
            target = container(frame)
            keys = [idx(frame) for idx in indices]
            try:
                positions = [_index(k) for k in keys]
            except TypeError as error:
                found = has_unknown(target) or _first_unknown_key(keys)
                if found is not None:
                    return found.plain()
                raise rt.error("type", f"an index must be an int, not a {error}", node) \
                    from None
            kind = type(target)
            if kind is Unknown:
                return target.plain()
            if kind is ListValue or kind is PoseValue:
                size = len(target)
                first = positions[0]
                _check_bounds(first, size, rt, node)
                item = target[first]
                if len(positions) == 2:
                    if type(item) is not ListValue:
                        raise rt.error("type", "m[i, j] needs a matrix", node)
                    _check_bounds(positions[1], len(item), rt, node)
                    return item[positions[1]]
                return item
            if kind is StructValue:
                values = list(target.members.values())
                _check_bounds(positions[0], len(values), rt, node)
                return values[positions[0]]
            raise rt.error("type", f"a {type_name(target)} cannot be indexed", node)

        return get

    def e_Attribute(self, node: n.Attribute):
        from .builtins import _RemoteHandle as remote

        rt = self.rt
        container = self.expr(node.value)
        attr = node.attr

        def get(frame):
            target = container(frame)
            if type(target) is StructValue:
                try:
                    return target.members[attr]
                except KeyError:
                    raise rt.error("undefined", f"the struct has no member '{attr}'",
                                   node) from None
            if type(target) is Unknown:
                return target.plain()
            if type(target) is remote:  # an XML-RPC server's dotted method names
                return target.member(attr)
            raise rt.error("type", f"a {type_name(target)} has no field '{attr}'", node)

        return get

    def e_Run(self, node: n.Run):
        rt = self.rt
        name = node.thread
        return lambda frame: rt.start_thread(name, node)

    def e_Call(self, node: n.Call):
        rt = self.rt
        args = [self.expr(a) for a in node.args]
        if isinstance(node.func, n.Attribute):
            keywords = [(k.name, self.expr(k.value)) for k in node.keywords]
            receiver = self.expr(node.func.value)
            method = node.func.attr

            def call_method(frame):
                return rt.builtins.call_method(
                    receiver(frame), method, [a(frame) for a in args],
                    {k: v(frame) for k, v in keywords}, node)

            return call_method
        if not isinstance(node.func, n.Name):
            raise rt.error("call", "only functions can be called", node)
        name = node.func.id
        # a def of the same name (collected before it runs) takes precedence at run time
        builtin = rt.builtins.prepare(name, len(args), tuple(k.name for k in node.keywords))
        if builtin is None:
            def builtin(values, named, node):
                return rt.builtins.call(name, values, named, node)
        functions = rt.functions
        # literal numbers given by name (a=1.2, v=0.25) are the same at every call
        fixed = {k.name: value[0] for k in node.keywords
                 if (value := _constants([k.value])) is not None}
        keywords = [(k.name, self.expr(k.value)) for k in node.keywords if k.name not in fixed]

        unknown = rt.unknown
        shaping = rt.shaping
        arg_names = [reads(a) for a in node.args]
        keyword_names = {k.name: reads(k.value) for k in node.keywords}
        every = frozenset().union(*arg_names, *keyword_names.values())

        def call(frame):
            values = [a(frame) for a in args]
            named = dict(fixed)
            for k, v in keywords:
                named[k] = v(frame)
            function = functions.get(name)
            if function is not None:
                rt.calls += 1  # recursion without loops meets the wall-clock bound here
                if not rt.calls & 1023:
                    rt.check_deadline(node)
                if shaping.names:  # its parameters are shaped where their arguments are
                    sources = ([shaping.source(names) for names in arg_names],
                               {k: shaping.source(names) for k, names in keyword_names.items()})
                    return self.call_user(function, values, named, node, sources)
                return self.call_user(function, values, named, node)
            if unknown:
                found = first_unknown(values, named)
                if found is not None:
                    return unknown_call(rt, name, values, named, found, node, builtin)
            return builtin(values, named, node)

        if name not in MOTION_CALLS:
            return call
        plain = call

        def motion(frame):
            # a move whose target the run computed on a path chosen for a device
            if not shaping.names:
                return plain(frame)
            shaping.returned = None
            source = shaping.source(every)
            try:
                return plain(frame)
            finally:
                source = source or shaping.returned
                shaping.returned = None
                if source is not None:
                    shaping.moves.setdefault(node.span, source)

        return motion

    def call_user(self, function: _Function, args: list, named: dict, node: n.Call,
                  sources: tuple[list, dict] | None = None) -> Any:
        """Call ``function``; ``sources``: the device replies that shaped each positional and
        named argument (None for a plain one), when the run has shaped values."""
        rt = self.rt
        params = function.params
        # bound once per call shape by the one call binder (cached in the signature)
        binding = function.signature.bind(len(args), tuple(named))
        if type(binding) is not Binding:
            raise rt.error("arguments", binding.message, node, binding.hint)
        frame = Frame({}, top=False)
        bound = frame.vars
        for name, value in zip(binding.positional, args, strict=True):
            bound[name] = copy_value(value)
        for name, value in named.items():
            bound[name] = copy_value(value)
        defaults = function.defaults
        for index, name in binding.defaulted:
            bound[name] = copy_value(defaults[index](frame))
        if sources is not None:
            shaping = rt.shaping
            positional, by_name = sources
            for name, source in zip(binding.positional, positional, strict=True):
                shaping.assigned(name, source, True)
            for name in named:
                shaping.assigned(name, by_name.get(name), True)
            for _index, name in binding.defaulted:
                shaping.assigned(name, None, True)
        frame.local_names.update(params)
        rt.depth += 1
        if rt.depth > rt.config.max_call_depth:
            rt.depth = 0
            raise rt.error("call", f"calls nested deeper than {rt.config.max_call_depth}",
                           node, "is the recursion meant to end?")
        try:
            function.body(frame)
        finally:
            rt.depth -= 1
        return frame.retval


class _Halt(Exception):
    """``halt``: the program ends here."""


def _first_unknown_key(keys: list) -> Unknown | None:
    for key in keys:
        if type(key) is Unknown:
            return key
    return None


def _check_bounds(position: int, size: int, rt: Interpreter, node: n.Node) -> None:
    if not 0 <= position < size:
        raise rt.error("index", f"index {position} is out of range (size {size})", node,
                       "indices count from 0")


def _bool_operand(value: Any, rt: Interpreter, node: n.BinOp) -> bool:
    if type(value) is bool:
        return value
    raise rt.error("type", f"'{node.op}' needs bools, not a {type_name(value)}", node)


def _operator_hint(op: str, a: Any, b: Any) -> str | None:
    if op == "+" and (type(a) is str or type(b) is str):
        return "join strings with str_cat(a, b); to_str(x) turns a value into a string"
    if type(a) is PoseValue or type(b) is PoseValue:
        return "combine poses with pose_add, pose_sub or pose_trans"
    return None


def assigned_names(module: n.Module) -> frozenset[str]:
    """The names a program assigns anywhere (``name = ...``, ``global name = ...``)."""
    names = set()
    for node in n.walk(module):
        if isinstance(node, n.Assign) and isinstance(node.target, n.Name):
            names.add(node.target.id)
        elif isinstance(node, n.Declare):
            names.add(node.name)
    return frozenset(names)


def _shaped_value(shaping: Shaping, names: frozenset[str]) -> str | None:
    """The device reply that shaped a value just computed from an expression reading
    ``names`` (see :mod:`urdsl.runtime.shaped`): a shaped name it read, or a function that
    returned a shaped value; None when plain. Takes :attr:`Shaping.returned`."""
    source = shaping.source(names) if names else None
    if source is None:
        source = shaping.returned
    shaping.returned = None
    return source


def _name_hint(name: str, frame: Frame, rt: Interpreter) -> str | None:
    import difflib

    known = list(rt.globals) + list(frame.local_names) + list(rt.functions)
    close = difflib.get_close_matches(name, known, n=1)
    if close:
        return f"did you mean '{close[0]}'?"
    if frame.top:
        return None
    return "inside a function or thread, assign it first or declare it global at the top"


def _device_reply(node: n.BinOp) -> tuple[str, object] | None:
    """For ``read(...) == constant`` (either side), where the read is a device read with
    constant arguments (``modbus_get_signal_status("JOB") == 2``): the read as text and the
    constant; else None."""
    from ..script.printer import format_expr
    from .unknown import DEVICE_READS

    literals = (n.Number, n.String, n.Bool)
    for call, other in ((node.left, node.right), (node.right, node.left)):
        while isinstance(call, n.Paren):
            call = call.expr
        while isinstance(other, n.Paren):
            other = other.expr
        if (isinstance(call, n.Call) and isinstance(call.func, n.Name)
                and call.func.id in DEVICE_READS and isinstance(other, literals)
                and all(isinstance(arg, literals) for arg in call.args)
                and not call.keywords):
            return format_expr(call), other.value
    return None


def _no_thread(handle: Any) -> bool:
    """A thread variable that was never given a thread: programs initialise one to ``0`` and
    ``join``/``kill`` it before any ``run`` — UR's own External Control script
    (Universal_Robots_Client_Library, resources/external_control.urscript) sets
    ``thread_move = 0`` and joins it on the first command of every session, so the
    controller takes both as doing nothing."""
    return type(handle) is int and handle == 0

