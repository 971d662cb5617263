"""``urdsl check X.urp`` and ``urdsl lint X.urp``: a PolyScope program compiled, then checked
and linted as the script it generates, each finding naming the program node it comes from.

The findings are placed on the generated script (the file name ``X.urp (compiled)``, the line
of the script ``urdsl compile X.urp`` writes, shown with that line); the message names the
node path as PolyScope shows it (``Robot Program > Loop > MoveL > Waypoint_3``) and the
node's position in the program's XML (``X.urp:45:9``, line and column of the node's element
in the decompressed XML). A script line belongs to the node of the nearest ``$ N`` marker
above it; the waypoint globals (``Waypoint_1_p``/``_q``) to their waypoint; the preamble to
the installation.

URCap nodes generate code only their URCap can write: each gets an info finding (URS214) and
the check runs the program without it. Names the program reads but defines nowhere while it
has URCap nodes (a URCap's result variables) are given unknown values, as a device's reply
(see :mod:`urdsl.runtime.unknown`).
"""

from __future__ import annotations

import dataclasses
import functools
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..script import nodes as n
from ..script.diagnostics import Diagnostic
from .compile import Compiled, names_installation
from .installation import Installation
from .urp import Node, Program

__all__ = ["Generated", "generate", "URCAP_CODE", "node_findings"]

URCAP_CODE = "URS214"
"""The code of the info finding on a URCap node (its code only the URCap can generate)."""

_MARKER = re.compile(r"\s*\$ (\d+) ")
_WAYPOINT_GLOBAL = re.compile(r"\s*global (\w+?)_(?:from_|to_)?[pq]\s*=")


@dataclass
class Generated:
    """A compiled program ready to check: the ``.urp`` path, the program, the compilation,
    the script text, the name findings are placed under, and the node of each script line
    (index 0 is line 1; ``None``: the installation preamble)."""

    path: str
    program: Program
    compiled: Compiled
    text: str
    filename: str
    owners: list[Node | None]
    installation: Installation | None = None

    def node_at(self, line: int) -> Node | None:
        """The node that generated script line ``line`` (1-based)."""
        return self.owners[line - 1] if 1 <= line <= len(self.owners) else None

    def where(self, node: Node | None) -> str:
        """``node Robot Program > MoveL > Waypoint_1 (pick.urp:31:13)`` or the preamble."""
        if node is None:
            return "the installation's preamble"
        place = f" ({self.path}:{node.position[0]}:{node.position[1]})" if node.position \
            else ""
        return f"node {node.path}{place}"

    def urcap_nodes(self) -> list[tuple[int, Node]]:
        """(marker number, node) of every URCap node, in program order."""
        return sorted((number, node) for number, node in self.compiled.numbers.items()
                      if node.kind == "Contributed")


def generate(path: str | Path, *, once: bool = False) -> Generated:
    """Read, compile and map the ``.urp`` at ``path``: a script line belongs to the node of
    the nearest marker above it whose block it is in (raises
    :class:`~urdsl.polyscope.urp.UrpError` or :class:`~urdsl.polyscope.compile.CompileError`,
    messages naming the file and node). ``once``: the Robot Program runs one pass (see
    :func:`~urdsl.polyscope.command.load_all`)."""
    from .command import load_all

    program, installation, compiled = load_all(path, once=once)
    text = compiled.text
    waypoints = {node.name: node for root in program.top for node in root.walk()
                 if node.kind == "Waypoint" and node.name}
    owners: list[Node | None] = []
    open_nodes: list[tuple[int, Node]] = []  # (indentation of the marker, node), innermost last
    for line in text.splitlines():
        indent = len(line) - len(line.lstrip())
        marker = _MARKER.match(line)
        node = compiled.numbers.get(int(marker.group(1))) if marker else None
        if node is not None:
            while open_nodes and open_nodes[-1][0] >= indent:
                open_nodes.pop()
            open_nodes.append((indent, node))
        elif line.strip():
            while open_nodes and open_nodes[-1][0] > indent:
                open_nodes.pop()  # the block of the node ended
        named = _WAYPOINT_GLOBAL.match(line)
        if named and named.group(1) in waypoints:
            owners.append(waypoints[named.group(1)])
        else:
            owners.append(open_nodes[-1][1] if open_nodes else None)
    lines = text.splitlines()
    for index in range(len(lines) - 1):  # the loop around the Robot Program is the program's
        marker = _MARKER.match(lines[index + 1])
        if owners[index] is None and marker and lines[index].strip().startswith("while"):
            node = compiled.numbers.get(int(marker.group(1)))
            if node is not None and node.kind == "MainProgram":
                owners[index] = node
    return Generated(str(path), program, compiled, text, f"{path} (compiled)", owners,
                     installation)


def _located(generated: Generated, line: int, message: str) -> str:
    return f"{message} [{generated.where(generated.node_at(line))}]"


