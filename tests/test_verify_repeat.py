"""A forever loop whose pass begins as an earlier one began repeats itself: the check stops
there (in a second, not at --max-time), and misses nothing a later pass would show."""

from __future__ import annotations

import textwrap

import pytest

from urdsl.runtime.interpreter import Interpreter, RuntimeConfig
from urdsl.runtime.repeat import detached_threads, inert_names
from urdsl.script import parse
from urdsl.verify.run import CheckOptions, check_text

A = "[0, -1.9, 1.9, -1.57, -1.57, 0]"
B = "[0.5, -1.9, 1.9, -1.57, -1.57, 0]"


def check(body: str, **options):
    text = textwrap.dedent(body).lstrip("\n")
    options.setdefault("max_time", 600.0)
    return check_text(text, "cell.script", options=CheckOptions(robot="ur5e", **options))


def repeats(report):
    return [f for f in report.findings if f.code == "URS312" and "repeats" in f.message]


def test_a_cell_loop_stops_once_a_pass_begins_as_the_one_before():
    report = check(f"""
        def cell():
          count = 0
          while True:
            movej({A}, a=1.4, v=1.05)
            movej({B}, a=1.4, v=1.05)
            count = count + 1
            textmsg("parts: ", count)
          end
        end
        """)
    (finding,) = repeats(report)
    assert finding.severity == "info" and finding.span.line == 3
    assert "pass 3 of this loop begins in the same state as the one before" in finding.message
    assert len(report.moves) == 4 and report.loop.passes == 2
    assert report.cycle_time == pytest.approx(report.moves[2].duration
                                              + report.moves[3].duration, abs=1e-6)
    assert not report.has_errors and "URS313" not in report.codes()


def test_a_pallet_counter_repeats_with_its_period_after_every_place_was_visited():
    report = check("""
        i = 0
        while True:
          movel(p[0.3 + 0.05 * i, -0.3, 0.2, 0, 3.1416, 0], a=1.2, v=0.25)
          movel(p[0.3, -0.45, 0.3, 0, 3.1416, 0], a=1.2, v=0.25)
          i = i + 1
          if i >= 3:
            i = 0
          end
        end
        """)
    (finding,) = repeats(report)
    assert "pass 5 of this loop begins in the same state as pass 2" in finding.message
    assert "passes 2 to 4" in finding.message
    assert len(report.moves) == 8  # passes 1-4: the three places, then the first again


def test_a_mistake_on_a_late_pass_is_still_found():
    # the counter decides a branch: no two passes begin alike until it fires
    report = check(f"""
        n = 0
        while True:
          movej({A})
          movej({B})
          n = n + 1
          if n == 40:
            movel(p[3.0, 0, 0.2, 0, 3.1416, 0])
          end
        end
        """, max_time=3600.0)
    assert "URS301" in report.codes() and report.has_errors
    assert not repeats(report)


def test_a_relative_move_that_drifts_each_pass_does_not_repeat():
    report = check("""
        movej([0, -1.57, 1.57, -1.57, -1.57, 0])
        while True:
          movel(pose_add(get_actual_tcp_pose(), p[0.05, 0, 0, 0, 0, 0]), a=1.2, v=0.25)
        end
        """)
    assert not repeats(report)
    assert "URS301" in report.codes()  # it drifts out of reach


def test_a_thread_that_changes_what_the_loop_reads_keeps_it_running_until_it_settles():
    report = check("""
        ready = 0
        thread warm():
          while ready < 5:
            sleep(1.0)
            ready = ready + 1
          end
        end
        run warm()
        while True:
          if ready >= 5:
            set_standard_digital_out(0, True)
          end
          sleep(0.5)
        end
        """)
    (finding,) = repeats(report)
    assert finding.time >= 5.0  # not before the thread's last change


def test_the_virtual_controller_runs_a_repeating_loop_on():
    module = parse("i = 0\nwhile True:\n  sleep(0.5)\n  i = i + 1\nend\n", "cell.script")
    result = Interpreter(module, config=RuntimeConfig(max_time=20.0)).run()
    assert result.stopped_at_max_time and result.stopped_early is None


