"""The files of one PolyScope project and the names each file can see.

A project is a folder tree (for one file, the file's folder, or the folder up to three
levels above whose program includes the file; for a fragment that no program includes, also
the script files of its repository when the repository's top, a folder holding ``.git``, is
at most three levels above) holding:

* script files (``*.script``, ``*.urscript``, ``*.urs``). A **host** is a complete program as
  PolyScope exports it: one top-level ``def`` without parameters wrapping the program,
  followed by a call of it or holding PolyScope's ``$`` labels. Everything else is a
  **fragment**: bare statements or definitions meant to be inlined into a program
  (PolyScope's "Script: file" node pastes the file's text at that place; a subprogram's
  ``def`` is pasted into its callers);
* installation variables (``*.variables``, see :mod:`urdsl.polyscope.variables`), globals of
  every program run with the installation;
* extra files named with ``--include`` or ``[tool.urdsl] include = [...]`` in the nearest
  ``pyproject.toml`` (paths relative to that file, glob patterns allowed).

A host **includes** a fragment when one of its ``$ N "Script: name.script"`` labels names the
fragment's file, or when the fragment's code lines are found inlined in the host (at least
80 % of them, or half of them for a subprogram whose ``def`` the host contains), or when the
host's PolyScope program (its ``.urp``) calls the fragment's ``.urp`` as a subprogram.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import re
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..polyscope.variables import VariablesFile, parse_variables, read_variables
from ..script import nodes as n
from ..script.diagnostics import Diagnostic, ScriptError
from ..script.parser import parse

__all__ = [
    "SCRIPT_SUFFIXES", "Definition", "ScriptFile", "Project", "FileContext", "Resolution",
    "ProjectError", "configured_includes",
]

SCRIPT_SUFFIXES = (".script", ".urscript", ".urs")
VARIABLES_SUFFIX = ".variables"
INSTALLATION_SUFFIX = ".installation"
"""A PolyScope installation: its point and plane features are globals of every program run
with it (see :func:`installation_features`)."""
URP_SUFFIX = ".urp"
"""A PolyScope program: a host of the script files its Script nodes name, read as the
URScript :mod:`urdsl.polyscope` compiles it to (see :func:`load_urp`)."""
MAX_FILE_BYTES = 5_000_000
"""Larger files are not read as part of a project (they are not hand-written programs)."""

MAX_TREE_FILES = 2000
"""A project found above a file takes at most this many files of that folder's tree."""
HOST_LEVELS = 3
"""How many folders above a file urdsl looks for the program that includes it."""

_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_INLINE_SHARE = 0.8
_SUBPROGRAM_SHARE = 0.5


class ProjectError(ValueError):
    """A project setting urdsl cannot use (a bad ``[tool.urdsl] include``)."""


@dataclass(frozen=True)
class Definition:
    """A name defined in a file of the project. ``kind`` is ``"function"``, ``"thread"``,
    ``"global"`` or ``"installation variable"``; ``node`` the defining statement (a
    ``def``/``thread``, or the first assignment or declaration)."""

    name: str
    kind: str
    filename: str
    span: n.Span
    node: n.Stmt

    @property
    def line(self) -> int:
        return self.span.line

    @property
    def where(self) -> str:
        """``file:line`` as a user would open it."""
        return f"{self.filename}:{self.line}"


@dataclass(eq=False)
class ScriptFile:
    """One script file of the project, parsed. ``program`` is the name of the wrapping
    ``def`` when the file is a host, else None; ``labels`` the file names (without folders)
    of its ``Script:`` labels; ``module`` None when the file does not parse."""

    path: Path
    filename: str
    text: str
    module: n.Module | None
    program: str | None = None
    labels: tuple[str, ...] = ()
    definitions: dict[str, list[Definition]] = field(default_factory=dict)
    top_level: dict[str, n.Stmt] = field(default_factory=dict)
    assigned_later: dict[str, n.Stmt] = field(default_factory=dict)
    code_lines: frozenset[str] = frozenset()
    code_line_list: tuple[str, ...] = ()
    subprogram_files: frozenset[str] = frozenset()
    """File names (lower case, without folders) of the PolyScope subprograms the program
    calls, from its ``.urp`` (for an exported ``.script``, the ``.urp`` of its name beside
    it): a subprogram saved as a program of its own is included by its caller, even where
    the caller's exported ``.script`` is older than its ``.urp``."""

    @property
    def is_host(self) -> bool:
        return self.program is not None


@dataclass(frozen=True)
class Resolution:
    """What to say about a name a file uses but does not define: ``severity`` None means no
    finding (it is defined where the program gets it); otherwise the severity and a message
    naming where the name is defined."""

    definition: Definition
    severity: str | None
    message: str
    hint: str | None = None


