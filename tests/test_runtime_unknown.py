"""Reads from the outside world are unknown offline: the interpreter follows a working device,
warns once per statement, and never turns a device's reply into an error."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl import parse
from urdsl.runtime import Environment, Interpreter, RuntimeConfig
from urdsl.runtime.unknown import DEVICE_REPLY_TIME, OPERATOR_REPLY_TIME, UNKNOWN_LOOP_PASSES
from urdsl.runtime.values import ListValue, Unknown


def run(text: str, devices: str = "unknown", **config):
    environment = Environment(devices=devices)
    interpreter = Interpreter(parse(text, "prog.script"), environment=environment,
                              config=RuntimeConfig(**config))
    return interpreter.run()


def lines(warnings) -> list[int]:
    return [w.span.line for w in warnings]


ROBOTIQ_STYLE = """\
rq = rpc_factory("xmlrpc", "http://127.0.0.1:4242/RPC2")
if not rq.is_ready():
  popup("the gripper is not ready", error=True)
  halt
end
ready = rq.status() == 3 and rq.fault() == 0
done = 1
"""


def test_xmlrpc_reply_is_unknown_and_not_ready_branch_is_not_taken():
    result = run(ROBOTIQ_STYLE)
    assert result.error is None
    assert result.globals["done"] == 1  # the error branch (popup, halt) was skipped
    assert type(result.globals["ready"]) is Unknown
    assert lines(result.warnings) == [2]
    message = result.warnings[0].message
    assert "is_ready() at line 2" in message and "skips this branch" in message
    assert result.time >= 3 * DEVICE_REPLY_TIME  # each call waits for the reply


def test_the_same_program_with_quiet_devices_fails_as_before():
    result = run(ROBOTIQ_STYLE, devices="quiet")
    assert result.error is not None and result.error.diagnostic.code == "URS203"


def test_blocking_socket_read_takes_robot_time_and_its_wait_loop_ends():
    result = run('socket_open("127.0.0.1", 63352, "gripper")\n'
                 'reply = socket_read_string("gripper", 0)\n'
                 'while reply != "ok":\n'
                 '  reply = socket_read_string("gripper", 0)\n'
                 'end\n'
                 'done = True\n')
    assert result.error is None and result.stopped_early is None
    assert result.globals["done"] is True
    assert lines(result.warnings) == [3]
    assert "socket_read_string() at line" in result.warnings[0].message
    assert result.time >= DEVICE_REPLY_TIME  # the read waited for the reply


def test_a_working_device_sends_as_many_values_as_were_asked_for():
    # Robotiq's preamble: a reply shorter than a gripper id list means "no gripper"
    result = run('socket_open("127.0.0.1", 63352, "gripper")\n'
                 'sids = socket_read_byte_list(17, "gripper", 0)\n'
                 'connected = False\n'
                 'if sids[0] > 2:\n'
                 '  connected = sids[2] == 57\n'
                 'end\n'
                 'floats = socket_read_ascii_float(6, "gripper")\n'
                 'many = socket_read_byte_list(1000, "gripper")\n'
                 'drained = 0\n'
                 'left = socket_read_byte_list(1, "gripper", 0.002)\n'
                 'while left[0] >= 1:\n'
                 '  left = socket_read_byte_list(1, "gripper", 0.002)\n'
                 '  drained = drained + 1\n'
                 'end\n')
    assert result.error is None
    sids = result.globals["sids"]
    assert len(sids) == 18 and sids[0].likely == 17 and type(sids[1]) is Unknown
    assert type(result.globals["connected"]) is Unknown  # the branch of a working device
    assert len(result.globals["floats"]) == 7 and result.globals["floats"][0].likely == 6
    assert type(result.globals["many"]) is Unknown  # more than one read gives: not modelled
    # a buffer drained while bytes come: a working device's buffer runs dry
    assert 1 <= result.globals["drained"] <= UNKNOWN_LOOP_PASSES
    assert lines(result.warnings) == [4, 11]
    assert "leaves the loop after at most" in result.warnings[1].message


def test_queued_socket_replies_stay_known():
    environment = Environment(devices="unknown", socket_replies={"s": ["ok"]})
    program = 'socket_open("127.0.0.1", 1, "s")\nx = socket_read_string("s")\n'
    result = Interpreter(parse(program, "p.script"), environment=environment).run()
    assert result.globals["x"] == "ok" and not result.warnings


def test_register_read_wait_loop_warns_once_and_goes_on():
    result = run("n = 0\n"
                 "while read_input_integer_register(0) < 1:\n"
                 "  n = n + 1\n"
                 "  sync()\n"
                 "end\n"
                 "after = 1\n")
    assert result.error is None and result.globals["after"] == 1
    assert result.globals["n"] == UNKNOWN_LOOP_PASSES
    assert lines(result.warnings) == [2]


def test_a_wait_for_the_expected_reply_ends_at_once():
    result = run("n = 0\n"
                 "while read_input_integer_register(0) != 1:\n"
                 "  n = n + 1\n"
                 "  sync()\n"
                 "end\n")
    assert result.error is None and result.globals["n"] == 0
    assert "reply ends the loop" in result.warnings[0].message


def test_a_reply_check_function_sees_the_expected_reply():
    result = run("def is_ack(b):\n"
                 "  if b[0] != 3:\n"
                 "    return False\n"
                 "  end\n"
                 "  if b[1] != 97 or b[2] != 99:\n"
                 "    return False\n"
                 "  end\n"
                 "  return True\n"
                 "end\n"
                 'socket_open("127.0.0.1", 1, "s")\n'
                 "tries = 0\n"
                 'while not is_ack(socket_read_byte_list(3, "s", 0)):\n'
                 "  tries = tries + 1\n"
                 "end\n")
    assert result.error is None and result.globals["tries"] == 0
    assert lines(result.warnings) == [2, 5]  # the count leans to what was asked for


def test_one_warning_per_statement_not_per_pass():
    result = run("i = 0\n"
                 "while i < 10:\n"
                 "  if get_standard_digital_in(0):\n"
                 "    set_standard_digital_out(1, True)\n"
                 "  end\n"
                 "  i = i + 1\n"
                 "  sync()\n"
                 "end\n")
    assert result.error is None
    assert lines(result.warnings) == [3]


def test_unknown_flows_through_expressions_without_errors():
    result = run("r = read_input_float_register(2)\n"
                 "a = r * 2 + 1\n"
                 "b = [r, 1, 2][0]\n"
                 "c = -r < 3\n"
                 "d = not (r == 1)\n"
                 "e = str_cat(\"r=\", r)\n"
                 "f = sqrt(r)\n"
                 "g = p[r, 0, 0, 0, 0, 0]\n"
                 "h = [r, r] + [1, 2]\n"
                 "k = False and r > 1\n")
    assert result.error is None, result.error
    for name in "abcdefgh":
        assert type(result.globals[name]) is Unknown, name
    assert result.globals["k"] is False  # decided without the unknown value
    assert "read_input_float_register() at line 1" in result.globals["a"].source


def test_own_outputs_flags_and_globals_stay_known():
    result = run("set_standard_digital_out(2, True)\n"
                 "write_output_integer_register(3, 7)\n"
                 "set_flag(1, True)\n"
                 "a = get_standard_digital_out(2)\n"
                 "b = read_output_integer_register(3)\n"
                 "c = get_flag(1)\n")
    assert (result.globals["a"], result.globals["b"], result.globals["c"]) == (True, 7, True)
    assert not result.warnings


def test_operator_prompt_takes_robot_time():
    result = run('n = request_integer_from_primary_client("How many parts?")\n')
    assert result.error is None and type(result.globals["n"]) is Unknown
    assert result.time >= OPERATOR_REPLY_TIME


def test_a_thread_looping_on_an_input_without_sync_is_still_stopped():
    result = run("thread watch():\n"
                 "  while True:\n"
                 "    if get_standard_digital_in(0):\n"
                 "      x = 1\n"
                 "    end\n"
                 "  end\n"
                 "end\n"
                 "run watch()\n"
                 "sleep(1)\n", runaway_limit=5_000)
    assert result.error is not None and result.error.diagnostic.code == "URS207"


POLLING = """\
movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])
while True:
  force = get_tcp_force()
  if force[2] <= -18:
    movej([0.3, -1.5708, 1.5708, -1.5708, -1.5708, 0])
  elif force[0] >= 18:
    movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])
  end
  while norm(get_target_joint_speeds()) >= 0.0001:
    sync()
  end
