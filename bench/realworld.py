"""The labelled real-world set: PolyScope projects from public repositories, linted and checked.

Issue 12's yardstick. ``bench/realworld/projects.tsv`` names each project by repository,
commit and folder; ``bench/realworld/labels.tsv`` says for every error finding urdsl reported
on them whether it is right (``true``) or a false alarm (``false``), with a reason. This
script does two things:

``extract --repos DIR --out OUT``
    For each project, read the pinned commit from the git directory found in
    ``DIR/owner+name`` (a bare mirror, a normal clone, or a folder holding either) and write the
    project's files to ``OUT/<id>/``. No network: obtain the repositories first (README).

``run --root OUT [--tune|--held|--all] [--project ID] [--timeout S] [--json FILE]``
    As a user would, run ``urdsl lint OUT/<id>`` (the folder) and ``urdsl check FILE`` for every
    ``.script`` of the project and every ``.urp`` without its ``.script``, each in its own
    process with a wall-clock limit (killed at ``--timeout`` s and recorded as a timeout).
    Collect every error finding, match it against
    the labels by (project, tool, file, line, code) and print precision per tool and rule
    (overall, tuning projects, held-back projects), the wall time of every run, the labelled-true
    findings no longer reported ("lost") and the unlabelled findings. Exit status 0.

``score SAVED.json... [--tune|--held|--all] [--project ID]``
    Match runs saved with ``run --json`` against the labels again and print the same tables
    (after labelling, or to combine runs made with different code or at different times).

Run: ``.venv/bin/python bench/realworld.py run --root /path/to/extracted --all``.
Not part of the tests.
"""

from __future__ import annotations

import argparse
import csv
import fnmatch
import importlib.util
import json
import os
import signal
import subprocess
import sys
import time
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent / "realworld"
MANIFEST = HERE / "projects.tsv"
LABELS = HERE / "labels.tsv"

#: What ``files = *`` takes from a project folder (the files PolyScope writes for a program).
PROGRAM_SUFFIXES = (".script", ".urp", ".installation", ".variables", ".txt")

LABEL_COLUMNS = ["project", "tool", "file", "line", "code", "verdict", "reason", "baseline",
                 "message"]


# ---- manifest and labels ---------------------------------------------------------------------


@dataclass(frozen=True)
class Project:
    """One row of projects.tsv: a PolyScope program folder at a pinned commit."""

    id: str
    repo: str
    commit: str
    folder: str
    files: tuple[str, ...]
    licence: str
    generation: str
    urcaps: str
    split: str
    notes: str

    @property
    def mirror_name(self) -> str:
        """The folder name the repository is expected under: ``owner+name``."""
        return self.repo.replace("/", "+", 1)


def read_manifest(path: Path = MANIFEST) -> list[Project]:
    """The projects of the manifest, in its order."""
    with path.open(newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle, delimiter="\t"))
    projects = []
    for row in rows:
        files = tuple(part.strip() for part in row["files"].split(",") if part.strip())
        projects.append(Project(row["id"], row["repo"], row["commit"], row["folder"], files,
                                row["licence"], row["generation"], row["urcaps"], row["split"],
                                row["notes"]))
    return projects


@dataclass(frozen=True)
class Label:
    """A verdict on one finding: key (project, tool, file, line, code) and why."""

    project: str
    tool: str
    file: str
    line: int
    code: str
    verdict: str
    reason: str
    baseline: str
    message: str

    @property
    def key(self) -> tuple[str, str, str, int, str]:
        return (self.project, self.tool, self.file, self.line, self.code)


def read_labels(path: Path = LABELS) -> dict[tuple[str, str, str, int, str], Label]:
    """The labels by match key; a missing file means no labels yet."""
    if not path.exists():
        return {}
    labels: dict[tuple[str, str, str, int, str], Label] = {}
    with path.open(newline="", encoding="utf-8") as handle:
        for row in csv.DictReader(handle, delimiter="\t", quoting=csv.QUOTE_NONE):
            if not row.get("project"):
                continue
            label = Label(row["project"], row["tool"], row["file"], int(row["line"]),
                          row["code"], row["verdict"].strip(), row.get("reason") or "",
                          row.get("baseline") or "", row.get("message") or "")
            if label.verdict not in ("true", "false"):
                raise SystemExit(f"{path}: verdict must be true or false: {row}")
            labels[label.key] = label
    return labels


