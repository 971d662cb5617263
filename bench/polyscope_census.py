"""Census of the variants PolyScope writes: every ``.urp`` and ``.installation`` in local git
mirrors of public repositories (every version in their history, each distinct file once).

For each program node type it counts the variants: the values of the attributes that choose
what a node does (``type``, ``motionType``, ``positionType``, ``valueSource``, ...), the
names of its other attributes and the tags of its child elements. For each installation it
counts how many TCPs and payloads it has, its feature kinds, tool I/O settings and the
PolyScope version. Nothing is downloaded: ``--repos DIR`` holds ``owner+name`` git
directories as ``fetch`` leaves them (``DIR/owner+name/repo`` or a bare ``DIR/owner+name``).
Repositories held back from the compile benchmark (split ``held`` in
``bench/polyscope/pairs.tsv``) are skipped.

Usage: ``python bench/polyscope_census.py --repos /work/.mirror [--kind Move] [--markdown]``
"""

from __future__ import annotations

import argparse
import collections
import gzip
import subprocess
import sys
import zlib
from pathlib import Path
from xml.etree import ElementTree

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from urdsl.polyscope.urp import Node, UrpError, parse_urp  # noqa: E402

CHOOSING = ("type", "motionType", "positionType", "valueSource", "useActiveTCP", "inputType",
            "action", "OrientationMode", "runOnlyOnce", "checkContinuously", "haltProgram",
            "valueType", "selectedDirection", "source")
"""Attributes whose value chooses what a node does (their values are counted)."""
SKIPPED_ATTRS = frozenset(("name", "reference", "class", "comment", "message", "count",
                           "speed", "acceleration", "blendRadius", "caseValue"))
"""Attributes counted by name only when present (their values are data)."""


def held_repos(pairs: Path) -> set[str]:
    """Repositories of the ``held`` split of the pairs file."""
    held = set()
    for line in pairs.read_text("utf-8").splitlines():
        cells = line.split("\t")
        if len(cells) >= 6 and not line.startswith("#") and cells[5].strip() == "held":
            held.add(cells[0])
    return held


def git_dir(repos: Path, repo: str) -> Path | None:
    base = repos / repo.replace("/", "+")
    for candidate in (base / "repo", base):
        if (candidate / "HEAD").exists() or (candidate / ".git").exists():
            return candidate
    return None


def files_in(git: Path) -> dict[str, str]:
    """Every distinct blob of a ``.urp`` or ``.installation`` in the history: blob → path."""
    blobs: dict[str, str] = {}
    commits = subprocess.run(["git", "-C", str(git), "rev-list", "--all"], capture_output=True,
                             text=True).stdout.split()
    for commit in commits:
        listing = subprocess.run(["git", "-C", str(git), "ls-tree", "-r", commit],
                                 capture_output=True, text=True).stdout
        for line in listing.splitlines():
            meta, _, path = line.partition("\t")
            parts = meta.split()
            if len(parts) == 3 and parts[1] == "blob" and \
                    path.lower().endswith((".urp", ".installation")):
                blobs.setdefault(parts[2], path)
    return blobs


def blob(git: Path, sha: str) -> bytes:
    return subprocess.run(["git", "-C", str(git), "cat-file", "blob", sha],
                          capture_output=True).stdout


def node_variant(node: Node) -> str:
    """A node's variant: its choosing attributes' values, other attribute names, child
    element tags (a Waypoint's ``position`` children too)."""
    choosing = [f"{key}={node.attrs[key]}" for key in CHOOSING if key in node.attrs]
    others = sorted(key for key in node.attrs if key not in CHOOSING and key != "class")
    tags: list[str] = []
    if node.element is not None:
        for child in node.element:
            if child.tag == "children":
                continue
            tag = child.tag
            if child.tag == "position":
                tag += "(" + ",".join(sorted({c.tag for c in child})) + ")"
            elif child.tag in ("tcp", "feature", "pin", "variable") and \
                    child.get("referencedName"):
                tag += "[ref]"
            if tag not in tags:
                tags.append(tag)
    out = ("(suppressed) " if node.suppressed else "") + " ".join(choosing)
    if others:
        out += " @" + ",".join(others)
    if tags:
        out += " <" + ",".join(sorted(tags)) + ">"
    return out.strip() or "-"