end
"""


def spinning(text: str, line: int):
    """The check's report of ``text``, whose one error is a loop without physical time
    (URS207) at ``line``."""
    from urdsl.verify.run import check_text

    report = check_text(text, "spin.script")
    (spin,) = [f for f in report.findings if f.severity == "error"]
    assert spin.code == "URS207" and spin.span.line == line
    return report


def test_a_loop_that_acts_only_when_pushed_spins_when_nobody_pushes():
    # it moves while the operator pushes the arm, and loops without physical time when
    # nobody does: the check follows a working sensor for a few passes, then an idle one
    from urdsl.runtime.unknown import IDLE_AFTER_PASSES

    report = spinning(POLLING, 2)
    (note,) = [f for f in report.findings if f.span.line == 4]
    assert f"for the loop's first {IDLE_AFTER_PASSES} passes, then skips it" in note.message
    assert len(report.moves) == 1 + IDLE_AFTER_PASSES  # the pushes of the first passes


@pytest.mark.parametrize("change", [
    ("  end\n  while norm", "  end\n  sync()\n  while norm"),  # it waits a frame each pass
    ("  force = get_tcp_force()", "  force = get_tcp_force()\n  sleep(0.1)"),
    ("  force = get_tcp_force()", "  force = get_tcp_force()\n  pause()"),  # a def may wait
])
def test_a_loop_that_takes_time_of_its_own_is_not_left_idle(change):
    from urdsl.runtime.unknown import polls_devices
    from urdsl.verify.run import CheckOptions, check_text

    text = ("def pause():\n  sleep(0.1)\nend\n" if "pause" in change[1] else "") + \
        POLLING.replace(*change)
    loop = next(s for s in parse(text, "prog.script").body if type(s).__name__ == "While")
    assert polls_devices(parse(POLLING, "prog.script").body[1].body)
    assert not polls_devices(loop.body)
    report = check_text(text, "push.script", options=CheckOptions(max_time=30.0))
    assert [f.code for f in report.findings if f.severity == "error"] == []
    assert any(f.code == "URS312" for f in report.findings)  # it ran until the bound


def test_a_socket_read_with_a_timeout_the_device_sent_still_waits():
    # UR's External Control loop: the read's timeout comes from the previous reply
    result = run('socket_open("127.0.0.1", 50001, "reverse")\n'
                 "timeout = 0.0\n"
                 "n = 0\n"
                 "while n < 20000:\n"
                 '  reply = socket_read_binary_integer(8, "reverse", timeout)\n'
                 "  timeout = reply[1] / 1000.0\n"
                 "  n = n + 1\n"
                 "end\n", runaway_limit=5_000)
    assert result.error is None, result.error
    assert result.time >= 19_999 * 0.002  # one controller frame per read at least
    assert any("its wait is taken as one controller frame" in w.message
               for w in result.warnings)


def test_real_errors_on_known_values_stay_errors():
    result = run("r = read_input_integer_register(0)\nx = [1, 2][5]\n")
    assert result.error is not None and result.error.diagnostic.code == "URS202"


def test_unknown_index_makes_the_list_unknown_not_wrong():
    result = run("l = [1, 2, 3]\nl[read_input_integer_register(0)] = 9\n")
    assert result.error is None and type(result.globals["l"]) is Unknown


def test_quiet_socket_read_with_timeout_0_waits_for_ever():
    result = run('x = socket_read_byte_list(1, "g", 0)\n', devices="quiet")
    assert result.error is None
    assert result.stopped_early is not None and result.stopped_early.kind == "blocked"
    assert "waits for ever" in result.stopped_early.message
    assert result.stopped_early.span.line == 1


def test_list_values_keep_their_type():
    result = run("x = [1, 2]\n")
    assert result.globals["x"] == ListValue([1, 2])


def test_and_or_with_an_unknown_on_either_side():
    result = run("r = get_standard_digital_in(0)\n"
                 "a = True and r\nb = r and False\nc = False or r\nd = r or True\n")
    assert result.error is None, result.error
    assert type(result.globals["a"]) is Unknown and result.globals["b"] is False
    assert type(result.globals["c"]) is Unknown and result.globals["d"] is True


def test_textmsg_of_an_unknown_prints_a_question_mark():
    result = run('textmsg("reply: ", read_input_integer_register(1))\n')
    assert result.error is None and result.events[-1].message == "reply: ?"


_KNOWN = {
    "int": "3", "float": "2.5", "bool": "True", "string": '"ok"', "list": "[1, 2, 3]",
    "matrix": "[[1, 2], [3, 4]]", "pose": "p[0.1, 0, 0.2, 0, 3.14, 0]",
}


@settings(max_examples=60, deadline=None)
@given(op=st.sampled_from(["+", "-", "*", "/", "%", "<", ">", "<=", ">=", "==", "!=", "and",
                           "or", "xor"]),
       known=st.sampled_from(sorted(_KNOWN)), unknown_left=st.booleans())
def test_an_operation_with_an_unknown_operand_never_fails(op, known, unknown_left):
    """Law: an operator on an unknown value gives an unknown value, or (and/or) the value
    it is decided by; it fails only when the known operand is wrong on its own (a boolean
    operator on something that is not a bool)."""
    left, right = ("r", _KNOWN[known]) if unknown_left else (_KNOWN[known], "r")
    result = run(f"r = read_input_integer_register(0)\nx = {left} {op} {right}\n")
    if op in ("and", "or", "xor") and known != "bool":
        assert result.error is not None and result.error.diagnostic.code == "URS203"
        return
    assert result.error is None, result.error
    x = result.globals["x"]
    assert type(x) is Unknown or (op in ("and", "or") and type(x) is bool)


@pytest.mark.parametrize("op", ["+", "-", "*", "/", "<", "==", "!=", "and", "or", "xor"])
def test_an_operation_on_two_unknowns_is_unknown(op):
    # PolyScope writes `read_input_boolean_register(64) xor read_input_boolean_register(65)`
    result = run("a = read_input_boolean_register(64)\nb = read_input_boolean_register(65)\n"
                 f"x = a {op} b\n")
    assert result.error is None, result.error
    assert type(result.globals["x"]) is Unknown


def test_boolean_registers_go_up_to_127():
    result = run("write_output_boolean_register(100, True)\n"
                 "a = read_output_boolean_register(100)\n"
                 "b = read_input_boolean_register(127)\n")
    assert result.error is None and result.globals["a"] is True
    assert type(result.globals["b"]) is Unknown


def test_a_force_sensor_loop_ends_where_contact_would_end_it():
    # press down until the force sensor reads 50 N: offline nothing touches the part, so a
    # modelled force of 0 N would drive the arm through the table and out of reach
    from urdsl.verify.run import check_text

    report = check_text(
        "movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])\n"
        "while force() < 50:\n"
        "  movel(pose_add(get_actual_tcp_pose(), p[0, 0, -0.0005, 0, 0, 0]))\n"
        "end\n"
        "done = 1\n", "press.script")
    assert not report.has_errors, report.render_text()
    assert [f.span.line for f in report.findings if f.code == "URS210"] == [2]
    assert "force() at line 2" in report.findings[0].message
    assert len([m for m in report.moves if m.kind == "movel"]) == UNKNOWN_LOOP_PASSES


def test_one_device_read_gets_one_reply_across_comparisons():
    # PolyScope writes a switch on a PLC's job number as separate ifs: a working PLC sends
    # one job, so only the branches of one number are followed
    result = run('if (modbus_get_signal_status("JOB") == 2):\n  a = 1\nend\n'
                 'if (modbus_get_signal_status("JOB") == 7):\n  b = 1\nend\n'
                 'if modbus_get_signal_status("JOB") != 2:\n  c = 1\nend\n'
                 'if (modbus_get_signal_status("SPEED") == 7):\n  d = 1\nend\n')
    assert result.error is None
    assert {k for k in "abcd" if k in result.globals} == {"a", "d"}


def test_a_name_left_unassigned_by_a_branch_the_check_skipped_is_a_warning():
    from urdsl.verify.run import check_text

    text = ('answer = request_integer_from_primary_client("1, 2 or 5 to stop")\n'
            "if answer == 5:\n  answer = 0\nend\n"
            "if answer == 1:\n  kind = 10\nelif answer == 2:\n  kind = 20\nend\n"
            "textmsg(kind)\n"
            "movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])\n")
    report = check_text(text, "ask.script")
    (finding,) = [f for f in report.findings if "'kind' is not defined" in f.message]
    assert finding.severity == "warning" and finding.span.line == 10
    assert "depends on the replies the check assumed (the first at line 2)" in finding.message
    # the check goes on with the name's value unknown: the move after it is checked
    assert not [f for f in report.findings if f.severity == "error"]
    assert [m.span.line for m in report.moves] == [11]
    # a name the program never assigns stays an error
    report = check_text(text.replace("textmsg(kind)", "textmsg(knid)"), "ask.script")
    (finding,) = [f for f in report.findings if f.code == "URS201"]
    assert finding.severity == "error"


GOES_ON = """\
def cell():
  rq_activate_and_wait()
  i = 0
  while i < 3:
    rq_move_and_wait(gripper_width)
    movej(home_q)
    i = i + 1
  end
  movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])
  while True:
    count = 1
  end
