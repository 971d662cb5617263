"""Collision checks: capsule distances against an independent segment-distance reference,
obstacles at known distances, URDF meshes, cell files."""

from __future__ import annotations

import math

import numpy as np
import pytest

from urdsl.kinematics import KinematicsError, Robot, pose
from urdsl.kinematics.collision import LINKS, CollisionModel

DOWN = [0.0, math.pi, 0.0]   # rotation vector of a tool pointing straight down
HOME = np.array([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])   # forearm along −x, tool down


def segment_distance(p0, p1, q0, q1) -> float:
    """Distance between segments [p0, p1] and [q0, q1], by dense sampling refined with the
    closed form of the closest points of two lines (clamped)."""
    u, v, w = p1 - p0, q1 - q0, p0 - q0
    a, b, c, d, e = u @ u, u @ v, v @ v, u @ w, v @ w
    candidates = []
    denominator = a * c - b * b
    if denominator > 1e-14:
        s = np.clip((b * e - c * d) / denominator, 0, 1)
        t = np.clip((a * e - b * d) / denominator, 0, 1) if c > 0 else 0.0
        candidates.append((s, t))
    for s in (0.0, 1.0):
        t = np.clip((b * s + e) / c, 0, 1) if c > 0 else 0.0
        candidates.append((s, t))
    for t in (0.0, 1.0):
        s = np.clip((b * t - d) / a, 0, 1) if a > 0 else 0.0
        candidates.append((s, t))
    return min(float(np.linalg.norm(p0 + s * u - q0 - t * v)) for s, t in candidates)


def capsules_in_base(robot: Robot, q: np.ndarray) -> list[tuple[str, np.ndarray, np.ndarray,
                                                                float]]:
    """The capsule table of the collision module's docstring, evaluated independently."""
    spec = robot.spec
    d1, a2, a3, d4, d5, d6 = spec.d1, spec.a2, spec.a3, spec.d4, spec.d5, spec.d6
    s, f = 1.2 * d4, 0.15 * d4
    frames = robot.frames_many(q[None])[0]
    joint = [np.eye(4)]
    for i in range(6):
        rz = np.eye(4)
        rz[:2, :2] = [[math.cos(q[i]), -math.sin(q[i])], [math.sin(q[i]), math.cos(q[i])]]
        joint.append(frames[i] @ rz)

    def at(i, point):
        return (joint[i] @ np.append(point, 1.0))[:3]

    table = [("base", 0, (0, 0, 0), (0, 0, d1 - 0.63 * d5), 0.63 * d5),
             ("shoulder", 1, (0, 0, d1), (0, -s, d1), 0.63 * d5),
             ("upper_arm", 2, (0, 0, s), (a2, 0, s), 0.57 * d5),
             ("forearm", 3, (0, 0, f), (a3, 0, f), 0.42 * d5),
             ("forearm", 3, (0, 0, f), (0, 0, s), 0.42 * d5),
             ("wrist_1", 4, (0, 0, f), (0, 0, d4), 0.48 * d5),
             ("wrist_2", 5, (0, 0, 0), (0, 0, d5), 0.48 * d5),
             ("wrist_3", 6, (0, 0, 0), (0, 0, d6), 0.40 * d5)]
    return [(label, at(i, np.array(a, float)), at(i, np.array(b, float)), r)
            for label, i, a, b, r in table]


SKIPPED = {frozenset(p) for p in (
    ("base", "shoulder"), ("shoulder", "upper_arm"), ("upper_arm", "forearm"),
    ("forearm", "wrist_1"), ("wrist_1", "wrist_2"), ("wrist_2", "wrist_3"),
    ("base", "upper_arm"), ("forearm", "wrist_2"), ("forearm", "wrist_3"),
    ("wrist_1", "wrist_3"))}


