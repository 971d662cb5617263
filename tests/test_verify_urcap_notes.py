"""Notes about code a URCap or PolyScope wrote into a program: one per URCap, not one per
device condition of its preamble; its threads may outlive the program unremarked."""

from __future__ import annotations

from urdsl.verify.run import CheckOptions, check_text

PREAMBLE = '''def prog():
  # begin: URCap Installation Node
  #   Source: Robotiq_Grippers, 1.8.13, Robotiq Inc.
  #   Type: Gripper
  socket_open("127.0.0.1", 63352, "1")
  a = socket_read_byte_list(3, "1")
  if a[1] == 97:
    textmsg("ack")
  end
  b = socket_read_string("1")
  if b == "ok":
    textmsg("ok")
  end
  thread rq_gripper_communication():
    while True:
      sync()
    end
  end
  rq_thread = run rq_gripper_communication()
  # end: URCap Installation Node
  thread Step_Counter_Thread_1a2b():
    while True:
      sync()
    end
  end
  run Step_Counter_Thread_1a2b()
  {body}
end
'''


def check(body: str):
    return check_text(PREAMBLE.replace("{body}", body), "prog.script",
                      options=CheckOptions(robot="ur5e", max_time=30.0))


def test_the_notes_of_a_urcaps_code_are_one():
    report = check("c = get_standard_digital_in(0)\n  if c:\n    textmsg(\"in\")\n  end")
    notes = [f for f in report.findings if f.code == "URS210"]
    (urcap,) = [f for f in notes if "URCap code" in f.message]
    assert "2 statements of the URCap code of Robotiq_Grippers (lines 2-20)" in urcap.message
    assert urcap.span.line == 7 and "lines 7, 11" in urcap.message
    assert urcap.severity == "warning"
    # the user's own condition keeps its note
    assert [f.span.line for f in notes if f is not urcap] == [28]


def test_threads_polyscope_and_urcaps_write_may_outlive_the_program():
    report = check("sleep(1)")
    assert "URS311" not in report.codes()


def test_a_users_thread_left_running_is_still_reported():
    report = check("thread mine():\n    while True:\n      sync()\n    end\n  end\n"
                   "  run mine()\n  sleep(1)")
    (left,) = [f for f in report.findings if f.code == "URS311"]
    assert "mine" in left.message and "rq_gripper" not in left.message


def test_threads_running_when_the_check_stops_the_program_are_not_left_running():
    report = check("thread mine():\n    while True:\n      sync()\n    end\n  end\n"
                   "  run mine()\n  n = 0\n  while True:\n    n = n + 1\n    if n < 0:\n"
                   "      halt\n    end\n    sleep(1)\n  end")
    assert "URS312" in report.codes() and "URS311" not in report.codes()