def unfinished_main(generated: Generated, findings: list) -> list:
    """``findings`` where the Robot Program holds nothing but PolyScope's ``<empty>``
    placeholder (a program saved before anything was put in it, project 53's ``test.urp``):
    the runaway loop (URS207) its looping Robot Program would be says so first: PolyScope
    shows such a program as unfinished [U: whether Play refuses it is not documented]."""
    main = generated.program.main
    if main is None or not all(child.kind == "Placeholder" or child.suppressed
                               for child in main.children):
        return findings
    return [dataclasses.replace(
        finding, message="the Robot Program holds only PolyScope's <empty> placeholder: "
        "PolyScope shows the program as unfinished; were it started, its loop would run "
        f"without using physical time ({finding.message})",
        hint="put the program's nodes in the Robot Program, or delete this program")
        if finding.code == "URS207" and generated.node_at(finding.span.line) is main
        else finding for finding in findings]


def node_findings(generated: Generated, findings: list) -> list:
    """``findings`` (verifier :class:`~urdsl.verify.findings.Finding` or lint
    :class:`Diagnostic`) with the node each comes from named in its message."""
    out = []
    for finding in findings:
        line = finding.span.line if hasattr(finding, "span") else finding.line
        if line <= 0:
            out.append(finding)
            continue
        out.append(dataclasses.replace(finding,
                                       message=_located(generated, line, finding.message)))
    return out


def urcap_diagnostics(generated: Generated) -> list[Diagnostic]:
    """An info finding per URCap node: only the URCap can generate its code."""
    lines = generated.text.splitlines()
    out = []
    for number, node in generated.urcap_nodes():
        line = next((i for i, text in enumerate(lines, 1)
                     if _MARKER.match(text) and _MARKER.match(text).group(1) == str(number)),
                    1)  # a URCap node without a marker of its own: on the program's line
        urcap = node.attrs.get("strategyURCapName", "?")
        message = (f"URCap node {node.title} of {urcap}: only the URCap can generate its "
                   "code; urdsl checks the program without it and treats what it does as a "
                   "device (its results are unknown)")
        out.append(Diagnostic(generated.filename, line, 1, "info", URCAP_CODE,
                              f"{message} [{generated.where(node)}]",
                              source_line=lines[line - 1] if lines else None))
    return out


def urcap_sources(generated: Generated) -> list[str]:
    """The URCaps whose code urdsl cannot generate into this program: its URCap program
    nodes and the URCaps contributing to its installation (their preamble code defines
    names the program uses, e.g. a gripper's state variables)."""
    names = [node.attrs.get("strategyURCapName") or node.title
             for _number, node in generated.urcap_nodes()]
    if generated.installation is not None:
        names.extend(name for name, _vendor, _title in generated.installation.urcaps)
    return list(dict.fromkeys(name for name in names if name))


_UNDEFINED_NAME = re.compile(r"name '(\w+)' is not defined")
_UNKNOWN_FUNCTION = re.compile(r"unknown function '(\w+)'")


def without_urcap_busy_loops(generated: Generated, found: list) -> list:
    """Lint findings of a compiled program without URS118 ("never gives up its time slice")
    on a loop that holds a URCap node: only the URCap generates its code, which may well
    take time (a gripper's command waits for the gripper)."""
    urcaps = {number for number, _node in generated.urcap_nodes()}
    busy = [finding for finding in found if finding.code == "URS118"]
    if not urcaps or not busy:
        return found
    from ..script import parse
    from ..script.diagnostics import ScriptError

    try:
        module = parse(generated.text, generated.filename)
    except (ScriptError, RecursionError):
        return found
    holding = {node.span.line for node in n.walk(module) if isinstance(node, n.While)
               and any(isinstance(inner, n.Marker) and inner.number in urcaps
                       for inner in n.walk(node))}
    return [finding for finding in found
            if finding.code != "URS118" or finding.line not in holding]


def soften_urcap_names(generated: Generated, found: list) -> list:
    """Lint findings of a compiled program that code urdsl cannot generate or read would
    complete: a name or function defined nowhere in what urdsl generated (URS101, URS102)
    may come from a URCap's code, and a feature the program reads from its installation is
    defined by the installation's preamble, which is not written when the installation is
    missing, as is a known URCap function (the installation's URCap code defines it), and a
    name or function the export beside the program defines that the installation beside it
    lacks (:func:`exported_names`): warnings that say so rather than errors."""
    from ..script.urcaps import urcap_of

    sources = urcap_sources(generated)
    features = missing_features(generated)
    exported = exported_names(generated)
    out = []
    for finding in found:
        name = _UNDEFINED_NAME.match(finding.message) if finding.code == "URS101" else None
        function = _UNKNOWN_FUNCTION.match(finding.message) if finding.code == "URS102" \
            else None
        either = (name or function).group(1) if name or function else None
        if name and name.group(1) in features and finding.severity == "error":
            finding = replace(finding, severity="warning",
                              message=f"{finding.message}: {features[name.group(1)]}",
                              hint="put the program's installation beside it")
        elif either in exported and finding.severity == "error":
            finding = replace(finding, severity="warning",
                              message=f"{finding.message}: {exported[either]}",
                              hint="put the installation the program ran with beside it")
        elif function and generated.installation is None and finding.severity == "error" \
                and urcap_of(function.group(1)) is not None:
            named = generated.program.installation
            finding = replace(finding, severity="warning", message=(
                f"{finding.message}: a function of the URCap "
                f"{' or '.join(urcap_of(function.group(1)) or ())}, whose code the "
                f"installation {named + '.installation ' if named else ''}adds (not beside "
                "the program)"), hint="put the program's installation beside it")
        elif sources and finding.code in ("URS101", "URS102") and finding.severity == "error":
            finding = replace(finding, severity="warning", message=(
                f"{finding.message}; it may come from code only a URCap generates "
                f"({', '.join(sources)})"))
        out.append(finding)
    return out


