"""The robot a PolyScope program was taught on: model from waypoint pairs, start joints, TCP,
payload and installation, as ``urdsl check`` infers and reports them."""

from __future__ import annotations

import gzip
import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.cli import main
from urdsl.kinematics import MODELS, pose
from urdsl.kinematics.dh import fk_ur
from urdsl.kinematics.identify import identify, same_arm_groups
from urdsl.script.parser import parse
from urdsl.verify.infer import first_move_joints, infer, static_payload, static_tcp, waypoint_pairs

RNG = np.random.default_rng(12)


def taught(model: str, joints, tcp=(0, 0, 0, 0, 0, 0)) -> np.ndarray:
    """The TCP poses (N, 6) PolyScope would store for ``joints`` on ``model``."""
    spec = MODELS[model]
    q = np.asarray(joints, float).reshape(-1, 6)
    flange = fk_ur(q, spec.d1, spec.a2, spec.a3, spec.d4, spec.d5, spec.d6)
    return pose.from_matrix(flange @ pose.to_matrix(np.asarray(tcp, float)))


def random_joints(count: int, rng=RNG) -> np.ndarray:
    q = rng.uniform(-np.pi, np.pi, size=(count, 6))
    q[:, 1] = rng.uniform(-2.8, -0.3, count)        # keep the arm above its base, mostly
    q[:, 2] = rng.uniform(-2.5, 2.5, count)
    return q


def group_of(model: str) -> tuple[str, ...]:
    return next(g for g in same_arm_groups() if model in g)


# ---- the fit -------------------------------------------------------------------------------


@pytest.mark.parametrize("model", ["ur3", "ur5", "ur10", "ur3e", "ur5e", "ur10e", "ur16e",
                                   "ur20", "ur30", "ur15", "ur18", "ur8long"])
def test_each_model_is_recognised_from_its_own_waypoints(model):
    q = random_joints(8)
    found = identify(q, taught(model, q))
    assert found.model == model
    assert found.used == 8 and found.residual < 1e-6
    assert found.runner_up is not None and found.runner_up[1] > 0.01


@pytest.mark.parametrize("renamed, arm", [("ur7e", "ur5e"), ("ur12e", "ur10e")])
def test_the_same_arm_under_two_names_is_named_once_and_the_twin_mentioned(renamed, arm):
    q = random_joints(5)
    found = identify(q, taught(renamed, q))
    assert found.model == arm and renamed in found.same_arm


def test_half_a_millimetre_of_noise_still_identifies_the_arm():
    q = random_joints(14)
    noisy = taught("ur10e", q)
    noisy[:, :3] += RNG.normal(0.0, 0.0005, size=(14, 3))
    found = identify(q, noisy)
    assert found.model == "ur10e"
    assert 0.0002 < found.residual < 0.0015


def test_the_given_tcp_is_used_for_the_fit():
    tcp = (0.01, -0.02, 0.18, 0.0, 0.3, 0.0)
    q = random_joints(6)
    found = identify(q, taught("ur20", q, tcp), tcp)
    assert found.model == "ur20" and not found.tcp_fitted and found.residual < 1e-6


def test_an_unknown_tcp_is_solved_for_when_the_flange_does_not_fit():
    tcp = (0.0, 0.05, 0.22, 0.1, -0.2, 0.3)
    q = random_joints(6)
    found = identify(q, taught("ur3e", q, tcp))     # fitted as if there were no TCP
    assert found.model == "ur3e" and found.tcp_fitted
    np.testing.assert_allclose(found.tcp, tcp, atol=1e-6)


def test_no_pairs_infers_nothing():
    found = identify(np.zeros((0, 6)), np.zeros((0, 6)))
    assert found.model is None and "no taught waypoint pairs" in found.reason


def test_pairs_from_two_different_arms_infer_nothing():
    q = random_joints(8)
    mixed = np.concatenate([taught("ur5e", q[:4]), taught("ur16e", q[4:])])
    found = identify(q, mixed)
    assert found.model is None
    assert found.reason == "the pairs fit different arms (4 ur5e, 4 ur16e)"


def test_a_few_pairs_taught_with_another_tcp_do_not_hide_the_arm():
    q = random_joints(10)
    poses = taught("ur10", q)
    poses[:2] = taught("ur10", q[:2], (0, 0, 0.2, 0, 0, 0))
    found = identify(q, poses)
    assert found.model == "ur10" and found.used == 8


