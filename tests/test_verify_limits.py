"""``urdsl check`` always ends: the wall-clock bound, the controller's limits, and every
hang of issue 14 as a regression test; device replies are unknown, not none."""

from __future__ import annotations

import math

import pytest

from urdsl.cli import main
from urdsl.verify.run import CheckOptions, check_text

Q = "[0, -1.5, 1.5, -1.5, -1.5, 0.5]"


def check(text: str, **options):
    options.setdefault("self_collision", False)
    return check_text(text, "prog.script", options=CheckOptions(**options))


def codes(report) -> list[str]:
    return [f.code for f in report.findings]


def only(report, code: str):
    found = [f for f in report.findings if f.code == code]
    assert len(found) == 1, report.findings
    return found[0]


# ---- the wall-clock bound ----------------------------------------------------------------------


def test_an_endless_program_stops_at_the_wall_clock_bound_and_says_where(tmp_path, capsys):
    path = tmp_path / "endless.script"
    # i decides a branch: no pass begins as an earlier one did (that would end the check)
    path.write_text("i = 0\nwhile True:\n  i = i + 1\n  if i < 0:\n    halt\n  end\n"
                    "  sync()\nend\n")
    status = main(["check", str(path), "--max-time", "1e9", "--timeout", "3"])
    out = capsys.readouterr().out
    assert status == 0  # a warning: the program has no error that was found
    assert "URS313" in out and "wall-clock bound of 3 s" in out
    assert "endless.script:2:1" in out and "robot time" in out


def test_timeout_must_be_positive(tmp_path, capsys):
    path = tmp_path / "p.script"
    path.write_text("x = 1\n")
    with pytest.raises(SystemExit) as stop:
        main(["check", str(path), "--timeout", "0"])
    assert stop.value.code == 2
    assert "--timeout" in capsys.readouterr().err


# ---- issue 14: reproducers that hung or ate memory -------------------------------------------


def test_sleep_0_loop_is_a_runaway_not_a_hang():
    report = check("while True:\n  sleep(0)\nend\n")
    assert only(report, "URS207").span.line == 1


def test_socket_read_with_timeout_0_on_a_socket_nobody_opened_waits_for_ever():
    report = check('while True:\n  socket_read_byte_list(1, "g", 0)\nend\n')
    finding = only(report, "URS313")
    assert finding.span.line == 2 and "waits for ever" in finding.message
    assert "socket 'g' is not open" in finding.message


def test_the_same_read_in_a_thread_while_main_sleeps():
    report = check('thread t():\n  while True:\n    socket_read_byte_list(1, "g", 0)\n'
                   '  end\nend\nrun t()\nsleep(10)\n')
    assert only(report, "URS313").span.line == 3
    assert report.cycle_time == pytest.approx(10.0)


def test_a_thread_that_loops_on_sleep_0_while_main_sleeps_is_a_runaway():
    report = check("thread t():\n  while True:\n    sleep(0)\n  end\nend\nrun t()\nsleep(10)\n")
    assert only(report, "URS207").span.line == 2


def test_a_thread_that_runs_itself_ends():
    report = check("thread t():\n  run t()\nend\nrun t()\nsleep(100)\n", max_time=200)
    assert "URS313" not in codes(report)
    assert report.cycle_time == pytest.approx(100.0)


def test_a_thread_per_command_never_ended_hits_the_thread_limit():
    report = check("thread w():\n  while True:\n    sync()\n  end\nend\n"
                   "while True:\n  run w()\n  sleep(0.01)\nend\n", max_time=3600)
    finding = only(report, "URS208")
    assert finding.span.line == 7 and "threads would run at once" in finding.message


def test_threads_that_end_do_not_pile_up():
    report = check("thread w():\n  sleep(0.001)\nend\n"
                   "i = 0\nwhile i < 2000:\n  h = run w()\n  join h\n  i = i + 1\nend\n")
    assert not [f for f in report.findings if f.severity == "error"], report.findings


def test_a_list_that_doubles_is_stopped_at_the_line():
    report = check("x = [1, 2]\nwhile True:\n  x = [x, x]\n  sync()\nend\n")
    finding = only(report, "URS203")
    assert finding.span.line == 3 and "matrix" in finding.message


def test_a_string_that_doubles_is_stopped_at_the_line():
    report = check('s = "ab"\nwhile True:\n  s = s + s\n  sync()\nend\n')
    finding = only(report, "URS203")
    assert finding.span.line == 3 and "1023 bytes" in finding.message


