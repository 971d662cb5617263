"""Benchmark: compile real PolyScope programs (.urp) and compare with the .script PolyScope
wrote beside them.

Pairs are listed in ``bench/polyscope/pairs.tsv`` (repository, commit, .urp path, .script path,
licence, split). Files are read from local git directories (``--repos DIR`` holding
``owner+name`` git dirs, as ``fetch`` leaves them: ``DIR/owner+name/repo`` or a bare git dir
``DIR/owner+name``); nothing is downloaded. The installation the program names is read from
the same folder when it is there, with its ``.variables``, as of the last commit that changed
the .script (when PolyScope wrote it; an installation committed only after the .script as of
the pair's commit; ``--installation pair`` reads both at the pair's commit).

Both scripts are parsed and printed canonically, statement by statement: comments and URCap
blocks (``# begin: URCap ...`` to ``# end: URCap ...``) are left out, numbers compare
within 1e-9 (two lines that differ only in numbers that close count as equal),
PolyScope's generated ids (``_3f89b84f_1daa_...``, the N of a ``SinglePulseN`` thread) are
masked, and ``$`` markers compare by number and flag (their label text is in the
language PolyScope ran in, which the .urp does not record). For the same reason a ``popup``
title that is PolyScope's own title of a Popup node in another language ("Erreur",
"Meldung", "メッセージ": see ``POPUP_TITLES``, the languages seen) compares as its English one
("Error", "Message") when the popup's warning/error flags are that type's; a title the user
wrote is compared as written. Two views: the whole program, and the program part (the top-
level statements from the first waypoint global, definition or marker on: what the program
tree, not the installation, generates).

The installation is the one the program names (``installationRelativePath``); when that
is not there, the one named like the ``.urp`` beside it (renamed with the program: the
``.urp`` keeps the name it was saved with). A Script
node's file is read from the repository as it was in the last commit that changed the
.script (PolyScope compiles the file's contents when it saves, not the copy the .urp keeps;
``--script-files cache`` takes that copy instead). A script file edited after the save but
committed with it makes a pair differ: that is stale data, not a compiler error. A Script
node whose file is the program's own ``.script`` (abutreca/imh-robotica ``prueba.urp`` runs
``prueba.script``) read the user's file and overwrote it with its output in one save: the
copy the ``.urp`` keeps is then what it read.

The preamble (what the installation generates before the program tree) is compared block
by block in any order, each block's statements in order (blocks: the step-counter thread,
transition hardness, tool wrench limit, motion version, tool communication, gravity, I/O
setup, Modbus signals, payload, TCP, the verification global, the other globals): the
statements of each kind in order, the kinds interleaved in any way. PolyScope does not keep
the order of these blocks: GapeCobot/Soudure's
``TRAVAIL 27112023/Cobot_soudure_29112023-2.script`` saved at 28e0e3a and at 05361bd with the
same installation (blob 66068667) has them in two orders, and Snupai/SZ's four
``UR/UR Programm/laengs_greifer_multi*.script`` share one installation file and show four
orders; the step-counter thread may also come between two globals. "Exact whole" is then:
the program part equal line for line and each kind's preamble statements equal in order;
"as written" also needs PolyScope's order of that save.
Pairs whose installation is not in the repository cannot have an exact preamble: they are
counted, and the exact share is given over all pairs and over those with their
installation.

Prints, per split (``tune``: used while writing the compiler; ``held``: projects held back;
``extra``: projects found later, used to find the variants the tune pairs lack; ``tune2``:
projects found after those, two of every three in the order they were added, the third
``held``; ``tune3``: the same for the projects found after the ``tune2`` ones; ``tune4``: the
same for the projects of the repositories fetched for the real-world benchmark, listed by
``bench/polyscope_pairs.py``; ``tune5``: the same for the projects found by their
repositories' file lists (a folder holding ``default.installation``, a program's name),
listed the same way; ``tune6``: the same for the projects of the next round (repositories
found by their names and file lists, URSim volume folders, course templates, and those the
real-world helpers fetched), listed the same way; ``tune7``: the same for the projects of
the round after (repositories found by their names: URCap, RTDE, socket and controller
repositories, vendors' example programs), listed the same way; ``tune8``: the same for the
projects of the round after that (repositories found by names of courses, tasks and arm
models), listed the same way),
the share of programs exact, the mean share of matching lines and the node types whose lines
differ most; then each project's share of programs exact (program part, whole, whole among
the programs with their installation) and the mean of these over the projects, each project
weighing the same (a few projects hold most pairs: nedlecky/UR, CA-Giken, mswaidan,
Unitedplasticfabricating). A program that does not compile counts as not exact.
``--show N`` prints the first differing lines of N programs.
"""