end
"""


def test_a_name_defined_nowhere_is_reported_once_and_the_check_goes_on():
    from urdsl.verify.run import check_text

    report = check_text(GOES_ON, "cell.script")
    undefined = [f for f in report.findings if f.code == "URS201"]
    # one error per missing name, at its first use, however often the loop meets it
    assert sorted((f.span.line, f.message) for f in undefined) == [
        (2, "name 'rq_activate_and_wait' is not defined"),
        (5, "name 'gripper_width' is not defined"),
        (5, "name 'rq_move_and_wait' is not defined"),
        (6, "name 'home_q' is not defined")]
    assert all(f.severity == "error" and "went on" in f.hint for f in undefined)
    # what depends on a missing name is no device warning; the rest of the program is checked
    assert not [f for f in report.findings if f.code == "URS210"]
    assert [m.span.line for m in report.moves] == [9]
    (spin,) = [f for f in report.findings if f.code == "URS207"]
    assert spin.span.line == 10


def test_the_program_itself_still_stops_at_a_name_defined_nowhere():
    # the virtual controller runs programs as the controller does: the first missing name
    # stops the program
    result = run(GOES_ON + "cell()\n", devices="quiet")
    assert result.error is not None and result.error.kind == "undefined"
    assert result.error.span.line == 2 and result.undefined == []


def test_a_dotted_xmlrpc_method_is_a_device_call():
    # Robotiq Copilot's preamble calls a server's dotted method names
    result = run('client = rpc_factory("xmlrpc", "http://127.0.0.1:4243/RPC2")\n'
                 "regs = client.ModbusServiceWrapper.readRegisters(1, 0, 4)\n"
                 "ready = regs[0] == 1\n")
    assert result.error is None
    assert "ModbusServiceWrapper.readRegisters()" in result.globals["regs"].source


COMMANDED = """\
def tray():
  movej([0, -1.57, 1.57, -1.57, -1.57, 0])
  socket_open("127.0.0.1", 30000, "pc")
  left = 10
  while (True):
    {wait}
    movel(p[0.4 - 0.1 * left, -0.3, 0.2, 0, 3.14, 0], a=1.2, v=0.5)
    left = left - 1
  end