@pytest.mark.parametrize("name", ["ur5e", "ur20", "ur8long"])
def test_capsule_distances_match_an_independent_reference(name):
    robot = Robot.model(name)
    model = CollisionModel(robot)
    floor = 0.02
    model.add_plane((0, 0, 1), floor, "floor")
    Q = np.random.default_rng(4).uniform(-math.pi, math.pi, (150, 6))
    result = model.check(Q)
    for q, distance, closest in zip(Q, result.distance, result.closest, strict=True):
        capsules = capsules_in_base(robot, q)
        reference = {}
        for i, (la, a0, a1, ra) in enumerate(capsules):
            if la != "base":
                reference[(la, "floor")] = min(reference.get((la, "floor"), np.inf),
                                               min(a0[2], a1[2]) - floor - ra)
            for lb, b0, b1, rb in capsules[i + 1:]:
                if la == lb or frozenset((la, lb)) in SKIPPED:
                    continue
                value = segment_distance(a0, a1, b0, b1) - ra - rb
                reference[(la, lb)] = min(reference.get((la, lb), np.inf), value)
        expected = min(reference.values())
        if expected > 0:  # penetration depths of overlapping capsules are EPA estimates
            assert distance == pytest.approx(expected, abs=1e-6)
            assert reference[closest] == pytest.approx(expected, abs=1e-6)
        else:
            assert distance <= 1e-9


def test_tool_above_a_box_at_a_known_height():
    robot = Robot.model("ur10e")
    model = CollisionModel(robot, tool_radius=0.02)
    model.add_box((0.4, 0.4, 0.2), (-0.6, 0.1, 0.0, 0, 0, 0), "crate")   # top at z = 0.1
    tcp = [0, 0, 0.1, 0, 0, 0]
    q = robot.ik(pose.to_matrix([-0.6, 0.1, 0.3 + 0.1, *DOWN]), HOME, tcp=tcp)  # 0.3 m above
    distances = model.distances(q, tcp=tcp)
    assert distances[("tool", "crate")] == pytest.approx(0.3 - 0.02, abs=1e-6)
    assert model.check(q, tcp=tcp).distance[0] == pytest.approx(min(distances.values()))
    # without a TCP there is no tool body
    assert ("tool", "crate") not in model.distances(q)
    # lower the TCP into the crate
    q_in = robot.ik(pose.to_matrix([-0.6, 0.1, 0.05, *DOWN]), q, tcp=tcp)
    inside = model.check(q_in, tcp=tcp)
    assert inside.colliding[0] and ("tool", "crate") in inside.pairs[0]


def test_cylinder_and_margin():
    robot = Robot.model("ur16e")
    model = CollisionModel(robot)
    model.add_cylinder(0.05, 2.0, (0.5, -0.5, 1.0, 0, 0, 0), "post")
    Q = np.array([[0.0, -1.57, 1.57, -1.57, -1.57, 0.0]] * 2)
    result = model.check(Q, margin=10.0)
    assert np.all(result.colliding)              # everything is within 10 m
    assert set(result.pairs) == {0, 1}
    assert all(len(pairs) > 3 for pairs in result.pairs.values())
    assert model.check(Q).pairs == {}


def test_self_collision_of_a_folded_arm():
    robot = Robot.model("ur5e")
    model = CollisionModel(robot)
    folded = np.array([-0.74, 0.02, -3.04, -0.04, 2.96, -1.35])   # forearm folded back
    result = model.check(folded)
    assert result.colliding[0]
    for pair in result.pairs[0]:
        assert set(pair) <= set(LINKS) and frozenset(pair) not in SKIPPED
    home = model.check(HOME)
    assert not home.colliding[0]


def test_base_is_not_checked_against_obstacles():
    model = CollisionModel(Robot.model("ur30"))
    model.add_plane((0, 0, 1), 0.05, "floor")        # cuts through the base
    result = model.check(np.array([0.0, -1.57, 0.0, -1.57, 0.0, 0.0]))
    assert not result.colliding[0]
    assert "base" not in result.closest[0]