def test_a_few_exact_pairs_identify_the_arm_when_the_rest_used_an_unknown_tcp():
    q = random_joints(10)
    poses = taught("ur20", q, (0.0, -0.3, 0.1, 1.2, -1.2, 1.2))
    poses[:4] = taught("ur20", q[:4])
    found = identify(q, poses)
    assert found.model == "ur20" and found.used == 4


def test_one_exact_pair_among_many_unexplained_is_not_enough():
    q = random_joints(6)
    poses = taught("ur20", q)
    poses[1:, :3] += RNG.uniform(0.03, 0.06, size=(5, 3))       # hand-edited poses
    found = identify(q, poses)
    assert found.model is None
    assert found.reason.startswith("only 1 of 6 pair(s) fit ur20 within 8 mm")


@settings(max_examples=40, deadline=None)
@given(model=st.sampled_from(sorted(MODELS)), seed=st.integers(0, 2**31 - 1),
       count=st.integers(4, 12))
def test_law_the_teaching_arm_is_found_for_any_waypoints(model, seed, count):
    q = random_joints(count, np.random.default_rng(seed))
    found = identify(q, taught(model, q))
    assert found.model in group_of(model)
    assert found.residual < 1e-6


# ---- reading a program ---------------------------------------------------------------------


def _literal(values, kind: str) -> str:
    body = ", ".join(f"{v:.12f}" for v in values)
    return f"p[{body}]" if kind == "p" else f"[{body}]"


UR10E_Q = np.array([[0.3, -0.5, 0.6, -1.67, -1.57, 0.2],
                    [0.0, -0.6, 0.9, -1.87, -1.57, 0.0],
                    [-0.4, -0.4, 0.5, -1.67, -1.57, -0.3]])
"""Joints of three waypoints 1.18 to 1.26 m from the base axis: a UR10e reaches them, a
UR5e (0.85 m) does not."""


def polyscope_program(model: str = "ur10e", joints=UR10E_Q, tcp=(0, 0, 0, 0, 0, 0),
                      preamble_tcp: bool = True, extra: str = "") -> str:
    poses = taught(model, joints, tcp)
    lines = ["def prog():"]
    if preamble_tcp:
        lines.append(f"  set_tcp({_literal(tcp, 'p')})")
    lines.append("  set_payload(1.5, [0.0, 0.0, 0.05])")
    for i, (q, p) in enumerate(zip(joints, poses, strict=True), start=1):
        lines.append(f"  global Waypoint_{i}_p={_literal(p, 'p')}")
        lines.append(f"  global Waypoint_{i}_q={_literal(q, 'q')}")
    lines += [
        "  $ 1 \"Robot Program\"",
        "  $ 2 \"MoveJ\"",
        "  $ 3 \"Waypoint_1\" \"breakAfter\"",
        "  movej(get_inverse_kin(Waypoint_1_p, qnear=Waypoint_1_q), a=1.4, v=1.05)",
        "  $ 4 \"MoveL\"",
        "  movel(Waypoint_2_p, a=1.2, v=0.25)",
        "  movel(Waypoint_3_p, a=1.2, v=0.25)",
        extra,
        "end",
    ]
    return "\n".join(lines) + "\n"


def test_pairs_are_read_from_globals_and_inlined_inverse_kinematics():
    text = """def prog():
  global Waypoint_1_p=p[.1, -.2, .3, 0, 3.14, 0]
  global Waypoint_1_q=[0, -1.5, 1.5, -1.5, -1.5, 0]
  global only_pose_p=p[.1, .2, .3, 0, 0, 0]
  global Pick_q=[0.1, -1.4, 1.4, -1.5, -1.5, 0]
  global Pick_p=p[.2, -.2, .3, 0, 3.14, 0]
  movej(get_inverse_kin(p[.3, -.1, .2, 0, 3.14, 0], qnear=[0.2, -1.2, 1.3, -1.6, -1.5, 0]))
end
"""
    pairs = waypoint_pairs(parse(text))
    assert [p.name for p in pairs] == ["Waypoint_1", "Pick", "get_inverse_kin at line 7"]
    assert pairs[0].joints == (0, -1.5, 1.5, -1.5, -1.5, 0)
    assert pairs[1].pose == (.2, -.2, .3, 0, 3.14, 0)
    assert pairs[0].span.line == 3