# ---- extract ---------------------------------------------------------------------------------


def find_git_dir(folder: Path) -> Path | None:
    """The git directory in ``folder``: the folder itself (bare), its ``.git``, or one nested
    a few levels down (``repo``, ``repo/.git``)."""
    if not folder.is_dir():
        return None
    candidates = [folder, folder / ".git"]
    for depth_one in sorted(folder.iterdir()):
        if depth_one.is_dir():
            candidates += [depth_one, depth_one / ".git"]
    for candidate in candidates:
        if (candidate / "HEAD").is_file() and (candidate / "objects").is_dir():
            return candidate
    return None


def git(git_dir: Path, *args: str) -> bytes:
    """Run a read-only git command on ``git_dir``; raise RuntimeError with git's message."""
    done = subprocess.run(["git", "--git-dir", str(git_dir), *args], capture_output=True)
    if done.returncode != 0:
        raise RuntimeError(done.stderr.decode(errors="replace").strip())
    return done.stdout


def select_files(project: Project, names: list[str]) -> list[str]:
    """The paths (relative to the project folder) the manifest's ``files`` entry selects."""
    if project.files == ("*",):
        return [name for name in names if name.lower().endswith(PROGRAM_SUFFIXES)]
    chosen = [name for name in names
              if any(fnmatch.fnmatchcase(name, pattern) for pattern in project.files)]
    for pattern in project.files:
        if not any(fnmatch.fnmatchcase(name, pattern) for name in names):
            print(f"{project.id}: warning: {pattern} matches no file", file=sys.stderr)
    return chosen


def extract(projects: list[Project], repos: Path, out: Path) -> int:
    """Write every project's files to ``out/<id>/``, each marked as a checkout's top (an
    empty ``.git`` folder: urdsl's project search stops there and takes a fragment's
    repository from there, as in a clone); return the number of failures."""
    failures = 0
    for project in projects:
        git_dir = find_git_dir(repos / project.mirror_name)
        if git_dir is None:
            print(f"{project.id}: no git directory in {repos / project.mirror_name} "
                  f"(git clone https://github.com/{project.repo})")
            failures += 1
            continue
        prefix = "" if project.folder in ("", ".") else project.folder.rstrip("/") + "/"
        try:
            listing = git(git_dir, "ls-tree", "-r", "-z", "--name-only", project.commit, "--",
                          prefix or ".")
        except RuntimeError as error:
            print(f"{project.id}: {project.repo} lacks commit {project.commit}: {error}")
            failures += 1
            continue
        names = [name[len(prefix):] for name in listing.decode().split("\0") if name]
        chosen = select_files(project, names)
        if not chosen:
            print(f"{project.id}: nothing matches {','.join(project.files)} in {prefix or '.'}")
            failures += 1
            continue
        target = out / project.id
        for name in chosen:
            data = git(git_dir, "show", f"{project.commit}:{prefix}{name}")
            path = target / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        # the top of a checkout: urdsl's project search stops there, as in the repository
        (target / ".git").mkdir(exist_ok=True)
        print(f"{project.id}: {project.repo} {project.folder} -> {target} ({len(chosen)} files)")
    return failures


# ---- run -------------------------------------------------------------------------------------


def urdsl_command() -> list[str]:
    """How to start urdsl's command line with this interpreter.

    ``-P`` keeps the working directory off the child's module path: without it, running the
    script from one checkout with another checkout's interpreter (to measure a baseline) would
    import the urdsl of the working directory, not the one installed for that interpreter.
    """
    if importlib.util.find_spec("urdsl.__main__") is not None:
        return [sys.executable, "-P", "-m", "urdsl"]
    return [sys.executable, "-P", "-c",
            "import sys; from urdsl.cli import main; sys.exit(main())"]


