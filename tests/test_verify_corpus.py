"""The verifier on real programs of the corpus.

Motion programs that need no external device (no gripper socket, no driver host, no
fieldbus) check without errors; the one the client library ships as a deliberate mistake is
reported at its line. Programs that wait for a device are run too: they must not crash the
verifier, and stop at the time limit or at the device's missing answer.
"""

from __future__ import annotations

import pytest
from _corpus import corpus_available, corpus_files, fill_template

from urdsl.verify.run import CheckOptions, check_text

pytestmark = pytest.mark.skipif(not corpus_available(), reason="corpus not found")

READY = (0.0, -1.9, 1.9, -1.57, -1.57, 0.0)  # tool down in front of the base

NO_DEVICE = [
    "UniversalRobots__URScript_Examples/admittance-control/admittance_control.script",
    "UniversalRobots__URScript_Examples/impedance-control/"
    "joint_impedance_cartesian_circle_motion.script",
]


def by_name(name: str):
    (found,) = [f for f in corpus_files() if f.name == name]
    text = found.text()
    return fill_template(text, found.path) if found.templated else text


@pytest.mark.parametrize("name", NO_DEVICE)
def test_motion_examples_without_devices_check_clean(name):
    report = check_text(by_name(name), name, options=CheckOptions(
        start_joints=READY, max_time=1.0, self_collision=False))
    assert not report.has_errors, report.render_text()
    # control loops run until stopped (or until a pass begins as an earlier one did): the
    # cycle time is one pass of the loop
    assert report.loop is not None
    assert report.loop.passes > 100 or "begins in the same state" in report.render_text()
    assert report.cycle_time == pytest.approx(report.loop.pass_time)
    assert report.cycle_time < 0.1


def test_the_client_librarys_bad_script_is_caught_at_its_line():
    name = "UniversalRobots__Universal_Robots_Client_Library/examples/send_script.cpp__" \
        "bad_script_code"
    report = check_text(by_name(name) + "bad_code()\n", name,
                        options=CheckOptions(self_collision=False))
    (finding,) = report.findings
    assert (finding.code, finding.span.line, finding.span.column) == ("URS201", 3, 9)
    assert "current_pose" in finding.hint


@pytest.mark.parametrize("corpus_file", corpus_files(), ids=lambda f: f.name[-60:])
def test_every_corpus_program_runs_without_crashing_the_verifier(corpus_file):
    text = corpus_file.text()
    if corpus_file.templated:
        text = fill_template(text, corpus_file.path)
    report = check_text(text, corpus_file.name, options=CheckOptions(
        start_joints=READY, max_time=0.5, self_collision=False))
    assert report.cycle_time <= 0.5 + 1e-9
    for finding in report.findings:  # every finding can be shown
        assert finding.diagnostic().render()