from __future__ import annotations

import argparse
import collections
import difflib
import posixpath
import re
import subprocess
import sys
from pathlib import Path, PurePosixPath

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from urdsl.polyscope.compile import (  # noqa: E402
    CompileError,
    compile_program,
    parse_variables,
)
from urdsl.polyscope.installation import (  # noqa: E402
    Installation,
    InstallationError,
    parse_installation,
)
from urdsl.polyscope.urp import UrpError, parse_urp  # noqa: E402
from urdsl.script import parse  # noqa: E402
from urdsl.script.diagnostics import ScriptError  # noqa: E402
from urdsl.script.nodes import (  # noqa: E402
    Blank,
    Comment,
    Declare,
    FunctionDef,
    Marker,
    Module,
    ThreadDef,
    While,
)
from urdsl.script.printer import format as print_tree  # noqa: E402

_ID = re.compile(r"_[0-9a-f]{8}_[0-9a-f]{4}_[0-9a-f]{4}_[0-9a-f]{4}_[0-9a-f]{12}")
_PULSE = re.compile(r"\b([Ss]inglePulse)\d+\b")
"""A single pulse thread's number: a counter PolyScope keeps across the programs it
compiles (CA-Giken/docker-noetic-capc: 2, 3 in SUB_109 and 397-402 in SUB_104RXF)."""
_NUMBER = re.compile(r"(?<![\w.])(\d+\.\d*|\.\d+|\d+)(e-?\d+)?(?![\w.])", re.IGNORECASE)
_NEGATIVE_ZERO = re.compile(r"(?<![\w.)\]])-0(?![\w.])")
"""A number that rounds to zero keeps no sign (PolyScope writes -1.2E-16 where urdsl
computes 3.4E-17)."""
_MARKER = re.compile(r'^(\s*)\$ (\d+) "(?:[^"]*)"(.*)$')
_POPUP = re.compile(r'^(\s*popup\(.*, )"([^"]*)"(, (True|False), (True|False))')

POPUP_TITLES = {
    # French (seen: "Erreur")
    "Erreur": "Error", "Avertissement": "Warning",
    # German (seen: "Meldung")
    "Fehler": "Error", "Warnung": "Warning", "Meldung": "Message",
    # Japanese (seen: "メッセージ", CA-Giken/docker-noetic-capc)
    "メッセージ": "Message",
}
"""PolyScope's own Popup titles in the languages seen in real programs → the English title
urdsl writes. A Popup node has no title of its own: PolyScope titles it with its type
(Message, Warning, Error) in the language it runs in."""
_POPUP_FLAGS = {"Message": ("False", "False"), "Warning": ("True", "False"),
                "Error": ("False", "True")}


def popup_title(line: str) -> str:
    """``line`` with a ``popup(...)`` title that is PolyScope's default title in another
    language (and whose warning/error flags are that type's) written in English; any other
    title (a user's own, in a script) is kept."""
    match = _POPUP.match(line)
    if not match:
        return line
    english = POPUP_TITLES.get(match.group(2))
    if english is None or _POPUP_FLAGS[english] != (match.group(4), match.group(5)):
        return line
    return f'{match.group(1)}"{english}"{line[match.end(2) + 1:]}'