def test_a_struct_that_doubles_is_stopped_at_the_line():
    report = check("s = struct(a=1)\nwhile True:\n  s = struct(a=s, b=s)\n  sync()\nend\n")
    assert only(report, "URS202").span.line == 3


def test_huge_make_list_is_stopped():
    assert only(check("x = make_list(1000000000, 0)\n"), "URS202").span.line == 1


@pytest.mark.parametrize("arguments", ["t=1e4", "t=1e6", "t=1e300", "a=1e-300, v=1e-300"])
def test_slow_moves_are_sampled_only_up_to_max_time(arguments):
    report = check(f"movej({Q}, {arguments})\n", max_time=10)
    assert report.trace.duration <= 10.0 + 1e-9
    assert len(report.trace.times) <= 10.0 / 0.002 + 2
    assert report.cycle_time == pytest.approx(10.0)
    assert "URS312" in codes(report)


# ---- unknown device values in a whole check -----------------------------------------------------


def test_robotiq_style_preamble_checks_without_errors():
    report = check('rq = rpc_factory("xmlrpc", "http://127.0.0.1:4242/RPC2")\n'
                   "if not rq.activated():\n"
                   '  popup("activate the gripper", error=True)\n'
                   "  halt\n"
                   "end\n"
                   f"movej({Q})\n")
    assert codes(report) == ["URS210"]
    assert report.findings[0].severity == "warning"
    assert len(report.moves) == 1  # the move after the check of the reply was planned


def test_a_move_to_an_unknown_pose_is_noted_once_and_not_checked():
    report = check("i = 0\nwhile i < 5:\n"
                   "  target = p[read_input_float_register(0), 0.3, 0.2, 0, 3.14, 0]\n"
                   "  movel(target)\n  i = i + 1\nend\n")
    finding = only(report, "URS210")
    assert finding.span.line == 4 and "not checked" in finding.message
    assert not report.moves and "URS301" not in codes(report)


def test_exponential_recursion_meets_the_wall_clock_bound():
    report = check("def f(n):\n  if n > 0:\n    f(n - 1)\n    f(n - 1)\n  end\nend\nf(60)\n",
                   timeout=0.5)
    finding = only(report, "URS313")
    assert "wall-clock bound of 0.5 s" in finding.message and finding.span.line in (3, 4)


def test_a_message_at_every_pass_does_not_fill_memory():
    from urdsl.runtime.interpreter import EVENT_LIMIT

    report = check('i = 0\nwhile True:\n  textmsg("tick")\n  i = i + 1\n  if i < 0:\n'
                   '    halt\n  end\n  sync()\nend\n', max_time=30)
    assert len(report.events) == EVENT_LIMIT + 1  # 15,000 passes; the rest are counted
    assert report.events[-1].message.startswith("5,0")
    assert len(report.trace.times) <= 1  # the arm never moved: nothing to sample


def test_absurd_move_parameters_raise_no_numpy_warning(recwarn):
    from urdsl.verify.run import CheckOptions, check_text

    report = check_text("q = [0.5, -1.5, 1.5, -1.5, -1.5, 0]\nmovej(q, a=1e300, v=1e-300)\n",
                        "absurd.script", options=CheckOptions(max_time=10.0))
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]
    assert "5.000e+299" in report.render_text()


def test_make_list_needs_whole_lengths():
    from urdsl.verify.run import check_text

    report = check_text("l = make_list(0.5, 0)\n", "ml.script")
    assert [f.code for f in report.findings] == ["URS203"]
    assert "whole number" in report.findings[0].message


def test_a_speed_a_move_ends_with_is_not_the_next_moves():
    # a movel that crosses the wrist singularity just before its end still turns wrist 3 fast
    # at its last sample; the next move's first sample shares that central difference, and
    # the movej after it was reported too (seen on a PolyScope export: 4.91 rad/s on a movej
    # whose own samples stay under 1.1 rad/s)
    from types import SimpleNamespace

    import numpy as np

    from urdsl.script.nodes import Source, Span
    from urdsl.verify.checks import joint_speeds

    limits = np.full(6, 3.14)
    qd = np.zeros((8, 6))
    qd[2:4, 5] = 60.0  # the movel's singular turn, up to its last sample (3)
    qd[4, 5] = 7.0     # the movej's first sample: half of the movel's last step
    qd[5:, 5] = 1.0
    source = Source("movel(a)\nmovej(b)\n", "t.script")
    segments = [SimpleNamespace(kind="movel", span=Span(source, 0, 8), params={}),
                SimpleNamespace(kind="movej", span=Span(source, 9, 17), params={})]
    trace = SimpleNamespace(qd=qd, times=np.arange(8) * 0.002, segments=segments,
                            segment=np.array([0, 0, 0, 0, 1, 1, 1, 1]))
    (finding,) = joint_speeds(trace, limits)
    assert finding.span.line == 1 and "60.00 rad/s" in finding.message
    qd[6, 5] = 5.0  # a speed the movej reaches by itself stays its own
    assert [f.span.line for f in joint_speeds(trace, limits)] == [1, 2]