def installation_variant(data: bytes) -> dict[str, str] | None:
    """A few facts of an installation: version, TCP and payload counts, feature kinds,
    tool I/O settings (``None`` when it is not a readable installation)."""
    if data[:2] == b"\x1f\x8b":
        try:
            data = gzip.decompress(data)
        except (OSError, EOFError, zlib.error):
            return None
    try:
        root = ElementTree.fromstring(data)
    except ElementTree.ParseError:
        return None
    if root.tag != "Installation":
        return {"layout": root.tag}
    version = root.find("Version")
    facts = {"layout": "Installation",
             "version": f"{version.get('major')}.{version.get('minor')}"
             if version is not None else "?"}
    tcps = root.find("TCPSettings")
    facts["tcps"] = str(len(list(tcps.iter("tcp")))) if tcps is not None else "none"
    payloads = root.find("PayloadSettings")
    if payloads is not None:
        facts["payloads"] = str(len(list(payloads.iter("Payload"))))
    elif tcps is not None and tcps.get("toolPayload") is not None:
        facts["payloads"] = "toolPayload (3.x)"
    else:
        facts["payloads"] = "none"
    kinds: set[str] = set()
    block = root.find("Features")
    for wrapper in block if block is not None else ():
        for element in wrapper:
            if element.get("name") and element.get("hiddenSubFeature") != "true":
                variable = "variable" if element.get("isVariable") == "true" else "fixed"
                kinds.add(f"{element.tag.removeprefix('Geom').removesuffix('Node')} "
                          f"({variable})")
    facts["features"] = ", ".join(sorted(kinds)) or "none"
    if tcps is not None:
        urcap = sum(1 for tcp in tcps.iter("tcp") if tcp.find("ContributorInfo") is not None)
        facts["URCap TCPs"] = str(urcap)
    inertia = payloads is not None and any(p.get("inertiaParameters")
                                           for p in payloads.iter("Payload"))
    facts["payload inertia"] = "yes" if inertia else "no"
    comm = root.find(".//ToolCommSettings")
    facts["tool I/O"] = "ToolCommSettings" if comm is not None else (
        "toolOutputVoltage only" if root.find(".//*[@toolOutputVoltage]") is not None
        else "none")
    return facts


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repos", type=Path, required=True)
    parser.add_argument("--pairs", type=Path, default=ROOT / "bench/polyscope/pairs.tsv")
    parser.add_argument("--kind", help="only this node type, with an example file per variant")
    parser.add_argument("--markdown", action="store_true", help="print markdown tables")
    args = parser.parse_args(argv)
    held = held_repos(args.pairs)
    variants: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
    projects: dict[tuple[str, str], set[str]] = collections.defaultdict(set)
    example: dict[tuple[str, str], str] = {}
    inst: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
    counts = collections.Counter()
    seen_projects: set[str] = set()
    for directory in sorted(args.repos.iterdir()):
        if not directory.is_dir() or "+" not in directory.name:
            continue
        repo = directory.name.replace("+", "/", 1)
        git = git_dir(args.repos, repo)
        if repo in held or git is None:
            continue
        for sha, path in sorted(files_in(git).items(), key=lambda item: item[1]):
            data = blob(git, sha)
            seen_projects.add(repo)
            if path.lower().endswith(".installation"):
                facts = installation_variant(data)
                counts["installation" if facts else "installation unreadable"] += 1
                for key, value in (facts or {}).items():
                    inst[key][value] += 1
                continue
            try:
                program = parse_urp(data, path)
            except UrpError:
                counts["urp unreadable"] += 1
                continue
            counts["urp"] += 1
            version = (program.saved_in or program.created_in or "?").split(".")[:2]
            inst["program version"][".".join(version)] += 1
            for top in program.top:
                for node in top.walk():
                    variant = node_variant(node)
                    variants[node.kind][variant] += 1
                    projects[(node.kind, variant)].add(repo)
                    example.setdefault((node.kind, variant), f"{repo}:{path}")
    print(f"{counts['urp']} programs, {counts['installation']} installations "
          f"({counts['urp unreadable']} programs and {counts['installation unreadable']} "
          f"installations unreadable) in {len(seen_projects)} repositories")
    kinds = [args.kind] if args.kind else sorted(variants, key=lambda k: -sum(variants[k].values()))
    for kind in kinds:
        print(f"\n{'### ' if args.markdown else ''}{kind} ({sum(variants[kind].values())} nodes)")
        if args.markdown:
            print("\n| nodes | projects | variant |\n|---:|---:|---|")
        for variant, number in variants[kind].most_common():
            where = len(projects[(kind, variant)])
            if args.markdown:
                print(f"| {number} | {where} | `{variant}` |")
            else:
                line = f"  {number:5d} {where:3d}  {variant}"
                if args.kind:
                    line += f"   e.g. {example[(kind, variant)]}"
                print(line)
    if not args.kind:
        print(f"\n{'### ' if args.markdown else ''}Installations")
        for key, counter in inst.items():
            values = ", ".join(f"{value}: {n}" for value, n in counter.most_common())
            print(f"{'- ' if args.markdown else '  '}{key}: {values}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
