"""``make demo``: what urdsl can do today, end to end, on the files in ``programs/``.

Today: read a URScript program, show its canonical form, and show how urdsl reports the
mistakes of the course's slides (file:line:col, the line, a caret, a hint). The demo grows
with the project (compile, check, send to ``urdsl sim``, record, plot).
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
    console.rule("[bold]done")
    console.print("next: urdsl fmt --help, urdsl parse --help")
    return 0


if __name__ == "__main__":
    sys.exit(main())