_READ_KINDS = frozenset(("global", "installation variable"))


def from_missing_program(name: str, command: str) -> str:
    """The hint for ``name``, defined nowhere in the project, read by a hostless fragment
    (:attr:`FileContext.hostless`): the PolyScope program that runs the file is the usual
    source of such names, and ``urdsl COMMAND`` with it settles the question (the error
    stands: run as it is, the controller rejects the name)."""
    return (f"if this file runs inside a PolyScope program (a Script node) and `{name}` is "
            "a waypoint, feature or variable of that program or its installation, "
            f"{command} it with them (--include PROGRAM.urp, its .installation or .variables)")


@dataclass
class FileContext:
    """One file seen from its project: its role, its hosts and every definition elsewhere."""

    project: Project
    file: ScriptFile
    hosts: list[ScriptFile]
    included: list[ScriptFile]  # fragments this file includes (when it is a host)

    @property
    def role(self) -> str:
        """``"fragment"`` (included by a host, or no program of its own) or ``"host"``."""
        return "host" if self.file.is_host and not self.hosts else "fragment"

    @property
    def hostless(self) -> bool:
        """A fragment that no program of the project includes (a Script-node file whose
        PolyScope program is not in the project)."""
        return self.role == "fragment" and not self.hosts

    @property
    def host_names(self) -> list[str]:
        return [host.filename for host in self.hosts]

    def near(self, filename: str) -> str:
        """``filename`` as seen from this file's folder (``robotiq.script``,
        ``../lib/math.script``)."""
        try:
            return os.path.relpath(filename, os.path.dirname(self.file.filename) or ".")
        except ValueError:
            return filename

    def resolve_read(self, name: str) -> Resolution | None:
        """A variable read here that this file does not define (None: defined nowhere)."""
        return self._resolve(name, _READ_KINDS)

    def resolve_call(self, name: str) -> Resolution | None:
        """A function called here that neither this file nor the builtins define."""
        return self._resolve(name, frozenset(("function",)))

    def resolve_thread(self, name: str) -> Resolution | None:
        """A thread started (``run``) here that this file does not define."""
        return self._resolve(name, frozenset(("thread",)))

    def definitions(self, name: str, kinds: frozenset[str]) -> list[tuple[str, Definition]]:
        """Where ``name`` is defined outside this file, best first, each with the relation
        of its file to this one: ``"variables"``, ``"host"``, ``"included"`` (a file this
        program includes), ``"explicit"`` (named with --include or in the configuration),
        ``"other"``."""
        found: list[tuple[str, Definition]] = []
        if "installation variable" in kinds:
            for variables in self.project.variables:
                variable = variables.names().get(name)
                if variable is not None:
                    found.append(("variables", Definition(
                        name, "installation variable", variables.filename, variable.span,
                        variable.statement)))
        hosts = {id(s): rank for rank, s in enumerate(self.hosts)}  # best host first
        included = {id(s) for s in self.included}
        order = {"host": 0, "included": 1, "explicit": 2, "other": 3}
        ranked = []
        for index, (script, definition) in enumerate(self.project.defined(name)):
            if script is self.file or definition.kind not in kinds:
                continue
            relation = ("host" if id(script) in hosts else "included" if id(script) in included
                        else "explicit" if self.project.is_explicit(script) else "other")
            ranked.append((order[relation], hosts.get(id(script), 0), index, relation,
                           definition))
        found.extend((relation, definition)
                     for _o, _h, _i, relation, definition in sorted(ranked, key=lambda r: r[:3]))
        return found

    def _resolve(self, name: str, kinds: frozenset[str]) -> Resolution | None:
        found = self.definitions(name, kinds)
        if not found:
            return None
        relation, definition = found[0]
        if relation in ("variables", "host", "included", "explicit"):
            return Resolution(definition, None, f"'{name}' is defined in {definition.where}")
        other = self.near(definition.filename)
        where = f"{other}:{definition.line}"
        if self.hosts:
            hosts = join_names([self.near(h) for h in self.host_names])
            return Resolution(
                definition, "info",
                f"'{name}' is defined in {where}, which {hosts} does not include",
                f"{hosts} includes this file; if it should run {other} too, "
                "add it to the program (a Script node in PolyScope)")
        if self.role == "host":
            return Resolution(
                definition, "error",
                f"'{name}' is not defined in this program ({where} defines it, but this "
                "program does not include it)",
                f"add {other} to the program (a Script node in PolyScope)")
        return Resolution(
            definition, "warning",
            f"'{name}' is defined in {where}; this file looks like a fragment that a program "
            "includes, but no program of the project includes it",
            "lint the program that includes this file with it, or name that program with "
            "--include (or [tool.urdsl] include in pyproject.toml)")