def undefined_globals(module: n.Module) -> list[str]:
    """Variables the compiled program reads but defines nowhere (what a URCap's code would
    have defined)."""
    from ..project.check import needed_names

    reads, _calls, _threads = needed_names(module)
    return sorted(reads)


def missing_features(generated: Generated) -> dict[str, str]:
    """Installation variables and features the program refers to while its installation is
    not there (the preamble and ``.variables`` that define them are not read): each with
    where its value would come from."""
    program = generated.program
    named = f"{program.installation}.installation" if program.installation else "(none named)"
    out = {} if generated.installation is not None else {
        name: f"a {'feature' if name in program.feature_variables else 'name'} of the "
              f"installation {named} (not beside the program)"
        for name in sorted(program.installation_names)}  # feature variables too
    # also with another installation found beside the program in its place
    for name, what in generated.compiled.unknown.items():
        export = generated.compiled.exported.get(name)
        out.setdefault(name, _from_export(generated, what, export) if export else
                       f"{what} of the installation {named} (not beside the program)")
    return out


def _installation_name(generated: Generated) -> str:
    """The file name of the installation found for the program, for messages."""
    return Path(str(generated.installation.path)).name if generated.installation else "?"


def _from_export(generated: Generated, what: str, export: str) -> str:
    """Where ``what`` (``"an I/O"``, ``"a name"``) that the export file ``export`` defines
    and the installation found for the program lacks comes from, for a message."""
    return (f"{what} of the installation {export} was exported with (the "
            f"{_installation_name(generated)} beside the program lacks it)")


def exported_values(generated: Generated, module: n.Module) -> dict[str, str]:
    """Variables and features the program reads but defines nowhere, while the installation
    found for it is there, that PolyScope's export beside the program defines (its preamble:
    the installation the program ran with had them; see :mod:`urdsl.polyscope.export`):
    each with where its unknown value comes from."""
    exported = exported_names(generated)
    return {name: exported[name] for name in undefined_globals(module)
            if name in exported and name not in generated.compiled.export.functions}


def exported_names(generated: Generated) -> dict[str, str]:
    """The variables, features and functions PolyScope's export beside the program defines
    while an installation was found for it, each with where it comes from for a message
    (see :mod:`urdsl.polyscope.export`)."""
    export = generated.compiled.export
    if export is None or generated.installation is None:
        return {}
    return dict.fromkeys(sorted(export.names | export.functions),
                         _from_export(generated, "a name", export.path.name))


def urcap_values(generated: Generated, module: n.Module) -> dict[str, str]:
    """The variables the program reads but defines nowhere that code urdsl cannot generate
    or read defines: URCap nodes' results, features of a missing installation; each with
    where its unknown value comes from."""
    values = {}
    urcaps = generated.urcap_nodes()
    if urcaps:
        names = ", ".join(dict.fromkeys(node.title for _number, node in urcaps))
        values = {name: f"a URCap node's result ({names})" for name in undefined_globals(module)}
        # a variable a URCap node is set up with (``<data key="selectedProgramVariable"
        # value="service"/>``, an OPC UA read of project 82): its code sets it, also where the
        # program assigns it elsewhere too (so it is not undefined to the program as a whole)
        for _number, node in urcaps:
            for data in node.element.iter("data") if node.element is not None else ():
                name = data.get("value") or ""
                if "variable" in (data.get("key") or "").lower() and name.isidentifier():
                    values.setdefault(name, f"a URCap node's result ({node.title})")
    # the missing installation's preamble would define each of its names the program uses
    # before the program runs, also one the program assigns itself (``i_count = i_count + 1``)
    used = {node.id for node in n.walk(module) if isinstance(node, n.Name)}
    return values | {name: why for name, why in missing_features(generated).items()
                     if name in used}