def git_dir(repos: Path, repo: str) -> Path:
    base = repos / repo.replace("/", "+")
    for candidate in (base / "repo" / ".git", base / "repo"):  # a work tree's, a bare one
        if (candidate / "HEAD").exists():
            return candidate
    return base


def git_show(gitdir: Path, commit: str, path: str) -> bytes | None:
    result = subprocess.run(["git", f"--git-dir={gitdir}", "show", f"{commit}:{path}"],
                            capture_output=True)
    return result.stdout if result.returncode == 0 else None


def last_commit(gitdir: Path, commit: str, path: str) -> str:
    """The last commit up to ``commit`` that changed ``path``: the script files a program
    names are read as they were then (when PolyScope wrote the .script), not as later
    edited."""
    result = subprocess.run(["git", f"--git-dir={gitdir}", "log", "-1", "--format=%H", commit,
                             "--", path], capture_output=True, text=True)
    return result.stdout.strip() or commit


def _join(folder: PurePosixPath, relative: str) -> str:
    """``folder/relative`` with ``..`` resolved (a path inside the repository)."""
    return posixpath.normpath(str(folder / relative))


def strip_urcap_text(text: str) -> str:
    """The text without the lines from each ``# begin: URCap`` to its ``# end: URCap``
    (counted in text order: a URCap's nested blocks may end inside a statement it opened)."""
    out, depth = [], 0
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("# begin: URCap"):
            depth += 1
            continue
        if stripped.startswith("# end: URCap"):
            depth = max(0, depth - 1)
            continue
        if depth == 0:
            out.append(line)
    return "\n".join(out) + "\n"


def _strip_urcap(items: tuple) -> list:
    out, depth = [], 0
    for item in items:
        if isinstance(item, Comment):
            text = item.text.lstrip("#").strip()
            if text.startswith("begin: URCap"):
                depth += 1
            elif text.startswith("end: URCap"):
                depth = max(0, depth - 1)
            continue
        if depth == 0:
            out.append(item)
    return out


def _clean(module: Module) -> Module:
    """The module with comments and URCap blocks left out, at every level."""
    def block(items):
        kept = []
        for item in _strip_urcap(items):
            kept.append(_clean_node(item))
        return tuple(kept)

    def _clean_node(node):
        from dataclasses import fields, replace
        changes = {}
        for f in fields(node):
            value = getattr(node, f.name)
            if f.name in ("body", "orelse") and isinstance(value, tuple):
                changes[f.name] = block(value)
            elif f.name == "elifs":
                changes[f.name] = tuple(replace(e, body=block(e.body)) for e in value)
        return replace(node, **changes) if changes else node

    # blank lines at the top level are layout: a comment an editor put above the program
    # leaves one (Roma4286/UniversalRobots Robot1.script: "#Code begins from 1560 line")
    return Module(tuple(item for item in block(module.body) if not isinstance(item, Blank)))


def _number(match: re.Match) -> str:
    """A number rounded to 1e-9, after rounding to 1e-12 as PolyScope prints waypoint poses
    (``1.191543262500``): so that a value and its 12-decimal print do not fall on two sides
    of a 1e-9 step (mswaidan/finishing-line SandCube5's ``Clear_p``)."""
    value = round(float(match.group(0)), 12)
    return f"{round(value, 9):.9f}".rstrip("0").rstrip(".") or "0"


def canonical_lines(module: Module) -> list[str]:
    """Canonical lines of a cleaned module: printed, ids masked, numbers rounded to 1e-9,
    marker labels masked."""
    text = print_tree(module)
    lines = []
    for line in text.splitlines():
        if not line.strip():
            continue
        line = _PULSE.sub(r"\1_N", _ID.sub("_ID", line))
        marker = _MARKER.match(line)
        if marker:
            line = f"{marker.group(1)}$ {marker.group(2)}{marker.group(3)}"
        else:
            line = _NEGATIVE_ZERO.sub("0", _NUMBER.sub(_number, popup_title(line)))
        lines.append(line)
    return lines