def join_names(names: list[str], most: int | None = None) -> str:
    """``a``, ``a and b``, ``a, b and c``; with ``most``, beyond it ``a, b and 2 more``."""
    if most is not None and len(names) > most:
        names = [*names[:most - 1], f"{len(names) - most + 1} more"]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


@dataclass(eq=False)
class Project:
    """The script files and installation variables of one project."""

    root: Path
    files: list[ScriptFile]
    variables: list[VariablesFile]
    explicit: frozenset[str] = frozenset()
    """Resolved paths of the files named with ``include`` or in the configuration."""
    _hosts: dict[int, list[ScriptFile]] | None = field(default=None, repr=False)
    _by_path: dict[str, ScriptFile] | None = field(default=None, repr=False)
    _explicit_ids: dict[int, bool] = field(default_factory=dict, repr=False)
    _by_name: dict[str, list[tuple[ScriptFile, Definition]]] | None = field(
        default=None, repr=False)

    # -- discovery ---------------------------------------------------------------------------

    @classmethod
    def discover(cls, path: str | Path, include: tuple[str | Path, ...] | list = (),
                 use_config: bool = True) -> Project:
        """The project of ``path``: a folder's whole tree; for a file, its folder's tree (as
        ``urdsl lint`` of that folder sees it; only the folder itself when its tree holds
        more than :data:`MAX_TREE_FILES` project files), or, when a program in a folder up to
        three levels above includes the file (PolyScope keeps script files in subfolders of
        the programs folder), that folder's tree. With the ``include`` files and the
        configured includes. Files that cannot be read are left out; a bad configuration
        raises :class:`ProjectError`."""
        path = Path(path)
        if path.is_dir():
            root = path
            found = _tree(path)
            scripts_here = [p for p in found if p.suffix in SCRIPT_SUFFIXES]
            if len(scripts_here) <= MAX_TREE_FILES:
                above = _folder_above(path, scripts_here, scripts_here)
                if above is not None:  # a subfolder of a project: add the program above
                    keys = {_key(p) for p in found}
                    found += [p for p in _listing(above) if _key(p) not in keys]
        else:
            root = path.parent if str(path.parent) else Path(".")
            # the folder's tree, or the folder alone when the tree is too large for a
            # project (a home or temporary folder)
            found = _bounded_tree(root, MAX_TREE_FILES) or _listing(root)
            if path.is_file() and _key(path) not in {_key(p) for p in found}:
                found.append(path)
            above = _host_folder(path, found)
            if above is None and path.suffix in SCRIPT_SUFFIXES:
                # no program includes the file, but one further up includes its neighbours
                # (PolyScope's script-file subfolders): add that program, as `urdsl lint` of
                # the folder does
                here = [p for p in found if p.parent == path.parent
                        and p.suffix in SCRIPT_SUFFIXES]
                beside = _folder_above(path.parent, here, here) if len(here) > 1 else None
                if beside is not None:
                    keys = {_key(p) for p in found}
                    found += [p for p in _listing(beside) if _key(p) not in keys]
                else:
                    found += _neighbours(path, root, {_key(p) for p in found})
            if above is not None:  # the program that includes the file is further up
                root = above
                tree = _bounded_tree(above, MAX_TREE_FILES)
                if tree is not None:
                    found = tree
                else:
                    keys = {_key(p) for p in found}
                    found += [p for p in _listing(above) if _key(p) not in keys]
        known = {_key(p) for p in found}
        extra = [Path(p) for p in include]
        if use_config:
            extra += configured_includes(root)
        explicit: set[str] = set()
        for item in extra:
            candidates = _tree(item) if item.is_dir() else [item]
            for candidate in candidates:
                if not candidate.is_file():
                    continue
                key = _key(candidate)
                explicit.add(key)
                if key not in known:
                    known.add(key)
                    found.append(candidate)
        scripts = [load_script(p) for p in found if p.suffix in SCRIPT_SUFFIXES]
        exported = {_key(p.with_suffix("")) for p in found if p.suffix in SCRIPT_SUFFIXES}
        scripts += [load_urp(p) for p in found if p.suffix == URP_SUFFIX
                    and _key(p.with_suffix("")) not in exported]  # else its .script is it
        variables = [read_variables(p) for p in found if p.suffix == VARIABLES_SUFFIX]
        variables += [features for p in found if p.suffix == INSTALLATION_SUFFIX
                      and (features := installation_features(p)) is not None]
        return cls(root, [s for s in scripts if s is not None], variables, frozenset(explicit))

    # -- questions ---------------------------------------------------------------------------

    def is_explicit(self, script: ScriptFile) -> bool:
        """Whether ``script`` was named with ``include`` or in the configuration."""
        if not self.explicit:
            return False
        if id(script) not in self._explicit_ids:
            self._explicit_ids[id(script)] = _key(script.path) in self.explicit
        return self._explicit_ids[id(script)]

    def find(self, path: str | Path) -> ScriptFile | None:
        """The project's script file at ``path``, if it is one."""
        if self._by_path is None:
            self._by_path = {_key(script.path): script for script in self.files}
        return self._by_path.get(_key(Path(path)))

    def defined(self, name: str) -> list[tuple[ScriptFile, Definition]]:
        """Every definition of ``name`` in the project's script files, in file order."""
        if self._by_name is None:
            self._by_name = {}
            for script in self.files:
                for key, found in script.definitions.items():
                    self._by_name.setdefault(key, []).extend((script, d) for d in found)
        return self._by_name.get(name, [])

    def hosts_of(self, script: ScriptFile) -> list[ScriptFile]:
        """The hosts that include ``script`` (by ``Script:`` label or inlined code), those
        holding more of its code in order first (of several saved versions of a program, the
        one that inlined this version of the file; its definitions are looked up first)."""
        if self._hosts is None:
            self._hosts = {}
            hosts = [s for s in self.files if s.is_host and s.module is not None]
            for fragment in self.files:
                self._hosts[id(fragment)] = _best_first(
                    [h for h in hosts if h is not fragment and _includes(h, fragment)],
                    fragment)
        if id(script) not in self._hosts:
            hosts = [s for s in self.files if s.is_host and s.module is not None]
            return _best_first([h for h in hosts if h is not script and _includes(h, script)],
                               script)
        return self._hosts[id(script)]

    def context(self, path: str | Path, text: str | None = None,
                filename: str | None = None) -> FileContext:
        """``path`` seen from the project. ``text`` replaces the file's text on disk (an
        editor's unsaved buffer); a file outside the project is added to it."""
        script = self.find(path)
        if text is not None or script is None:
            if text is None:
                loaded = load_script(Path(path))
                text = loaded.text if loaded is not None else ""
            name = filename or (script.filename if script is not None else str(path))
            replacement = script_file(Path(path), name, text)
            if script is not None:
                self.files = [replacement if s is script else s for s in self.files]
            else:
                self.files = [*self.files, replacement]
            self._hosts = self._by_path = self._by_name = None
            script = replacement
        hosts = self.hosts_of(script)
        included = [s for s in self.files if s is not script and script.is_host
                    and script in self.hosts_of(s)]
        return FileContext(self, script, hosts, included)

    def diagnostics(self, near: str | Path | None = None) -> list[Diagnostic]:
        """Problems in the installation variables files (bad lines); with ``near`` (a file
        linted on its own), only those of the files in its folder or a folder above it: the
        installations of other programs of the tree are not its business."""
        chosen = self.variables
        if near is not None:
            folders = {Path(near).resolve().parent, *Path(near).resolve().parents}
            chosen = [v for v in chosen if Path(v.filename).resolve().parent in folders]
        return [d for variables in chosen for d in variables.diagnostics]


