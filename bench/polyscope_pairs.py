"""List the PolyScope program pairs of local git mirrors that ``bench/polyscope/pairs.tsv`` does
not hold yet: a ``.urp`` and the ``.script`` of the same stem in the same folder of one commit.

Nothing is compiled and no script is compared: the listing is what chooses the new projects
and their split before any of their programs is compiled. Repositories whose repository or
author (owner) is already in ``pairs.tsv`` are skipped. For each pair the commit is the last
one (newest first over every ref) that holds both files; pairs whose two blobs are the same
as another pair's (a folder copied) are listed once. Each pair says what the ``.urp`` is (the
root element and PolyScope's ``lastSavedIn`` version) and whether the ``.script`` has ``$``
markers (PolyScope writes them; a ``.script`` without them was written by something else).

``--tsv SPLITS`` prints the rows to add to ``pairs.tsv``: the repositories in the order
listed (owner/name, case-insensitive), split by position: ``--tsv tune4,tune4,held`` gives
every third project ``held`` and the others ``tune4``. Only pairs PolyScope 3.x-5.x wrote
are rows (root ``<URProgram>``, a ``.script`` with markers: not PolyScope 1.x's serialised
programs, a generator's files, a ``__MACOSX`` resource fork); a repository with none is not
a project. ``--studied REPO`` (repeatable): a repository whose programs a helper has already
compiled is not blind: it takes the first split and no position in the cycle. ``--exclude
REPO`` (repeatable): a repository that is not a project of its own, such as a fork whose pairs
are another listed repository's blob for blob (students' forks of a course template): it is
left out and takes no position.

Usage: ``python bench/polyscope_pairs.py --repos /work/.mirror [--tsv tune4,tune4,held]``
"""

from __future__ import annotations

import argparse
import gzip
import posixpath
import re
import subprocess
import sys
import zlib
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

_VERSION = re.compile(rb'lastSavedIn="([^"]*)"')
_CREATED = re.compile(rb'createdIn="([^"]*)"')
_ROOT_TAG = re.compile(rb"<([A-Za-z_][\w.]*)")


@dataclass
class Pair:
    """One program and the script beside it, at the last commit holding both."""

    repo: str
    commit: str
    urp: str
    script: str
    urp_blob: str
    script_blob: str
    root: str = "?"
    version: str = "?"
    markers: bool = False


def git(directory: Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(directory), *args], capture_output=True,
                          text=True, errors="replace").stdout


def git_dir(repos: Path, name: str) -> Path | None:
    base = repos / name
    for candidate in (base / "repo", base):
        if (candidate / "HEAD").exists() or (candidate / ".git").exists():
            return candidate
    return None


def known(pairs: Path) -> tuple[set[str], set[str]]:
    """Repositories and authors already in the pairs file."""
    repos: set[str] = set()
    for line in pairs.read_text("utf-8").splitlines():
        cells = line.split("\t")
        if len(cells) >= 6 and not line.startswith("#"):
            repos.add(cells[0])
    return repos, {repo.split("/")[0].lower() for repo in repos}


def tree(directory: Path, commit: str) -> dict[str, str]:
    """Path → blob of the ``.urp`` and ``.script`` files of one commit."""
    out: dict[str, str] = {}
    for line in git(directory, "ls-tree", "-r", commit).splitlines():
        meta, _, path = line.partition("\t")
        parts = meta.split()
        if len(parts) == 3 and parts[1] == "blob" and \
                path.lower().endswith((".urp", ".script")):
            out[path] = parts[2]
    return out