def preamble_part(module: Module, waypoints: frozenset[str]) -> Module:
    """The top-level statements before the program part: what the installation generates."""
    body = module.body
    if len(body) == 1 and isinstance(body[0], FunctionDef):
        items = body[0].body
        rest = program_part(module, waypoints).body
        return Module(items[:len(items) - len(rest)])
    return Module(())


_PREAMBLE_KINDS = (
    ("steps", re.compile(r"(step_count_ID\b|thread Step_Counter_Thread_ID|run Step_Counter)")),
    ("safety", re.compile(r"set_safety_mode_transition_hardness\(")),
    ("wrench", re.compile(r"tool_wrench_limit_\w+\(")),
    ("motion", re.compile(r"motion_version_set\(")),
    ("tool", re.compile(r"(set_tool_communication|set_tool_output_mode|"
                        r"set_tool_digital_output_mode|set_tool_voltage)\(")),
    ("gravity", re.compile(r"set_gravity\(")),
    ("io", re.compile(r"(set_\w*analog_\w*domain|set_input_actions_to_default|"
                      r"set_\w+_input_action|set_runstate_\w+)\(")),
    ("modbus", re.compile(r"modbus_\w+\(")),
    ("payload", re.compile(r"(set_payload|set_target_payload|set_payload_mass)\(")),
    ("tcp", re.compile(r"set_tcp\(")),
    ("verification", re.compile(r"global _hidden_verificationVariable\b")),
    ("globals", re.compile(r"global ")),
)
"""Kinds of preamble statements: PolyScope writes each kind as one block."""


def preamble_blocks(module: Module) -> list[tuple[str, tuple[str, ...]]]:
    """The preamble's blocks in written order: (kind, canonical lines), a block being a run
    of top-level statements of one kind (see ``_PREAMBLE_KINDS``; ``other`` for the rest)."""
    blocks: list[tuple[str, list[str]]] = []
    for item in module.body:
        lines = canonical_lines(Module((item,)))
        if not lines:
            continue
        kind = next((name for name, pattern in _PREAMBLE_KINDS if pattern.match(lines[0])),
                    "other")
        if blocks and blocks[-1][0] == kind:
            blocks[-1][1].extend(lines)
        else:
            blocks.append((kind, list(lines)))
    return [(kind, tuple(lines)) for kind, lines in blocks]


def by_kind(blocks: list[tuple[str, tuple[str, ...]]]) -> dict[str, tuple[str, ...]]:
    """Kind → its statements' lines in written order. PolyScope does not keep the order of
    the blocks (the same installation saved twice gives two orders), and may write a block
    between two globals: two preambles are equal in any block order when these are."""
    out: dict[str, tuple[str, ...]] = {}
    for kind, lines in blocks:
        out[kind] = out.get(kind, ()) + lines
    return out


def program_part(module: Module, waypoints: frozenset[str]) -> Module:
    """The top-level statements of the program's def from the first global of a waypoint of
    the program (``waypoints``: their names in the .urp), definition or marker on."""
    body = module.body
    if len(body) == 1 and isinstance(body[0], FunctionDef):
        items = body[0].body
        for index, item in enumerate(items):
            if isinstance(item, Marker) or (
                    isinstance(item, (FunctionDef, ThreadDef)) and not _ID.search(item.name)) \
                    or isinstance(item, While) \
                    or (isinstance(item, Declare) and re.sub(r"(_from|_to)?_[pq]$", "", item.name)
                        in waypoints and item.name != re.sub(r"_[pq]$", "", item.name)):
                return Module(items[index:])
        return Module(())
    return module