# ---- files -----------------------------------------------------------------------------------

def _wanted(path: Path) -> bool:
    return path.is_file() and (path.suffix in SCRIPT_SUFFIXES or path.suffix in (
        VARIABLES_SUFFIX, URP_SUFFIX, INSTALLATION_SUFFIX))


def installation_features(path: Path) -> VariablesFile | None:
    """The features of the installation at ``path`` that programs see as variables (point
    and plane features: ``pose_trans(Plane_1, p)``), as installation variables
    ``Plane_1=p[...]`` of a file named ``PATH (features)``; None when it has none or cannot be
    read (a ``.urp`` that names it says so). PolyScope writes them into the preamble of every
    program run with that installation, so a script file a program includes may use them.
    Cached as :func:`load_script`."""
    return _cached(path, "features", _features_file)


def _features_file(path: Path) -> VariablesFile | None:
    """:func:`installation_features`, not cached."""
    from ..polyscope.compile import ascii_name
    from ..polyscope.installation import InstallationError, read_installation

    try:
        installation = read_installation(path)
    except (InstallationError, OSError):
        return None

    # named as PolyScope writes them in a script ("点_1" is u28857_1); a name or pose that
    # still is no URScript (a damaged file) is left out, never reported as the user's line
    lines = [f"{ascii_name(name)}=p[{', '.join(repr(float(v)) for v in pose)}]\n"
             for name, pose in installation.features
             if _IDENTIFIER.fullmatch(ascii_name(name)) and all(map(math.isfinite, pose))]
    if not lines:
        return None
    features = parse_variables("".join(lines), f"{path} (features)")
    features.diagnostics = []
    return features


