"""``urdsl show X.urp`` (the program tree as PolyScope shows it) and the ``.urp`` half of
``urdsl compile``."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from pathlib import Path

from .compile import (
    Compiled,
    CompileError,
    compile_program,
    names_installation,
    parse_variables,
)
from .export import exported_by
from .installation import Installation, InstallationError, find_installation, read_installation
from .urp import Node, Program, UrpError, read_urp

__all__ = ["add_commands", "collect_programs", "compile_urp", "expand_folders", "load",
           "load_all"]

SCRIPT_SUFFIXES = (".script", ".urscript", ".urs")


def collect_programs(folder: str | Path) -> tuple[list[str], list[tuple[str, str]]]:
    """The programs in ``folder`` and its subfolders (hidden ones left out), sorted:
    URScript files and PolyScope programs (``.urp``), except a ``.urp`` with a ``.script`` of
    the same name beside it (not empty). That ``.script`` is what PolyScope generated when it
    saved the program and what the controller ran: it holds the code URCaps generate and the
    preamble of the installation the program ran with, which compiling the ``.urp`` here cannot
    reproduce (a folder check of the ``.urp`` reported the URCaps' names as undefined).
    Name the ``.urp`` itself to lint or check its program tree. Returns ``(files,
    skipped)``, ``skipped`` holding ``(urp, script)`` pairs."""
    root = Path(folder)
    found = sorted(
        path for path in root.rglob("*")
        if path.suffix.lower() in (*SCRIPT_SUFFIXES, ".urp") and path.is_file()
        and not any(part.startswith(".") for part in path.parts[len(root.parts):]))
    # an empty .script (a lost export, a placeholder) is not what PolyScope wrote
    scripts = {path.with_suffix(""): path for path in found
               if path.suffix.lower() == ".script" and _has_text(path)}
    files: list[str] = []
    skipped: list[tuple[str, str]] = []
    for path in found:
        script = scripts.get(path.with_suffix("")) if path.suffix.lower() == ".urp" else None
        if script is not None:
            skipped.append((str(path), str(script)))
        else:
            files.append(str(path))
    return files, skipped


def _has_text(path: Path) -> bool:
    """Whether the file at ``path`` holds more than white space (read up to 4 KiB)."""
    try:
        with path.open("rb") as file:
            return bool(file.read(4096).strip())
    except OSError:
        return False


def report_skipped(skipped: list[tuple[str, str]], verb: str) -> None:
    """Say on standard error which ``.urp`` programs were left out for PolyScope's
    ``.script`` beside them."""
    for urp, script in skipped:
        print(f"note: {urp} skipped: {Path(script).name} beside it is what PolyScope "
              f"generated from it (with its URCaps' code), and is {verb} instead; name "
              f"{Path(urp).name} to {verb[:-2] if verb.endswith('ed') else verb} its program "
              "tree", file=sys.stderr)


def expand_folders(names: list[str], verb: str) -> list[tuple[str, str | None]]:
    """The files named on a command line, each with the folder named it was found in (None
    for a file named itself): a folder stands for its programs (:func:`collect_programs`,
    the ``.urp`` programs left out are named on standard error as ``verb``, e.g.
    "linted"). Raises :class:`~urdsl._cli.UsageError` for a folder without programs."""
    import os

    from .._cli import UsageError

    files: list[tuple[str, str | None]] = []
    for name in names:
        if name != "-" and os.path.isdir(name):
            found, skipped = collect_programs(name)
            report_skipped(skipped, verb)
            if not found:
                raise UsageError(f"no URScript files (*.script, *.urscript) or PolyScope "
                                 f"programs (*.urp) in {name}")
            files.extend((file, name) for file in found)
        else:
            files.append((name, None))
    return files


def _warn(message: str) -> None:
    print(f"warning: {message}", file=sys.stderr)


def _installation_for(program: Program, path: str | Path,
                      warn: Callable[[str], None] = _warn) -> Installation | None:
    """The installation the program names (``installationRelativePath``, e.g.
    ``../default.installation``, else ``NAME.installation`` in its folder), else the only
    installation there; ``None`` when there is none. A missing or broken installation is
    said through ``warn`` (standard error) and left out."""
    folder = Path(path).parent
    candidate: Path | None = None
    for name in (program.installation_path, program.installation):
        named = folder / f"{name}.installation" if name else None
        if named is not None and named.is_file():
            candidate = named
            break
    if candidate is None and program.installation:
        candidate = _named_above(folder, program.installation)
        if candidate is not None:
            warn(f"{path}: the installation it names is not beside it; compiled with "
                 f"{candidate}, the one of that name in a folder above (PolyScope saved the "
                 "program beside it, in a folder the program has since been moved out of)")
    if candidate is None:
        candidate = find_installation(path)
        if candidate is not None and not names_installation(program, str(candidate)):
            warn(f"{path}: the installation it names, {program.installation}.installation, is "
                 f"not there; compiled with {candidate.name} beside it instead (an I/O name "
                 "only the named one gives is read as an unknown value)")
    if candidate is None:
        if program.installation:
            warn(f"{path}: the installation it names, "
                 f"{folder / (program.installation + '.installation')}, is not there; "
                 "compiled without its preamble")
        return None
    try:
        return read_installation(candidate)
    except InstallationError as error:
        warn(f"{error}; compiled without it")
        return None


INSTALLATION_LEVELS = 3
"""How many folders above a program :func:`_installation_for` looks for the installation it
names, when it is not beside it: PolyScope users sort programs into subfolders of the
programs folder, whose installation stays at its top."""


def _named_above(folder: Path, name: str) -> Path | None:
    """``NAME.installation`` in one of the :data:`INSTALLATION_LEVELS` folders above
    ``folder``, the nearest first, not above a repository's top (a folder holding ``.git``).
    A relative ``folder`` (``.`` for ``urdsl check home.urp``) is taken from the working
    folder."""
    folder = Path(os.path.abspath(folder))
    for _level in range(INSTALLATION_LEVELS):
        if (folder / ".git").exists() or folder.parent == folder:
            return None
        folder = folder.parent
        candidate = folder / f"{name}.installation"
        if candidate.is_file():
            return candidate
    return None


def load(path: str | Path, warn: Callable[[str], None] = _warn) -> tuple[Program, Compiled]:
    """Read and compile the ``.urp`` at ``path`` with its installation and the
    installation's variables. Raises :class:`UrpError` or :class:`CompileError` (messages
    name the file and node); a missing or broken installation is said through ``warn``."""
    program, _installation, compiled = load_all(path, warn)
    return program, compiled


def load_all(path: str | Path, warn: Callable[[str], None] = _warn, *, once: bool = False
             ) -> tuple[Program, Installation | None, Compiled]:
    """:func:`load`, also giving the installation read (None when there is none). ``once``:
    compile the Robot Program to run one pass, as PolyScope runs a subprogram that another
    program calls, whatever its "Program Loops Forever" setting says."""
    program = read_urp(path)
    if once and program.main is not None:
        program.main.attrs["runOnlyOnce"] = "true"
    installation = _installation_for(program, path, warn)
    folder = Path(path).parent
    variables: list[tuple[str, str]] = []
    # the installation's variables live in a file of its name beside it, kept also where the
    # installation itself is missing (a repository that commits default.variables alone)
    file = Path(installation.path).with_suffix(".variables") if installation is not None \
        else folder / f"{program.installation}.variables" if program.installation else None
    if file is not None:
        try:
            variables = parse_variables(file.read_bytes())
        except OSError:
            variables = []

    def files(relative: str) -> bytes | None:
        file = folder / relative
        return file.read_bytes() if file.is_file() else None

    export = exported_by(path) if installation is not None else None
    compiled = compile_program(program, installation, variables, files, export)
    if compiled.exported and installation is not None and export is not None:
        warn(f"{path}: {Path(str(installation.path)).name} lacks "
             f"{', '.join(compiled.exported)}, which {export.path.name} beside the program "
             "adds (the installation the program ran with had them): read as unknown values, "
             "the Set nodes writing them as their markers alone")
    if set(compiled.unknown) - set(compiled.exported):
        warn(f"{path}: values only the missing installation gives ({compiled.unknown_text()}): "
             "read as names of their own, unknown to the check; the Set nodes writing such "
             "an I/O are written as their markers alone")
    return program, installation, compiled


def compile_urp(path: str, output: str | None) -> int:
    """``urdsl compile X.urp [-o X.script]``: the exit status."""
    from .._cli import EXIT_OK, EXIT_PROBLEMS, UsageError, write_script

    if not Path(path).is_file():
        raise UsageError(f"cannot read {path}: No such file")
    try:
        _program, compiled = load(path)
        text = compiled.text
    except (UrpError, CompileError) as error:
        print(str(error), file=sys.stderr)
        return EXIT_PROBLEMS
    write_script(text, output)
    return EXIT_OK


def _generated(compiled: Compiled) -> dict[int, list[str]]:
    """Marker number → the script lines after that marker up to the next one."""
    out: dict[int, list[str]] = {}
    current: list[str] | None = None
    for line in compiled.text.splitlines():
        stripped = line.strip()
        if stripped.startswith("$ "):
            number = stripped[2:].split(" ", 1)[0]
            current = out.setdefault(int(number), []) if number.isdigit() else None
        elif current is not None and stripped not in ("end", "else:") and stripped \
                and not stripped.startswith("#"):
            current.append(stripped)
    return out


def tree_lines(program: Program, compiled: Compiled, with_lines: bool = False) -> list[str]:
    """The program tree as PolyScope shows it, one node a line, with its marker number
    (``suppressed`` nodes marked, URCap nodes with their URCap's name); ``with_lines``: each
    node followed by the script lines it generates."""
    numbers = {id(node): number for number, node in compiled.numbers.items()}
    generated = _generated(compiled) if with_lines else {}
    lines = [f"Program {program.name}  (saved by PolyScope {program.saved_in or '?'}, "
             f"installation {program.installation or '?'})"]

    def show(node: Node, depth: int) -> None:
        number = numbers.get(id(node))
        label = compiled.labels.get(number) if number is not None else None
        if label is None:
            label = f"{node.kind} {node.name}" if node.name else node.title
        if node.kind == "Contributed":
            label += f"  [URCap {node.attrs.get('strategyURCapName', '?')}]"
        if node.suppressed:
            label += "  (suppressed)"
        prefix = f"{number:>4} " if number is not None else "     "
        lines.append(f"{prefix}{'  ' * depth}{label}")
        for code in generated.get(number, []) if number is not None else []:
            lines.append(f"     {'  ' * depth}  | {code}")
        if node.kind != "CallSubProgram":
            for child in node.children:
                show(child, depth + 1)

    for node in program.top:
        show(node, 0)
    return lines


def add_commands(commands) -> None:
    p = commands.add_parser("show", help="show a PolyScope program's tree (.urp)",
                            description="Show the program tree of a PolyScope program (.urp) "
                            "as PolyScope shows it, each node with the number of its `$` "
                            "marker in the compiled script (`urdsl compile X.urp`).")
    p.add_argument("program", metavar="PROGRAM.urp")
    p.add_argument("--lines", action="store_true",
                   help="under each node, the script lines it generates")
    p.set_defaults(run=cmd_show)


def cmd_show(args: argparse.Namespace) -> int:
    from .._cli import EXIT_OK, EXIT_PROBLEMS, UsageError

    if Path(args.program).suffix.lower() != ".urp":
        raise UsageError(f"cannot show {args.program}: urdsl show takes a PolyScope program "
                         "(.urp)")
    if not Path(args.program).is_file():
        raise UsageError(f"cannot read {args.program}: No such file")
    try:
        program, compiled = load(args.program)
    except (UrpError, CompileError) as error:
        print(str(error), file=sys.stderr)
        return EXIT_PROBLEMS
    sys.stdout.write("\n".join(tree_lines(program, compiled, args.lines)) + "\n")
    return EXIT_OK