def _walk_items(module: Module):
    stack = list(module.body)
    while stack:
        item = stack.pop()
        yield item
        for name in ("body", "orelse"):
            value = getattr(item, name, None)
            if isinstance(value, tuple):
                stack.extend(value)
        for elif_ in getattr(item, "elifs", ()) or ():
            stack.extend(elif_.body)


def load_installation(gitdir: Path, commit: str, urp_path: str, name: str | None
                      ) -> tuple[Installation | None, list[tuple[str, str]], str]:
    """The installation a program names (read beside it), its variables, and why there is
    none ("" when there is one)."""
    if not name:
        return None, [], "the program names no installation"
    folder = PurePosixPath(urp_path).parent
    data = git_show(gitdir, commit, _join(folder, f"{name}.installation"))
    if data is None:
        # renamed with the program: the files of one save carry the .urp's new name
        # (loukjeab/WS2223_Master_Semester_Project_Workpiece_Transfer_Unit: UR5e_Program.urp,
        # .script, .installation, .variables; the .urp names the installation it was saved
        # with, OPC_UA_LJ_Henrik_Installation_01.02.2023)
        name = PurePosixPath(urp_path).stem
        data = git_show(gitdir, commit, _join(folder, f"{name}.installation"))
    if data is None:
        return None, [], "the installation file is not in the repository"
    try:
        installation = parse_installation(data, f"{name}.installation")
    except InstallationError:
        return None, [], "the installation file does not read"
    text = git_show(gitdir, commit, _join(folder, f"{name}.variables"))
    return installation, parse_variables(text) if text is not None else [], ""


def _same_within(ours: str, theirs: str) -> bool:
    """Whether two canonical lines differ only in numbers, each pair within 1e-9 (the
    canonical print rounds to 1e-9, so two values 1e-11 apart may print one step apart)."""
    if _NUMBER.sub("#", ours) != _NUMBER.sub("#", theirs):
        return False
    a = [float(m.group(0)) for m in _NUMBER.finditer(ours)]
    b = [float(m.group(0)) for m in _NUMBER.finditer(theirs)]
    return len(a) == len(b) and all(abs(x - y) <= 2e-9 for x, y in zip(a, b, strict=True))


def reconcile(ours: list[str], theirs: list[str]) -> list[str]:
    """``ours`` with each line that equals its counterpart in ``theirs`` to 1e-9 replaced by
    it (lines paired where a stretch of ours replaces a stretch of theirs of the same
    length), so that equality of the lists compares numbers within 1e-9, not their prints."""
    if ours == theirs:
        return ours
    out = list(ours)
    matcher = difflib.SequenceMatcher(a=theirs, b=ours, autojunk=False)
    for tag, i1, i2, j1, j2 in matcher.get_opcodes():
        if tag == "replace" and i2 - i1 == j2 - j1:
            for i, j in zip(range(i1, i2), range(j1, j2), strict=True):
                if _same_within(ours[j], theirs[i]):
                    out[j] = theirs[i]
    return out


def compare(ours: list[str], theirs: list[str]) -> float:
    if not ours and not theirs:
        return 1.0
    matcher = difflib.SequenceMatcher(a=theirs, b=ours, autojunk=False)
    same = sum(block.size for block in matcher.get_matching_blocks())
    return same / max(len(theirs), len(ours))


def project_means(projects: dict[str, list[int]]) -> tuple[float, float, float | None, int]:
    """The mean over projects of the share of programs exact: program part, whole, whole
    among the programs with their installation (None when no project has one), and how many
    projects have their installation. Each project weighs the same, whatever its number of
    programs; a program that does not compile counts as not exact. ``projects`` maps a
    repository to [programs, exact program part, exact whole, programs with their
    installation, exact whole of those]."""
    counted = [v for v in projects.values() if v[0]]
    if not counted:
        return 0.0, 0.0, None, 0
    part = sum(v[1] / v[0] for v in counted) / len(counted)
    whole = sum(v[2] / v[0] for v in counted) / len(counted)
    with_ = [v for v in counted if v[3]]
    whole_with = sum(v[4] / v[3] for v in with_) / len(with_) if with_ else None
    return part, whole, whole_with, len(with_)