def pairs_of(directory: Path, repo: str) -> list[Pair]:
    """Every distinct ``.urp``/``.script`` pair of a repository's history."""
    if not git(directory, "log", "--all", "--format=%H", "-1", "--", "*.urp", "*.URP").strip():
        return []
    touching = git(directory, "rev-list", "--all", "--parents", "--", "*.urp", "*.URP",
                   "*.script").split("\n")
    order: list[str] = []
    for line in [git(directory, "rev-parse", "HEAD").strip(), *touching]:
        for commit in line.split():
            if commit and commit not in order:
                order.append(commit)
    dates = {}
    for line in git(directory, "log", "--all", "--format=%H %ct").splitlines():
        commit, _, stamp = line.partition(" ")
        dates[commit] = int(stamp or 0)
    head = order[0]
    order = [head] + sorted(order[1:], key=lambda c: -dates.get(c, 0))
    found: dict[str, Pair] = {}
    for commit in order:
        files = tree(directory, commit)
        for path, blob in files.items():
            if not path.lower().endswith(".urp"):
                continue
            script = path[:-4] + ".script"
            if script in files and path not in found:
                found[path] = Pair(repo, commit, path, script, blob, files[script])
    seen: set[tuple[str, str]] = set()
    out = []
    for pair in sorted(found.values(), key=lambda p: (posixpath.dirname(p.urp).count("/"),
                                                      p.urp)):
        key = (pair.urp_blob, pair.script_blob)
        if key in seen:
            continue
        seen.add(key)
        describe(directory, pair)
        out.append(pair)
    return sorted(out, key=lambda p: p.urp)


def describe(directory: Path, pair: Pair) -> None:
    """The root element and version of the program; whether the script has markers."""
    data = subprocess.run(["git", "-C", str(directory), "cat-file", "blob", pair.urp_blob],
                          capture_output=True).stdout
    if data[:2] == b"\x1f\x8b":
        try:
            data = gzip.decompress(data)
        except (OSError, EOFError, zlib.error):
            data = b""
    head = data[:2000]
    root = _ROOT_TAG.search(head.split(b"?>", 1)[-1] if head.startswith(b"<?") else head)
    pair.root = root.group(1).decode() if root else "?"
    version = _VERSION.search(head) or _CREATED.search(head)
    pair.version = version.group(1).decode() if version else "?"
    script = subprocess.run(["git", "-C", str(directory), "cat-file", "blob",
                             pair.script_blob], capture_output=True).stdout
    pair.markers = re.search(rb'^\s*\$ \d+ "', script, re.MULTILINE) is not None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repos", type=Path, required=True)
    parser.add_argument("--pairs", type=Path, default=ROOT / "bench/polyscope/pairs.tsv")
    parser.add_argument("--tsv", help="comma-separated splits by position, repeated")
    parser.add_argument("--studied", action="append", default=[],
                        help="a repository already compiled by a helper (repeatable)")
    parser.add_argument("--exclude", action="append", default=[],
                        help="a repository that is not a project of its own (a fork; "
                             "repeatable)")
    args = parser.parse_args(argv)
    have, authors = known(args.pairs)
    projects: list[tuple[str, list[Pair]]] = []
    for entry in sorted(args.repos.iterdir(), key=lambda p: p.name.lower()):
        if not entry.is_dir() or "+" not in entry.name:
            continue
        repo = entry.name.replace("+", "/", 1)
        if (repo in have or repo.split("/")[0].lower() in authors
                or repo in args.exclude):
            continue
        directory = git_dir(args.repos, entry.name)
        if directory is None:
            continue
        pairs = pairs_of(directory, repo)
        if pairs:
            projects.append((repo, pairs))
    splits = args.tsv.split(",") if args.tsv else []
    position = 0
    for repo, pairs in projects:
        if splits:
            pairs = [p for p in pairs if p.root == "URProgram" and p.markers]
            if not pairs:
                continue
            if repo in args.studied:
                split = splits[0]
            else:
                split = splits[position % len(splits)]
                position += 1
            for pair in pairs:
                print("\t".join((repo, pair.commit, pair.urp, pair.script,
                                 "none (referenced only)", split)))
            continue
        versions = sorted({p.version.rsplit(".", 1)[0] if p.version.count(".") > 2
                           else p.version for p in pairs})
        print(f"{repo}: {len(pairs)} pairs; versions {', '.join(versions)}")
        for pair in pairs:
            flags = [] if pair.root == "URProgram" else [f"root <{pair.root}>"]
            if not pair.markers:
                flags.append("no $ markers")
            print(f"  {pair.commit[:7]} {pair.urp}  {pair.version}"
                  + (f"  ({'; '.join(flags)})" if flags else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