def with_urcap_functions(generated: Generated, module: n.Module) -> tuple[n.Module, list[str]]:
    """When code urdsl cannot generate is part of the program (URCap nodes, URCaps of the
    installation, PolyScope 3's Conveyor Tracking with its preamble function): ``module`` with
    a stand-in for each function the program calls but defines nowhere, taking a device's
    reply time (:data:`urdsl.runtime.unknown.DEVICE_REPLY_TIME`) and as many parameters as
    its calls pass (keywords as parameters with a default), so that the check runs the rest
    of the program; and their names. Without such code, only where the installation is
    missing: a known URCap function the program calls (``rq_activate_and_wait()`` in a Script
    node) is one its URCap's preamble code defines there (PolyScope writes the installed
    URCaps' code into every program). Nothing changes otherwise."""
    from ..project.check import needed_names
    from ..runtime.unknown import DEVICE_REPLY_TIME
    from ..script.urcaps import urcap_of

    _reads, calls, _threads = needed_names(module)
    if not urcap_sources(generated):
        export = generated.compiled.export
        if generated.installation is not None:
            # a function the installation's URCaps define, which the installation beside
            # the program lacks and the export's preamble has
            calls = {name for name in calls if export is not None and name in export.functions}
        else:
            calls = {name for name in calls if urcap_of(name) is not None}
    if not calls:
        return module, []
    positional: dict[str, int] = {name: 0 for name in calls}
    keywords: dict[str, list[str]] = {name: [] for name in calls}
    for node in n.walk(module):
        if isinstance(node, n.Call) and isinstance(node.func, n.Name) and \
                node.func.id in positional:
            positional[node.func.id] = max(positional[node.func.id], len(node.args))
            for keyword in node.keywords:
                if keyword.name not in keywords[node.func.id]:
                    keywords[node.func.id].append(keyword.name)
    stubs = tuple(
        n.FunctionDef(name, tuple(n.Param(f"arg{i + 1}") for i in range(positional[name])) +
                      tuple(n.Param(k, n.Number(0)) for k in keywords[name]),
                      (n.ExprStmt(n.Call(n.Name("sleep"), (n.Number(DEVICE_REPLY_TIME),))),
                       n.Return(n.Name(stand_in_reply(name)))))
        for name in sorted(calls))
    body = module.body
    if len(body) == 1 and isinstance(body[0], n.FunctionDef):
        program = body[0]
        body = (dataclasses.replace(program, body=stubs + tuple(program.body)),)
    else:
        body = stubs + tuple(body)
    return dataclasses.replace(module, body=body), sorted(calls)


def stand_in_reply(name: str) -> str:
    """The global a stand-in for function ``name`` (:func:`with_urcap_functions`) returns: the
    check gives it an unknown value, the reply of code urdsl cannot see (a factory's
    handle, a computed pose), never none."""
    return f"urdsl_reply_of_{name}"


def with_urcap_time(module: n.Module, numbers: set[int]) -> n.Module:
    """``module`` with each URCap node (marker number in ``numbers``) taking a device's
    reply time (:data:`urdsl.runtime.unknown.DEVICE_REPLY_TIME`, as ``sleep``, placed on the
    node's marker): what the URCap's code does takes robot time, never none, so a loop of
    URCap nodes is not taken for a busy loop."""
    from ..runtime.unknown import DEVICE_REPLY_TIME

    def block(items: tuple) -> tuple:
        out = []
        for item in items:
            out.append(visit(item))
            if isinstance(item, n.Marker) and item.number in numbers:
                out.append(n.ExprStmt(n.Call(n.Name("sleep", span=item.span),
                                             (n.Number(DEVICE_REPLY_TIME, span=item.span),),
                                             span=item.span), span=item.span))
        return tuple(out)

    def visit(node):
        if not dataclasses.is_dataclass(node) or isinstance(node, n.Expr):
            return node
        changes = {}
        for f in dataclasses.fields(node):
            value = getattr(node, f.name)
            if isinstance(value, tuple) and value and all(
                    isinstance(v, (n.Stmt, n.Comment, n.Blank, n.Marker, n.Elif))
                    for v in value):
                changes[f.name] = tuple(visit(v) for v in value) if all(
                    isinstance(v, n.Elif) for v in value) else block(value)
        return dataclasses.replace(node, **changes) if changes else node

    return visit(module) if numbers else module