@pytest.mark.parametrize("name", ["ur3", "ur5", "ur10"])
def test_urdf_meshes(name):
    model = CollisionModel(Robot.model(name), tool_radius=0.03)
    assert model.uses_meshes
    model.add_plane((0, 0, 1), 0.0, "floor")
    upright = model.check(np.array([0.0, -math.pi / 2, 0.0, -math.pi / 2, 0.0, 0.0]))
    assert not upright.colliding[0]
    # the arm tilted down by 0.5 rad from horizontal reaches below the floor
    flat = model.check(np.array([0.0, 0.5, 0.0, 0.0, 0.0, 0.0]), tcp=[0, 0, 0.1, 0, 0, 0])
    assert flat.colliding[0]
    assert any(pair[1] == "floor" for pair in flat.pairs[0])


def test_urdf_obstacles_are_placed_in_the_controller_base_frame():
    """base_link is turned by π from Base: a box in front of the robot (Base +x) must be
    hit by an arm reaching to Base +x."""
    robot = Robot.model("ur5")
    model = CollisionModel(robot)
    model.add_box((0.1, 0.1, 0.1), (0.5, 0.0, 0.4, 0, 0, 0), "target")
    reach = robot.ik(pose.to_matrix([0.5, 0.0, 0.4, *DOWN]), HOME + [math.pi, 0, 0, 0, 0, 0])
    assert model.check(reach).colliding[0]
    mirrored = robot.ik(pose.to_matrix([-0.5, 0.0, 0.4, *DOWN]), HOME)
    assert not model.check(mirrored).colliding[0]


def test_cell_file(tmp_path):
    cell = tmp_path / "cell.toml"
    cell.write_text("""
[floor]
height = -0.01

[[plane]]
name = "wall"
normal = [1, 0, 0]
offset = -0.7

[[box]]
name = "table"
size = [1.0, 0.6, 0.04]
pose = [-0.5, 0.0, -0.03, 0, 0, 0]

[[cylinder]]
name = "post"
radius = 0.05
length = 1.5
pose = [-0.5, 0.5, 0.75, 0, 0, 0]

[tool]
radius = 0.04
""")
    model = CollisionModel(Robot.model("ur5e"))
    model.load_cell(cell)
    assert model.obstacles == ["floor", "wall", "table", "post"]
    assert model.tool_radius == 0.04
    assert not model.check(HOME).colliding[0]
    # reaching through the wall at x = −0.7 with the tool pointing along −x
    robot = model.robot
    q = robot.ik(pose.to_matrix([-0.78, 0.0, 0.3, 0, -math.pi / 2, 0]), HOME)
    result = model.check(q)
    assert result.colliding[0] and any("wall" in pair for pair in result.pairs[0])


@pytest.mark.parametrize("text, message", [
    ("[[sphere]]\nradius = 1\n", "unknown tables"),
    ("[[box]]\nsize = [1, 1, 1]\n", "lacks 'pose'"),
    ("[[box]]\nsize = [1, 1]\npose = [0, 0, 0, 0, 0, 0]\n", "box size must be 3"),
    ("[[box]]\nsize = [1, 1, -1]\npose = [0, 0, 0, 0, 0, 0]\n", "positive"),
    ("[[plane]]\nnormal = [0, 0, 0]\noffset = 0\n", "must not be zero"),
    ('[[cylinder]]\nname = "wrist_1"\nradius = 1\nlength = 1\npose = [0, 0, 0, 0, 0, 0]\n',
     "a link name"),
    ("[floor\n", "not valid TOML"),
])
def test_bad_cell_files_say_what_is_wrong(tmp_path, text, message):
    cell = tmp_path / "bad.toml"
    cell.write_text(text)
    with pytest.raises(KinematicsError, match=message):
        CollisionModel(Robot.model("ur5e")).load_cell(cell)


def test_duplicate_obstacle_names_and_bad_joints():
    model = CollisionModel(Robot.model("ur5e"))
    model.add_plane((0, 0, 1), 0.0, "floor")
    with pytest.raises(KinematicsError, match="taken"):
        model.add_box((1, 1, 1), (0, 0, 0, 0, 0, 0), "floor")
    with pytest.raises(KinematicsError, match=r"\(N, 6\)"):
        model.check(np.zeros((2, 5)))