def test_preamble_tcp_and_payload_are_read_statically():
    module = parse(polyscope_program(tcp=(0, 0, 0.15, 0, 0, 0)))
    tcp, span = static_tcp(module)
    assert tcp == (0, 0, 0.15, 0, 0, 0) and span.line == 2
    mass, cog, span, name = static_payload(module)
    assert (mass, cog, span.line, name) == (1.5, (0.0, 0.0, 0.05), 3, "set_payload")


@pytest.mark.parametrize("first, expected", [
    ("movej(get_inverse_kin(Home_p, qnear=Home_q))", "Home_q"),
    ("movel(Home_p)", "Home_q"),
    ("movel(pose_trans(Plane_1, Home_p))", "Home_q"),
    ("movej(Home_q)", "Home_q"),
    ("movej([0.5, -1, 1, -1.5, -1.5, 0])", "the first move's joint target"),
    ("pick()", "Home_q"),
    ("thread Thread_if_4():\n    movel(Home_p)\n  end\n  t = run Thread_if_4()", "Home_q"),
])
def test_start_joints_are_the_first_moves_taught_target(first, expected):
    text = f"""def prog():
  global Plane_1=p[0, 0, 0.1, 0, 0, 0]
  global Home_p=p[.1, -.2, .3, 0, 3.14, 0]
  global Home_q=[0.1, -1.5, 1.5, -1.5, -1.5, 0]
  thread Thread_1():
    movej([1, 1, 1, 1, 1, 1])
  end
  def pick():
    movel(Home_p)
  end
  {first}
  movel(p[.2, -.2, .3, 0, 3.14, 0])
end
"""
    joints, source, span = first_move_joints(parse(text))
    assert source == expected
    if expected == "Home_q":
        assert joints == (0.1, -1.5, 1.5, -1.5, -1.5, 0) and span.line == 4
    else:
        assert joints == (0.5, -1, 1, -1.5, -1.5, 0)


@pytest.mark.parametrize("first", [
    "movej(q2r(Home_deg_q))",                  # a hand-written waypoint in degrees
    "movej(target)",                           # a variable waypoint
    "movej(Sentinel_q)",                       # outside ±2π: not joint positions
    "movej(get_actual_joint_positions())",
])
def test_a_first_target_that_is_not_a_taught_waypoint_leaves_the_start_unknown(first):
    text = f"""def prog():
  global Home_deg_q=[0, -90, 90, -90, -90, 0]
  global Sentinel_q=[255, 255, 255, 255, 255, 255]
  global target=[0.1, -1.5, 1.5, -1.5, -1.5, 0]
  $ 1 "Robot Program"
  {first}
end
"""
    assert first_move_joints(parse(text)) is None


def test_inference_for_a_program_without_waypoints_says_nothing_was_inferred():
    result = infer(parse("movej([0, -1.5, 1.5, -1.5, -1.5, 0])\n"))
    assert result.robot == "ur5e" and result.robot_source == "default"
    assert result.start_source == "default"
    assert "not inferred: no taught waypoint pairs" in result.lines()[0]
    assert "not a PolyScope program" in result.lines()[0]


# ---- urdsl check ---------------------------------------------------------------------------


@pytest.fixture
def ur10e_program(tmp_path):
    path = tmp_path / "pick.script"
    path.write_text(polyscope_program())
    return path


def test_check_infers_the_model_and_start_and_says_so(ur10e_program, capsys):
    assert main(["check", str(ur10e_program), "--no-self-collision"]) == 0
    out = capsys.readouterr().out
    assert "robot ur10e inferred from 3 waypoint pair(s) (residual 0.0 mm)" in out
    assert "ur12e is the same arm" in out
    assert "start joints from Waypoint_1_q (line 5)" in out
    assert "payload 1.5 kg" in out
    assert "ok on ur10e" in out


