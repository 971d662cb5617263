"""Fuzzing the checker (issue 14): random small valid programs through ``check_text``.

The generator writes URScript that parses: moves to random joint targets and poses, loops
(counted, endless with a sleep, broken out of), threads started, joined and killed, functions,
sleeps, device and register reads (the checker's environment answers "unknown"), lists and
arithmetic (a division by zero or an index past the end now and then). The property: the
check returns a report, raises nothing, ends within its wall-clock bound (plus a generous
margin for a loaded machine) and stays under a memory ceiling (``tracemalloc`` peak per
program); every finding names a line of the program.

Bounded and seeded like tests/test_fuzz_script.py: ``URDSL_FUZZ_SECONDS`` (default 3) and at
least :data:`MIN_CASES` programs; program ``i`` comes from ``random.Random(f"{seed}/check/
{i}")``, ``seed = URDSL_FUZZ_SEED`` (default 14); ``URDSL_FUZZ_CASE=i`` checks that one.
"""

from __future__ import annotations

import math
import random
import time
import tracemalloc

from test_fuzz_script import SEED, Findings, cases

import urdsl
from urdsl.verify.run import CheckOptions, check_text

MIN_CASES = 5

TIMEOUT = 2.0
"""The check's wall-clock bound (s) in these tests."""
MARGIN = 30.0
"""Wall-clock time (s) a check may take beyond TIMEOUT before it counts as not ending: the
checker bounds itself; this only catches a hang, on a machine as loaded as it may be."""
MEMORY_CEILING = 256 * 2**20
"""Peak of Python allocations (bytes) one small program's check may reach."""


def _number(rng: random.Random, low: float, high: float) -> str:
    value = rng.uniform(low, high)
    return repr(round(value, rng.choice((0, 1, 3, 6)))) if rng.random() < 0.9 else "0"


def _positive(rng: random.Random, low: float, high: float) -> str:
    return repr(round(rng.uniform(low, high), rng.choice((1, 3, 6))) or low)