def test_a_tcp_change_between_moves_is_no_tcp_speed():
    # set_tcp moves the TCP point 5 cm while the arm stands still: differentiated across the
    # change it was 0.05 m / 2 ms = 25 m/s over a cell's 1.5 m/s (a PolyScope program that
    # switches from a deburring to a polishing tool)
    text = ("movej([0, -1.57, 1.57, -1.57, -1.57, 0])\n"
            "set_tcp(p[0, 0, 0.05, 0, 0, 0])\n"
            "movej([0.1, -1.57, 1.57, -1.57, -1.57, 0], a=1.4, v=0.1)\n")
    report = check(text, tcp_speed_limit=1.5)
    assert not [f for f in report.findings if f.code == "URS306"], report.findings
    fast = text.replace("v=0.1", "v=3.0")  # a real overspeed is still one
    report = check(fast, tcp_speed_limit=0.1)
    assert [f.code for f in report.findings if f.code == "URS306"] == ["URS306"]


def test_a_joint_limit_at_an_assumed_start_is_not_the_programs():
    # an installation limits the shoulder to -82°; the program starts wherever the arm was
    # left, which the check draws at its default pose (shoulder -90°): neither that pose nor
    # the first move's start is the program's, its target is
    low = (-6.28, math.radians(-82), -3.14, -6.28, -6.28, -6.28)
    high = (6.28, 0.0, 3.14, 6.28, 6.28, 6.28)
    text = "sleep(1)\nmovej([0.2, -1.2, 1.5, -1.8, -1.57, 0])\n"
    report = check(text, q_min=low, q_max=high, start_unknown=True)
    assert not [f for f in report.findings if f.code == "URS303"], report.findings
    assert not [f for f in check(text.replace("-1.2", "-1.5"), q_min=low, q_max=high,
                                 start_unknown=True).findings
                if f.code == "URS303" and f.severity == "error"] == []  # a target beyond
    # given, the start is the user's: named at the first move, not at '<generated>:0:0'
    (found,) = [f for f in check(text, q_min=low, q_max=high).findings if f.code == "URS303"]
    assert found.span.line == 2 and "where the arm starts, before this first move" in \
        found.message


def test_a_tcp_speed_a_move_ends_with_is_not_the_next_moves():
    # a move from where the arm's position is unknown offline is drawn from where the arm was
    # last known, and that drawn path may race into the move's target (its findings are not
    # reported); the next move's first sample shares its central difference, and a 0.4 m/s
    # movel after it was reported at 5.2 m/s against an installation's 5 m/s limit (seen on a
    # PolyScope subprogram, CA-Giken SUB_003)
    from types import SimpleNamespace

    import numpy as np

    from urdsl.script.nodes import Source, Span
    from urdsl.verify.checks import tcp_speed

    dt = 0.002
    x = np.concatenate([np.linspace(0.0, 0.15, 4), 0.2 + 0.0008 * np.arange(4)])
    q = np.zeros((8, 6))
    q[:, 0] = x  # the fake arm's TCP x is joint 1's value (m)
    robot = SimpleNamespace(fk_many=lambda qs, tcp=None: np.stack(
        [np.block([[np.eye(3), row[:3, None]], [np.zeros((1, 3)), np.ones((1, 1))]])
         for row in qs]))
    source = Source("movel(a)\nmovel(b)\n", "t.script")
    segments = [SimpleNamespace(kind="movel", span=Span(source, 0, 8), tcp=None, params={}),
                SimpleNamespace(kind="movel", span=Span(source, 9, 17), tcp=None, params={})]
    trace = SimpleNamespace(q=q, times=np.arange(8) * dt, dt=dt, segments=segments,
                            segment=np.array([0, 0, 0, 0, 1, 1, 1, 1]))
    (finding,) = tcp_speed(trace, robot, 5.0)
    assert finding.span.line == 1  # 25 m/s on the drawn path, not the next move's
    q[6:, 0] += 0.05  # a speed the second move reaches by itself stays its own
    assert [f.span.line for f in tcp_speed(trace, robot, 5.0)] == [1, 2]