MAX_TREE_VISITS = 50_000
"""Entries a bounded tree search looks at before it stops (a home folder is no project)."""


def _tree(folder: Path) -> list[Path]:
    """The project files in ``folder``'s tree (hidden folders left out)."""
    return _bounded_tree(folder, None) or []


def _bounded_tree(folder: Path, limit: int | None) -> list[Path] | None:
    """:func:`_tree`, or None when it holds more than ``limit`` project files or the search
    meets more than :data:`MAX_TREE_VISITS` entries first (a home or temporary folder)."""
    if not folder.is_dir():
        return []
    found: list[Path] = []
    visited = 0
    with contextlib.suppress(OSError):
        for p in folder.rglob("*"):
            visited += 1
            if limit is not None and visited > MAX_TREE_VISITS:
                return None
            if _wanted(p) and not any(part.startswith(".")
                                      for part in p.parts[len(folder.parts):]):
                found.append(p)
                if limit is not None and len(found) > limit:
                    return None
    return sorted(found)


def _neighbours(path: Path, root: Path, known: set[str]) -> list[Path]:
    """For a fragment (a script file without a program of its own) that no program
    includes, inside a repository whose top (a folder holding ``.git``) is at most
    :data:`HOST_LEVELS` folders above its own: the project files of that repository, as
    ``urdsl lint`` of it sees them (a generator's pieces kept in one folder, the programs
    whose definitions they use in another, the installation variables in a folder of
    their own: names found there are not "defined nowhere"): its script files and
    ``.variables``, as `urdsl lint` of the repository reads them. Nothing for a program,
    outside a repository (a download or temporary folder holds unrelated files), or when the
    repository is too large for a project."""
    script = load_script(path)
    if script is None or script.module is None or script.is_host:
        return []
    try:
        folder = root.resolve()
    except OSError:
        return []
    for _level in range(HOST_LEVELS):
        if (folder / ".git").exists() or folder.parent == folder:
            return []  # the file's folder is the repository's top, or there is none
        folder = folder.parent
        if (folder / ".git").exists():
            tree = _bounded_tree(folder, MAX_TREE_FILES)
            return [p for p in tree or () if (p.suffix in SCRIPT_SUFFIXES or p.suffix in (
                VARIABLES_SUFFIX, INSTALLATION_SUFFIX)) and _key(p) not in known]
    return []


def _listing(folder: Path) -> list[Path]:
    """The project files directly in ``folder``."""
    try:
        return [p for p in sorted(folder.iterdir()) if _wanted(p)]
    except OSError:  # no such folder, or not allowed to list it
        return []


def _host_folder(path: Path, beside: list[Path]) -> Path | None:
    """The folder, up to :data:`HOST_LEVELS` above ``path``'s, whose programs include the
    script file ``path`` — None when a program beside it does, or none does. The search
    does not leave the repository (a folder holding ``.git``)."""
    if path.suffix not in SCRIPT_SUFFIXES:
        return None
    return _folder_above(path.parent, [path], beside)


def _folder_above(start: Path, paths: list[Path], beside: list[Path]) -> Path | None:
    """The folder up to :data:`HOST_LEVELS` above ``start`` whose programs include one of
    the script files ``paths`` — None when a program among ``beside`` does, or none does."""
    fragments = [f for f in (load_script(p) for p in paths if p.suffix in SCRIPT_SUFFIXES)
                 if f is not None and f.module is not None and not f.is_host]
    if not fragments:
        return None
    own = {_key(p) for p in paths}

    def includes(candidates: list[Path], skip: set[str]) -> bool:
        for candidate in candidates:
            if candidate.suffix not in SCRIPT_SUFFIXES or _key(candidate) in skip:
                continue
            if not any(_may_include(candidate, fragment) for fragment in fragments):
                continue  # cannot include any of them: not parsed
            host = load_script(candidate)
            if host is not None and host.is_host and any(
                    _includes(host, fragment) for fragment in fragments):
                return True
        return False

    if includes(beside, own if len(paths) == 1 else set()):
        return None
    try:
        folder = start.resolve()
    except OSError:
        return None
    for _level in range(HOST_LEVELS):
        if (folder / ".git").exists() or folder.parent == folder:
            return None
        folder = folder.parent
        if includes(_listing(folder), own):
            return Path(_display(folder))
    return None


def _display(path: Path) -> str:
    """``path`` as a user would type it: relative to the working folder when inside it."""
    if path.is_absolute():
        try:
            return str(path.relative_to(Path.cwd()))
        except ValueError:
            return str(path)
    return str(path)


