"""Lint a generated toolpath program and compare with ruff linting the same lines as Python.

No other URScript linter exists, so the peer is the closest tool people run on the same text:
the program's ``movel(p[...], a=..., v=..., r=...)`` lines are valid Python (with ``p`` a
name), and ruff (Rust, the linter urdsl's interface imitates) checks them with its default
rules. urdsl's time includes parsing and every rule. Also prints urdsl's parse time alone
(the floor of the linter).

Run: ``.venv/bin/python bench/lint_bench.py [--lines N] [--repeat R]``. Not part of the tests.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
from parse_bench import toolpath_lines  # noqa: E402

from urdsl.lint import lint_text  # noqa: E402
from urdsl.script.parser import parse  # noqa: E402


def best(function, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=20_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    lines = toolpath_lines(args.lines)
    program = "def toolpath():\n" + "".join(f"  {line}\n" for line in lines) + "end\n"
    python = "p = list\n" + "".join(f"{line.replace('p[', 'p([').replace('],', ']),')}\n"
                                     for line in lines)
    parse(program)  # build the parser tables once
    t_parse = best(lambda: parse(program, "toolpath.script"), args.repeat)
    found = []
    t_lint = best(lambda: found.__setitem__(slice(None), lint_text(program, "tp.script")),
                  args.repeat)
    print(f"urdsl parse: {args.lines / t_parse:,.0f} lines/s")
    print(f"urdsl lint:  {args.lines / t_lint:,.0f} lines/s ({len(found)} findings), "
          f"{t_lint / t_parse:.2f}x the parse time")
    ruff = shutil.which("ruff") or os.path.join(os.path.dirname(sys.executable), "ruff")
    if not os.path.exists(ruff):
        print("ruff not installed: no peer comparison")
        return
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "toolpath.py")
        with open(path, "w") as handle:
            handle.write(python)
        command = [ruff, "check", "--no-cache", "--isolated", "--quiet", "--exit-zero", path]
        t_ruff = best(lambda: subprocess.run(command, check=True, capture_output=True),
                      args.repeat)
    print(f"ruff check:  {args.lines / t_ruff:,.0f} lines/s (process start included)")
    print(f"ratio urdsl lint / ruff speed: {t_ruff / t_lint:.2f} (> 1: urdsl faster)")


if __name__ == "__main__":
    main()