end
"""
"""A cell program that takes the next piece of a tray each pass, with a counter it never
resets: after the tray's last piece its target leaves the arm's reach (pass 10 on)."""

WAIT_FOR_PC = """reply = socket_read_string("pc", timeout=2)
    while (reply == ""):
      reply = socket_read_string("pc", timeout=2)
    end"""


def test_what_the_passes_of_a_device_paced_loop_accumulate_is_a_warning():
    # every pass waits for the PC's command: how many passes there are is the PC's to say
    # (a game's nine moves); the tray running empty is then a warning that says so
    from urdsl.verify.run import CheckOptions, check_text

    options = CheckOptions(robot="ur5e", max_time=200)
    report = check_text(COMMANDED.format(wait=WAIT_FOR_PC), "tray.script", options=options)
    (reach,) = [f for f in report.findings if f.code == "URS301"]
    assert reach.severity == "warning"
    assert "depends on how many times that device answers" in reach.message
    assert "socket_read_string()" in reach.message
    # without the wait, every pass happens whatever a device says: an error
    report = check_text(COMMANDED.format(wait="sleep(0.1)"), "tray.script", options=options)
    (reach,) = [f for f in report.findings if f.code == "URS301"]
    assert reach.severity == "error"


def test_an_error_of_a_device_paced_loops_first_passes_stays_an_error():
    # out of reach in the first pass: no device reply decides that
    from urdsl.verify.run import CheckOptions, check_text

    text = COMMANDED.format(wait=WAIT_FOR_PC).replace("left = 10", "left = -10")
    report = check_text(text, "tray.script", options=CheckOptions(robot="ur5e", max_time=200))
    (reach,) = [f for f in report.findings if f.code == "URS301"]
    assert reach.severity == "error"


def test_a_handle_a_builtin_factory_gives_is_a_device_not_none():
    # eip_writer_factory (EtherNet/IP) gives a writer whose methods the program calls
    result = run('w = eip_writer_factory(1, 2)\nw.define_bit(1, 0, "ready")\n')
    assert result.error is None


def test_a_thread_polling_a_device_does_not_pace_the_main_loop():
    # the gripper's status is read all along by a thread; the main loop's passes happen
    # whatever it says, so what they accumulate stays an error
    from urdsl.verify.run import CheckOptions, check_text

    watcher = ('thread watch():\n    while (True):\n      if (read_input_integer_register(0)'
               ' == 1):\n        textmsg("ready")\n      end\n      sync()\n    end\n  end\n'
               '  run watch()\n  ')
    text = COMMANDED.format(wait="sleep(0.1)").replace("  left = 10\n", watcher + "left = 10\n")
    report = check_text(text, "tray.script", options=CheckOptions(robot="ur5e", max_time=200))
    (reach,) = [f for f in report.findings if f.code == "URS301"]
    assert reach.severity == "error"


def test_what_a_builtin_urdsl_does_not_simulate_returns_is_unknown_not_zeros():
    # offline, a builtin urdsl does not model returns a value it does not know (zeros were
    # taken for a pose the program then moved to); with devices that answer, the neutral one
    result = run("w = tool_pose()\nx = w[2]\n")
    assert result.error is None, result.error
    assert isinstance(result.globals["w"], Unknown) and isinstance(result.globals["x"], Unknown)
    assert not isinstance(run("w = tool_pose()\n", devices="quiet").globals["w"], Unknown)


def test_get_joint_positions_reads_the_arms_joints():
    # a PolyScope Script node turns wrist 3 to its limit: q = get_joint_positions() (External
    # Control's name for the joints) then q[5] = d2r(-350): with zeros for the joints, the
    # arm was sent straight out
    from urdsl.verify.run import check_text

    report = check_text("movej([0.3, -1.5, 1.5, -1.5, -1.5, 0])\nq = get_joint_positions()\n"
                        "q[5] = d2r(-350)\ntextmsg(q)\nmovej(q)\n", "wrist.script")
    (shown,) = [e.message for e in report.events if e.kind == "textmsg"]
    assert shown.startswith("[0.3, -1.5, 1.5, -1.5, -1.5, -6.1")


PLC_CELL = """\
while True:
  global flag = 0
  thread work():
    if read_input_integer_register(4) == 1:
      movej([0.3, -1.5708, 1.5708, -1.5708, -1.5708, 0])
    end
    flag = 1
  end
  if read_input_boolean_register(9):
    global handle = run work()
    while flag == 0:
      if not read_input_boolean_register(9):
        kill handle
        flag = 2
      else:
        sync()
      end
    end
  else:
    flag = 2
  end
  if not read_input_boolean_register(9):
    stopl(1.2)
    sleep(999999)
  end
