"""``make demo``: what urdsl can do today, end to end, on the files in ``programs/``.

Read a URScript program and show its canonical form; show how urdsl reports the mistakes
of the course's slides (file:line:col, the line, a caret, a hint); compile a Python DSL
program; check the course's program offline on a simulated UR5e — first as the slides order
it (a straight line out of a singular pose, which the robot cannot do), then corrected —
and write its report and plot; check a PolyScope program (``programs/polyscope/pick.urp``:
its tree, findings by node, cycle time); finally the whole story against the built-in virtual
controller: check, send, record RTDE while the program runs, plot (all on 127.0.0.1).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from rich.console import Console
from rich.panel import Panel
from rich.syntax import Syntax

from . import ScriptSyntaxError, format, parse

PROGRAMS = Path(__file__).resolve().parents[1] / "programs"

COURSE_MISTAKES = {
    "stray parenthesis (course slide 3)": "p1 = p[0.200, -0.300, 0.300, 0.5, 0.0, -0.3])\n",
    "Python habit": "def count():\n  i = 0\n  while i < 5:\n    i += 1\n  end\nend\n",
}


def main() -> int:
    console = Console()
    console.rule("[bold]urdsl demo: read and format URScript")
    program = PROGRAMS / "course_examples.script"
    text = program.read_text(encoding="utf-8")
    tree = parse(text, str(program))
    moves = sum(1 for line in format(tree).splitlines() if line.strip().startswith("move"))
    console.print(f"parsed {program.name}: {len(text.splitlines())} lines, {moves} moves")
    console.print(Panel(Syntax(format(tree), "python", theme="ansi_dark"),
                        title="urdsl fmt programs/course_examples.script"))
    for title, snippet in COURSE_MISTAKES.items():
        try:
            parse(snippet, f"{title.split(' (')[0].replace(' ', '_')}.script")
        except ScriptSyntaxError as error:
            console.print(f"[bold]{title}[/bold]")
            console.print(error.diagnostic.render(), markup=False, highlight=False)
            console.print()
    compile_program(console)
    check_programs(console)
    check_polyscope(console)
    story = run_story(console)
    console.rule("[bold]done")
    console.print("next: urdsl compile --help, urdsl check --help, urdsl sim --help")
    return 0 if story else 1


def compile_program(console: Console) -> None:
    """``urdsl compile`` on the DSL pick-and-place program."""
    from .dsl.command import load_program

    console.rule("[bold]urdsl compile: a Python program becomes URScript")
    program = PROGRAMS / "pick_and_place.py"
    text = load_program(program).script()
    head = "\n".join(text.splitlines()[:14]) + "\n  ..."
    console.print(Panel(Syntax(head, "python", theme="ansi_dark"),
                        title=f"urdsl compile {program.relative_to(PROGRAMS.parent)}"))


def check_polyscope(console: Console) -> None:
    """A PolyScope program (``.urp`` with its ``.installation``): its tree as PolyScope shows
    it, then ``urdsl check`` on the arm of its ``<kinematics>`` with the installation's
    safety limits, each finding naming its node, and the cycle time."""
    from .polyscope.check import check_urp
    from .polyscope.command import load, tree_lines
    from .verify.run import CheckOptions

    program = PROGRAMS / "polyscope" / "pick.urp"
    shown = program.relative_to(PROGRAMS.parent)
    console.rule("[bold]PolyScope programs: check the program the operator edits")
    console.print(f"[bold]$ urdsl show {shown}[/bold]")
    tree, compiled = load(program)
    console.print("\n".join(tree_lines(tree, compiled)), markup=False, highlight=False)
    console.print()
    console.print(f"[bold]$ urdsl check {shown}[/bold]")
    report = check_urp(os.path.relpath(program), CheckOptions(), robot_given=False)
    report.print_rich(console, max_moves=7)
    console.print()


def run_story(console: Console) -> bool:
    """Write → check → send → record → plot against the built-in virtual controller."""
    from .sim.story import demo_story

    console.rule("[bold]urdsl sim: send the checked program, record RTDE while it runs")
    result = demo_story("out", speed=4.0)
    console.print(f"sent: {result.sent}; {result.samples} RTDE samples; planned cycle time "
                  f"{result.planned_time:.2f} s, observed {result.observed_time:.2f} s")
    for path in result.paths():
        console.print(f"  wrote {path}")
    return result.sent


def check_programs(console: Console) -> None:
    """``urdsl check`` on the course's program as the slides order it, then corrected."""
    from .verify.run import CheckOptions, check_file

    out = Path("out")
    out.mkdir(exist_ok=True)
    console.rule("[bold]urdsl check: run the program offline on a simulated UR5e")
    for program in (PROGRAMS / "mistakes" / "course_movel_from_singular.script",
                    PROGRAMS / "course_examples.script"):
        console.print(f"[bold]$ urdsl check {program.relative_to(PROGRAMS.parent)}[/bold]")
        report = check_file(program, CheckOptions(robot="ur5e"))
        report.print_rich(console)
        console.print()
    json_path, plot_path = out / "course_examples.json", out / "course_examples.png"
    json_path.write_text(report.to_json() + "\n", encoding="utf-8")
    report.plot(plot_path)
    console.print(f"report: {json_path}   plot: {plot_path}")


if __name__ == "__main__":
    sys.exit(main())
