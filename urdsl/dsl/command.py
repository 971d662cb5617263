"""``urdsl compile``: run a DSL program file and print its URScript."""

from __future__ import annotations

import argparse
import runpy
import sys
import traceback
from pathlib import Path

from .errors import DslError
from .program import Program

__all__ = ["add_commands", "load_program", "ProgramFileError"]

_DESCRIPTION = """\
Compile a Python program written with urdsl.dsl into URScript. The file defines a
Program named `program`, or a function main() that returns one; it is run as Python (it is
your program), with __name__ set to "__urdsl__" so that an `if __name__ == "__main__":`
block does not run. The output is exactly what `urdsl fmt` prints for it.

A PolyScope program (.urp) is compiled as PolyScope does (its installation is read from
the same folder when it is there); see `urdsl show X.urp` for its program tree.

Exit status: 0 compiled, 1 the program has a mistake (shown with file:line), 2 usage errors.
"""

_EPILOG = """\
examples:
  urdsl compile programs/pick_and_place.py
  urdsl compile programs/toolpath.py -o toolpath.script
  urdsl compile programs/palletizing.py | urdsl check - --robot ur10e
  urdsl compile usbdisk/pick.urp -o pick.script
"""


class ProgramFileError(Exception):
    """A DSL program file that fails: its own exception, or neither ``program`` nor
    ``main``. The message names the file and line."""


def load_program(path: str | Path) -> Program:
    """Run the program file ``path`` and return its :class:`Program` (``program`` or
    ``main()``). Raises :class:`DslError` for DSL mistakes, :class:`ProgramFileError` when
    the file raises or defines no program, ``OSError`` when it cannot be read."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(2, "No such file", str(path))
    try:
        namespace = runpy.run_path(str(path), run_name="__urdsl__")
        program = namespace.get("program")
        if program is None and callable(namespace.get("main")):
            program = namespace["main"]()
    except DslError:
        raise
    except SyntaxError as error:
        raise ProgramFileError(f"{error.filename}:{error.lineno}: error: {error.msg}\n"
                               f"  {(error.text or '').strip()}") from None
    except Exception as error:  # the user's own code failed: show where, in their file
        raise ProgramFileError(_where(error, path)) from None
    if not isinstance(program, Program):
        found = "nothing" if program is None else f"a {type(program).__name__}"
        raise ProgramFileError(f"{path}: error: defines {found} as its program; it must define "
                               "`program = Program(...)` or `def main(): return Program(...)`")
    return program


def _where(error: Exception, path: Path) -> str:
    frames = [f for f in traceback.extract_tb(error.__traceback__)
              if Path(f.filename).resolve() == path.resolve()]
    head = f"{type(error).__name__}: {error}"
    if not frames:
        return f"{path}: error: {head}"
    frame = frames[-1]
    return f"{frame.filename}:{frame.lineno}: error: {head}\n  {(frame.line or '').strip()}"


def add_commands(commands) -> None:
    p = commands.add_parser("compile", help="compile a Python DSL program or a PolyScope "
                            "program (.urp) to URScript",
                            description=_DESCRIPTION, epilog=_EPILOG,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("program", metavar="PROGRAM.py|PROGRAM.urp",
                   help="a Python file using urdsl.dsl (it is run as Python, with your "
                   "permissions), or a PolyScope program")
    p.add_argument("-o", "--output", metavar="OUT.script",
                   help="write the URScript here instead of standard output")
    p.set_defaults(run=cmd_compile)


def cmd_compile(args: argparse.Namespace) -> int:
    from .._cli import EXIT_OK, EXIT_PROBLEMS, UsageError, write_script

    suffix = Path(args.program).suffix.lower()
    if suffix == ".urp":  # a PolyScope program: compiled as PolyScope does
        from ..polyscope.command import compile_urp

        return compile_urp(args.program, args.output)
    if suffix != ".py":
        raise UsageError(f"cannot compile {args.program}: urdsl compile takes a Python DSL "
                         "program (.py) or a PolyScope program (.urp)")
    try:
        program = load_program(args.program)
        text = program.script()
    except OSError as error:
        raise UsageError(f"cannot read {args.program}: {error.strerror}") from None
    except (DslError, ProgramFileError) as error:
        print(str(error), file=sys.stderr)
        return EXIT_PROBLEMS
    write_script(text, args.output)
    return EXIT_OK
