"""bench/realworld.py: the manifest and labels are consistent, extraction reads a pinned commit
from a git directory (no network), and scoring matches findings to labels."""

from __future__ import annotations

import json
import shutil
import subprocess

import pytest
from _bench import load_bench

rw = load_bench("realworld.py", "realworld_bench")


#: The first id of the blind batch: every project from it on is held back (README, "The split").
BLIND_FIRST = 37


def test_manifest_split_is_every_third_project_and_commits_are_pinned():
    projects = rw.read_manifest()
    assert len(projects) >= 21
    for project in projects:
        assert len(project.commit) == 40 and int(project.commit, 16) >= 0
        held = int(project.id) % 3 == 0 or int(project.id) >= BLIND_FIRST
        assert project.split == ("held" if held else "tune")
        assert project.generation in ("cb2", "cb3", "e-series", "unknown")
    assert 3 * sum(project.split == "held" for project in projects) >= len(projects)
    repos = [project.repo for project in projects]
    assert max(repos.count(repo) for repo in repos) <= 2


def test_every_label_names_a_project_a_tool_and_a_reason():
    ids = {project.id for project in rw.read_manifest()}
    labels = rw.read_labels()
    assert labels
    for label in labels.values():
        assert label.project in ids
        assert label.tool in ("lint", "check")
        assert label.verdict in ("true", "false")
        assert label.reason.strip()
        assert label.baseline in ("yes", "no")


@pytest.mark.skipif(shutil.which("git") is None, reason="needs git")
def test_extract_reads_the_pinned_commit_from_a_nested_git_dir(tmp_path):
    work = tmp_path / "src"
    (work / "progs" / "lib").mkdir(parents=True)
    (work / "progs" / "main.script").write_text("def main():\n  helper()\nend\n")
    (work / "progs" / "lib" / "helper.script").write_text("def helper():\n  sync()\nend\n")
    (work / "progs" / "notes.md").write_text("not a program file\n")

    def git(*args: str) -> str:
        return subprocess.run(["git", "-C", str(work), *args], check=True, capture_output=True,
                              text=True).stdout.strip()

    git("init", "-q")
    git("-c", "user.email=a@b", "-c", "user.name=a", "add", ".")
    git("-c", "user.email=a@b", "-c", "user.name=a", "commit", "-qm", "one")
    commit = git("rev-parse", "HEAD")
    (work / "progs" / "main.script").write_text("changed after the pinned commit\n")
    git("-c", "user.email=a@b", "-c", "user.name=a", "commit", "-qam", "two")
    repos = tmp_path / "repos"
    (repos / "someone+cell").mkdir(parents=True)
    shutil.move(str(work), str(repos / "someone+cell" / "repo"))  # nested clone

    project = rw.Project("7", "someone/cell", commit, "progs", ("*",), "none", "cb3", "none",
                         "tune", "")
    out = tmp_path / "out"
    assert rw.extract([project], repos, out) == 0
    assert (out / "7" / "main.script").read_text() == "def main():\n  helper()\nend\n"
    assert (out / "7" / "lib" / "helper.script").exists()
    assert not (out / "7" / "notes.md").exists()
    assert (out / "7" / ".git").is_dir()  # a checkout's top: urdsl's project search stops there

    missing = rw.Project("8", "someone/absent", commit, ".", ("*",), "none", "cb3", "none",
                         "tune", "")
    assert rw.extract([missing], repos, out) == 1


def test_precision_counts_labelled_true_and_false_and_leaves_the_rest_unlabelled():
    label_true = rw.Label("1", "lint", "a.script", 3, "URS101", "true", "real", "yes", "")
    label_false = rw.Label("1", "lint", "a.script", 4, "URS101", "false", "host", "yes", "")
    scored = [rw.Scored("1", "tune", "lint", "a.script", 3, "URS101", "", label_true),
              rw.Scored("1", "tune", "lint", "a.script", 4, "URS101", "", label_false),
              rw.Scored("1", "tune", "lint", "a.script", 5, "URS101", "", None)]
    table = "\n".join(rw.precision_table(scored, "t"))
    assert "URS101        3     1     1     1     50.0%" in table


def test_score_matches_saved_runs_against_the_labels_without_running(tmp_path, capsys):
    """``score`` reads what ``run --json`` saved and matches it against labels.tsv again."""
    finding = {"file": "pwm_control.script", "line": 24, "code": "URS101",
               "severity": "error", "message": "name 'aj' is not defined"}
    other = dict(finding, line=9999)  # no label: counted as unlabelled
    warning = dict(finding, line=25, severity="warning")  # not an error: not scored
    saved = tmp_path / "runs.json"
    saved.write_text(json.dumps({"runs": [
        {"project": "35", "tool": "lint", "target": ".", "seconds": 1.0, "status": "ok",
         "findings": [finding, other, warning]},
        {"project": "2", "tool": "lint", "target": ".", "seconds": 1.0, "status": "ok",
         "findings": [finding]}]}))
    assert rw.main(["score", str(saved), "--project", "35"]) == 0
    out = capsys.readouterr().out
    assert "  lint   URS101        2     1     0     1    100.0%" in out
    assert "unlabelled error findings: 1" in out
    assert "35\tlint\tpwm_control.script\t9999\tURS101" in out