def calibration_of(program: Program, robot: str | None = None):
    """The program's ``<kinematics>`` as a :class:`~urdsl.kinematics.Calibration` of the
    model whose arm it describes (``robot`` when given), with that model's name;
    ``(None, None)`` when the program has none or it matches no model (``robot``).

    Factory calibrations are "linearized": the lengths along parallel axes trade off (a
    UR3e's stores d = 1.79, 30.86, −32.52 m where the nominal table has 0, 0, 0.131 m), so
    the table is compared by what it does: a model matches when the flange positions of the
    calibrated and nominal tables differ by at most :data:`_FK_MATCH` m at every one of a
    fixed set of joint positions (two models differ by centimetres to decimetres)."""
    import numpy as np

    from ..kinematics import MODELS, Calibration, KinematicsError, Robot
    from ..kinematics.models import model_spec

    block = program.kinematics
    if block is None or any(len(v) != 6 for v in (block.a, block.d, block.alpha,
                                                   block.delta_theta)):
        return None, None
    samples = np.random.default_rng(13).uniform(-np.pi, np.pi, (24, 6))
    best = None
    for name in [robot] if robot else list(MODELS):
        spec = model_spec(name)
        calibration = Calibration(np.asarray(block.delta_theta),
                                  np.asarray(block.a) - spec.dh_a,
                                  np.asarray(block.d) - spec.dh_d,
                                  np.asarray(block.alpha) - spec.dh_alpha, model=spec.name)
        try:
            nominal = Robot.model(spec.name).fk_many(samples)
            calibrated = Robot.model(spec.name, calibration=calibration).fk_many(samples)
        except (KinematicsError, ValueError, FloatingPointError):
            continue
        error = float(np.max(np.linalg.norm(nominal[:, :3, 3] - calibrated[:, :3, 3],
                                            axis=1)))
        if error <= _FK_MATCH and (best is None or error < best[0]):
            best = (error, spec.name, calibration)
    if best is None:
        return None, None
    return best[2], best[1]


_FK_MATCH = 0.01
"""Largest flange position difference [m] between a program's calibrated kinematics and a
model's nominal ones for the calibration to be that model's (factory corrections move the
flange by a few millimetres at most)."""


CALLER_SCAN_LIMIT = 500
"""Most ``.urp`` files beside a program that :func:`calling_programs` reads."""

CALLER_XML_LIMIT = 64_000_000
"""Most bytes of XML :func:`calling_programs` reads of one file beside the program (the
largest real programs in the labelled set are a few megabytes): a larger file is skipped."""

_PROGRAM_FILE = re.compile(rb"<programFile>([^<]*)</programFile>")


def calling_programs(path: str | Path) -> list[str]:
    """The names of the ``.urp`` programs beside ``path`` that call it as a subprogram: a
    ``CallSubProgram`` or ``SubProgram`` node whose ``<programFile>`` names this file
    (``/programs/GD/SUB_104.urp``; PolyScope keeps the subprogram's nodes in the caller and
    syncs them with that file). Files that cannot be read are skipped; at most
    :data:`CALLER_SCAN_LIMIT` files are read, each once per process while it is unchanged
    (checking every program of a folder reads each file once, not once per program)."""
    target = Path(path)
    name = target.name.lower()
    found: list[str] = []
    try:
        siblings = sorted(p for p in target.parent.iterdir()
                          if p.suffix.lower() == ".urp" and p.name != target.name)
    except OSError:
        return found
    for sibling in siblings[:CALLER_SCAN_LIMIT]:
        try:
            stat = sibling.stat()
        except OSError:
            continue
        if stat.st_size <= CALLER_XML_LIMIT and name in _called_files(
                str(sibling), stat.st_mtime_ns, stat.st_size, CALLER_XML_LIMIT):
            found.append(sibling.name)
    return found


@functools.lru_cache(maxsize=CALLER_SCAN_LIMIT)
def _called_files(path: str, _mtime_ns: int, _size: int, limit: int) -> frozenset[str]:
    """The file names (lower case, no folder) that the ``<programFile>`` elements of the
    ``.urp`` at ``path`` name; empty for a file that cannot be read or decompresses to more
    than ``limit`` bytes. Keyed by the file's modification time and size too: a file saved
    again is read again."""
    from .gz import InflateError, inflate

    try:
        data = inflate(Path(path).read_bytes(), limit)
    except (OSError, InflateError):
        return frozenset()
    return frozenset(re.split(r"[\\/]", match.group(1).decode("utf-8", "replace").strip())[-1]
                     .lower() for match in _PROGRAM_FILE.finditer(data))