def _key(path: Path) -> str:
    try:
        return str(path.resolve())
    except OSError:
        return str(path)


_CACHE: dict[tuple, Any] = {}
"""What :func:`_cached` read, by :func:`_cache_key` (at most 512 entries, then it starts
again)."""


def _cache_key(path: Path, kind: str) -> tuple | None:
    """What a file read as ``kind`` is cached by: its path, size and modification time (and,
    for an absolute path, the working folder its shown name is relative to); None when it
    cannot be read or is larger than :data:`MAX_FILE_BYTES`."""
    try:
        stat = path.stat()
    except OSError:
        return None
    if stat.st_size > MAX_FILE_BYTES:
        return None
    program: tuple = ()
    if kind == "script":  # a PolyScope export is read with its program (subprogram_files)
        with contextlib.suppress(OSError):
            beside = path.with_suffix(URP_SUFFIX).stat()
            program = (beside.st_size, beside.st_mtime_ns)
    return (kind, str(path.resolve()), str(path), stat.st_size, stat.st_mtime_ns, program,
            os.getcwd() if path.is_absolute() else "")  # the name shown depends on it


def _cached(path: Path, kind: str, read: Callable[[Path], Any]) -> Any:
    """``read(path)``, cached by :func:`_cache_key` (None when the file cannot be read or is
    too large, without calling ``read``)."""
    key = _cache_key(path, kind)
    if key is None:
        return None
    if key in _CACHE:
        return _CACHE[key]
    value = read(path)
    if len(_CACHE) > 512:
        _CACHE.clear()
    _CACHE[key] = value
    return value


def load_script(path: Path) -> ScriptFile | None:
    """The parsed script file at ``path`` (None when it cannot be read or is too large).
    Parsed files are cached by path, size and modification time (and, for an absolute path,
    the working folder its shown name is relative to)."""
    return _cached(path, "script", _read_script)


def _read_script(path: Path) -> ScriptFile | None:
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    script = script_file(path, _display(path), text)
    program = path.with_suffix(URP_SUFFIX)
    if script.is_host and program.is_file():  # PolyScope's export beside its program
        from ..polyscope.urp import UrpError, read_urp

        try:
            files = read_urp(program).subprogram_files()
        except (UrpError, RecursionError):
            files = frozenset()
        if files:
            script = dataclasses.replace(script, subprogram_files=files)
    return script


def load_urp(path: Path) -> ScriptFile | None:
    """The PolyScope program at ``path`` as the URScript it compiles to (with the script
    files its Script nodes name, its installation and variables, as ``urdsl compile``
    writes it), as a host of those files; None when it cannot be read or compiled (that is
    said by ``urdsl lint``/``check`` of the ``.urp`` itself). Cached as :func:`load_script`."""
    return _cached(path, "urp", _read_urp)


def _read_urp(path: Path) -> ScriptFile | None:
    from ..polyscope.command import load
    from ..polyscope.compile import CompileError
    from ..polyscope.urp import UrpError

    try:
        # a missing installation is said by a lint or check of the .urp itself, not here
        program, compiled = load(path, warn=lambda _message: None)
    except (UrpError, CompileError, OSError, RecursionError):
        return None  # an unreadable program is not a host here; its own lint says why
    return dataclasses.replace(script_file(path, _display(path), compiled.text),
                               subprogram_files=program.subprogram_files())


def script_file(path: Path, filename: str, text: str) -> ScriptFile:
    """Parse ``text`` as the script file ``path`` (shown as ``filename``)."""
    lines = tuple(_code_lines(text))
    try:
        module = parse(text, filename)
    except (ScriptError, RecursionError):
        return ScriptFile(path, filename, text, None, code_lines=frozenset(lines),
                          code_line_list=lines)
    program = program_name(module, text)
    labels = tuple(_labels(text))
    definitions, top_level, late = _definitions(module, filename, program)
    return ScriptFile(path, filename, text, module, program, labels, definitions, top_level,
                      late,
                      frozenset(lines), lines)


def program_name(module: n.Module, text: str | None = None) -> str | None:
    """The name of the wrapping ``def`` when ``module`` is a complete program: one
    ``def`` without parameters followed by a call of it, or alone with PolyScope's ``$``
    labels in it (as PolyScope exports a program). A lone ``def`` without labels is taken
    for a fragment (a helper function meant to be included)."""
    statements = [item for item in module.body if isinstance(item, n.Stmt)]
    if not statements or not isinstance(statements[0], n.FunctionDef):
        return None
    program = statements[0]
    if program.params:
        return None
    rest = statements[1:]
    if not rest:  # PolyScope writes the def alone, with its $ labels
        if text is not None:
            return program.name if _MARKER_LINE.search(text) else None
        return program.name if any(isinstance(x, n.Marker) for x in n.walk(program)) else None
    if len(rest) == 1 and isinstance(rest[0], n.ExprStmt):
        call = rest[0].expr
        if (isinstance(call, n.Call) and isinstance(call.func, n.Name)
                and call.func.id == program.name and not call.args):
            return program.name
    return None


