"""``urdsl lint``, ``urdsl rules`` and ``urdsl lsp``: the linter on the command line and in
an editor."""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

__all__ = ["add_commands", "cmd_lint", "cmd_rules", "cmd_lsp"]

_SUFFIXES = (".script", ".urscript", ".urs")

_LINT_DESCRIPTION = """\
Check URScript files without running them: syntax (URS001), names that are not defined in
the controller's scoping, builtins that are unknown, missing in the target controller
version or deprecated, arguments that do not fit, joint vectors that are not 6 long,
degrees where radians belong, speeds beyond the arm, blends that cannot happen, unused
variables, unreachable code, what a sec program must not do, loops that never yield, and
habits from Python. 'urdsl rules' explains every rule.

Each file is linted in its project: names defined in the host program that includes it, in
the other script files of the folder tree named (or of a file's folder), in installation
variables (*.variables) and in --include files are known. A name defined nowhere stays an
error; see "Real projects" in the README.

Settings come from [tool.urdsl.lint] in the nearest pyproject.toml (select, ignore, robot,
version); options given here win. [tool.urdsl] include = ["lib/*.script"] adds files to the
project (paths relative to the pyproject.toml). '# noqa' or '# noqa: URS112' at the end of
a line silences findings on it.

Exit status: 0 no error-severity finding (warnings allowed), 1 errors found, 2 usage errors.
"""

_LINT_EPILOG = """\
examples:
  urdsl lint pick.script
  urdsl lint programs/ --robot ur10e --version 5.15
  urdsl lint *.script --select URS1 --ignore URS112,URS113
  urdsl lint pick.script --format json | jq '.[] | .code'
  urdsl lint . --format sarif > urdsl.sarif       # GitHub code scanning
  urdsl lint . --format github                    # annotations in a GitHub Actions step
  urdsl lint pick.script --include ../lib/robotiq.script

pyproject.toml:
  [tool.urdsl]
  include = ["lib/*.script", "installation/default.variables"]
  [tool.urdsl.lint]
  select = ["URS0", "URS1"]
  ignore = ["URS113"]
  robot = "ur5e"
  version = "5.15"
"""


def _codes(text: str) -> list[str]:
    return [part.strip() for part in text.split(",") if part.strip()]


