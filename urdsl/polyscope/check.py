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
import re
from dataclasses import dataclass
from pathlib import Path

from ..script import nodes as n
from ..script.diagnostics import Diagnostic
from .compile import Compiled
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


def generate(path: str | Path) -> Generated:
    """Read, compile and map the ``.urp`` at ``path``: a script line belongs to the node of
    the nearest marker above it whose block it is in (raises
    :class:`~urdsl.polyscope.urp.UrpError` or :class:`~urdsl.polyscope.compile.CompileError`,
    messages naming the file and node)."""
    from .command import load

    program, compiled = load(path)
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
    return Generated(str(path), program, compiled, text, f"{path} (compiled)", owners)


def _located(generated: Generated, line: int, message: str) -> str:
    return f"{message} [{generated.where(generated.node_at(line))}]"


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
                    0)
        urcap = node.attrs.get("strategyURCapName", "?")
        message = (f"URCap node {node.title} of {urcap}: only the URCap can generate its "
                   "code; urdsl checks the program without it and treats what it does as a "
                   "device (its results are unknown)")
        out.append(Diagnostic(generated.filename, line, 1, "info", URCAP_CODE,
                              _located(generated, line, message),
                              source_line=lines[line - 1] if line else None))
    return out


def undefined_globals(module: n.Module) -> list[str]:
    """Variables the compiled program reads but defines nowhere (what a URCap's code would
    have defined)."""
    from ..project.check import needed_names

    reads, _calls, _threads = needed_names(module)
    return sorted(reads)


def urcap_values(generated: Generated, module: n.Module) -> dict[str, str]:
    """When the program has URCap nodes: the variables it reads but defines nowhere (what a
    URCap's code defines), each with where its unknown value comes from."""
    urcaps = generated.urcap_nodes()
    if not urcaps:
        return {}
    names = ", ".join(dict.fromkeys(node.title for _number, node in urcaps))
    return {name: f"a URCap node's result ({names})" for name in undefined_globals(module)}


def calibration_of(program: Program, robot: str | None = None):
    """The program's ``<kinematics>`` as a :class:`~urdsl.kinematics.Calibration` of the
    model whose nominal DH table it corrects (``robot`` when given), with that model's name;
    ``(None, None)`` when the program has none or it matches no model (``robot``) within
    :data:`_DH_MATCH` m."""
    import numpy as np

    from ..kinematics import MODELS, Calibration
    from ..kinematics.models import model_spec

    block = program.kinematics
    if block is None or len(block.a) != 6 or len(block.d) != 6 or len(block.alpha) != 6 \
            or len(block.delta_theta) != 6:
        return None, None
    candidates = [robot] if robot else list(MODELS)
    best = None
    for name in candidates:
        spec = model_spec(name)
        da = np.asarray(block.a) - spec.dh_a
        dd = np.asarray(block.d) - spec.dh_d
        dalpha = np.asarray(block.alpha) - spec.dh_alpha
        error = float(max(np.max(np.abs(da)), np.max(np.abs(dd))))
        if error <= _DH_MATCH and float(np.max(np.abs(dalpha))) <= _ALPHA_MATCH and (
                best is None or error < best[0]):
            best = (error, spec.name, Calibration(np.asarray(block.delta_theta), da, dd,
                                                  dalpha, model=spec.name))
    if best is None:
        return None, None
    return best[2], best[1]


_DH_MATCH = 0.005
"""Largest difference [m] of a calibrated DH length from a model's nominal one for the
calibration to be taken as that model's (factory corrections are well under a millimetre;
two models differ by centimetres)."""

_ALPHA_MATCH = 0.01
"""Largest difference [rad] of a calibrated DH twist from the nominal one."""


def check_urp(path: str, options, *, robot_given: bool, start_joints=None, tcp=None,
              nominal: bool = False, cell_path: str | None = None):
    """``urdsl check X.urp``: compile the program and check the script it generates on the
    very arm (the program's ``<kinematics>`` as the calibration unless ``nominal``), with the
    installation's settings as defaults (see :func:`installation_defaults`) where ``options``
    leave them open. Raises UrpError/CompileError for a program that cannot be compiled."""
    from ..script.diagnostics import ScriptError
    from ..script.parser import parse
    from ..verify.findings import Finding
    from ..verify.infer import apply, infer
    from ..verify.run import check_text, check_tree

    generated = generate(path)
    try:
        module = parse(generated.text, generated.filename)
    except ScriptError:
        return check_text(generated.text, generated.filename, options=options)
    notes = [f"compiled from {path} (PolyScope {generated.program.saved_in or '?'})"]
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
    inference = infer(module, path, robot=options.robot if robot_given else calibrated_model,
                      start_joints=start_joints, tcp=tcp, default_robot=options.robot)
    file_options = apply(options, inference, tcp_given=tcp is not None)
    if cell_path and file_options.robot != options.robot:
        from ..verify.command import _load_cell

        file_options.cell = _load_cell(file_options.robot, cell_path)
    if calibration is not None and calibration.model == file_options.robot:
        file_options.calibration = calibration
        notes.append(f"on this very arm: the {calibration.model} calibration of the program's "
                     "<kinematics>")
    file_options.unknown_globals = urcap_values(generated, module)
    if file_options.unknown_globals:
        notes.append("unknown values from URCap nodes: "
                     + ", ".join(sorted(file_options.unknown_globals)))
    report = check_tree(module, generated.filename, file_options)
    report.inferred = inference
    report.findings = node_findings(generated, [
        f for f in report.findings if not _polyscope_threads_only(f)])
    source = module.span.source
    for diagnostic in urcap_diagnostics(generated):
        span = n.Span(source, _offset(generated.text, diagnostic.line), _offset(
            generated.text, diagnostic.line) + len(diagnostic.source_line or "")) \
            if diagnostic.line else n.NO_SPAN
        report.findings.append(Finding(URCAP_CODE, "info", diagnostic.message, span))
    report.findings.sort(key=lambda f: (f.span.line, f.span.column, f.time or 0.0, f.code))
    report.context = "; ".join(notes)
    report.generated = generated  # type: ignore[attr-defined]
    return report


_THREADS_LEFT = re.compile(r"thread\(s\) (.+?) still ran")


def _polyscope_threads_only(finding) -> bool:
    """A URS311 finding about PolyScope's own step-counter thread only (the controller stops
    it at the program's end, as it is meant to)."""
    if finding.code != "URS311":
        return False
    names = _THREADS_LEFT.search(finding.message)
    return names is not None and all(name.startswith("Step_Counter_Thread_")
                                     for name in names.group(1).split(", "))


def _offset(text: str, line: int) -> int:
    """Character offset of the start of 1-based ``line`` in ``text``."""
    offset = 0
    for _ in range(line - 1):
        offset = text.index("\n", offset) + 1
    return offset