def check_urp(path: str, options, *, robot_given: bool, start_joints=None, tcp=None,
              nominal: bool = False, cell_path: str | None = None):
    """``urdsl check X.urp``: compile the program and check the script it generates on the
    very arm (the program's ``<kinematics>`` as the calibration unless ``nominal``), with the
    installation's settings as defaults (see :func:`installation_defaults`) where ``options``
    leave them open. Raises UrpError/CompileError for a program that cannot be compiled."""
    from ..project.model import join_names
    from ..script.diagnostics import ScriptError
    from ..script.parser import parse
    from ..verify.findings import Finding
    from ..verify.infer import apply, infer, qualify_report, waypoint_pairs
    from ..verify.run import check_text, check_tree

    callers = calling_programs(path)
    generated = generate(path, once=bool(callers))
    try:
        module = parse(generated.text, generated.filename)
    except ScriptError:
        return check_text(generated.text, generated.filename, options=options)
    notes = [f"compiled from {path} (PolyScope {generated.program.saved_in or '?'})"]
    if callers:
        verb = "calls" if len(callers) == 1 else "call"
        notes.append(f"a subprogram that {join_names(callers, 3)} {verb}"
                     " (its <programFile>): checked as one call, one pass from where the "
                     "caller leaves the arm, which is not known unless --start-joints gives it "
                     "(the first move is not checked)")
    if generated.installation is None:
        named = generated.program.installation
        notes.append(f"no installation {named + '.installation ' if named else ''}beside the "
                     "program: compiled and checked without its preamble and limits")
    calibration, calibrated_model = (None, None)
    if generated.program.kinematics is not None:
        if nominal:
            notes.append("nominal kinematics (--nominal): the program's <kinematics> ignored")
        else:
            calibration, calibrated_model = calibration_of(
                generated.program, options.robot if robot_given else None)
            if calibration is None:
                notes.append("the program's <kinematics> matches no "
                             + (f"{options.robot}" if robot_given else "UR model")
                             + "; nominal kinematics used")
    taught = None
    tcp_unknown = False
    if tcp is None and generated.installation is None:
        # the preamble that sets the active TCP is the installation's: without it, the TCP
        # the waypoints were taught with (PolyScope keeps it with each), when there is one
        tcps = taught_tcps(generated.program)
        if len(tcps) == 1 and any(abs(v) > 1e-9 for v in tcps[0]):
            taught = tcps[0]
            notes.append("TCP p[" + ", ".join(f"{v:.6g}" for v in taught) + "] the "
                         "waypoints were taught with (the installation that sets it is "
                         "missing)")
        tcp_unknown = len(tcps) > 1
    inference = infer(module, path, robot=options.robot if robot_given else calibrated_model,
                      start_joints=start_joints, tcp=tcp, default_robot=options.robot)
    if calibrated_model is not None and not robot_given:
        model = calibrated_model
        inference.robot_source = "program"  # the arm the program's <kinematics> describe
        inference.robot_line = lambda: (  # type: ignore[method-assign]
            f"robot {model} from the program's <kinematics> (the arm's calibration)")
    file_options = apply(options, inference, tcp_given=tcp is not None)
    if taught is not None:
        file_options = dataclasses.replace(file_options, tcp=np.array(taught))
    elif tcp is None and generated.installation is not None and inference.tcp is not None:
        tcps = taught_tcps(generated.program)
        active = np.asarray(inference.tcp, dtype=float)
        if len(tcps) == 1 and (np.linalg.norm(np.subtract(tcps[0][:3], active[:3])) > 1e-3
                               or np.linalg.norm(np.subtract(tcps[0][3:], active[3:])) > 1e-2):
            # an installation edited after the waypoints were taught (or another one)
            notes.append("the waypoints were taught with TCP p[" + ", ".join(
                f"{v:.6g}" for v in tcps[0]) + "], the installation's active TCP is p["
                + ", ".join(f"{v:.6g}" for v in active) + "]: the active TCP goes to the taught "
                "poses, so the arm's joints are not those taught")
            if inference.start_source == "inferred" and not callers:
                # PolyScope brings the arm to the first move's target as the active TCP
                # reaches it, not to the joints taught with the other TCP
                file_options = dataclasses.replace(file_options, start_unknown=True)
                notes.append("where the arm starts is not known (not the first waypoint's "
                             "taught joints): the first move is not checked")
    if callers and inference.start_source != "given":
        # a call starts where the caller left the arm: PolyScope does not bring the arm to
        # the subprogram's first waypoint as it does for a program started on its own
        file_options = dataclasses.replace(file_options, start_unknown=True)
    if cell_path and file_options.robot != options.robot:
        from .._cli import load_cell

        file_options.cell = load_cell(file_options.robot, cell_path)
    if calibration is not None and calibration.model == file_options.robot:
        file_options.calibration = calibration
        notes.append(f"on this very arm: the {calibration.model} calibration of the program's "
                     "<kinematics>")
    joints_open = file_options.q_min is None and file_options.q_max is None
    planes_open = not file_options.safety_planes
    if generated.installation is not None and generated.installation.safety is not None:
        notes.extend(installation_defaults(file_options, generated.installation))
    # limits taken from an installation that the program does not name as its own
    borrowed = generated.installation is not None and not (
        generated.program.installation
        and names_installation(generated.program, str(generated.installation.path)))
    borrowed_joints = borrowed and joints_open and file_options.q_min is not None
    borrowed_planes = borrowed and planes_open and bool(file_options.safety_planes)
    file_options.unknown_globals = urcap_values(generated, module)
    exported = exported_values(generated, module)
    stale = sorted({*exported, *generated.compiled.exported})
    missing = sorted(set(file_options.unknown_globals) - set(stale))
    if missing:
        notes.append("unknown values (URCap nodes' results, names of a missing "
                     "installation): " + ", ".join(missing))
    if stale and generated.compiled.export is not None:
        notes.append(f"names the {_installation_name(generated)} beside the program lacks and "
                     f"{generated.compiled.export.path.name} (PolyScope's export of it) defines, "
                     "read as unknown values of the installation the program ran with: "
                     + ", ".join(stale))
    file_options.unknown_globals |= exported
    module, stand_ins = with_urcap_functions(generated, module)
    for name in stand_ins:
        file_options.unknown_globals[stand_in_reply(name)] = \
            f"the reply of {name}(), which code only a URCap generates defines"
    if stand_ins:
        where = ("URCap functions, defined by the URCaps' code of the missing installation"
                 if generated.installation is None and not urcap_sources(generated)
                 else "functions defined by code urdsl cannot generate")
        notes.append(f"{where}, taken as devices: " + ", ".join(stand_ins))
    if file_options.environment is None and (urcap_sources(generated)
                                             or generated.installation is None):
        # a URCap's code (of the installation, missing or not, or of a node) opens sockets
        # the program then uses (seen: Vention's MachineMotion1, project 6)
        from ..runtime import Environment

        file_options = dataclasses.replace(
            file_options, environment=Environment(devices="unknown", foreign_sockets=True))
    urcaps = {number for number, _node in generated.urcap_nodes()}
    report = check_tree(with_urcap_time(module, urcaps), generated.filename, file_options)
    report.inferred = inference
    if borrowed_joints or borrowed_planes:
        report.findings = taught_beyond(
            report.findings, waypoint_pairs(module), file_options,
            Path(str(generated.installation.path)).name, joints=borrowed_joints,
            planes=borrowed_planes)
    if tcp_unknown:
        report.findings = tcp_dependent(report.findings, len(tcps))
    # as for a script: on a model only assumed, what depends on it is a warning; a target
    # a fraction of a millimetre beyond the nominal reach, the arm's calibration decides
    qualify_report(report, inference, calibrated=file_options.calibration is not None)
    report.findings = node_findings(generated, unfinished_main(generated, report.findings))
    source = module.span.source
    for diagnostic in urcap_diagnostics(generated):
        start = source.line_start(diagnostic.line)
        span = n.Span(source, start, start + len(diagnostic.source_line or "")) \
            if diagnostic.line else n.NO_SPAN
        report.findings.append(Finding(URCAP_CODE, "info", diagnostic.message, span))
    report.findings.sort(key=lambda f: (f.span.line, f.span.column, f.time or 0.0, f.code))
    report.context = "; ".join(notes)
    report.generated = generated  # type: ignore[attr-defined]
    return report


