"""The interpreter runs URScript with the controller's rules and stops where it would."""

from __future__ import annotations

import pytest

from urdsl import parse
from urdsl.runtime import Environment, Interpreter, RuntimeConfig
from urdsl.runtime.values import ListValue, PoseValue, StructValue


def run(text: str, **config):
    interpreter = Interpreter(parse(text, "prog.script"), config=RuntimeConfig(**config))
    return interpreter.run()


def value(text: str, name: str = "x"):
    result = run(text)
    assert result.error is None, result.error
    return result.globals[name]


def error(text: str, **config):
    result = run(text, **config)
    assert result.error is not None, "the program should have failed"
    return result.error


# ---- values and operators ------------------------------------------------------------------


@pytest.mark.parametrize(("expression", "expected"), [
    ("1 + 2 * 3", 7), ("7 / 2", 3.5), ("7 % 3", 1), ("2.5 - 1", 1.5), ("-3 + 1", -2),
    ("1 < 2 and 2 <= 2", True), ("not 1 == 2", True), ("True xor True", False),
    ("\"ab\" + \"cd\"", "abcd"), ("[1, 2] + [3, 4]", ListValue([4, 6])),
    ("[1, 2] * 2", ListValue([2, 4])), ("[[1, 2], [3, 4]] * [1, 1]", ListValue([3, 7])),
    ("str_cat(\"n=\", 3)", "n=3"), ("to_str(1.5)", "1.5"), ("sqrt(16)", 4.0),
    ("pow(2, 10)", 1024.0), ("floor(2.7)", 2), ("norm([3, 4])", 5.0),
    ("length([1, 2, 3])", 3), ("str_len(\"abc\")", 3), ("to_num(\"42\")", 42),
    ("binary_list_to_integer([True, False, True])", 5), ("d2r(180)", 3.141592653589793),
])
def test_expressions(expression, expected):
    assert value(f"x = {expression}") == expected


def test_poses_lists_structs_matrices():
    assert value("x = p[1, 2, 3, 0, 0, 0]\nx[2] = 9") == PoseValue([1, 2, 9, 0, 0, 0])
    assert value("x = [[1, 2], [3, 4]]\nx[1, 0] = 7\n") == ListValue([ListValue([1, 2]),
                                                                     ListValue([7, 4])])
    assert value("m = [[1, 2], [3, 4]]\nx = m[1, 1]") == 4
    s = value("x = struct(a=1, b=\"t\")\nx.a = 5\n")
    assert s == StructValue({"a": 5, "b": "t"})
    assert value("s = struct(a=1, b=2)\nx = s[1] + s.a") == 3
    # a struct loops like a list in real 5.14 programs: length() counts its members
    assert value("s = struct(a=1, b=2, c=p[0, 0, 0, 0, 0, 0])\nx = length(s)") == 3
    assert value("x = make_list(2, 0, 5)\nx.append(7)\nx.append(8)\n") == ListValue([0, 0, 7, 8])


def test_the_manuals_list_struct_and_matrix_methods():
    # "Methods in URScript" (5.15 and later): the manual's own examples
    fill = ("l1 = make_list(5, 9, 10)\nl2 = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\nidx = 0\n"
            "while (idx < l2.length()):\n  if (l1.excess_capacity() > 0):\n"
            "    l1.append(l2[idx])\n  end\n  idx = idx + 1\nend\nx = l1\n")
    assert value(fill) == ListValue([9, 9, 9, 9, 9, 1, 2, 3, 4, 5])
    assert value("x = make_list(2, 0, 100)\nx.extend([1, 2, 3])\nx.remove(0)\n") == \
        ListValue([0, 1, 2, 3])
    assert value("l = [1, 2, 3, 4, 5]\nx = l.slice(1, 4)\n") == ListValue([2, 3, 4])
    assert value("x = [1, 2].to_string()") == "[1, 2]"
    assert value("s = struct(a=1, b=2)\nx = s.length()") == 2
    assert value("m = [[1, 2, 3], [4, 5, 6]]\nx = m.shape()") == ListValue([2, 3])
    assert value("m = [[1, 2, 3], [4, 5, 6]]\nx = m.get_column(1)") == ListValue([2, 5])
    assert value("m = [[1, 2, 3], [4, 5, 6]]\nx = m.get_row(1)") == ListValue([4, 5, 6])
    assert "full" in error("x = [1, 2]\nx.extend([3])\n").message
    assert "outside" in error("x = [1, 2]\nx.remove(2)\n").message
    assert "has no method 'shape'" in error("x = [1, 2]\ny = x.shape()\n").message


