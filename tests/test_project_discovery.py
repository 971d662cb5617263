"""``urdsl.project``: which files make a project, which are hosts and fragments, which host
includes which fragment, and where the names a file uses are defined."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from urdsl.project import Project, ProjectError

DATA = Path(__file__).parent / "data" / "projects"


def names(files) -> list[str]:
    return sorted(Path(f.filename).name for f in files)


def test_a_folder_is_one_project_with_hosts_fragments_and_variables():
    project = Project.discover(DATA / "cell")
    assert names(project.files) == ["main.script", "pick.script", "robotiq.script",
                                    "spare.script"]
    assert [Path(v.filename).name for v in project.variables] == ["default.variables"]
    roles = {Path(f.filename).name: project.context(f.path).role for f in project.files}
    assert roles == {"main.script": "host", "pick.script": "fragment",
                     "robotiq.script": "fragment", "spare.script": "fragment"}


def test_a_host_includes_a_fragment_by_its_script_label_or_its_inlined_lines(tmp_path):
    project = Project.discover(DATA / "cell")
    for fragment in ("robotiq.script", "pick.script"):
        context = project.context(DATA / "cell" / fragment)
        assert names(context.hosts) == ["main.script"]
    assert project.context(DATA / "cell" / "spare.script").hosts == []
    # without the labels, the inlined lines still say it
    shutil.copytree(DATA / "cell", tmp_path / "cell")
    main = tmp_path / "cell" / "main.script"
    main.write_text("\n".join(line for line in main.read_text().splitlines()
                              if "Script:" not in line) + "\n")
    project = Project.discover(tmp_path / "cell")
    assert names(project.context(tmp_path / "cell" / "pick.script").hosts) == ["main.script"]


def test_a_subprogram_file_is_included_by_the_program_that_contains_its_def():
    project = Project.discover(DATA / "subprogram")
    context = project.context(DATA / "subprogram" / "SubProgram_1.script")
    assert context.role == "fragment"
    assert names(context.hosts) == ["main.script"]
    found = context.resolve_read("home_q")
    assert found is not None and found.severity is None
    assert (Path(found.definition.filename).name, found.definition.line) == ("main.script", 3)


def test_a_file_sees_its_folder_but_not_subfolders():
    project = Project.discover(DATA / "configured" / "prog" / "cycle.script", use_config=False)
    assert names(project.files) == ["cycle.script"]


def test_definitions_elsewhere_say_where_and_how_bad_a_use_of_them_is():
    project = Project.discover(DATA / "cell")
    pick = project.context(DATA / "cell" / "pick.script")
    opened = pick.resolve_call("rq_open")
    assert opened.severity is None  # its host defines it
    assert "main.script:" in opened.message
    count = pick.resolve_read("part_count")
    assert count.severity is None and count.definition.kind == "installation variable"
    assert pick.resolve_read("no_such_name") is None
    spare = project.context(DATA / "cell" / "spare.script")
    assert spare.resolve_read("home_q").severity == "warning"
    mixed = Project.discover(DATA / "mixed")
    assert mixed.context(DATA / "mixed" / "frag.script").resolve_call("wave").severity == "info"
    host = mixed.context(DATA / "mixed" / "host.script").resolve_call("wave")
    assert host.severity == "error"
    assert host.message == ("'wave' is not defined in this program (helpers.script:1 defines "
                            "it, but this program does not include it)")


def test_include_adds_files_and_their_names_are_defined(tmp_path):
    target = DATA / "included" / "prog" / "run.script"
    alone = Project.discover(target, use_config=False).context(target)
    assert alone.resolve_call("clamp") is None
    library = DATA / "included" / "lib" / "math.script"
    project = Project.discover(target, [library], use_config=False)
    found = project.context(target).resolve_call("clamp")
    assert found.severity is None and found.definition.line == 1


def test_configured_include_is_relative_to_the_pyproject(tmp_path, monkeypatch):
    target = DATA / "configured" / "prog" / "cycle.script"
    monkeypatch.chdir(tmp_path)  # the working folder does not matter
    context = Project.discover(target).context(target)
    found = context.resolve_call("settle")
    assert found.severity is None
    assert Path(found.definition.filename).name == "tools.script"


def test_a_bad_configured_include_is_a_clear_error(tmp_path):
    (tmp_path / "pyproject.toml").write_text('[tool.urdsl]\ninclude = ["nowhere.script"]\n')
    (tmp_path / "a.script").write_text("textmsg(1)\n")
    with pytest.raises(ProjectError, match="nowhere.script"):
        Project.discover(tmp_path / "a.script")
    (tmp_path / "pyproject.toml").write_text("[tool.urdsl]\ninclude = 3\n")
    with pytest.raises(ProjectError, match="list of paths"):
        Project.discover(tmp_path / "a.script")


def test_an_editor_buffer_replaces_the_file_on_disk():
    project = Project.discover(DATA / "cell")
    context = project.context(DATA / "cell" / "spare.script",
                              "def spare_wiggle():\n  rq_open()\nend\n", "spare.script")
    assert context.resolve_call("rq_open").severity == "warning"


def test_two_copies_of_a_program_are_two_hosts(tmp_path):
    program = (DATA / "subprogram" / "main.script").read_text()
    (tmp_path / "cell_v1.script").write_text(program)
    (tmp_path / "cell_v2.script").write_text(program.replace('textmsg("at home")',
                                                             'textmsg("home")'))
    project = Project.discover(tmp_path, use_config=False)
    for name in ("cell_v1.script", "cell_v2.script"):
        context = project.context(tmp_path / name)
        assert (context.role, context.hosts) == ("host", [])


def test_a_file_in_a_subfolder_finds_the_program_above_that_includes_it(capsys):
    target = DATA / "nested" / "scripts" / "start_seam.script"
    project = Project.discover(target, use_config=False)
    assert project.root.resolve() == (DATA / "nested").resolve()
    context = project.context(target)
    assert names(context.hosts) == ["weld.script"]
    assert context.resolve_read("seam_speed").severity is None
    # a file no program above includes keeps its own folder
    lonely = DATA / "configured" / "lib" / "tools.script"
    assert Project.discover(lonely, use_config=False).root == lonely.parent


def test_the_search_above_parses_only_files_that_may_include_the_fragment(tmp_path,
                                                                          monkeypatch):
    # searching the folders above a fragment (for /tmp/x.script: /tmp) meets unrelated
    # scripts; only one that names the fragment or holds its lines is parsed
    from urdsl.project import model

    (tmp_path / "cell" / "scripts").mkdir(parents=True)
    fragment = tmp_path / "cell" / "scripts" / "seam.script"
    fragment.write_text("seam_speed = 0.01\nmovel(seam_end, v=seam_speed)\n")
    (tmp_path / "cell" / "weld.script").write_text(
        'def weld():\n  $ 1 "Script: seam.script"\n  seam_end = p[0.4, 0, 0.2, 0, 3.14, 0]\n'
        "  seam_speed = 0.01\n  movel(seam_end, v=seam_speed)\nend\n")
    (tmp_path / "cell" / "other.script").write_text(
        "def other():\n" + "  x = 1\n" * 2000 + "end\n")
    parsed: list[str] = []
    real = model.script_file
    monkeypatch.setattr(model, "script_file",
                        lambda path, *a: parsed.append(path.name) or real(path, *a))
    model._CACHE.clear()
    project = Project.discover(fragment, use_config=False)
    assert names(project.context(fragment).hosts) == ["weld.script"]
    assert "weld.script" in parsed and "other.script" not in parsed[:parsed.index("weld.script")]