def taught_tcps(program: Program) -> list[tuple[float, ...]]:
    """The TCPs (poses in the flange frame, m and rad) the taught waypoints of ``program``
    were taught with (PolyScope stores one with each), each once (equal to 0.1 mm and 0.1
    mrad), in program order."""
    seen: dict[tuple, tuple[float, ...]] = {}
    for root in program.top:
        for node in root.walk():
            offset = node.fields.get("tcp_offset") if node.kind == "Waypoint" else None
            if offset is not None and len(offset) == 6:
                seen.setdefault(tuple(round(v, 4) for v in offset), tuple(offset))
    return list(seen.values())


def taught_beyond(findings: list, pairs, options, installation: str, *, joints: bool,
                  planes: bool) -> list:
    """Errors about an installation's joint position limits (URS303, with ``joints``) and
    safety planes (URS308, with ``planes``) that one of the program's taught waypoints
    (``pairs``: :class:`~urdsl.verify.infer.WaypointPair`) lies beyond, where the program does
    not name that installation as its own: the arm stood at the waypoint when it was taught,
    so that limit was not in force then, and the installation beside the program is not the
    one it was taught with. They are warnings that say so; the limits the taught waypoints
    keep stay errors."""
    from ..verify.checks import JOINTS, SAFETY_PLANE_TOLERANCE, past_plane

    beyond: dict[str, str] = {}  # a finding's cause -> the waypoint taught beyond its limit
    for pair in pairs:
        q = np.asarray(pair.joints, dtype=float)
        if joints:
            for joint in range(6):
                if q[joint] > options.q_max[joint] + 1e-6:
                    beyond.setdefault(f"{JOINTS[joint]} upper", pair.name)
                if q[joint] < options.q_min[joint] - 1e-6:
                    beyond.setdefault(f"{JOINTS[joint]} lower", pair.name)
        if planes:
            for plane in options.safety_planes:
                if past_plane(pair.pose[:3], plane) > SAFETY_PLANE_TOLERANCE:
                    beyond.setdefault(f"plane {plane.name}", pair.name)
    if not beyond:
        return findings
    out = []
    for finding in findings:
        cause = finding.cause or ""
        if finding.code == "URS308" and " passes the safety plane " in cause:
            cause = "plane " + cause.split(" passes the safety plane ", 1)[1]  # TCP or elbow
        waypoint = beyond.get(cause) if finding.severity == "error" and \
            finding.code in ("URS303", "URS308") else None
        if waypoint is not None:
            finding = replace(finding, severity="warning", message=(
                f"{finding.message}; the program's waypoint {waypoint} was taught beyond this "
                f"limit of {installation}, which the program does not name as its own: it was "
                "taught under other safety settings"),
                hint="check the program with the installation it runs with")
        out.append(finding)
    return out