_MARKER_LINE = re.compile(r"^[ \t]*\$[ \t]*\d", re.MULTILINE)
_SCRIPT_LABEL = re.compile(
    r'^[ \t]*\$[ \t]*\d+[ \t]*"?[ \t]*Script:[ \t]*([^"\r\n]+?)[ \t]*"?[ \t]*'
    r'(?:"[^"\r\n]*"[ \t]*)?\r?$', re.MULTILINE | re.IGNORECASE)


def _labels(text: str) -> list[str]:
    """The file names (without folders) of the ``$ N "Script: name.script"`` labels in
    ``text``."""
    return [re.split(r"[\\/]", match.group(1))[-1] for match in _SCRIPT_LABEL.finditer(text)]


def _definitions(module: n.Module, filename: str, program: str | None
                 ) -> tuple[dict[str, list[Definition]], dict[str, n.Stmt], dict[str, n.Stmt]]:
    """The names ``module`` defines for other files, the first-level assignment of each
    global, and the first assignment anywhere of each global (``global x = v`` in a loop or
    a function)."""
    from ..lint.scope import analyse, statements  # the controller's scoping rules

    late: dict[str, n.Stmt] = {}
    try:
        analysis = analyse(module)
    except RecursionError:
        return {}, {}, late
    found: dict[str, list[Definition]] = {}

    def add(name: str, kind: str, node: n.Stmt, span: n.Span) -> None:
        found.setdefault(name, []).append(Definition(name, kind, filename, span, node))

    for table, kind in ((analysis.functions, "function"), (analysis.threads, "thread")):
        for name, nodes in table.items():
            if name == program and kind == "function":
                continue  # the program itself is not callable from the program
            for node in nodes:
                add(name, kind, node, node.span)
    for name in sorted(analysis.globals):
        node = None
        writes = analysis.top.assigned.get(name)
        if writes:
            node = writes[0]
        else:
            for scope in analysis.scopes:
                if name in scope.declared_global:
                    node = scope.declared_global[name]
                    break
                if name in scope.assigned and analysis.is_global_in(name, scope):
                    node = scope.assigned[name][0]
                    break
        if node is not None:
            add(name, "global", node, node.span)  # type: ignore[arg-type, attr-defined]
    top_level: dict[str, n.Stmt] = {}
    for scope in analysis.scopes:  # a global given a value only inside a block or function
        for statement in statements(scope.body):
            name = _assigned_name(statement)
            if name is not None and name in analysis.globals and name not in late \
                    and analysis.is_global_in(name, scope):
                late[name] = statement
    for item in analysis.top.body:
        if isinstance(item, n.Assign) and isinstance(item.target, n.Name):
            top_level.setdefault(item.target.id, item)
        elif isinstance(item, n.Declare) and item.value is not None:
            top_level.setdefault(item.name, item)
    return found, top_level, late


def _assigned_name(statement: n.Stmt) -> str | None:
    """The variable a statement gives a value to (``x = v``, ``global x = v``), if any."""
    if isinstance(statement, n.Assign) and isinstance(statement.target, n.Name):
        return statement.target.id
    if isinstance(statement, n.Declare) and statement.value is not None:
        return statement.name
    return None


def _code_lines(text: str) -> list[str]:
    """The lines of ``text`` that carry code, without spaces (for finding inlined files)."""
    lines = []
    for line in text.splitlines():
        compact = "".join(line.split())
        if not compact or compact[0] in "#$" or compact in ("end", "else:"):
            continue
        lines.append(compact)
    return lines


def _may_include(path: Path, fragment: ScriptFile) -> bool:
    """Whether the file at ``path`` could include ``fragment`` (see :func:`_includes`),
    decided from its text without parsing it: its text names the fragment's file, or holds
    enough of its code lines. Searching the folders above a file (for ``/tmp/x.script``,
    ``/tmp`` itself) meets large unrelated scripts; only a possible host is parsed."""
    try:
        if path.stat().st_size > MAX_FILE_BYTES:
            return False
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return False
    if fragment.path.name.lower() in text.lower():
        return True
    lines = fragment.code_line_list
    if not lines:
        return False
    return _share(lines, frozenset(_code_lines(text))) >= min(_INLINE_SHARE, _SUBPROGRAM_SHARE)


