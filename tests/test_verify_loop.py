"""The cycle time of a program that loops forever (PolyScope's "Loop forever"): one pass of its
loop, not the robot time the check happened to follow."""

from __future__ import annotations

import json
import textwrap

import pytest

from urdsl.cli import main
from urdsl.verify.run import CheckOptions, check_text

A = "[0, -1.9, 1.9, -1.57, -1.57, 0]"
B = "[0.5, -1.9, 1.9, -1.57, -1.57, 0]"


def check(body: str, **options):
    text = textwrap.dedent(body).lstrip("\n")
    options.setdefault("max_time", 60.0)
    return check_text(text, "cell.script", options=CheckOptions(robot="ur5e", **options))


def test_a_polyscope_loop_forever_has_the_cycle_time_of_one_pass():
    report = check(f"""
        def cell():
          movej({A})
          while (True):
            movej({B}, a=1.4, v=1.05)
            sleep(0.5)
            movej({A}, a=1.4, v=1.05)
          end
        end
        """)
    moves = {m.span.line: m.duration for m in report.moves}
    one_pass = moves[4] + 0.5 + moves[6]
    assert report.loop is not None and report.loop.span.line == 3
    assert report.cycle_time == pytest.approx(one_pass, abs=1e-6)
    assert report.loop.first_pass == pytest.approx(one_pass, abs=1e-6)
    assert report.loop.passes == 2  # the third pass begins as the second did: it repeats
    assert "URS312" in report.codes()  # the check still says where it stopped
    assert f"cycle time {one_pass:.3f} s (one pass of the loop at line 3, which runs forever:" \
        in report.summary()


def test_the_first_pass_includes_the_way_from_the_start():
    report = check(f"""
        while True:
          movej({A})
          movej({B})
        end
        """, start_joints=[2.0, -1.0, 1.0, -1.57, -1.57, 0])
    assert report.loop is not None
    assert report.loop.first_pass > report.cycle_time + 0.5
    assert "the first" in report.loop.describe()


def test_passes_of_different_lengths_give_their_mean_and_range():
    report = check("""
        i = 0
        while True:
          i = i + 1
          if i % 2 == 0:
            sleep(1)
          else:
            sleep(3)
          end
        end
        """, max_time=100)
    assert report.cycle_time == pytest.approx(2.0, abs=0.05)
    assert (report.loop.shortest, report.loop.longest) == (pytest.approx(1.0),
                                                           pytest.approx(3.0))
    assert "from 1.000 to 3.000 s" in report.summary()


def test_the_innermost_loop_that_runs_forever_is_the_cycle():
    report = check("""
        while True:
          sleep(5)
          while True:
            sleep(0.25)
          end
        end
        """)
    assert report.loop.span.line == 3 and report.cycle_time == pytest.approx(0.25)


@pytest.mark.parametrize("program", [
    "i = 0\nwhile i < 3:\n  sleep(1)\n  i = i + 1\nend\n",      # a loop that ends
    "while True:\n  sleep(1)\n  break\nend\nsleep(2)\n",        # left with break
    "thread t():\n  while True:\n    sleep(0.1)\n  end\nend\nrun t()\nsleep(3)\n",  # a thread's
])
def test_a_program_that_ends_has_its_whole_time(program):
    report = check(program)
    assert report.loop is None
    assert report.cycle_time == pytest.approx(3.0)
    assert "which runs forever" not in report.summary()


def test_a_loop_stopped_by_an_error_is_no_cycle():
    report = check("i = 0\nwhile True:\n  sleep(1)\n  i = i + 1\n  if i > 3:\n"
                   "    x = [1][5]\n  end\nend\n")
    assert report.has_errors and report.loop is None


def test_the_json_report_has_the_loop(tmp_path, capsys):
    program = tmp_path / "cell.script"
    program.write_text("while True:\n  sleep(0.5)\nend\n")
    program.write_text("i = 0\nwhile True:\n  sleep(0.5)\n  i = i + 1\n  if i > 100:\n"
                       "    i = 0\n  end\nend\n")  # i decides: every pass begins anew
    main(["check", str(program), "--json", "--max-time", "10"])
    report = json.loads(capsys.readouterr().out)
    assert report["cycle_time"] == pytest.approx(0.5)
    assert report["loop"]["line"] == 2 and report["loop"]["passes"] == 20  # 0 to 10 s
    assert report["loop"]["pass_time"] == pytest.approx(0.5)