def tcp_dependent(findings: list, count: int) -> list:
    """Errors about where the arm goes (URS301-URS308) of a program whose installation, which
    sets the active TCP, is missing, and whose waypoints were taught with ``count`` different
    TCPs: every target the controller solves with the active TCP depends on it, so they are
    warnings that say so."""
    from ..verify.run import PACED_CODES

    out = []
    for finding in findings:
        if finding.severity == "error" and finding.code in PACED_CODES:
            finding = replace(finding, severity="warning", message=(
                f"{finding.message}; depends on the active TCP, which the missing "
                f"installation sets (the waypoints were taught with {count} different TCPs)"),
                hint="put the program's installation beside it, or give --tcp")
        out.append(finding)
    return out


def installation_defaults(options, installation: Installation) -> list[str]:
    """Set the installation's normal-mode safety limits on ``options`` (a
    :class:`~urdsl.verify.run.CheckOptions` for its robot) where the command line left them
    open: joint position limits (a joint the installation does not limit keeps the model's),
    joint speed limits, the TCP speed limit, and the safety planes that restrict normal mode
    (``NORMAL``, ``BOTH``), which the TCP (and the elbow where a plane restricts it) must not
    pass (URS308). Returns what was taken, for the report."""
    import numpy as np

    from ..kinematics import Robot

    safety = installation.safety
    if safety is None:
        return []
    robot = Robot.model(options.robot, calibration=options.calibration)
    taken: list[str] = []
    if options.q_min is None and options.q_max is None and safety.q_min and safety.q_max:
        low = tuple(float(robot.q_min[j]) if v is None else max(v, float(robot.q_min[j]))
                    for j, v in enumerate(safety.q_min))
        high = tuple(float(robot.q_max[j]) if v is None else min(v, float(robot.q_max[j]))
                     for j, v in enumerate(safety.q_max))
        if low != tuple(float(v) for v in robot.q_min) or \
                high != tuple(float(v) for v in robot.q_max):
            options.q_min, options.q_max = low, high
            taken.append("joint position limits")
    if safety.joint_speed and bool(np.any(np.asarray(safety.joint_speed) < robot.qd_max)):
        options.joint_speed_limit = tuple(safety.joint_speed)
        taken.append("joint speed limits")
    if options.tcp_speed_limit is None and safety.tcp_speed is not None:
        options.tcp_speed_limit = safety.tcp_speed
        taken.append(f"TCP speed limit {safety.tcp_speed:g} m/s")
    planes = tuple(p for p in safety.planes if p.mode in ("NORMAL", "BOTH"))
    if planes and not options.safety_planes:
        options.safety_planes = planes
        taken.append(f"{len(planes)} safety plane(s) for the TCP"
                     + (" and elbow" if any(p.elbow for p in planes) else "")
                     + " (" + ", ".join(p.name for p in planes) + ")")
    if not taken:
        return []
    return [f"from {Path(installation.path).name}: " + ", ".join(taken)]


def send_check(path: str, robot: str, check: bool):
    """``urdsl send X.urp``: ``(tree, filename, report)`` of the compiled program, the report
    of :func:`check_urp` (None when ``check`` is false); None when the program cannot be
    compiled (the message printed). ``robot`` is the command line's model; the default
    (ur5e) gives way to the arm the program's ``<kinematics>`` describe."""
    import sys
    from pathlib import Path

    from .._cli import UsageError
    from ..script.diagnostics import ScriptError
    from ..script.parser import parse
    from ..verify.run import CheckOptions
    from .compile import CompileError
    from .urp import UrpError

    if not Path(path).is_file():
        raise UsageError(f"cannot read {path}: No such file")
    try:
        generated = generate(path)
        tree = parse(generated.text, generated.filename)
    except (UrpError, CompileError) as error:
        print(str(error), file=sys.stderr)
        return None
    except ScriptError as error:
        print(error.diagnostic.render(), file=sys.stderr)
        return None
    if generated.compiled.unknown:
        # compiled for reading and checking only: the robot would stop at the first of these
        # names, and the outputs they name would never be set
        named = generated.program.installation or "?"
        print(f"{path}: not sent: {generated.compiled.unknown_text()} only in the "
              f"installation {named}.installation, which is not beside the program; put it "
              "there to send the program", file=sys.stderr)
        return None
    report = None
    if check:
        report = check_urp(path, CheckOptions(robot=robot), robot_given=robot != "ur5e")
        if report.context:
            print(report.context, file=sys.stderr)
    return tree, generated.filename, report