def test_inv_of_a_matrix_and_of_a_pose():
    # the manual's inv(m) takes a square non-singular matrix, and a pose (its inverse pose);
    # seen in a PolyScope program: pose_trans(inv(teach_frame), p)
    assert value("x = inv([[2, 0], [0, 4]])") == ListValue([ListValue([0.5, 0.0]),
                                                            ListValue([0.0, 0.25])])
    p = "p[0.1, -0.2, 0.3, 0.4, 0.5, -0.6]"
    inverse = value(f"x = inv({p})")
    assert type(inverse) is PoseValue
    assert list(inverse) == pytest.approx(list(value(f"x = pose_inv({p})")), abs=1e-12)
    assert "matrix of numbers, not a" in error("x = inv([1, 2])").message


# ---- scoping and calls ---------------------------------------------------------------------


def test_first_level_is_global_even_when_local():
    result = run("def prog():\n  local a = 1\n  b = 2\n  def f():\n    return a + b\n  end\n"
                 "  c = f()\nend\n")
    assert result.error is None
    assert result.globals == {"a": 1, "b": 2, "c": 3}


def test_function_locals_shadow_and_globals_assign():
    src = ("g = 1\n"
           "def f():\n  g = 5\n  local g2 = 7\n  h = 3\n  return h\nend\n"
           "def k():\n  local g = 100\n  return g\nend\n"
           "r = f()\nr2 = k()\n")
    result = run(src)
    assert result.error is None
    assert result.globals["g"] == 5  # unqualified: the global exists, so it is assigned
    assert result.globals["r"] == 3 and result.globals["r2"] == 100
    assert "h" not in result.globals and "g2" not in result.globals


def test_pass_by_value():
    src = ("def change(l):\n  l[0] = 99\n  return l\nend\n"
           "a = [1, 2]\nb = change(a)\nc = a\nc[1] = 5\n")
    result = run(src)
    assert result.globals["a"] == ListValue([1, 2])
    assert result.globals["b"] == ListValue([99, 2]) and result.globals["c"] == ListValue([1, 5])


def test_defaults_and_keywords():
    assert value("def f(a, b=10, c=100):\n  return a + b + c\nend\nx = f(1, c=2)") == 13


def test_halt_return_break_continue():
    src = ("x = 0\ni = 0\nwhile True:\n  i = i + 1\n  if i > 5:\n    break\n  elif i == 2:\n"
           "    continue\n  end\n  x = x + i\nend\nhalt\nx = -1\n")
    assert value(src) == 1 + 3 + 4 + 5


# ---- threads and time ----------------------------------------------------------------------


def test_threads_run_round_robin_in_robot_time():
    src = ("global n = 0\nthread counter():\n  while True:\n    n = n + 1\n    sync()\n  end\n"
           "end\nh = run counter()\nsleep(0.1)\nkill h\n")
    result = run(src)
    assert result.error is None
    assert result.time == pytest.approx(0.1)
    assert result.globals["n"] == 50  # one turn per 2 ms frame


def test_cb3_frames_are_8_ms():
    src = ("global n = 0\nthread counter():\n  while True:\n    n = n + 1\n    sync()\n  end\n"
           "end\nh = run counter()\nsleep(0.08)\nkill h\n")
    assert run(src, step_time=0.008).globals["n"] == 10


def test_join_waits_for_the_thread():
    src = ("global done = 0\nthread worker():\n  sleep(0.5)\n  done = 1\nend\n"
           "h = run worker()\njoin h\nt = done\n")
    result = run(src)
    assert result.globals["t"] == 1 and result.time == pytest.approx(0.5)


def test_join_or_kill_of_a_thread_variable_never_run_does_nothing():
    # UR's External Control script initialises its thread variables to 0 and joins them
    # before any `run`; anything else that is not a handle stays a type error
    assert value("thread_move = 0\njoin thread_move\nkill thread_move\nx = 1\n") == 1
    assert "join needs a thread handle, not a float" in str(error("h = 1.5\njoin h\n"))
    assert "kill needs a thread handle, not a int" in str(error("h = 2\nkill h\n"))


def test_program_end_with_threads_running_is_reported():
    result = run("thread t():\n  while True:\n    sync()\n  end\nend\nrun t()\nsleep(0.01)\n")
    assert result.error is None and result.threads_left_running == ["t"]
    assert any(e.kind == "thread" for e in result.events)