def test_check_json_reports_what_was_inferred(ur10e_program, capsys):
    main(["check", str(ur10e_program), "--json", "--no-self-collision"])
    report = json.loads(capsys.readouterr().out)
    inferred = report["inferred"]
    assert report["robot"] == "ur10e"
    assert inferred["robot"]["source"] == "inferred" and inferred["robot"]["pairs"] == 3
    assert inferred["robot"]["residual"] < 1e-6
    assert inferred["start"] == {"joints": pytest.approx(list(UR10E_Q[0])),
                                 "source": "inferred", "from": "Waypoint_1_q", "line": 5}
    # the arm starts at the first waypoint: the first move takes no time
    assert report["moves"][0]["duration"] == pytest.approx(0.0, abs=1e-6)


def test_robot_flag_overrides_and_a_ur5e_cannot_reach_the_ur10e_waypoints(ur10e_program,
                                                                          capsys):
    assert main(["check", str(ur10e_program), "--robot", "ur5e", "--json",
                 "--no-self-collision"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["robot"] == "ur5e"
    assert report["inferred"]["robot"] == {"model": "ur5e", "source": "given", "pairs": 3}
    assert "URS301" in [f["code"] for f in report["findings"]]


def test_start_joints_flag_overrides(ur10e_program, capsys):
    main(["check", str(ur10e_program), "--json", "--no-self-collision",
          "--start-joints-deg", "0,-90,90,-90,-90,0"])
    report = json.loads(capsys.readouterr().out)
    assert report["inferred"]["start"]["source"] == "given"
    assert report["inferred"]["robot"]["source"] == "inferred"
    assert report["moves"][0]["duration"] > 0.1


def test_a_pose_no_model_reaches_stays_an_error(tmp_path, capsys):
    path = tmp_path / "far.script"
    path.write_text(polyscope_program(extra="  movel(p[3.0, 0, 0.3, 0, 3.14, 0])"))
    assert main(["check", str(path), "--json", "--no-self-collision"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["robot"] == "ur10e"
    assert [f["code"] for f in report["findings"] if f["severity"] == "error"] == ["URS301"]


def test_conflicting_waypoints_fall_back_to_the_default_and_say_why(tmp_path, capsys):
    q = random_joints(6)
    text = polyscope_program("ur5e", q[:3]).replace("Waypoint_", "A_")
    text = text.replace("end\n", polyscope_program("ur16e", q[3:]).split("\n", 1)[1])
    path = tmp_path / "mixed.script"
    path.write_text(text)
    main(["check", str(path), "--json", "--no-self-collision"])
    report = json.loads(capsys.readouterr().out)
    robot = report["inferred"]["robot"]
    assert robot["source"] == "default" and robot["model"] == "ur5e" and robot["pairs"] == 6
    assert "reason" in robot


def _installation(tcp: str, mass: str = "2.0") -> bytes:
    return f"""<Installation directory="/programs" fileName="default">
  <Version projectName="URSoftware" major="5" minor="11" bugfix="0"/>
  <PayloadSettings><Payload name="Payload" mass="{mass}" defaultPayload="true"
    centerOfGravity="0.0, 0.0, 0.04"/></PayloadSettings>
  <TCPSettings activePose="Gripper"><availablePoses>
    <tcp id="1" name="Gripper" offset="{tcp}"/></availablePoses></TCPSettings>
</Installation>
""".encode()


def test_the_installations_tcp_is_used_when_the_script_sets_none(tmp_path, capsys):
    tcp = (0.0, 0.0, 0.2, 0.0, 0.0, 0.0)
    program = polyscope_program("ur10e", tcp=tcp, preamble_tcp=False)
    program = program.replace("  set_payload(1.5, [0.0, 0.0, 0.05])\n", "")
    (tmp_path / "pick.script").write_text(program)
    (tmp_path / "default.installation").write_bytes(gzip.compress(_installation(
        "0.0, 0.0, 0.2, 0.0, 0.0, 0.0")))
    main(["check", str(tmp_path / "pick.script"), "--json", "--no-self-collision"])
    inferred = json.loads(capsys.readouterr().out)["inferred"]
    assert inferred["robot"]["model"] == "ur10e" and not inferred["robot"]["tcp_fitted"]
    assert inferred["tcp"] == {"pose": [0.0, 0.0, 0.2, 0.0, 0.0, 0.0],
                               "from": "TCP 'Gripper' of default.installation"}
    assert inferred["payload"]["mass"] == 2.0
    assert inferred["installation"].endswith("default.installation")


def test_a_corrupt_installation_is_a_note_not_a_traceback(tmp_path, capsys):
    (tmp_path / "pick.script").write_text(polyscope_program())
    data = gzip.compress(_installation("0,0,0,0,0,0"))
    (tmp_path / "default.installation").write_bytes(data[:40])
    assert main(["check", str(tmp_path / "pick.script"), "--no-self-collision"]) == 0
    out = capsys.readouterr().out
    assert "installation not used:" in out and "default.installation" in out
    assert "truncated" in out
    assert "robot ur10e inferred" in out


def test_a_cell_is_checked_with_the_inferred_robot(ur10e_program, tmp_path, capsys):
    cell = tmp_path / "cell.toml"
    cell.write_text("[floor]\nheight = -0.5\n")
    assert main(["check", str(ur10e_program), "--cell", str(cell), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["robot"] == "ur10e"


def _untaught_program(target: str) -> str:
    # a PolyScope export ($ labels) whose moves are computed: no waypoint pairs to infer from
    return ("def Untaught():\n"
            '  $ 1 "Robot Program"\n'
            "  movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])\n"
            f'  $ 2 "MoveL"\n'
            f"  movel(p{target}, a=1.2, v=0.25)\n"
            "end\n")


def _check_json(tmp_path, capsys, text: str, *flags: str) -> dict:
    path = tmp_path / "untaught.script"
    path.write_text(text)
    main(["check", "--json", *flags, str(path)])
    return json.loads(capsys.readouterr().out)


def test_model_findings_on_an_unknown_robot_are_warnings_that_say_so(tmp_path, capsys):
    # 1.1 m from the base: out of a UR5e's reach, inside a UR10e's
    report = _check_json(tmp_path, capsys, _untaught_program("[-1.1, -0.1, 0.3, 0, 3.14, 0]"))
    (finding,) = [f for f in report["findings"] if f["code"] == "URS301"]
    assert finding["severity"] == "warning" and report["ok"]
    assert "on the assumed ur5e" in finding["message"] and "--robot" in finding["hint"]
    # given the robot, the same move is an error
    report = _check_json(tmp_path, capsys, _untaught_program("[-1.1, -0.1, 0.3, 0, 3.14, 0]"),
                         "--robot", "ur5e")
    (finding,) = [f for f in report["findings"] if f["code"] == "URS301"]
    assert finding["severity"] == "error" and not report["ok"]


def test_a_target_no_ur_model_reaches_stays_an_error(tmp_path, capsys):
    report = _check_json(tmp_path, capsys, _untaught_program("[-3.5, 0, 0.3, 0, 3.14, 0]"))
    (finding,) = [f for f in report["findings"] if f["code"] == "URS301"]
    assert finding["severity"] == "error" and "assumed" not in finding["message"]


def test_a_hand_written_script_is_checked_on_an_assumed_model(tmp_path, capsys):
    # nothing says which arm a hand-written script runs on: a pose only the assumed UR5e
    # cannot reach (1.1 m out; a UR10 reaches it) is a warning that says so, a pose no UR
    # model reaches (2.5 m out) stays an error, and --robot makes the first certain
    far = "movel(p[-1.1, -0.1, 0.3, 0, 3.14, 0], a=1.2, v=0.25)\n"
    start = "movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])\n"
    report = _check_json(tmp_path, capsys, start + far)
    (finding,) = [f for f in report["findings"] if f["code"] == "URS301"]
    assert finding["severity"] == "warning"
    assert "on the assumed ur5e: the program does not say which arm" in finding["message"]
    report = _check_json(tmp_path, capsys, start + far.replace("-1.1", "-2.5"))
    (finding,) = [f for f in report["findings"] if f["code"] == "URS301"]
    assert finding["severity"] == "error"
    report = _check_json(tmp_path, capsys, start + far, "--robot", "ur5e")
    assert [f["severity"] for f in report["findings"] if f["code"] == "URS301"] == ["error"]


@pytest.mark.parametrize(("y", "severity"), [(-0.12, "warning"), (-0.05, "error")])
def test_a_path_no_ur_model_can_follow_stays_an_error(tmp_path, capsys, y, severity):
    # a tool-down line past the base's axis: 0.12 m from it, inside the UR5e's shoulder
    # offset (0.133 m) but not the UR5's (0.109 m), is a warning on the assumed UR5e; 0.05 m
    # from it no UR model can follow, and the path error stays one, as does the joint speed
    # on the way there (a speed on the first line is a warning, if there is one)
    text = (f"movej(get_inverse_kin(p[-0.4, {y}, 0.35, 0, 3.1416, 0]))\n"
            f"movel(p[0.4, {y}, 0.35, 0, 3.1416, 0], a=1.2, v=0.25)\n")
    report = _check_json(tmp_path, capsys, text)
    (finding,) = [f for f in report["findings"] if f["code"] == "URS302"]
    assert finding["severity"] == severity
    assert ("no UR model can follow it" in finding["message"]) == (severity == "error")
    speeds = {f["severity"] for f in report["findings"] if f["code"] == "URS304"}
    assert speeds == ({"error"} if severity == "error" else speeds - {"error"})


def test_a_fragment_of_a_polyscope_program_is_taught_too(tmp_path, capsys):
    # a script file a PolyScope program includes (it uses the program's `speed`): its moves
    # were taught on the program's arm, which is not known here
    far = "movel(p[-1.1, -0.1, 0.3, 0, 3.14, 0], a=1.2, v=speed)\n"
    host = _untaught_program("[-0.4, -0.1, 0.3, 0, 3.14, 0]").replace(
        '  $ 2 "MoveL"\n', '  $ 2 "Script: far.script"\n  ' + far).replace(
        '  $ 1 "Robot Program"\n', '  global speed = 0.25\n  $ 1 "Robot Program"\n')
    (tmp_path / "host.script").write_text(host)
    (tmp_path / "far.script").write_text(far)
    main(["check", "--json", str(tmp_path / "far.script")])
    report = json.loads(capsys.readouterr().out)
    assert "context of" in report["context"]
    (finding,) = [f for f in report["findings"] if f["code"] == "URS301"]
    assert finding["severity"] == "warning" and "on the assumed ur5e" in finding["message"]


@pytest.mark.parametrize(("z", "severity"), [(1.079483178718, "warning"), (1.09, "error")])
def test_a_target_a_fraction_of_a_millimetre_beyond_the_nominal_reach_is_a_warning(
        tmp_path, capsys, z, severity):
    # an upright home taught on the arm: its calibration put the pose 0.3 mm beyond the
    # nominal UR5e's reach; 1 cm beyond stays an error
    text = ("def prog():\n"
            f"  global Home_p=p[-.001703142952, -.233433365732, {z}, -.009004197313, "
            "-2.218443849278, 2.216349783219]\n"
            "  movej([0, -1.2, 1.2, -1.5708, -1.5708, 0])\n"
            "  movel(Home_p, a=1.2, v=0.25)\n"
            "end\n")
    path = tmp_path / "home.script"
    path.write_text(text)
    main(["check", str(path), "--json", "--robot", "ur5e", "--no-self-collision"])
    report = json.loads(capsys.readouterr().out)
    (reach,) = [f for f in report["findings"] if f["code"] == "URS301"]
    assert reach["severity"] == severity and reach["line"] == 4
    assert ("the arm's calibration decides" in reach["message"]) == (severity == "warning")


@pytest.mark.parametrize("call", [
    "movel(p[-1.1, -0.1, 0.3, 0, 3.14, 0], a=1.2, v=0.25)",  # solved with the move's batch
    "movej(p[-1.1, -0.1, 0.3, 0, 3.14, 0], a=1.4, v=1.05)",  # solved when it runs
    "x = get_inverse_kin(p[-1.1, -0.1, 0.3, 0, 3.14, 0])",
])
def test_an_unreachable_target_carries_where_it_lies(call):
    # the assumed-model and nominal-accuracy rules read where a target lies and how far out
    # from the finding itself, not from its message's text
    from urdsl.verify.run import CheckOptions, check_text

    report = check_text("movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])\n" + call + "\n",
                        "t.script", options=CheckOptions(robot="ur5e"))
    (finding,) = [f for f in report.findings if f.code == "URS301"]
    position, distance = finding.beyond
    assert np.allclose(position, (-1.1, -0.1, 0.3), atol=1e-9)
    assert 0.2 < distance < 0.4  # a UR5e reaches 0.85 m from its shoulder
