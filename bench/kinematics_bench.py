"""Throughput of urdsl's kinematics next to its peers, in one run.

* FK: ``Robot.fk_many`` (vectorised NumPy, closed form) on N joint vectors, against a Python
  loop calling Pinocchio's ``forwardKinematics`` + ``updateFramePlacement`` per configuration
  and against ur-analytic-ik's compiled ``forward_kinematics`` called per configuration.
* IK: ``Robot.ik_all_many`` (all eight analytic solutions of N poses, vectorised) and
  ``Robot.ik_many`` (plus the controller's choice closest to q_near), against
  ur-analytic-ik's compiled ``inverse_kinematics`` and ``inverse_kinematics_closest`` per pose.
* Calibrated arm: ``fk_many`` on the general DH product and ``ik_many`` with Newton refinement.
* Collision: ``CollisionModel.check`` samples/s (UR5 convex hulls, UR5e capsules) with a floor
  and a box.

Run: ``.venv/bin/python bench/kinematics_bench.py [--model ur5e] [--n 200000]``. Rates are
best of ``--repeat`` runs; a ratio > 1 means urdsl is faster. Not part of the test run.
"""

from __future__ import annotations

import argparse
import gc
import math
import time

import numpy as np


def best_of(repeat: int, work) -> float:
    best = math.inf
    for _ in range(repeat):
        gc.collect()
        start = time.perf_counter()
        work()
        best = min(best, time.perf_counter() - start)
    return best


def row(label: str, count: int, seconds: float) -> float:
    rate = count / seconds
    print(f"  {label:<58} {rate:>12,.0f} /s  {seconds / count * 1e6:>8.2f} µs each")
    return rate


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="ur5e")
    parser.add_argument("--n", type=int, default=200_000, help="batch size")
    parser.add_argument("--loop", type=int, default=20_000, help="per-call loop length")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    import pinocchio as pin

    from urdsl.kinematics import Calibration, Robot
    from urdsl.kinematics.collision import CollisionModel

    try:
        import ur_analytic_ik
    except ImportError:  # pragma: no cover - the test extra installs it
        ur_analytic_ik = None

    robot = Robot.model(args.model)
    rng = np.random.default_rng(0)
    Q = rng.uniform(-math.pi, math.pi, (args.n, 6))
    loop_q = Q[: args.loop]
    poses = robot.fk_many(Q)
    loop_poses = np.ascontiguousarray(poses[: args.loop])
    near = Q + rng.normal(0.0, 0.2, Q.shape)

    print(f"model {robot.name}, batch {args.n:,}, per-call loops {args.loop:,}, "
          f"best of {args.repeat}")

    print("forward kinematics")
    fk_rate = row("urdsl Robot.fk_many (NumPy, batched)", args.n,
                  best_of(args.repeat, lambda: robot.fk_many(Q)))
    model, data = robot.pin_model, robot.pin_data
    frame = model.getFrameId("tool0")

    def pinocchio_loop():
        for q in loop_q:
            pin.forwardKinematics(model, data, q)
            pin.updateFramePlacement(model, data, frame)

    pin_rate = row("Pinocchio forwardKinematics, Python loop", args.loop,
                   best_of(args.repeat, pinocchio_loop))
    row("urdsl Robot.fk (Pinocchio, one call)", args.loop,
        best_of(args.repeat, lambda: [robot.fk(q) for q in loop_q]))
    peer = getattr(ur_analytic_ik, robot.name) if ur_analytic_ik else None
    uaik_fk = None
    if peer is not None:
        uaik_fk = row("ur-analytic-ik forward_kinematics, per call", args.loop,
                      best_of(args.repeat, lambda: [peer.forward_kinematics(*q)
                                                    for q in loop_q]))

    print("inverse kinematics")
    ik_all_rate = row("urdsl Robot.ik_all_many (8 solutions, batched)", args.n,
                      best_of(args.repeat, lambda: robot.ik_all_many(poses)))
    ik_rate = row("urdsl Robot.ik_many (+ choice closest to q_near)", args.n,
                  best_of(args.repeat, lambda: robot.ik_many(poses, near)))
    row("urdsl Robot.ik (one pose)", args.loop // 10,
        best_of(args.repeat, lambda: [robot.ik(T, q) for T, q in
                                      zip(loop_poses[: args.loop // 10],
                                          near[: args.loop // 10], strict=True)]))
    uaik_ik = uaik_closest = None
    if peer is not None:
        uaik_ik = row("ur-analytic-ik inverse_kinematics, per call", args.loop,
                      best_of(args.repeat, lambda: [peer.inverse_kinematics(T)
                                                    for T in loop_poses]))
        uaik_closest = row("ur-analytic-ik inverse_kinematics_closest, per call", args.loop,
                           best_of(args.repeat, lambda: [
                               peer.inverse_kinematics_closest(T, *q)
                               for T, q in zip(loop_poses, near, strict=False)]))

    print("calibrated arm (DH corrections)")
    calibrated = Robot.model(robot.name, Calibration(
        delta_theta=[1e-4, -2e-4, 3e-4, 1e-4, -1e-4, 0], delta_a=[0, 2e-4, -3e-4, 0, 0, 0],
        delta_d=[1e-4, 0, 0, -1e-4, 1e-4, 0], delta_alpha=[2e-4, 0, -1e-4, 1e-4, 0, 0]))
    small = Q[: args.n // 10]
    row("urdsl fk_many (general DH product)", len(small),
        best_of(args.repeat, lambda: calibrated.fk_many(small)))
    calibrated_poses = calibrated.fk_many(small)
    row("urdsl ik_many (analytic + Newton refinement)", len(small),
        best_of(max(1, args.repeat - 1),
                lambda: calibrated.ik_many(calibrated_poses, near[: len(small)])))

    print("collision checks (floor + box)")
    for name in ("ur5", args.model if args.model not in ("ur3", "ur5", "ur10") else "ur5e"):
        checker = CollisionModel(Robot.model(name), tool_radius=0.04)
        checker.add_plane((0, 0, 1), 0.0, "floor")
        checker.add_box((0.3, 0.3, 0.3), (-0.5, 0.2, 0.15, 0, 0, 0), "box")
        samples = Q[:5000]
        kind = "convex hulls of URDF meshes" if checker.uses_meshes else "DH capsules"
        checker.check(samples[:10], tcp=[0, 0, 0.15, 0, 0, 0])
        row(f"{name} CollisionModel.check ({kind})", len(samples),
            best_of(args.repeat, lambda c=checker, s=samples: c.check(
                s, tcp=[0, 0, 0.15, 0, 0, 0])))

    print("ratios (urdsl / peer; > 1: urdsl faster)")
    print(f"  batched FK vs Pinocchio Python loop:           {fk_rate / pin_rate:8.1f}x")
    if uaik_fk:
        print(f"  batched FK vs ur-analytic-ik per call:         {fk_rate / uaik_fk:8.1f}x")
    if uaik_ik:
        print(f"  batched IK (all) vs ur-analytic-ik per call:   {ik_all_rate / uaik_ik:8.1f}x")
        print(f"  batched IK (nearest) vs ur-analytic-ik closest:"
              f" {ik_rate / uaik_closest:7.1f}x")
    print("targets: >= 1,000,000 FK/s and >= 200,000 IK/s batched: "
          f"FK {'met' if fk_rate >= 1e6 else 'NOT met'}, "
          f"IK {'met' if ik_rate >= 2e5 else 'NOT met'} (nearest), "
          f"{'met' if ik_all_rate >= 2e5 else 'NOT met'} (all)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