def add_commands(commands) -> None:
    p = commands.add_parser(
        "lint", help="check URScript files for mistakes without running them",
        description=_LINT_DESCRIPTION, epilog=_LINT_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="+", metavar="FILE",
                   help="URScript file, PolyScope program (.urp) or folder (searched "
                   "for *.script, *.urscript and *.urp; a .urp with PolyScope's .script "
                   "beside it is left out for that .script); '-' reads stdin")
    p.add_argument("--select", action="append", type=_codes, metavar="CODES",
                   help="run only these rules: codes, prefixes (URS1) or names, "
                   "comma-separated (default: all, or the configured selection)")
    p.add_argument("--ignore", action="append", type=_codes, metavar="CODES",
                   help="skip these rules (added to the configured ignores)")
    p.add_argument("--robot", metavar="MODEL",
                   help="robot model whose joint speed limits URS110 uses, e.g. ur5e "
                   "(default: the fastest UR arm)")
    p.add_argument("--version", dest="target_version", metavar="VERSION",
                   help="controller software version for URS103, e.g. 5.15 or 3.15 "
                   "(default: no version check)")
    p.add_argument("--format", choices=("text", "json", "sarif", "github"), default="text",
                   help="output format (default: text)")
    p.add_argument("--no-config", action="store_true",
                   help="ignore pyproject.toml files")
    p.add_argument("--stdin-filename", metavar="NAME",
                   help="the name to report for '-' (also where the configuration is "
                   "looked for)")
    p.add_argument("--include", action="append", default=[], metavar="FILE",
                   help="another file of the project (a script file a program includes, a "
                   ".variables file, or a folder of them) whose names the linted files may "
                   "use; repeatable")
    p.add_argument("--no-project", action="store_true",
                   help="lint each file alone, without its project (the other script files "
                   "of its folder, installation variables, includes)")
    p.set_defaults(run=cmd_lint)

    p = commands.add_parser(
        "rules", help="list urdsl's rule codes (lint, runtime, check), or explain one",
        description="Explain every rule code urdsl reports (code, severity, what it checks "
        "and why, an example and its fix): syntax errors URS001, lint rules URS1xx, runtime "
        "errors URS2xx and the checker's findings URS3xx; or only the one named, or those "
        "whose code starts with the prefix given.",
        epilog="examples:\n  urdsl rules | less\n  urdsl rules --short\n  urdsl rules URS108\n"
        "  urdsl rules URS304\n  urdsl rules URS3 --short\n  urdsl rules unused-variable\n"
        "  urdsl rules --json",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("code", nargs="?", metavar="CODE",
                   help="a rule code, a code prefix (URS3) or a rule name")
    p.add_argument("--json", action="store_true", help="print the rules as JSON")
    p.add_argument("--short", action="store_true",
                   help="one line per rule: code, severity, name, summary")
    p.set_defaults(run=cmd_rules)

    p = commands.add_parser(
        "lsp", help="run the URScript language server (for editors) on stdin/stdout",
        description="A Language Server Protocol server over stdio: diagnostics from the "
        "linter as you type, hover with builtin signatures, go to the definition of functions, "
        "threads and globals, and formatting with 'urdsl fmt'. Point your editor's LSP "
        "client at the command 'urdsl lsp' for *.script files.",
        epilog="example (Neovim):\n  vim.lsp.start({ name = 'urdsl', cmd = { 'urdsl', 'lsp' } })",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.set_defaults(run=cmd_lsp)


def _expand(names: list[str]) -> list[str]:
    """Files named on the command line; folders are searched for URScript files and
    PolyScope programs."""
    return [file for file, _root in _expand_with_roots(names)]


def _expand_with_roots(names: list[str]) -> list[tuple[str, str | None]]:
    """Each file with the folder named on the command line it was found in (None for a
    file named itself): a folder named on the command line is one project."""
    from ..polyscope.command import expand_folders

    return expand_folders(names, "linted")


class _Projects:
    """The project of each linted file, discovered once per folder named (or per folder of
    a file named); the problems of its installation variables are reported once."""

    def __init__(self, include: list[str], use_config: bool) -> None:
        self.include = include
        self.use_config = use_config
        self.projects: dict[str, object] = {}
        self.reported: set[int] = set()

    def context(self, file: str, root: str | None):
        """``(FileContext, new diagnostics of the project)`` for ``file``."""
        from .._cli import UsageError
        from ..project import Project, ProjectError

        key = root if root is not None else str(Path(file).resolve().parent)
        project = self.projects.get(key)
        if project is None:
            try:
                project = Project.discover(root if root is not None else file,
                                           self.include, self.use_config)
            except ProjectError as error:
                raise UsageError(str(error)) from None
            self.projects[key] = project
        extra = []
        if id(project) not in self.reported:
            self.reported.add(id(project))
            extra = project.diagnostics(  # type: ignore[attr-defined]
                file if root is None else None)
        return project.context(file), extra  # type: ignore[attr-defined]


_TEXT_URP = ("this .urp is text, not a PolyScope program (PolyScope saves a program as XML, "
             "gzip-compressed or plain): read as a URScript file")
_TEXT_URP_SKIPPED = ("not linted: this .urp is text, not a PolyScope program (PolyScope saves a "
                     "program as XML, gzip-compressed or plain); name it on the command line "
                     "to lint it as a URScript file")


def cmd_lint(args: argparse.Namespace) -> int:
    from .._cli import EXIT_OK, EXIT_PROBLEMS, UsageError, read_input
    from ..polyscope.urp import is_text_file
    from ..script.diagnostics import Diagnostic
    from . import report
    from .config import ConfigError, settings_for
    from .linter import lint_text, lint_tree

    select = [c for group in args.select or [] for c in group] or None
    ignore = [c for group in args.ignore or [] for c in group]
    pairs = _expand_with_roots(args.files)
    files = [file for file, _root in pairs]
    for extra in args.include:
        if not os.path.exists(extra):
            raise UsageError(f"--include {extra}: no such file")
    projects = None if args.no_project else _Projects(args.include, not args.no_config)
    found = []
    ran: set[str] = set()
    for name, root in pairs:
        if name.lower().endswith(".urp"):
            if not is_text_file(name):
                found.extend(_lint_urp(name, select, ignore, args))
                continue
            if root is not None:  # found in a folder, not named: its names may live in
                # other such files, which a project does not read; say so, lint nothing
                found.append(Diagnostic(name, 1, 1, "warning", "URS001", _TEXT_URP_SKIPPED))
                continue
            found.append(Diagnostic(name, 1, 1, "info", "URS001", _TEXT_URP))
        source = read_input(name)
        label = args.stdin_filename if name == "-" and args.stdin_filename else source.name
        where = source.path if source.path is not None else args.stdin_filename
        try:
            settings = settings_for(where, select=select, ignore=ignore, robot=args.robot,
                                    version=args.target_version,
                                    use_config=not args.no_config)
        except ConfigError as error:
            raise UsageError(str(error)) from None
        ran |= settings.codes
        context = None
        if projects is not None and (name != "-" or args.stdin_filename):
            path = name if name != "-" else args.stdin_filename
            context, extra = projects.context(path, root)
            if name == "-":
                context = context.project.context(path, source.text, label)
            found.extend(extra)
        parsed = context.file if context is not None else None
        if (parsed is not None and parsed.module is not None and parsed.filename == label
                and parsed.text == source.text):
            found.extend(lint_tree(parsed.module, settings, project=context))  # parsed once
        else:
            found.extend(lint_text(source.text, label, settings, project=context))
    if args.format == "json":
        sys.stdout.write(report.render_json(found))
    elif args.format == "sarif":
        sys.stdout.write(report.render_sarif(found, ran))
    elif args.format == "github":
        sys.stdout.write(report.render_github(found))
    else:
        sys.stdout.write(report.render_text(found, len(files)))
    return EXIT_PROBLEMS if any(d.severity == "error" for d in found) else EXIT_OK


def _lint_urp(name: str, select, ignore, args: argparse.Namespace) -> list:
    """A PolyScope program: compiled, its script linted, each finding naming its node (see
    :mod:`urdsl.polyscope.check`); a program that cannot be compiled is one URS001 error."""
    from .._cli import UsageError
    from ..polyscope.check import (
        generate,
        node_findings,
        soften_urcap_names,
        urcap_diagnostics,
        without_urcap_busy_loops,
    )
    from ..polyscope.compile import CompileError
    from ..polyscope.urp import UnsupportedProgram, UrpError
    from ..script.diagnostics import Diagnostic
    from .config import ConfigError, settings_for
    from .linter import lint_text

    if not os.path.isfile(name):
        raise UsageError(f"cannot read {name}: No such file")
    try:
        settings = settings_for(name, select=select, ignore=ignore, robot=args.robot,
                                version=args.target_version, use_config=not args.no_config)
    except ConfigError as error:
        raise UsageError(str(error)) from None
    try:
        generated = generate(name)
    except UnsupportedProgram as error:  # urdsl's limit, not the program's mistake
        text = str(error)
        message = text.split(": error: ", 1)[1] if ": error: " in text else text
        return [Diagnostic(name, 1, 1, "warning", "URS001", f"not linted: {message}")]
    except (UrpError, CompileError) as error:
        text = str(error)
        message = text.split(": error: ", 1)[1] if ": error: " in text else text
        return [Diagnostic(name, 1, 1, "error", "URS001", message)]
    found = node_findings(generated, without_urcap_busy_loops(generated, soften_urcap_names(
        generated, lint_text(generated.text, generated.filename, settings))))
    wanted = not select or any("URS214".startswith(code) for code in select)
    if wanted and not any("URS214".startswith(code) for code in ignore):
        found.extend(urcap_diagnostics(generated))
    return sorted(found, key=lambda d: (d.line, d.column))


def load_rules() -> dict:
    """Every rule of every stage, by code: imports the modules that register them."""
    from ..rules import RULES as every
    from ..runtime import errors  # noqa: F401 - URS2xx
    from ..verify import checks, findings  # noqa: F401 - URS3xx, URS210
    from . import linter  # noqa: F401 - URS0xx, URS1xx

    return every


def cmd_rules(args: argparse.Namespace) -> int:
    from .._cli import EXIT_OK, UsageError

    every = load_rules()
    chosen = sorted(every.values(), key=lambda rule: rule.code)
    if args.code:
        by_name = {rule.name: rule for rule in every.values()}
        rule = every.get(args.code.upper()) or by_name.get(args.code)
        chosen = [rule] if rule is not None else [
            r for r in chosen if r.code.startswith(args.code.upper())]
        if not chosen or len(args.code) < 4:
            raise UsageError(f"unknown rule {args.code!r}; 'urdsl rules' lists them")
        if rule is not None:
            if args.json:
                print(json.dumps(rule.to_dict(), indent=2, ensure_ascii=False))
            else:
                print(rule.describe())
            return EXIT_OK
    if args.json:
        print(json.dumps([r.to_dict() for r in chosen], indent=2, ensure_ascii=False))
        return EXIT_OK
    if args.short:
        for rule in chosen:
            print(f"{rule.code}  {rule.severity:<8} {rule.name:<26} {rule.summary}")
        print("\nRun 'urdsl rules CODE' for the explanation of a rule with an example.")
        return EXIT_OK
    print("\n\n".join(rule.describe() for rule in chosen))
    return EXIT_OK


def cmd_lsp(args: argparse.Namespace) -> int:
    from .lsp import serve

    serve()
    return 0
