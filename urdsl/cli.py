"""The ``urdsl`` command.

Each subcommand is a function ``cmd_<name>(args) -> int`` registered in :func:`build_parser`;
the return value is the exit status. Bad input (a file that is not URScript, a missing file)
is reported as a message naming ``file:line:col``, never as a Python traceback.

Helpers the command modules share (exit status, :class:`UsageError`, :func:`read_input`,
``--robot`` names) live in :mod:`urdsl._cli`, below every command module; they import them
from there, never from this module, which loads them.

Exit status: 0 success, 1 the input has problems (syntax errors, files that ``fmt --check``
would change), 2 usage or I/O errors.
"""

from __future__ import annotations

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_PROBLEMS", "EXIT_USAGE", "UsageError",
           "InputFile", "read_input", "robot_model"]

import argparse
import difflib
import importlib
import sys
from collections.abc import Sequence

from . import __version__
from ._cli import EXIT_OK, EXIT_PROBLEMS, EXIT_USAGE, InputFile, UsageError, read_input, robot_model
from ._cli import error as _error
from ._deep import FOLLOWED_DEPTH, run_deep
from .script.diagnostics import ScriptError
from .script.nodes import dump_json, to_dict
from .script.parser import parse
from .script.printer import format as format_tree

# ---- parse ---------------------------------------------------------------------------------


def cmd_parse(args: argparse.Namespace) -> int:
    status = EXIT_OK
    trees = []
    for name in args.files:
        source = read_input(name)
        try:
            tree = parse(source.text, source.name)
        except ScriptError as error:
            print(error.diagnostic.render(), file=sys.stderr)
            status = EXIT_PROBLEMS
            continue
        if args.json:
            trees.append({"file": source.name, "tree": to_dict(tree)})
        elif not args.quiet:
            print(f"{source.name}: ok ({len(tree.body)} top-level items)", file=sys.stderr)
    if args.json:
        sys.stdout.write(dump_json(trees, indent=1 if args.pretty else None))
        sys.stdout.write("\n")
    return status


# ---- fmt -----------------------------------------------------------------------------------


def cmd_fmt(args: argparse.Namespace) -> int:
    if args.in_place and "-" in args.files:
        raise UsageError("-i cannot rewrite standard input")
    status = EXIT_OK
    indent = " " * args.indent
    for name in args.files:
        source = read_input(name)
        try:
            formatted = format_tree(parse(source.text, source.name), indent=indent)
        except ScriptError as error:
            print(error.diagnostic.render(), file=sys.stderr)
            status = EXIT_PROBLEMS
            continue
        changed = formatted != source.text
        if args.check or args.diff:
            if changed:
                status = EXIT_PROBLEMS
                if args.diff:
                    _write_diff(source.name, source.text, formatted)
                else:
                    print(f"would reformat {source.name}", file=sys.stderr)
        elif args.in_place:
            if changed and source.path is not None:
                with open(source.path, "w", encoding=source.encoding, newline="") as handle:
                    handle.write(formatted)
                print(f"reformatted {source.name}", file=sys.stderr)
        else:
            sys.stdout.write(formatted)
    return status


def _write_diff(name: str, before: str, after: str) -> None:
    """A unified diff on stdout; a last line without a line break is marked as diff does."""
    for line in difflib.unified_diff(
        before.splitlines(keepends=True), after.splitlines(keepends=True),
        fromfile=f"{name} (original)", tofile=f"{name} (formatted)",
    ):
        sys.stdout.write(line)
        if not line.endswith("\n"):
            sys.stdout.write("\n\\ No newline at end of file\n")


# ---- the parser ----------------------------------------------------------------------------

_DESCRIPTION = """\
urdsl: write, check, send and observe Universal Robots programs.

Work with URScript files (.script, .urscript) as PolyScope, driver libraries and people
write them. Every message about a program names file:line:col and shows the line.
"""

_EPILOG = """\
examples:
  urdsl parse program.script            check that a file is URScript
  urdsl parse --json program.script     print its syntax tree as JSON
  urdsl fmt program.script              print it in canonical form
  urdsl fmt --check *.script            exit 1 if any file is not formatted
  urdsl fmt -i program.script           reformat in place

Run 'urdsl COMMAND --help' for the options of a command.
"""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="urdsl", description=_DESCRIPTION, epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"urdsl {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = commands.add_parser(
        "parse", help="check that files are URScript; print their syntax tree",
        description="Parse URScript files. Exit 0 when all parse; otherwise print each "
        "syntax error (file:line:col, the line, a caret and a hint) on stderr and exit 1.",
        epilog="example:\n  urdsl parse --json --pretty course.script | less",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("files", nargs="+", metavar="FILE", help="URScript file; '-' reads stdin")
    p.add_argument("--json", action="store_true",
                   help="print the syntax trees as JSON on stdout: a list of "
                   "{file, tree} objects; each node has its type, fields and span")
    p.add_argument("--pretty", action="store_true", help="indent the JSON")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing for good files")
    p.set_defaults(run=cmd_parse)

    p = commands.add_parser(
        "fmt", help="format URScript files canonically",
        description="Print URScript files in canonical form: one statement per line, "
        "blocks indented by two spaces, def/sec and their end in column 0, numbers in "
        "their shortest exact form. Comments, blank-line breaks and $ labels are kept.",
        epilog="examples:\n  urdsl fmt prog.script > clean.script\n"
        "  urdsl fmt --diff prog.script\n  urdsl fmt -i *.script",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("files", nargs="+", metavar="FILE", help="URScript file; '-' reads stdin")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--check", action="store_true",
                      help="write nothing; exit 1 if any file would change")
    mode.add_argument("--diff", action="store_true",
                      help="print a unified diff of the changes; exit 1 if there are any")
    mode.add_argument("-i", "--in-place", action="store_true",
                      help="rewrite the files in place")
    p.add_argument("--indent", type=int, default=2, metavar="N",
                   help="spaces per block level (default: 2)")
    p.set_defaults(run=cmd_fmt)

    # Commands of the other layers register themselves here, each from its own module:
    # a function add_commands(commands) that calls commands.add_parser(...) and sets
    # run=<function(args) -> exit status>.
    for module in _COMMAND_MODULES:
        importlib.import_module(module).add_commands(commands)
    return parser


_COMMAND_MODULES: list[str] = [
    "urdsl.dsl.command",
    "urdsl.kinematics.command",
    "urdsl.verify.command",
    "urdsl.robot.command",
    "urdsl.sim.command",
    "urdsl.lint.command",
    "urdsl.polyscope.command",
]
"""Modules whose ``add_commands(subparsers)`` adds their ``urdsl`` subcommands."""


_DEEP_COMMANDS = frozenset(("parse", "fmt", "lint", "check", "compile", "send", "lsp"))
"""Commands that walk a program's syntax tree, run on a deep stack (see urdsl._deep)."""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``urdsl`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return EXIT_USAGE
    try:
        if args.command in _DEEP_COMMANDS:
            return run_deep(args.run, args)
        return args.run(args)
    except RecursionError:
        _error("the program nests too deeply for urdsl to follow (it follows at least "
               f"{FOLLOWED_DEPTH:,} levels of nested blocks and expressions)")
        return EXIT_PROBLEMS
    except UsageError as error:
        _error(str(error))
        return EXIT_USAGE
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