def test_critical_section_keeps_other_threads_out():
    src = ("global log = 0\nthread other():\n  log = log + 1\nend\n"
           "enter_critical\nrun other()\nsleep(0.01)\nseen = log\nexit_critical\nsleep(0.01)\n")
    result = run(src)
    assert result.globals["seen"] == 0 and result.globals["log"] == 1


def test_textmsg_and_popup_are_events():
    result = run("textmsg(\"hello \", 3)\npopup(\"careful\")\n")
    assert [(e.kind, e.message) for e in result.events] == [
        ("textmsg", "hello 3"), ("popup", "Popup: careful")]


def test_io_and_registers_go_to_the_environment():
    environment = Environment()
    environment.standard_digital_in[2] = True
    interpreter = Interpreter(parse("set_standard_digital_out(1, True)\n"
                                    "write_output_float_register(3, 1.5)\n"
                                    "x = get_standard_digital_in(2)\n"), environment=environment)
    result = interpreter.run()
    assert result.error is None and result.globals["x"] is True
    assert environment.standard_digital_out[1] and environment.output_float_registers[3] == 1.5


# ---- runtime errors name the line ------------------------------------------------------------


def test_undefined_name():
    err = error("def prog():\n  x = 1\n  y = z + x\nend\n")
    assert (err.line, err.column, err.diagnostic.code) == (3, 7, "URS201")
    assert "name 'z' is not defined" in str(err) and "  y = z + x" in str(err)


def test_undefined_in_thread_suggests_a_name():
    err = error("count = 0\nthread t():\n  x = cuont + 1\nend\nh = run t()\njoin h\n")
    assert err.line == 3 and "did you mean 'count'" in str(err)


def test_index_out_of_range():
    err = error("l = [1, 2, 3]\nx = l[3]\n")
    assert (err.line, err.column, err.diagnostic.code) == (2, 5, "URS202")


def test_type_mismatch():
    err = error("x = 1 + \"a\"\n")
    assert err.diagnostic.code == "URS203" and "str_cat" in (err.hint or "")


def test_division_by_zero():
    assert error("x = 1 / 0\n").diagnostic.code == "URS205"


def test_busy_thread_is_stopped_like_the_controller():
    err = error("thread t():\n  while True:\n    x = 1\n  end\nend\nrun t()\nsleep(1)\n",
                runaway_limit=10_000)
    assert (err.line, err.diagnostic.code) == (2, "URS207")
    assert "sync()" in (err.hint or "")


def test_wrong_builtin_arguments():
    err = error("sleep(1, 2)\n")
    assert err.diagnostic.code == "URS206" and "sleep(t)" in str(err)
    assert "no parameter 'speed'" in str(error("textmsg(\"a\", speed=1)\n"))
    assert "did you mean 'textmsg'" in str(error("textmgs(\"a\")\n"))


def test_runaway_recursion_is_stopped():
    err = error("def f(n):\n  return f(n + 1)\nend\nx = f(0)\n", max_call_depth=50)
    assert err.diagnostic.code == "URS208" and err.line == 2


def test_max_time_stops_endless_programs():
    result = run("while True:\n  sleep(1)\nend\n", max_time=10)
    assert result.stopped_at_max_time and result.error is None
    assert result.time == pytest.approx(10)


def test_unsupported_builtin_is_an_event_by_default():
    result = run("modbus_set_output_signal(\"x\", True, False)\n")
    assert result.error is None
    assert any(e.kind == "unsupported" for e in result.events)


def test_pace_sees_robot_time_advance_and_can_stop_the_program():
    seen: list[float] = []
    holder: dict = {}

    def pace(when: float) -> None:
        seen.append(when)
        if when >= 2.0:
            holder["rt"].request_stop()

    text = "i = 0\nwhile True:\n  i = i + 1\n  sleep(0.5)\nend\n"
    rt = Interpreter(parse(text, "t.script"), config=RuntimeConfig(pace=pace))
    holder["rt"] = rt
    result = rt.run()
    assert result.stopped and result.error is None
    assert seen == [0.5, 1.0, 1.5, 2.0]
    assert result.globals["i"] == 4 and result.time == 1.5