class Program:
    """Writes one random program; ``text()`` is its URScript."""

    def __init__(self, rng: random.Random) -> None:
        self.rng = rng
        self.threads: list[str] = []
        self.functions: list[str] = []
        self.variables = ["n", "f", "q", "l"]
        self.lines: list[str] = []

    # -- expressions -----------------------------------------------------------------------

    def joints(self) -> str:
        rng = self.rng
        if rng.random() < 0.2:
            return rng.choice(("q", "get_actual_joint_positions()",
                               "get_inverse_kin(get_actual_tcp_pose())"))
        spread = rng.choice((0.3, 1.5, math.pi, 7.0))
        start = (0.0, -1.57, 1.57, -1.57, -1.57, 0.0)
        return "[" + ", ".join(_number(rng, s - spread, s + spread) for s in start) + "]"

    def pose(self) -> str:
        rng = self.rng
        if rng.random() < 0.2:
            return rng.choice(("get_actual_tcp_pose()", "pose_trans(get_actual_tcp_pose(), "
                               "p[0, 0, 0.01, 0, 0, 0])", "get_forward_kin()"))
        xyz = [_number(rng, -0.9, 0.9) for _ in range(3)]
        rotation = [_number(rng, -3.2, 3.2) for _ in range(3)]
        return "p[" + ", ".join(xyz + rotation) + "]"

    def number(self, depth: int = 0) -> str:
        rng = self.rng
        kind = rng.randrange(12 if depth < 3 else 5)
        if kind == 0:
            return _number(rng, -100, 100)
        if kind == 1:
            return str(rng.randrange(-5, 20))
        if kind == 2:
            return "n"
        if kind == 3:
            return "f"
        if kind == 4:
            return rng.choice(("read_input_integer_register(0)", "get_standard_analog_in(0)",
                               "read_input_float_register(3)", "l[0]", "get_list_length(l)",
                               "length(l)"))
        op = rng.choice(("+", "-", "*", "/", "%"))
        if kind in (5, 6, 7):
            return f"({self.number(depth + 1)} {op} {self.number(depth + 1)})"
        if kind == 8:
            function = rng.choice(("sin", "cos", "sqrt", "floor", "ceil", "d2r", "r2d", "norm"))
            return f"{function}({self.number(depth + 1)})"
        if kind == 9:
            return f"pow({self.number(depth + 1)}, {rng.randrange(-3, 4)})"
        if kind == 10 and self.functions:
            return f"{rng.choice(self.functions)}({self.number(depth + 1)})"
        return f"q[{rng.choice((0, 1, 2, 3, 4, 5, 6))}]"

    def condition(self) -> str:
        rng = self.rng
        kind = rng.randrange(5)
        if kind == 0:
            return f"get_digital_in({rng.randrange(8)})"
        if kind == 1:
            return rng.choice(("True", "False", "is_steady()"))
        compare = rng.choice(("<", ">", "<=", ">=", "==", "!="))
        test = f"{self.number()} {compare} {self.number()}"
        if kind == 2:
            return f"not ({test})"
        if kind == 3:
            return f"{test} and get_digital_in({rng.randrange(8)}) or n > 3"
        return test

    # -- statements -------------------------------------------------------------------------

    def block(self, depth: int, size: int, pad: str) -> list[str]:
        lines: list[str] = []
        for _ in range(size):
            lines += self.statement(depth, pad)
        return lines or [pad + "sync()"]

    def statement(self, depth: int, pad: str) -> list[str]:
        rng = self.rng
        kind = rng.randrange(20 if depth < 3 else 11)
        speed = f"a={_positive(rng, 0.1, 3)}, v={_positive(rng, 0.05, 2)}"
        if kind == 0:
            timing = rng.choice(("", f", t={_number(rng, 0.1, 5)}", f", r={_number(rng, 0, 0.05)}"))
            return [f"{pad}movej({self.joints()}, {speed}{timing})"]
        if kind == 1:
            return [f"{pad}movel({self.pose()}, {speed})"]
        if kind == 2:
            return [f"{pad}{rng.choice(('movej', 'movel', 'movep'))}({self.pose()}, {speed})"]
        if kind == 3:
            return [f"{pad}sleep({_number(self.rng, 0, 0.5)})", f"{pad}sync()"]
        if kind == 4:
            return [f"{pad}n = {self.number()}"]
        if kind == 5:
            return [f"{pad}f = {self.number()}"]
        if kind == 6:
            items = ", ".join(self.number(2) for _ in range(rng.randrange(1, 6)))
            return [f"{pad}l = [{items}]"]
        if kind == 7:
            return [f"{pad}l[{rng.choice((0, 0, 1, 2, 3, -1))}] = {self.number(2)}"]
        if kind == 8:
            return [f"{pad}set_digital_out({rng.randrange(8)}, {rng.choice(('True', 'False'))})"]
        if kind == 9:
            return [f'{pad}textmsg("n = ", n)']
        if kind == 10:
            return [f"{pad}q = {self.joints()}"]
        inner = pad + "  "
        if kind in (11, 12):
            counter = f"i{depth}"
            return ([f"{pad}{counter} = 0", f"{pad}while {counter} < {rng.randrange(0, 6)}:"]
                    + self.block(depth + 1, rng.randrange(1, 4), inner)
                    + [f"{inner}{counter} = {counter} + 1", f"{pad}end"])
        if kind == 13:  # endless: runs until --max-time, or breaks on an input
            body = self.block(depth + 1, rng.randrange(0, 3), inner)
            stop = rng.choice(("", f"{inner}if get_digital_in(1):\n{inner}  break\n{inner}end"))
            rest = [f"{inner}sleep({_number(self.rng, 0.01, 0.5)})"] + ([stop] if stop else [])
            return [f"{pad}while True:"] + body + rest + [f"{pad}end"]
        if kind in (14, 15):
            lines = [f"{pad}if {self.condition()}:"] + self.block(depth + 1, 2, inner)
            if rng.random() < 0.5:
                lines += [f"{pad}elif {self.condition()}:"] + self.block(depth + 1, 1, inner)
            if rng.random() < 0.5:
                lines += [f"{pad}else:"] + self.block(depth + 1, 2, inner)
            return lines + [f"{pad}end"]
        if kind == 16 and self.threads:
            handle = f"h{depth}"
            ending = rng.choice(("join", "kill", "sleep", ""))
            lines = [f"{pad}{handle} = run {rng.choice(self.threads)}()"]
            if ending == "sleep":
                return lines + [f"{pad}sleep({_number(rng, 0, 1)})", f"{pad}kill {handle}"]
            return lines + ([f"{pad}{ending} {handle}"] if ending else [])
        if kind == 17:
            return [f"{pad}q = get_inverse_kin({self.pose()})"]
        if kind == 18:
            return [f"{pad}{rng.choice(('stopj', 'stopl'))}({_number(rng, 0.5, 5)})"]
        if rng.random() < 0.3:
            return [pad + line for line in self.hostile().split("\n")]
        return [f"{pad}f = {self.number()}"]

    def hostile(self) -> str:
        """A statement of the kinds issue 14 found to hang the checker or eat its memory."""
        rng = self.rng
        choices = [
            "while True:\n  sleep(0)\nend",
            'socket_read_byte_list(1, "g", 0)',
            f"movej(q, t={rng.choice(('1e4', '1e6', '1e300'))})",
            f"movej(q, a={rng.choice(('1e-300', '1e300'))}, v={rng.choice(('1e-300', '1e300'))})",
            "g = [1]\nwhile True:\n  g = [g, g]\nend",
            's = "ab"\nwhile True:\n  s = str_cat(s, s)\nend',
            "rec(0)",
            f"l = make_list({rng.choice(('10', '1e9', '-1', '0.5'))}, 0)",
        ]
        if self.threads:
            worker = rng.choice(self.threads)
            choices.append(f"while True:\n  h = run {worker}()\n  sync()\nend")
        return rng.choice(choices)

    def text(self) -> str:
        rng = self.rng
        head = ["global n = 0", "global f = 0.0", "global l = [0, 0, 0]",
                "global q = [0, -1.57, 1.57, -1.57, -1.57, 0]"]
        head += ["def rec(x):", "  return rec(x + 1)", "end"]
        for index in range(rng.randrange(0, 3)):
            name = f"fn{index}"
            body = self.block(2, rng.randrange(1, 3), "  ")
            head += [f"def {name}(x):"] + body + [f"  return x * {_number(rng, -2, 2)}", "end"]
            self.functions.append(name)
        for index in range(rng.randrange(0, 3)):
            name = f"worker{index}"
            body = self.block(2, rng.randrange(1, 4), "  ")
            head += [f"thread {name}():"] + body + ["end"]
            self.threads.append(name)
        main = self.block(0, rng.randrange(1, 12), "")
        return "\n".join(head + main) + "\n"


