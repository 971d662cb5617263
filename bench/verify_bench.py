"""How much faster than the robot does ``urdsl check`` run?

Checks the generated toolpath program (``programs/toolpath.py``: thousands of blended
movels) and prints the wall time of each stage, the robot time the program would take, their
ratio, and the peak memory. The target is checking at least 1,000x faster than the robot
runs the program, with peak memory under 2 GB.

    .venv/bin/python bench/verify_bench.py            # 10,000 moves on a UR5e
    .venv/bin/python bench/verify_bench.py --moves 2000 --robot ur10e
"""

from __future__ import annotations

import argparse
import importlib.util
import resource
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
    args = parser.parse_args()

    from urdsl.script.parser import parse
    from urdsl.script.printer import format as format_tree
    from urdsl.verify.run import CheckOptions, check_tree

    started = time.perf_counter()
    text = format_tree(load_toolpath().make_program(args.moves).tree())
    generated = time.perf_counter()
    tree = parse(text, "toolpath.script")
    parsed = time.perf_counter()
    options = CheckOptions(robot=args.robot)
    report = check_tree(tree, "toolpath.script", options)
    checked = time.perf_counter()

    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    check_time = checked - generated
    lines = text.count("\n")
    print(f"program: {args.moves:,} moves, {lines:,} lines, robot {args.robot}")
    print(f"generate (DSL + printer): {generated - started:7.3f} s")
    print(f"parse:                    {parsed - generated:7.3f} s")
    print(f"run + sample + checks:    {checked - parsed:7.3f} s "
          f"({len(report.trace.times):,} samples at {report.trace.dt * 1000:g} ms)")
    print(f"robot time (cycle time):  {report.cycle_time:9.1f} s")
    print(f"findings: {report.count('error')} error(s), {report.count('warning')} warning(s)")
    print(f"ratio robot time / check time (parse + check): "
          f"{report.cycle_time / check_time:,.0f}x  (target >= 1,000x)")
    print(f"peak memory: {peak_mib:,.0f} MiB (target < 2,048 MiB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