def test_old_combined_io_builtins_reach_the_tool_io():
    # get_digital_in/get_digital_out/set_digital_out take 0..9 (8 and 9 are the tool's),
    # get_analog_in 0..3 (2 and 3 are the tool's), on CB3 and e-Series alike
    from urdsl import parse
    from urdsl.runtime import Environment, Interpreter

    environment = Environment()
    result = Interpreter(parse(
        "set_digital_out(9, True)\n"
        "a = get_digital_out(9)\n"
        "b = get_tool_digital_out(1)\n"
        "c = get_digital_in(8)\n"
        "d = get_analog_in(3)\n", "io.script"), environment=environment).run()
    assert result.error is None
    assert result.globals["a"] is True and result.globals["b"] is True
    assert environment.tool_digital_out == [False, True]
    result = Interpreter(parse("e = get_digital_in(10)\n", "io.script"),
                         environment=Environment()).run()
    assert result.error is not None and "0..9; 8..9 are the tool's" in result.error.message


def test_integer_to_binary_list_takes_a_whole_float_and_refuses_a_fraction():
    from urdsl import parse
    from urdsl.runtime import Interpreter

    result = Interpreter(parse("bits = integer_to_binary_list(5.0)\n", "b.script")).run()
    assert result.error is None
    assert list(result.globals["bits"])[:4] == [True, False, True, False]
    result = Interpreter(parse("bits = integer_to_binary_list(2.5)\n", "b.script")).run()
    assert result.error is not None and result.error.kind == "type"


@pytest.mark.parametrize("call", ["str_sub(1, 2, 3)", "str_find(1, 2)"])
def test_a_builtin_model_that_fails_on_its_arguments_is_an_error_at_the_call(call):
    # the string builtins' models were written for strings: a number is a program error
    # at the call (file:line:col), never a Python traceback
    from urdsl.verify.run import check_text

    report = check_text(f"textmsg(1)\nx = {call}\n", "s.script")
    (error,) = [f for f in report.findings if f.severity == "error"]
    assert error.code == "URS203" and (error.span.line, error.span.column) == (2, 5)
    assert "cannot take these arguments" in error.message


def test_get_inverse_kin_of_a_taught_waypoint_is_its_joints_near_a_singularity():
    # a waypoint PolyScope wrote with wrist 2 at -0.07° on an arm 2.8 mm off the nominal
    # UR5e: the model's nearest solution turned wrist 1 by a radian, and the next movel
    # away from the singularity turned it back at 4.5 rad/s; on the arm itself the answer
    # is the taught joints
    from urdsl.verify.run import check_text

    pose = "p[.250543879133, .376142644240, .393738464893, .028656114718, 1.563205411513, " \
           "-.035762589999]"
    joints = "[1.5293444395065308, -1.5700282705114041, -1.8200201988220215, " \
             "-2.831017633477682, -0.0012190977679651382, -1.6372764746295374]"
    text = (f"movej({joints})\nq = get_inverse_kin({pose}, qnear={joints})\ntextmsg(q)\n"
            f"r = get_inverse_kin(pose_add({pose}, p[0, 0, 0.02, 0, 0, 0]), qnear={joints})\n"
            "textmsg(r)\n")
    shown = [e.message for e in check_text(text, "taught.script").events
             if e.kind == "textmsg"]
    assert shown[0].startswith("[1.529344, -1.570028, -1.82002, -2.831018, -0.001219")
    assert not shown[1].startswith("[1.529344, -1.570028")  # 2 cm away: the model's own


def test_get_inverse_kin_of_a_waypoint_taught_stretched_out_is_its_joints():
    # PolyScope's upright home, taught on the arm: its calibration puts the pose 0.3 mm
    # beyond the nominal UR5e's reach, where the model has no solution; the taught joints
    # are the arm's own (CederGroupHub alab_control OpenDoor_B Home_WP)
    from urdsl.verify.run import check_text

    pose = "p[-.001703142952, -.233433365732, 1.079483178718, -.009004197313, " \
           "-2.218443849278, 2.216349783219]"
    joints = "[-1.732503072560121E-6, -1.5707525371365882, 1.889864076787262E-5, " \
             "-1.5708004436888636, -4.083315004521637E-5, -3.0819569722950746E-5]"
    text = f"movej(get_inverse_kin({pose}, qnear={joints}))\n"
    report = check_text(text, "home.script", robot="ur5e")
    assert not [f for f in report.findings if f.severity == "error"], report.findings
    # a pose further out is still out of reach, taught joints or not
    far = pose.replace("1.079483178718", "1.09")
    report = check_text(f"movej(get_inverse_kin({far}, qnear={joints}))\n", "far.script",
                        robot="ur5e")
    assert [f.code for f in report.findings if f.severity == "error"] == ["URS301"]
