"""``make demo``: what urdsl can do today, end to end, on the files in ``programs/``.

Today: read a URScript program and show its canonical form; show how urdsl reports the
mistakes of the course's slides (file:line:col, the line, a caret, a hint); check the
course's program offline on a simulated UR5e — first as the slides order it (a straight
line out of a singular pose, which the robot cannot do), then corrected — and write the
report (JSON) and a plot. The demo grows with the project (compile, send to ``urdsl sim``,
record).
"""

from __future__ import annotations

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
    check_programs(console)
    console.rule("[bold]done")
    console.print("next: urdsl fmt --help, urdsl check --help")
    return 0


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