def program(case: int) -> tuple[str, CheckOptions]:
    """Program ``case`` and the options it is checked with."""
    rng = random.Random(f"{SEED}/check/{case}")
    text = Program(rng).text()
    options = CheckOptions(
        robot=rng.choice(("ur5e", "ur10e", "ur3", "ur16e")),
        max_time=rng.choice((1.0, 5.0, 20.0)),
        self_collision=rng.random() < 0.2,
        timeout=TIMEOUT,
    )
    return text, options


def test_generated_programs_parse():
    # the generator writes URScript: a check of a syntax error would test nothing
    for case in range(30):
        urdsl.parse(program(case)[0], filename=f"case{case}.script")


def test_check_of_random_programs_ends_and_stays_small(tmp_path):
    codes: set[str] = set()
    findings = Findings("check", tmp_path)
    # first imports and caches (kinematics, IK) are not the program's: made before measuring
    check_text("movej([0, -1.5, 1.5, -1.5, -1.5, 0])\n", options=CheckOptions(timeout=30))
    tracemalloc.start()
    try:
        for case in cases("check", MIN_CASES):
            if findings.full:
                break
            text, options = program(case)
            tracemalloc.reset_peak()
            before = tracemalloc.get_traced_memory()[0]
            started = time.monotonic()
            try:
                report = check_text(text, "fuzz.script", options=options)
                elapsed = time.monotonic() - started
                peak = tracemalloc.get_traced_memory()[1] - before
                assert elapsed < TIMEOUT + MARGIN, f"the check took {elapsed:.1f} s"
                assert peak < MEMORY_CEILING, f"the check peaked at {peak / 2**20:.0f} MiB"
                lines = text.count("\n")
                for finding in report.findings:
                    assert 0 <= finding.span.line <= lines, finding
                    codes.add(finding.code)
                    finding.diagnostic().render()
            except Exception as error:  # noqa: BLE001 - any escape is the finding
                findings.add(case, text, error)
    finally:
        tracemalloc.stop()
    print(f"finding codes seen: {' '.join(sorted(codes))}")
    findings.check()
