"""``urdsl models``, ``urdsl fk`` and ``urdsl ik``: the kinematics from the command line.

Joint angles are in rad unless ``--deg`` says degrees; poses are URScript poses
``x y z rx ry rz`` (m, rotation vector in rad) in the controller's Base frame. Exit status: 0
success, 1 the pose is out of reach (``ik``), 2 usage errors (unknown model, bad numbers).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from .._cli import EXIT_OK, EXIT_PROBLEMS, UsageError
from .calibration import Calibration
from .errors import KinematicsError
from .models import MODELS, model_spec

__all__ = ["add_commands"]


def _numbers(values: list[str], count: int, what: str) -> np.ndarray:
    if len(values) != count:
        raise UsageError(f"{what} needs {count} numbers, got {len(values)}")
    try:
        array = np.array([float(v) for v in values])
    except ValueError as error:
        raise UsageError(f"{what}: {error}") from None
    if not np.all(np.isfinite(array)):
        raise UsageError(f"{what} must be finite numbers")
    return array


def _robot(args: argparse.Namespace):
    from .robot import Robot

    try:
        spec = model_spec(args.model)
        calibration = Calibration.from_toml(args.calibration, model=spec.name) \
            if args.calibration else None
        return Robot(spec, calibration)
    except KinematicsError as error:
        raise UsageError(str(error)) from None


def _format(values, digits: int = 6) -> str:
    """Numbers with at most ``digits`` decimals, trailing zeros dropped, no "-0"."""
    texts = []
    for value in values:
        text = f"{float(value):.{digits}f}".rstrip("0").rstrip(".")
        texts.append("0" if text in ("-0", "") else text)
    return ", ".join(texts)


def _joints_out(q, degrees: bool) -> str:
    return "[" + _format(np.degrees(q) if degrees else q, 4 if degrees else 6) + "]"


def cmd_models(args: argparse.Namespace) -> int:
    print(f"{'model':<9} {'series':<10} {'reach':>6} {'payload':>8}   "
          f"{'d1':>8} {'a2':>8} {'a3':>8} {'d4':>8} {'d5':>8} {'d6':>8}")
    for spec in MODELS.values():
        print(f"{spec.name:<9} {spec.generation:<10} {spec.reach:>5.2f}m {spec.payload:>6.1f}kg   "
              + " ".join(f"{v:>8.5g}" for v in (spec.d1, spec.a2, spec.a3, spec.d4, spec.d5,
                                                spec.d6)))
    print("lengths in m; joint limits ±2π (UR3/UR3e wrist 3 unlimited); "
          "see 'urdsl fk --help'")
    return EXIT_OK


def cmd_fk(args: argparse.Namespace) -> int:
    from . import pose

    robot = _robot(args)
    q = _numbers(args.q, 6, "q")
    if args.deg:
        q = np.radians(q)
    tcp = _numbers(args.tcp, 6, "--tcp") if args.tcp else None
    T = robot.fk(q, tcp)
    if args.matrix:
        for row in T:
            print(" ".join(f"{v: .9f}" for v in row))
    else:
        print("p[" + _format(pose.from_matrix(T)) + "]")
    return EXIT_OK


def cmd_ik(args: argparse.Namespace) -> int:
    robot = _robot(args)
    target = _numbers(args.pose, 6, "pose")
    tcp = _numbers(args.tcp, 6, "--tcp") if args.tcp else None
    near = _numbers(args.near, 6, "--near") if args.near else np.zeros(6)
    if args.deg:
        near = np.radians(near)
    try:
        if args.all:
            solutions = robot.ik_all(target, tcp, q6_hint=float(near[5]))
            if len(solutions) == 0:
                robot.ik(target, near, tcp)  # raises with the distance
            for solution in solutions:
                print(_joints_out(solution, args.deg))
        else:
            print(_joints_out(robot.ik(target, near, tcp), args.deg))
    except KinematicsError as error:
        print(f"urdsl: {error}", file=sys.stderr)
        return EXIT_PROBLEMS
    return EXIT_OK


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("model", metavar="MODEL", help="robot model, e.g. ur5e (see 'urdsl models')")
    p.add_argument("--tcp", nargs=6, metavar="V",
                   help="TCP offset x y z rx ry rz in the flange frame (m, rad)")
    p.add_argument("--calibration", metavar="FILE",
                   help="DH corrections of this robot (TOML, see the README)")
    p.add_argument("--deg", action="store_true", help="joint angles in degrees")


def add_commands(commands) -> None:
    """Register ``models``, ``fk`` and ``ik`` with the ``urdsl`` command."""
    p = commands.add_parser(
        "models", help="list the supported UR models with reach, payload and DH lengths",
        description="List the UR arms urdsl models: series, reach, payload and the DH "
        "lengths d1, a2, a3, d4, d5, d6 (m, standard DH).")
    p.set_defaults(run=cmd_models)

    p = commands.add_parser(
        "fk", help="forward kinematics: joints to the TCP pose",
        description="Print the TCP pose p[x, y, z, rx, ry, rz] (m, rotation vector in rad) "
        "in the controller's Base frame for six joint angles (rad, or degrees with --deg).",
        epilog="examples:\n  urdsl fk ur5e 0 -1.5708 1.5708 -1.5708 -1.5708 0\n"
        "  urdsl fk ur10 --deg 0 -90 90 -90 -90 0 --tcp 0 0 0.15 0 0 0\n"
        "  urdsl fk ur5e --matrix 0 0 0 0 0 0",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    _common(p)
    p.add_argument("q", nargs=6, metavar="Q", help="joint angles base … wrist 3")
    p.add_argument("--matrix", action="store_true", help="print the 4x4 matrix instead")
    p.set_defaults(run=cmd_fk)

    p = commands.add_parser(
        "ik", help="inverse kinematics: a TCP pose to joints, as the controller chooses",
        description="Print the joint angles for a TCP pose x y z rx ry rz (m, rad) in the "
        "controller's Base frame: the solution closest to --near (as get_inverse_kin and "
        "movej do), or all of them with --all. Exit 1 when the pose is out of reach; the "
        "message says by how much.",
        epilog="examples:\n  urdsl ik ur5e -- -0.5 -0.2 0.4 0 3.1416 0 --near 0 -1.57 1.57 "
        "-1.57 -1.57 0\n  urdsl ik ur5e --all -- -0.5 -0.2 0.4 0 3.1416 0 --deg",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    _common(p)
    p.add_argument("pose", nargs=6, metavar="P", help="target pose x y z rx ry rz")
    p.add_argument("--near", nargs=6, metavar="Q",
                   help="joints to be closest to (default: all zero)")
    p.add_argument("--all", action="store_true", help="print every solution (up to 8)")
    p.set_defaults(run=cmd_ik)