end
"""


def test_a_branch_that_stops_motion_fires_in_a_loop_that_gives_no_time():
    # PolyScope's continuously checked If (a thread the loop kills when its input drops) and
    # an If whose branch stops the arm: such a branch fires once the arm is at rest, and a
    # loop that tests it again without robot time passing (nothing to wait for) sees it fire,
    # as the controller does, instead of spinning with neither branch taken
    from urdsl.verify.run import check_text

    report = check_text(PLC_CELL, "sub.script")
    assert not [f for f in report.findings if f.severity == "error"], report.findings
    assert report.moves  # the PLC's first work order was followed


def test_a_stopping_branch_in_a_thread_still_waits_for_the_move():
    # the Until pattern: the move is checked to where it goes, the stop fires after it
    from urdsl.verify.run import check_text

    text = ("thread until():\n"
            "  while True:\n"
            "    if get_standard_digital_in(0):\n"
            "      stopl(1.2)\n"
            "    end\n"
            "    sync()\n"
            "  end\n"
            "end\n"
            "movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])\n"
            "global t = run until()\n"
            "movel(p[0.3, -0.3, 0.3, 0, 3.14, 0], v=0.1)\n"
            "kill t\n")
    report = check_text(text, "until.script")
    assert len(report.moves) == 2 and report.moves[1].duration > 0.5


PLC_SPIN = """\
while True:
  global state = read_port_register(200)
  global flag = 0
  thread work():
    movej([0.3, -1.5708, 1.5708, -1.5708, -1.5708, 0])
    flag = 1
  end
  if state == 1:
    global handle = run work()
    while flag == 0:
      if not(state == 1):
        kill handle
        flag = 2
      else:
        sync()
      end
    end
  else:
    flag = 2
  end
end
"""


def test_a_plc_loop_that_waits_for_no_state_still_spins_when_the_plc_is_idle():
    # PolyScope's continuously checked If on a PLC register (its branch kills the thread it
    # runs): while the register holds a value no branch waits for (0 at power-up), the loop
    # spins without time; the branch that stops the arm fires for a working PLC, and an
    # idle one (reads at rest) leaves the loop spinning, as on the controller
    report = spinning(PLC_SPIN, 1)
    assert report.moves  # the working PLC's first order was followed


@pytest.mark.parametrize(("test", "holds"), [
    ("reg", False), ("not reg", True), ("not (reg)", True), ("state == 1", False),
    ("state == 0", True), ("state != 0", False), ("0 == state", True),
    ("reg == False", True), ("not reg and not other", True), ("reg or not other", True),
    ("not (reg or other)", True), ("reg and not other", False),
])
def test_an_idle_device_reads_at_rest(test, holds):
    from urdsl.runtime.unknown import idle_truth

    (statement,) = parse(f"if {test}:\n  x = 1\nend\n", "t.script").body
    assert idle_truth(statement.test) is holds