@dataclass
class Run:
    """One lint or check process: what it ran on, how long it took, how it ended."""

    project: str
    tool: str
    target: str
    seconds: float
    status: str  # ok, findings, timeout, crash
    detail: str = ""
    findings: list[dict] = field(default_factory=list)


def run_process(command: list[str], timeout: float) -> tuple[str, str, float, str]:
    """Run ``command`` in its own process group; kill the group at ``timeout`` s.
    Returns (status, stdout, wall seconds, stderr tail)."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               start_new_session=True)
    try:
        out, err = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        return "timeout", "", time.perf_counter() - start, ""
    seconds = time.perf_counter() - start
    tail = err.decode(errors="replace").strip().splitlines()[-3:]
    if process.returncode not in (0, 1):
        return "crash", out.decode(errors="replace"), seconds, " | ".join(tail)
    return "ok", out.decode(errors="replace"), seconds, " | ".join(tail)


def relative(path: str, root: Path) -> str:
    """``path`` relative to the project folder ``root`` (as given if outside it)."""
    try:
        return Path(path).resolve().relative_to(root.resolve()).as_posix()
    except ValueError:
        return path


def lint_project(project: Project, root: Path, timeout: float) -> Run:
    folder = root / project.id
    status, out, seconds, tail = run_process(
        urdsl_command() + ["lint", str(folder), "--format", "json", "--no-config"], timeout)
    result = Run(project.id, "lint", ".", seconds, status, tail)
    if status == "ok":
        try:
            findings = json.loads(out or "[]")
        except json.JSONDecodeError:
            result.status, result.detail = "crash", "output is not JSON: " + out[:200]
            return result
        for finding in findings:
            finding["file"] = relative(finding.get("file", ""), folder)
        result.findings = findings
    return result


def check_file(project: Project, root: Path, script: Path, timeout: float) -> Run:
    folder = root / project.id
    target = relative(str(script), folder)
    status, out, seconds, tail = run_process(
        urdsl_command() + ["check", str(script), "--json"], timeout)
    result = Run(project.id, "check", target, seconds, status, tail)
    if status == "ok":
        try:
            document = json.loads(out)
        except json.JSONDecodeError:
            result.status, result.detail = "crash", "output is not JSON: " + out[:200]
            return result
        documents = document if isinstance(document, list) else [document]
        for report in documents:
            for finding in report.get("findings", []):
                finding["file"] = relative(finding.get("file") or str(script), folder)
                result.findings.append(finding)
    return result


def project_scripts(root: Path, project: Project) -> list[Path]:
    """The files ``urdsl check`` runs on: every ``.script``, and every PolyScope program
    (``.urp``) with no ``.script`` of its name beside it (with one, PolyScope's export is
    what the robot ran and what is checked; without, the user checks the program)."""
    files = [path for path in (root / project.id).rglob("*") if path.is_file()]
    scripts = [path for path in files if path.suffix.lower() == ".script"]
    exported = {path.with_suffix("").as_posix().lower() for path in scripts
                if path.read_bytes().strip()}  # an empty .script is no export
    programs = [path for path in files if path.suffix.lower() == ".urp"
                and path.with_suffix("").as_posix().lower() not in exported]
    return sorted(scripts + programs)


@dataclass
class Scored:
    """An error finding with its label (None when unlabelled)."""

    project: str
    split: str
    tool: str
    file: str
    line: int
    code: str
    message: str
    label: Label | None


def precision_table(scored: list[Scored], title: str) -> list[str]:
    """Lines of a table: per tool and rule, errors, true, false, unlabelled, precision."""
    counts: dict[tuple[str, str], list[int]] = defaultdict(lambda: [0, 0, 0, 0])
    for item in scored:
        for key in ((item.tool, "all"), (item.tool, item.code)):
            row = counts[key]
            row[0] += 1
            if item.label is None:
                row[3] += 1
            elif item.label.verdict == "true":
                row[1] += 1
            else:
                row[2] += 1
    lines = [f"{title}", f"  {'tool':<6} {'rule':<8} {'errors':>6} {'true':>5} {'false':>5} "
             f"{'unlab':>5} {'precision':>9}"]
    for (tool, code), (errors, true, false, unlabelled) in sorted(
            counts.items(), key=lambda kv: (kv[0][0], kv[0][1] != "all", kv[0][1])):
        precision = f"{100 * true / (true + false):8.1f}%" if true + false else "        -"
        lines.append(f"  {tool:<6} {code:<8} {errors:>6} {true:>5} {false:>5} {unlabelled:>5} "
                     f"{precision}")
    if not counts:
        lines.append("  (no error findings)")
    return lines


def run(projects: list[Project], root: Path, timeout: float, json_out: Path | None,
        tools: tuple[str, ...]) -> None:
    runs: list[Run] = []
    for project in projects:
        if not (root / project.id).is_dir():
            print(f"{project.id}: not extracted under {root} (run extract first)",
                  file=sys.stderr)
            continue
        if "lint" in tools:
            runs.append(lint_project(project, root, timeout))
            print(f"  {project.id} lint {runs[-1].seconds:7.2f} s {runs[-1].status}",
                  file=sys.stderr)
        if "check" in tools:
            for script in project_scripts(root, project):
                runs.append(check_file(project, root, script, timeout))
                print(f"  {project.id} check {runs[-1].target} {runs[-1].seconds:7.2f} s "
                      f"{runs[-1].status}", file=sys.stderr)
    report(runs, projects, json_out)


def load_runs(paths: list[Path]) -> list[Run]:
    """The runs saved by ``run --json`` (several files: their runs one after another)."""
    runs: list[Run] = []
    for path in paths:
        document = json.loads(path.read_text(encoding="utf-8"))
        for item in document["runs"]:
            runs.append(Run(item["project"], item["tool"], item["target"], item["seconds"],
                            item["status"], item.get("detail", ""), item.get("findings", [])))
    return runs


def hit_bound(item: Run) -> bool:
    """Whether a check stopped at its own wall-clock bound (URS313 naming the bound)."""
    return any(finding.get("code") == "URS313" and "wall-clock bound" in
               finding.get("message", "") for finding in item.findings)


def report(runs: list[Run], projects: list[Project], json_out: Path | None) -> None:
    """Match the runs' error findings against the labels and print the tables."""
    labels = read_labels()
    split_of = {project.id: project.split for project in projects}
    runs = [item for item in runs if item.project in split_of]
    scored: list[Scored] = []
    for item in runs:
        for finding in item.findings:
            if finding.get("severity") != "error":
                continue
            key = (item.project, item.tool, finding["file"], int(finding.get("line", 0)),
                   finding.get("code", ""))
            scored.append(Scored(item.project, split_of[item.project], item.tool, key[2],
                                 key[3], key[4], finding.get("message", ""), labels.get(key)))
    reported = {(s.project, s.tool, s.file, s.line, s.code) for s in scored}
    ran = {(item.project, item.tool) for item in runs}
    lost = [label for label in labels.values()
            if label.verdict == "true" and (label.project, label.tool) in ran
            and label.key not in reported]

    out: list[str] = []
    out += precision_table(scored, "error findings, all projects")
    out += precision_table([s for s in scored if s.split == "tune"], "tuning projects")
    out += precision_table([s for s in scored if s.split == "held"], "held-back projects")
    out.append("wall time per run (s); 'bound' = the check stopped at its own wall-clock "
               "bound (URS313) and says how far it got:")
    for item in runs:
        extra = f"  [{item.detail}]" if item.status in ("crash",) and item.detail else ""
        extra += "  bound" if hit_bound(item) else ""
        out.append(f"  {item.project:>3} {item.tool:<5} {item.seconds:8.2f} {item.status:<7} "
                   f"{item.target}{extra}")
    if runs:
        slowest = max(runs, key=lambda item: item.seconds)
        out.append(f"slowest: project {slowest.project} {slowest.tool} {slowest.target} "
                   f"{slowest.seconds:.2f} s ({slowest.status}); timeouts: "
                   f"{sum(item.status == 'timeout' for item in runs)}; crashes: "
                   f"{sum(item.status == 'crash' for item in runs)}; checks that hit their "
                   f"wall-clock bound: {sum(hit_bound(item) for item in runs)}")
    out.append(f"lost (labelled true, no longer reported): {len(lost)}")
    for label in sorted(lost, key=lambda lab: lab.key):
        out.append(f"  {label.project} {label.tool} {label.file}:{label.line} {label.code} "
                   f"{label.message}")
    unlabelled = [s for s in scored if s.label is None]
    out.append(f"unlabelled error findings: {len(unlabelled)}")
    for item in unlabelled:
        out.append(f"  {item.project}\t{item.tool}\t{item.file}\t{item.line}\t{item.code}\t"
                   f"{item.message}")
    print("\n".join(out))
    if json_out is not None:
        document = {
            "runs": [{"project": r.project, "tool": r.tool, "target": r.target,
                      "seconds": round(r.seconds, 3), "status": r.status, "detail": r.detail,
                      "findings": r.findings} for r in runs],
            "errors": [{"project": s.project, "split": s.split, "tool": s.tool, "file": s.file,
                        "line": s.line, "code": s.code, "message": s.message,
                        "verdict": s.label.verdict if s.label else None} for s in scored],
            "lost": [dict(zip(LABEL_COLUMNS, (lab.project, lab.tool, lab.file, lab.line,
                                              lab.code, lab.verdict, lab.reason, lab.baseline,
                                              lab.message), strict=True)) for lab in lost],
        }
        json_out.write_text(json.dumps(document, indent=1), encoding="utf-8")