@pytest.mark.parametrize(("program", "inert"), [
    ("count = 0\ncount = count + 1\ntextmsg(count)\n", {"count"}),
    ("count = 0\ncount = count + 1\nx = count\nif x > 3:\n  halt\nend\n", set()),
    ("a = [0, 0]\ni = 1\nv = 2\na[i] = v\n", set()),
    ("t = 0\nu = t + 1\nt = u\nmovej([u, 0, 0, 0, 0, 0])\n", set()),
    ("log = 0\ndef f(x):\n  return x\nend\nlog = f(log)\n", set()),
    ("n = 0\nm = n\nn = m + 1\n", {"n", "m"}),
    ("n = 0\nn = n + 1\nz = 1 / (5 - n)\n", {"z"}),  # n divides: it may reach 5
    ('s = ""\ns = str_cat(s, "x")\n', set()),
])
def test_inert_names_are_those_that_change_nothing_the_program_does(program, inert):
    assert set(inert_names(parse(program, "x.script"))) == inert


def test_a_thread_asleep_past_the_next_pass_keeps_the_loop_running_until_it_wakes():
    report = check(f"""
        stop = False
        thread watchdog():
          sleep(60)
          stop = True
        end
        run watchdog()
        while True:
          if stop:
            movel(p[3.0, 0, 0.2, 0, 3.1416, 0])
          end
          movej({A}, a=1.4, v=1.05)
          movej({B}, a=1.4, v=1.05)
        end
        """)
    assert "URS301" in report.codes()  # the move after 60 s is checked


def test_what_a_loop_sends_is_a_log_not_a_state():
    report = check(f"""
        socket_open("127.0.0.1", 30000, "plc")
        while True:
          movej({A}, a=1.4, v=1.05)
          socket_send_string("at A", "plc")
          movej({B}, a=1.4, v=1.05)
        end
        """)
    assert repeats(report) and len(report.moves) == 4


def test_a_sync_thread_whose_offset_inside_a_frame_drifts_still_repeats():
    # PolyScope's step-counter thread syncs every 2 ms frame; a pass that takes a time that
    # is no whole number of frames (a move of 1.0713 s) leaves the thread's offset inside its
    # frame different each pass. The controller runs threads on frames: the passes repeat.
    report = check(f"""
        def cell():
          steps = 0.0
          thread Step_Counter_Thread_1():
            while (True):
              steps = steps + 1.0
              sync()
            end
          end
          run Step_Counter_Thread_1()
          while True:
            movej({A}, a=1.4, v=1.05)
            sleep(0.0007)
            movej({B}, a=1.4, v=1.05)
          end
        end
        """)
    assert repeats(report) and report.loop.passes <= 3


def test_a_heartbeat_thread_that_nothing_reads_does_not_keep_the_loop_from_repeating():
    # the heartbeat counts and writes a register once a second; the cell loop's pass takes
    # no whole number of seconds, so the heartbeat's wake time inside a pass drifts. Nothing
    # else reads what it writes, so when it wakes does not change what the program does.
    body = f"""
        def cell():
          heartbeat = 0
          thread beat():
            while (True):
              heartbeat = heartbeat + 1
              if (heartbeat > 9):
                heartbeat = 0
              end
              write_port_register(128, heartbeat)
              sleep(1.0)
            end
          end
          run beat()
          while True:
            movej({A}, a=1.4, v=1.05)
            movej({B}, a=1.4, v=1.05)
          end
        end
        """
    report = check(body)
    assert repeats(report) and report.loop.passes <= 12
    assert not report.has_errors
    # the same heartbeat read by the cell loop: its timing matters, it is not detached
    coupled = textwrap.dedent(body).replace("run beat()", "run beat()\n  x = heartbeat")
    assert detached_threads(parse(coupled, "cell.script")) == frozenset()


def test_which_threads_are_detached():
    text = textwrap.dedent("""
        def prog():
          n = 0
          thread counter():
            while True:
              n = n + 1
              sync()
            end
          end
          thread mover():
            while True:
              movej([0, -1.57, 0, -1.57, 0, 0])
            end
          end
          thread lamp():
            while True:
              set_standard_digital_out(1, True)
              sleep(0.5)
            end
          end
          thread watchdog():
            sleep(100)
            halt
          end
          run counter()
          while True:
            if get_standard_digital_out(1):
              sleep(1)
            end
          end
        end
        """)
    assert detached_threads(parse(text, "t.script")) == frozenset({"counter"})
