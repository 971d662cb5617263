"""How much faster than the robot does ``urdsl check`` run?

Checks the generated toolpath program (``programs/toolpath.py``: thousands of blended
movels) and prints the wall time of each stage, the robot time the program would take, their
ratio, and the peak memory. The target is checking at least 1,000x faster than the robot
runs the program, with peak memory under 2 GB.

Two ratios are printed, each from the median of ``--repeat`` runs (this machine's timings
vary by ±30 % from run to run, so the best run is shown too):

* check: the syntax tree in hand, as ``urdsl check programs/toolpath.py`` has it once the
  DSL program is built — run, sample at the controller rate, every check;
* parse + check: the same program as ``.script`` text, as ``urdsl check toolpath.script``
  does it.

    .venv/bin/python bench/verify_bench.py            # 10,000 moves on a UR5e
    .venv/bin/python bench/verify_bench.py --moves 2000 --robot ur10e --repeat 5
"""

from __future__ import annotations

import argparse
import importlib.util
import resource
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def load_toolpath():
    spec = importlib.util.spec_from_file_location("toolpath", ROOT / "programs" / "toolpath.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--moves", type=int, default=10_000)
    parser.add_argument("--robot", default="ur5e")
    parser.add_argument("--repeat", type=int, default=3, help="runs of parse and check")
    args = parser.parse_args()

    from urdsl.script.parser import parse
    from urdsl.script.printer import format as format_tree
    from urdsl.verify.run import CheckOptions, check_tree

    started = time.perf_counter()
    program = load_toolpath().make_program(args.moves)
    tree = program.tree()
    built = time.perf_counter()
    text = format_tree(tree)
    printed = time.perf_counter()
    from urdsl.kinematics import Robot

    loading = time.perf_counter()
    Robot.model(args.robot)  # built once here; each check builds its own (about 2 ms)
    loaded = time.perf_counter()
    parses, checks = [], []
    report = None
    for _ in range(max(1, args.repeat)):
        begin = time.perf_counter()
        parsed = parse(text, "toolpath.script")
        middle = time.perf_counter()
        report = check_tree(parsed, "toolpath.script", CheckOptions(robot=args.robot))
        end = time.perf_counter()
        parses.append(middle - begin)
        checks.append(end - middle)
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    robot_time = report.cycle_time
    check = statistics.median(checks)
    totals = [p + c for p, c in zip(parses, checks, strict=True)]
    both = statistics.median(totals)
    lines = text.count("\n")
    print(f"program: {args.moves:,} moves, {lines:,} lines, robot {args.robot}, "
          f"{len(checks)} run(s)")
    print(f"DSL program -> syntax tree:  {built - started:7.3f} s (the user's Python)")
    print(f"syntax tree -> .script text: {printed - built:7.3f} s")
    print(f"parse:  median {statistics.median(parses):6.3f} s, best {min(parses):6.3f} s")
    print(f"robot model:                 {loaded - loading:7.3f} s (before the runs)")
    print(f"check:  median {check:6.3f} s, best {min(checks):6.3f} s "
          f"({len(report.trace.times):,} samples at {report.trace.dt * 1000:g} ms)")
    print("check runs: " + ", ".join(f"{c:.3f}" for c in checks) + " s")
    print(f"robot time (cycle time): {robot_time:9.1f} s")
    print(f"findings: {report.count('error')} error(s), {report.count('warning')} warning(s)")
    print(f"ratio robot time / check time:          {robot_time / check:7,.0f}x "
          f"(best run {robot_time / min(checks):,.0f}x; target >= 1,000x)")
    print(f"ratio robot time / (parse + check):     {robot_time / both:7,.0f}x "
          f"(best run {robot_time / min(totals):,.0f}x)")
    print(f"peak memory: {peak_mib:,.0f} MiB (target < 2,048 MiB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