@pytest.mark.parametrize("name", ["ur5", "ur5e", "ur20"])
def test_levers_bound_how_fast_clearances_change(name, tmp_path):
    """The sweep's premise: between two joint vectors, no clearance (link-link or
    link-obstacle) changes by more than the joints' travel weighted by the levers."""
    cell = tmp_path / "cell.toml"
    cell.write_text('[floor]\nheight = -0.05\n[[box]]\nname = "b"\nsize = [0.2, 0.2, 0.2]\n'
                    'pose = [0.5, 0.2, 0.3, 0, 0, 0]\n[tool]\nradius = 0.03\n')
    model = CollisionModel(Robot.model(name))
    model.load_cell(cell)
    tcp = [0.0, 0.0, 0.15, 0.0, 0.0, 0.0]
    rng = np.random.default_rng(7)
    q = rng.uniform(-np.pi, np.pi, (300, 6))
    step = rng.normal(0.0, 0.05, (300, 6))
    model.check(q[:1], tcp=tcp)  # builds the geometry with the tool
    levers = model.levers()
    for a, b in zip(q, q + step, strict=True):
        before, after = model.distances(a, tcp=tcp), model.distances(b, tcp=tcp)
        bound = float(np.abs(b - a) @ levers)
        change = max(abs(after[pair] - before[pair]) for pair in before)
        assert change <= bound + 1e-9


def test_sweep_finds_what_checking_every_sample_finds():
    """A path that dips into a box and rises again: the sweep skips the free stretches but
    finds the contact, and agrees with checking every sample about where it is."""
    robot = Robot.model("ur5e")
    model = CollisionModel(robot)
    t = np.linspace(0.0, 1.0, 2001)[:, None]
    path = HOME + np.array([0.0, 1.0, 0.5, 0.0, 0.0, 0.0]) * np.sin(np.pi * t)
    lowest = robot.fk_many(path[1000:1001])[0, :3, 3]   # the flange at the bottom of the dip
    model.add_box([0.3, 0.3, 0.1], [lowest[0], lowest[1], lowest[2] - 0.02, 0, 0, 0], "box")
    dense = model.check(path)
    assert not dense.colliding[0] and not dense.colliding[-1]
    index, result = model.sweep(path, stride=5)
    assert len(index) < len(path) / 5   # fewer checks than every 5th sample
    assert dense.colliding.any() and result.colliding.any()
    first_dense = int(np.argmax(dense.colliding))
    first_sweep = int(index[np.argmax(result.colliding)])
    assert first_dense <= first_sweep < first_dense + 5
    np.testing.assert_array_equal(result.distance, dense.distance[index])
    at_rest = np.repeat(HOME[None], 500, axis=0)
    assert len(model.sweep(at_rest)[0]) == 1   # nothing moves: one check


def test_a_statement_that_folds_the_arm_onto_itself_is_one_finding_however_the_pairs_differ():
    """A loop's second pass folds the arm at other link pairs (project 135 program3:53): the
    same problem, reported once; hitting the cell's obstacles is another cause."""
    from urdsl.verify.checks import _collision_cause
    from urdsl.verify.findings import Finding
    from urdsl.verify.report import Report

    first = [("shoulder", "forearm"), ("shoulder", "wrist_1"), ("upper_arm", "wrist_1")]
    second = [("shoulder", "forearm"), ("upper_arm", "wrist_1")]
    table = [("forearm", "table"), ("wrist_3", "table")]
    assert _collision_cause(first, LINKS) == _collision_cause(second, LINKS) == "self"
    assert _collision_cause(table, LINKS) == "obstacle table"
    report = Report("p.script", "ur5")
    report.findings = [
        Finding.of("URS308", f"collision {n}", time=t, cause=_collision_cause(pairs, LINKS))
        for n, t, pairs in ((1, 1.0, first), (2, 21.0, second), (3, 22.0, table))]
    report.sort()
    assert [f.message for f in report.findings] == [
        "collision 1 (2 times, first at t=1.000 s)", "collision 3"]
