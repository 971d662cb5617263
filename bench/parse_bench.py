"""Parse a generated 100,000-line toolpath and compare with CPython's ``ast.parse``.

The program is one ``def`` holding ``movel(p[...], a=..., v=..., r=...)`` lines, the shape of
CAM-generated toolpaths. The movel lines alone are valid Python, so ``ast.parse`` (CPython's
C parser, building Python's syntax tree) reads the same lines as the reference.

Run: ``.venv/bin/python bench/parse_bench.py [--lines N] [--repeat R]``. Prints lines/s for
both, the ratio (ours / ast.parse; > 1 means we are faster) and the peak memory (RSS) of
parsing our tree. Not part of the test run.
"""

from __future__ import annotations

import argparse
import ast
import gc
import math
import resource
import sys
import time


def toolpath_lines(count: int) -> list[str]:
    """``count`` blended movel lines along a spiral (metres, radians)."""
    lines = []
    for i in range(count):
        angle = i * 0.01
        radius = 0.05 + 0.1 * (i % 1000) / 1000
        x = 0.4 + radius * math.cos(angle)
        y = -0.1 + radius * math.sin(angle)
        z = 0.2 + 0.0001 * (i % 100)
        lines.append(
            f"  movel(p[{x:.6f}, {y:.6f}, {z:.6f}, 0.0, 3.14159, 0.0], "
            f"a=1.2, v=0.25, r=0.001)"
        )
    return lines


def best_of(repeat: int, work) -> float:
    best = math.inf
    for _ in range(repeat):
        gc.collect()
        start = time.perf_counter()
        work()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    from urdsl import parse

    body = toolpath_lines(args.lines)
    program = "def toolpath():\n" + "\n".join(body) + "\nend\n"
    python = "\n".join(line.strip() for line in body) + "\n"

    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    tree = parse(program, "toolpath.script")  # warm-up; builds the tables
    rss_peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    assert len(tree.body[0].body) == args.lines
    del tree

    ours = best_of(args.repeat, lambda: parse(program, "toolpath.script"))
    theirs = best_of(args.repeat, lambda: ast.parse(python))

    n = args.lines
    print(f"lines:                 {n:,}")
    print(f"urdsl.parse:           {n / ours:12,.0f} lines/s  ({ours:.2f} s)")
    print(f"ast.parse (CPython):   {n / theirs:12,.0f} lines/s  ({theirs:.2f} s)")
    print(f"ratio urdsl/ast.parse: {theirs / ours:.2f}x  (target >= 1.0)")
    print(f"peak RSS while parsing: {rss_peak / 1024:.0f} MiB "
          f"(before: {rss_before / 1024:.0f} MiB; target < 1024)")
    print(f"python {sys.version.split()[0]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