def _selection(parser: argparse.ArgumentParser) -> None:
    """The options that choose projects: --tune, --held or --all, and --project ID."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--tune", action="store_true", help="only the tuning projects")
    group.add_argument("--held", action="store_true", help="only the held-back projects")
    group.add_argument("--all", action="store_true", help="every project (default)")
    parser.add_argument("--project", action="append", default=[], metavar="ID",
                        help="only this project (repeatable)")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    p_extract = commands.add_parser("extract", help="write the projects' files from git")
    p_extract.add_argument("--repos", type=Path, required=True,
                           help="folder holding one git repository per project as owner+name")
    p_extract.add_argument("--out", type=Path, required=True, help="where OUT/<id>/ goes")
    p_extract.add_argument("--tune", action="store_true", help="only the tuning projects")
    p_extract.add_argument("--held", action="store_true", help="only the held-back projects")
    p_run = commands.add_parser("run", help="lint and check the extracted projects")
    p_run.add_argument("--root", type=Path, required=True, help="the extract --out folder")
    _selection(p_run)
    p_run.add_argument("--tool", choices=("lint", "check"), action="append",
                       help="only this tool (repeatable; default both)")
    p_run.add_argument("--timeout", type=float, default=120.0,
                       help="wall-clock limit per lint or check run in s (default 120)")
    p_run.add_argument("--json", type=Path, help="also write everything as JSON here")
    p_score = commands.add_parser("score", help="match saved runs (run --json) against the "
                                  "labels again, without running anything")
    p_score.add_argument("saved", type=Path, nargs="+", help="JSON files written by run --json")
    _selection(p_score)
    p_score.add_argument("--json", type=Path, help="also write everything as JSON here")
    args = parser.parse_args(argv)

    projects = read_manifest()
    if args.tune:
        projects = [p for p in projects if p.split == "tune"]
    elif args.held:
        projects = [p for p in projects if p.split == "held"]
    if args.command == "extract":
        failures = extract(projects, args.repos, args.out)
        return 1 if failures else 0
    if args.project:
        projects = [p for p in projects if p.id in args.project]
    if args.command == "score":
        report(load_runs(args.saved), projects, args.json)
        return 0
    run(projects, args.root, args.timeout, args.json, tuple(args.tool or ("lint", "check")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