def print_projects(projects: dict[str, list[int]]) -> None:
    """The per-project view of a split: one line per project (share exact of its programs:
    program part, whole; whole among those with their installation), then the means over
    the projects. One project with many programs can carry a split's per-program figure."""
    counted = {k: v for k, v in projects.items() if v[0]}
    print(f"  per project ({len(counted)}; exact program part, whole, whole with installation,"
          " of programs):")
    width = max((len(repo) for repo in counted), default=0)
    for repo, v in sorted(counted.items(), key=lambda item: (-item[1][0], item[0])):
        with_ = f"{v[4]}/{v[3]}" if v[3] else "-"
        print(f"    {repo:<{width}} {v[1]:>3}/{v[0]:<3} {v[2]:>3}/{v[0]:<3} {with_:>7}"
              f"  ({v[1] / v[0]:.0%} part, {v[2] / v[0]:.0%} whole)")
    if counted:
        part, whole, whole_with, n_with = project_means(counted)
        print(f"  mean over the {len(counted)} projects: program part exact {part:.1%}, "
              f"whole exact {whole:.1%}" + (
                  f", whole exact with installation {whole_with:.1%} (over {n_with})"
                  if whole_with is not None else ""))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repos", type=Path, default=Path("/work/.mirror"),
                        help="folder of owner+name git dirs")
    parser.add_argument("--pairs", type=Path, default=ROOT / "bench/polyscope/pairs.tsv")
    parser.add_argument("--split", choices=("tune", "held", "extra", "tune2", "tune3", "tune4",
                                                   "tune5", "tune6", "tune7", "tune8", "all"),
                        default="all")
    parser.add_argument("--show", type=int, default=0, help="show the diffs of N programs")
    parser.add_argument("--script-files", choices=("file", "cache"), default="file",
                        help="a Script node's file: read it from the repository as of the "
                             "commit that last wrote the .script (file), or take the copy "
                             "the .urp keeps (cache)")
    parser.add_argument("--installation", choices=("saved", "pair"), default="saved",
                        help="read the installation (and .variables) as of the commit that "
                             "last wrote the .script (saved), or as of the pair's commit")
    parser.add_argument("--only", default="", help="only pairs whose .urp path contains this")
    parser.add_argument("--repo", action="append", default=[],
                        help="only pairs of this repository (owner/name; repeatable)")
    parser.add_argument("--not-repo", action="append", default=[],
                        help="leave out the pairs of this repository (repeatable): the "
                             "held projects of one round apart from another's")
    args = parser.parse_args(argv)

    rows = [line.rstrip("\n").split("\t") for line in args.pairs.read_text().splitlines()
            if line and not line.startswith("#")]
    stats: dict[str, dict] = {}
    shown = 0
    for repo, commit, urp_path, script_path, _licence, split in rows:
        if args.split != "all" and split != args.split:
            continue
        if args.only and args.only not in urp_path:
            continue
        if (args.repo and repo not in args.repo) or repo in args.not_repo:
            continue
        st = stats.setdefault(split, {"n": 0, "exact": 0, "exact_prog": 0, "share": 0.0,
                                      "share_prog": 0.0, "errors": collections.Counter(),
                                      "kinds": collections.Counter(), "missing": 0,
                                      "not_polyscope": 0, "exact_written": 0, "pre_total": 0,
                                      "pre_found": 0, "pre_extra": 0, "with": 0,
                                      "exact_with": 0, "no_installation": collections.Counter(),
                                      "pre_kinds": collections.Counter(), "projects": {}})
        # programs, exact program part, exact whole, with their installation, exact whole
        # of those: every program counts, one that does not compile as not exact
        project = st["projects"].setdefault(repo, [0, 0, 0, 0, 0])
        gitdir = git_dir(args.repos, repo)
        urp = git_show(gitdir, commit, urp_path)
        script = git_show(gitdir, commit, script_path)
        if urp is None or script is None:
            st["missing"] += 1
            continue
        st["n"] += 1
        project[0] += 1
        try:
            program = parse_urp(urp, urp_path)
        except UrpError as error:
            st["errors"][str(error).split("error: ", 1)[-1][:150]] += 1
            st["no_installation"]["the .urp does not read"] += 1
            continue
        # the installation as it was when PolyScope wrote the .script (a later commit may
        # hold an installation saved after it: GapeCobot/Soudure Cobot_soudure_28112023);
        # one committed only after the .script (vicisnotokay/Devs-1, 66 s later) as of the
        # pair's commit
        saved = last_commit(gitdir, commit, script_path)
        # the names `urdsl compile` tries, in its order: the relative path (``../default``:
        # the parent folder on the robot), then the name in the program's folder (a copy
        # beside the programs: o2ac/o2ac-ur b_bot)
        names = [n for n in (program.installation_path, program.installation) if n] or [None]
        for name in dict.fromkeys(names):
            installation, variables, absent = load_installation(
                gitdir, saved if args.installation == "saved" else commit, urp_path, name)
            if absent and saved != commit:
                installation, variables, absent = load_installation(
                    gitdir, commit, urp_path, name)
            if not absent:
                break
        if absent:
            st["no_installation"][absent] += 1
        else:
            st["with"] += 1
            project[3] += 1
        reference = script.decode("utf-8", "replace")
        by_text = True
        try:
            theirs_tree = _clean(parse(strip_urcap_text(reference), script_path))
        except ScriptError:
            by_text = False  # a URCap block cut a statement: leave the blocks out by tree
            try:
                theirs_tree = _clean(parse(reference, script_path))
            except ScriptError:
                st["errors"]["reference does not parse"] += 1
                continue
        if not any(isinstance(item, Marker) for item in _walk_items(theirs_tree)):
            st["n"] -= 1
            project[0] -= 1
            st["not_polyscope"] += 1
            if absent:
                st["no_installation"][absent] -= 1
            else:
                st["with"] -= 1
                project[3] -= 1
            continue
        try:
            folder = PurePosixPath(urp_path).parent

            def files(relative: str, folder=folder, gitdir=gitdir, saved=saved,
                      script_path=script_path):
                path = _join(folder, relative)
                if path == script_path:
                    # the Script node's file is where PolyScope writes this program's
                    # .script: the save read the user's file and then overwrote it with its
                    # output, so what it read is only in the copy the .urp keeps
                    return None
                return git_show(gitdir, saved, path)

            compiled = compile_program(program, installation, variables,
                                       files if args.script_files == "file" else None)
            ours_tree = _clean(parse(strip_urcap_text(compiled.text), "compiled")
                               if by_text else compiled.module)
        except CompileError as error:
            st["errors"][str(error).split("error: ", 1)[-1][:150]] += 1
            continue
        except ScriptError as error:  # a compiler bug: what it wrote is not URScript
            st["errors"]["compiled script does not parse: "
                         + str(error).split("error: ", 1)[-1][:100]] += 1
            continue
        theirs = canonical_lines(theirs_tree)
        ours = canonical_lines(ours_tree)
        names = frozenset(node.name for root in program.top for node in root.walk()
                          if node.kind == "Waypoint" and node.name)
        theirs_prog = canonical_lines(program_part(theirs_tree, names))
        ours_prog = canonical_lines(program_part(ours_tree, names))
        theirs_blocks = preamble_blocks(preamble_part(theirs_tree, names))
        ours_blocks = preamble_blocks(preamble_part(ours_tree, names))
        theirs_pre = collections.Counter(line for _k, lines in theirs_blocks for line in lines)
        ours_pre = collections.Counter(line for _k, lines in ours_blocks for line in lines)
        st["pre_total"] += sum(theirs_pre.values())
        st["pre_found"] += sum((theirs_pre & ours_pre).values())
        st["pre_extra"] += sum((ours_pre - theirs_pre).values())
        ours = reconcile(ours, theirs)
        ours_prog = reconcile(ours_prog, theirs_prog)
        theirs_kinds, ours_kinds = by_kind(theirs_blocks), by_kind(ours_blocks)
        ours_kinds = {kind: tuple(reconcile(list(lines), list(theirs_kinds.get(kind, ()))))
                      for kind, lines in ours_kinds.items()}
        for kind in sorted(set(theirs_kinds) | set(ours_kinds)):
            if theirs_kinds.get(kind) != ours_kinds.get(kind):
                st["pre_kinds"][kind] += 1
        share = compare(ours, theirs)
        share_prog = compare(ours_prog, theirs_prog)
        st["share"] += share
        st["share_prog"] += share_prog
        exact = ours_prog == theirs_prog and ours_kinds == theirs_kinds
        st["exact"] += exact
        st["exact_written"] += ours == theirs
        st["exact_prog"] += ours_prog == theirs_prog
        project[1] += ours_prog == theirs_prog
        project[2] += exact
        if not absent:
            st["exact_with"] += exact
            project[4] += exact
        if ours_prog != theirs_prog:
            for kind in compiled.kinds_in_diff(ours_prog, theirs_prog):
                st["kinds"][kind] += 1
        if not exact and shown < args.show:
            shown += 1
            print(f"==== {repo} {urp_path} (program part {share_prog:.0%}"
                  f"{'; ' + absent if absent else ''})")
            diff = difflib.unified_diff(theirs_prog, ours_prog, "polyscope", "urdsl",
                                        n=1, lineterm="")
            for number, line in enumerate(diff):
                if number > 40:
                    break
                print(line[:160])
            for kind in sorted(set(theirs_kinds) | set(ours_kinds)):
                if theirs_kinds.get(kind) != ours_kinds.get(kind):
                    diff = difflib.unified_diff(theirs_kinds.get(kind, ()),
                                                ours_kinds.get(kind, ()), n=0, lineterm="")
                    for line in list(diff)[2:14]:
                        if not line.startswith("@@"):
                            print(f"{line[0]}[preamble {kind}] {line[1:140]}")
    for split, st in sorted(stats.items(), reverse=True):
        n = max(st["n"], 1)
        print(f"[{split}] {st['n']} programs ({st['missing']} missing, "
              f"{st['not_polyscope']} .script not written by PolyScope: no $ markers): "
              f"exact {st['exact'] / n:.1%} whole, {st['exact_prog'] / n:.1%} program part; "
              f"mean matching lines {st['share'] / n:.1%} whole, "
              f"{st['share_prog'] / n:.1%} program part")
        with_ = max(st["with"], 1)
        absent = sum(st["no_installation"].values())
        print(f"  exact whole as written (preamble blocks in PolyScope's order of that save): "
              f"{st['exact_written'] / n:.1%}")
        print(f"  with their installation: {st['with']} programs, exact whole "
              f"{st['exact_with'] / with_:.1%}; without: {absent} ("
              + "; ".join(f"{k}: {v}" for k, v in st["no_installation"].most_common())
              + "): no exact preamble possible")
        print(f"  preamble statements (any order): {st['pre_found']} of {st['pre_total']} "
              f"written ({st['pre_found'] / max(st['pre_total'], 1):.1%}), "
              f"{st['pre_extra']} extra; differing blocks: "
              + ", ".join(f"{k} {v}" for k, v in st["pre_kinds"].most_common()))
        if st["errors"]:
            print("  not compiled: " + "; ".join(f"{k} ({v})" for k, v in
                                                 st["errors"].most_common(5)))
        print("  node types in differing lines: " + ", ".join(
            f"{k} {v}" for k, v in st["kinds"].most_common(8)))
        print_projects(st["projects"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