def _includes(host: ScriptFile, fragment: ScriptFile) -> bool:
    """Whether ``host`` includes ``fragment`` (a ``Script:`` label, or its code inlined)."""
    name = fragment.path.name.lower()
    if any(label.lower() == name for label in host.labels):
        return True
    if fragment.path.stem.lower() + URP_SUFFIX in host.subprogram_files:
        return True  # a subprogram the host's program calls, saved as its own program
    lines = fragment.code_line_list
    if not lines:
        return False
    if fragment.program is not None:
        # a complete program is included only as a subprogram: the host has its def (two
        # copies of one program are two programs, however alike)
        if not any(d.kind == "function" for d in host.definitions.get(fragment.program, [])):
            return False
        return _share(lines, host.code_lines) >= _SUBPROGRAM_SHARE
    return (len(lines) >= 2 and _share(lines, host.code_lines) >= _INLINE_SHARE
            and _in_order(lines, host) >= _INLINE_SHARE)


def _best_first(hosts: list[ScriptFile], fragment: ScriptFile) -> list[ScriptFile]:
    """``hosts`` of ``fragment``, those holding a larger share of its code lines in their
    order first (a ``Script:`` label names the file, not its version); otherwise in file
    order."""
    lines = fragment.code_line_list
    if len(hosts) < 2 or not lines:
        return hosts
    return sorted(hosts, key=lambda host: -_in_order(lines, host))


_GAP = 3
"""Host code lines that may stand between two lines of an inlined file (lines edited since)."""
_MAX_STARTS = 200


def _in_order(lines: tuple[str, ...], host: ScriptFile) -> float:
    """The largest share of ``lines`` that ``host`` holds in their order, one after the other
    (at most :data:`_GAP` other lines between two of them): PolyScope inlines a script file
    as one block, so a few common lines (``i = 0``, ``sync()``) spread over an unrelated
    program do not make it a host."""
    within = host.code_line_list
    index = _line_positions(host)
    best = 0
    starts: list[int] = []
    for first in lines[:3]:
        starts.extend(index.get(first, ())[:_MAX_STARTS])
    for start in sorted(set(starts))[:_MAX_STARTS]:
        position, matched = start, 0
        for line in lines:
            for ahead in range(position, min(position + _GAP + 1, len(within))):
                if within[ahead] == line:
                    matched += 1
                    position = ahead + 1
                    break
        best = max(best, matched)
        if best == len(lines):
            break
    return best / len(lines)


_POSITIONS: dict[int, tuple[object, dict[str, list[int]]]] = {}


def _line_positions(host: ScriptFile) -> dict[str, list[int]]:
    """Where each code line of ``host`` stands in its list (cached per file)."""
    cached = _POSITIONS.get(id(host))
    if cached is not None and cached[0] is host:
        return cached[1]
    positions: dict[str, list[int]] = {}
    for number, line in enumerate(host.code_line_list):
        positions.setdefault(line, []).append(number)
    if len(_POSITIONS) > 512:
        _POSITIONS.clear()
    _POSITIONS[id(host)] = (host, positions)
    return positions


def _share(lines: tuple[str, ...], within: frozenset[str]) -> float:
    """The share of ``lines`` found in ``within``."""
    return sum(1 for line in lines if line in within) / len(lines)


# ---- configuration ---------------------------------------------------------------------------

def configured_includes(start: Path) -> list[Path]:
    """The files named by ``[tool.urdsl] include`` in the nearest ``pyproject.toml`` that
    has that key, walking up from folder ``start``; entries are paths or glob patterns
    relative to that file."""
    try:
        folder = start.resolve()
    except OSError:
        return []
    for candidate_folder in (folder, *folder.parents):
        candidate = candidate_folder / "pyproject.toml"
        if not candidate.is_file():
            continue
        try:
            with open(candidate, "rb") as handle:
                data = tomllib.load(handle)
        except (OSError, tomllib.TOMLDecodeError) as error:
            raise ProjectError(f"{candidate}: {error}") from None
        table = data.get("tool", {}).get("urdsl", {})
        if not isinstance(table, dict) or "include" not in table:
            continue
        entries = table["include"]
        if isinstance(entries, str):
            entries = [entries]
        if not isinstance(entries, list) or not all(isinstance(e, str) for e in entries):
            raise ProjectError(f"{candidate}: [tool.urdsl] include must be a list of paths")
        paths: list[Path] = []
        for entry in entries:
            if any(ch in entry for ch in "*?["):
                paths.extend(sorted(candidate_folder.glob(entry)))
            else:
                target = candidate_folder / entry
                if not target.exists():
                    raise ProjectError(f"{candidate}: [tool.urdsl] include names {entry}, "
                                       "which does not exist")
                paths.append(target)
        return paths
    return []
