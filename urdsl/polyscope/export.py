"""What the ``.script`` PolyScope exported beside a ``.urp`` proves about the installation the
program ran with.

PolyScope writes ``X.script`` next to ``X.urp`` each time it saves the program: the program
tree compiled with the installation loaded then, its preamble included (installation
variables and features as ``global`` assignments, each Modbus signal as
``modbus_add_signal(ip, slave, address, type, "NAME")``, the URCaps' functions). A repository
often keeps an older or another robot's ``.installation`` beside both (a shared
``default.installation`` at the top of a repository of two robots' programs, project 213 of
``bench/realworld``; an installation edited after the export, projects 37 and 53). A name the
program uses that this installation lacks and the export defines is then no mistake of the
program: the installation it ran with had it. ``urdsl check X.urp`` reads such a name as an
unknown value of that installation (:func:`exported_by`), not as an undefined name or an I/O
the installation does not name.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..script import nodes as n

LIMIT = 16 * 1024 * 1024
"""The largest export read (bytes); a longer file is not read as evidence."""


@dataclass(frozen=True)
class Export:
    """What an export's preamble (the code before the program tree's first node marker)
    defines: ``path`` (the ``.script``), ``names`` (the installation's variables and features
    it assigns), ``functions`` (the URCaps' functions it defines) and ``signals`` (the Modbus
    signals it adds). What the program tree's own nodes assign is left out: an older export's
    variable is no evidence for the program as it is now."""

    path: Path
    names: frozenset[str]
    functions: frozenset[str]
    signals: frozenset[str]


def exported_by(urp_path: str | Path) -> Export | None:
    """The export beside the ``.urp`` at ``urp_path`` (``X.script`` for ``X.urp``): what it
    defines, or None when there is none, it is empty, longer than :data:`LIMIT`, or not a
    URScript program (one ``def`` PolyScope wrote)."""
    from ..script.diagnostics import ScriptError
    from ..script.parser import parse

    path = Path(urp_path).with_suffix(".script")
    try:
        if not path.is_file() or path.stat().st_size > LIMIT:
            return None
        text = path.read_bytes().decode("utf-8", errors="replace")
    except OSError:
        return None
    try:
        module = parse(text, str(path))
    except (ScriptError, RecursionError):
        return None
    programs = [item for item in module.body if isinstance(item, n.FunctionDef)]
    if len(programs) != 1 or programs[0].params:
        return None
    names: set[str] = set()
    functions: set[str] = set()
    preamble: list[n.Node] = []
    for item in programs[0].body:
        if isinstance(item, n.Marker):
            break  # the program tree's own code begins: what follows is no installation's
        preamble.append(item)
        if isinstance(item, n.FunctionDef) and any(isinstance(inner, n.Marker)
                                                   for inner in n.walk(item)):
            continue  # a subprogram of the program tree (its nodes' markers), not a URCap's
        if isinstance(item, n.Declare) and item.value is not None:
            names.add(item.name)
        elif isinstance(item, n.Assign) and isinstance(item.target, n.Name):
            names.add(item.target.id)
        elif isinstance(item, n.FunctionDef):
            functions.add(item.name)
    signals = {
        call.args[4].value for item in preamble for call in n.walk(item)
        if isinstance(call, n.Call) and isinstance(call.func, n.Name)
        and call.func.id == "modbus_add_signal" and len(call.args) >= 5
        and isinstance(call.args[4], n.String)}
    return Export(path, frozenset(names), frozenset(functions), frozenset(signals))
