"""Compiling a PolyScope program tree to URScript as PolyScope does.

:func:`compile_program` turns a :class:`~urdsl.polyscope.urp.Program` (and, when known, its
:class:`~urdsl.polyscope.installation.Installation`) into a URScript syntax tree; the one
printer (:mod:`urdsl.script.printer`) writes the text. Nothing here writes URScript text:
statements PolyScope generates are built as tree nodes, and the code users typed into the
program (expressions, script lines, script files) is parsed into tree nodes.

What PolyScope generates, learned from programs saved by PolyScope 3.x and 5.x beside their
``.script``:

* ``def NAME():`` where NAME is the program name with every character that is not a letter,
  digit or ``_`` removed; the installation's preamble; one ``global W_p=p[...]`` (the
  waypoint's pose: forward kinematics of its joint angles with the arm's calibration and the
  waypoint's TCP) and ``global W_q=[...]`` per fixed waypoint; subprogram ``def``s; the
  BeforeStart sequence; threads; then the Robot Program, inside ``while (True):`` unless it
  runs only once.
* Every program node gets a ``$ N "label"`` marker. N counts the nodes in program order:
  BeforeStart, the Robot Program, then threads and subprograms in the order the file lists
  them; a subprogram's nodes are counted with the subprogram, not at its calls.
* URCap nodes become a block ``# begin: URCap Program Node`` / ``# end: URCap Program Node``
  with ``#   Source: ...`` and ``#   Type: ...`` comments: their code only the URCap can
  generate, so the block holds no statements.

Marker labels are the English ones; PolyScope writes them in the language it runs in.
"""

from __future__ import annotations

import dataclasses
import math
import posixpath
import re
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..script import parse
from ..script.diagnostics import ScriptError
from ..script.nodes import (
    Assign,
    BinOp,
    Bool,
    Break,
    Call,
    Comment,
    Declare,
    Elif,
    EnterCritical,
    ExitCritical,
    Expr,
    ExprStmt,
    FunctionDef,
    Halt,
    If,
    Index,
    Item,
    Join,
    Keyword,
    Kill,
    List,
    Marker,
    Module,
    Name,
    Number,
    Param,
    Paren,
    Pose,
    Return,
    Run,
    String,
    ThreadDef,
    UnaryOp,
    While,
)
from ..script.parser import keywords
from ..script.printer import format as print_tree
from .export import Export
from .installation import Installation
from .preamble import _call, _num, _stmt, _version, payload_statements, preamble
from .urp import Expression, Kinematics, Node, Program
from .variables import parse_variables_file

__all__ = ["CompileError", "Compiled", "FileReader", "compile_program", "names_installation",
           "parse_variables", "script_file_candidates", "waypoint_pose"]

FileReader = Callable[[str], "bytes | None"]
"""Reads a file by its path relative to the program's folder (``/``-separated, ``..``
allowed); ``None`` when there is no such file."""


class CompileError(Exception):
    """A program node that cannot be compiled; the message names the file and node path."""


SAFE_HOME = "urdsl_safe_home"
"""The name a SafeHome node moves to when the installation the program names is not beside
it: the installation's safe home joint positions (rad), unknown to urdsl."""


def names_installation(program: Program, path: str) -> bool:
    """Whether the installation file at ``path`` is the one ``program`` names: by its name or
    its relative path, or named like the program (the files renamed together); any one when
    the program names none."""
    if not program.installation:
        return True
    stem = posixpath.basename(path.replace("\\", "/"))
    stem = stem[:-len(".installation")] if stem.endswith(".installation") else stem
    return stem in {program.installation, posixpath.basename(program.installation_path or ""),
                    posixpath.splitext(posixpath.basename(program.path.replace("\\", "/")))[0]}


@dataclass
class Compiled:
    """The result: ``module`` (the URScript tree), ``numbers`` (marker number → node) and
    ``labels`` (marker number → label)."""

    module: Module
    numbers: dict[int, Node] = field(default_factory=dict)
    labels: dict[int, str] = field(default_factory=dict)
    """Marker number → the label PolyScope shows (in English)."""
    unknown: dict[str, str] = field(default_factory=dict)
    """Names standing for what only the missing installation gives, in order, each with what
    it stands for: its I/O names (a renamed pin or a Modbus signal: read as a name of that
    value, their Set nodes left with their marker alone) and its safe home position
    (``SAFE_HOME``). Unknown to the check; a controller would stop at the first of them."""
    exported: dict[str, str] = field(default_factory=dict)
    """Of :attr:`unknown`, the I/O names the installation beside the program lacks and the
    export beside it (:mod:`urdsl.polyscope.export`) adds: name → that export's file name.
    The installation the program ran with gave them."""
    export: Export | None = None
    """What that export defines (read when an installation was found for the program)."""

    def unknown_text(self) -> str:
        """:attr:`unknown` for a message: ``gripper (an I/O), urdsl_safe_home (the safe home
        position)``."""
        return ", ".join(f"{name} ({what})" for name, what in self.unknown.items())

    @property
    def text(self) -> str:
        """The URScript text, printed by the one printer."""
        return print_tree(self.module)

    def kinds_in_diff(self, ours: list[str], theirs: list[str]) -> list[str]:
        """Node kinds owning the lines of ``ours`` that differ from ``theirs`` (both lists of
        printed lines; a line belongs to the nearest marker above it)."""
        import difflib

        owner: list[str] = []
        current = "preamble"
        for line in ours:
            match = re.match(r"\s*\$ (\d+)", line)
            if match:
                node = self.numbers.get(int(match.group(1)))
                current = node.kind if node is not None else "?"
            owner.append(current)
        kinds = set()
        matcher = difflib.SequenceMatcher(a=theirs, b=ours, autojunk=False)
        for tag, _i1, _i2, j1, j2 in matcher.get_opcodes():
            if tag == "equal":
                continue
            for index in range(max(0, j1 - (j1 == j2)), max(j2, j1 + 1)):
                if index < len(owner):
                    kinds.add(owner[index])
        return sorted(kinds)


# ---- waypoint poses ------------------------------------------------------------------------


def _dh(theta: float, d: float, a: float, alpha: float) -> list[list[float]]:
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d], [0.0, 0.0, 0.0, 1.0]]


def _matmul4(a: list[list[float]], b: list[list[float]]) -> list[list[float]]:
    """The product of two 4×4 matrices, each element summed over k = 0..3 in turn in plain
    double arithmetic (no fused multiply-add, no vector reordering). Near a half turn the
    rotation vector's angle depends on the last bit of the trace (π - 1.5e-8 for a trace one
    rounding step above -1), so the rounding of these sums decides what PolyScope writes:
    this order reproduces 44 of 48 such waypoints PolyScope wrote (eggsu, inaki1111,
    CA-Giken, orlandingabriel, manelpuig), numpy's product 38."""
    return [[a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + a[i][3] * b[3][j]
             for j in range(4)] for i in range(4)]


def _rotvec_to_matrix(rv) -> np.ndarray:
    rv = np.asarray(rv, dtype=float)
    angle = float(np.linalg.norm(rv))
    if angle < 1e-300:
        return np.eye(3)
    k = rv / angle
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx


def _matrix_to_rotvec(m: np.ndarray) -> np.ndarray:
    """Rotation vector of a rotation matrix, angle in [0, π] (as the controller's
    ``rotmat2rotvec``)."""
    axis = np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])
    sin2 = float(np.linalg.norm(axis))
    angle = math.atan2(sin2 / 2.0, (np.trace(m) - 1.0) / 2.0)  # acos loses digits near π
    if angle < 1e-12:
        return np.zeros(3)
    if math.pi - angle < 1e-6:
        # near π the antisymmetric part vanishes: as PolyScope, the angle from the acos of
        # the trace (π - 1.5e-8 for a trace one rounding step above -1) and the axis from
        # the symmetric part, its largest component positive (a half turn [U: one project])
        cos = min(1.0, max(-1.0, (float(np.trace(m)) - 1.0) / 2.0))
        exact, angle = angle, math.acos(cos)
        b = ((m + m.T) / 2.0 - cos * np.eye(3)) / (1.0 - cos)
        column = int(np.argmax(np.diag(b)))
        axis = b[:, column] / np.linalg.norm(b[:, column])
        if math.pi - exact > 1e-9 and float(axis @ np.array(
                [m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])) < 0:
            axis = -axis  # not quite a half turn: the antisymmetric part gives the sign
        return axis * angle
    return axis / sin2 * angle


def _java_hash(text: str) -> int:
    """Java's ``String.hashCode`` (UTF-16 code units), as an unsigned 32-bit number."""
    value = 0
    for unit in text.encode("utf-16-be").hex(" ", 2).split():
        value = (31 * value + int(unit, 16)) & 0xFFFFFFFF
    return value


def java_hash_order(names: list[str]) -> list[str]:
    """``names`` (given in the order they were added) in the order a Java ``HashSet`` of
    them iterates: by bucket (the hash with its high half folded in, modulo a table of 16
    slots doubled while more than 3/4 full), then in the order added. PolyScope writes a
    program's timers in this order (seen: eight timers of CA-Giken/docker-noetic-capc
    MAIN and two of mswaidan/finishing-line modbustest, both as this gives)."""
    size = 16
    while len(names) > size * 3 // 4:
        size *= 2

    def bucket(name: str) -> int:
        value = _java_hash(name)
        return (value ^ (value >> 16)) & (size - 1)

    return sorted(names, key=bucket)  # a stable sort keeps the order added in a bucket


_NAME_FIELDS = {Name: "id", Run: "thread", Declare: "name", Param: "name",
                FunctionDef: "name", ThreadDef: "name"}
"""The node fields that hold a name the program defines or uses."""


def ascii_name(name: str) -> str:
    """A name as PolyScope writes it in a script: each character beyond ASCII becomes
    ``u`` and its code point in decimal (seen: a thread "スレッド_2" is
    ``u12473u12524u12483u12489_2``, a waypoint "ウェイポイント_1" ``u12454…u12488_1_p``)."""
    return "".join(c if ord(c) < 128 else f"u{ord(c)}" for c in name)


def _ascii_code(text: str) -> str:
    """URScript text with the characters beyond ASCII outside strings and comments written
    as :func:`ascii_name` writes them (a name typed in PolyScope's own language, e.g. the
    waypoint "ウェイポイント_1_p" in an expression)."""
    if text.isascii():
        return text
    out: list[str] = []
    quote: str | None = None
    comment = False
    for c in text:
        if comment:
            comment = c != "\n"
        elif quote:
            quote = None if c == quote else quote
        elif c in "\"'":
            quote = c
        elif c == "#":
            comment = True
        elif ord(c) >= 128:
            out.append(f"u{ord(c)}")
            continue
        out.append(c)
    return "".join(out)


def _ascii_names(item):
    """``item`` (a URScript tree) with every name made ASCII by :func:`ascii_name`; strings,
    comments and marker labels are kept as written."""
    if isinstance(item, tuple):
        return tuple(_ascii_names(part) for part in item)
    if not dataclasses.is_dataclass(item) or isinstance(item, type):
        return item
    changes = {}
    for spec in dataclasses.fields(item):
        value = getattr(item, spec.name)
        if spec.name == "span":
            continue
        if isinstance(value, str):
            if _NAME_FIELDS.get(type(item)) == spec.name and not value.isascii():
                changes[spec.name] = ascii_name(value)
        elif isinstance(value, tuple) or dataclasses.is_dataclass(value):
            new = _ascii_names(value)
            if new is not value:
                changes[spec.name] = new
    return dataclasses.replace(item, **changes) if changes else item


def waypoint_pose(q, tcp, kinematics: Kinematics) -> tuple[float, ...]:
    """The TCP pose (x, y, z in m, rotation vector in rad, in the base frame) of joint angles
    ``q`` (rad) with TCP offset ``tcp`` on the arm described by ``kinematics`` (standard DH;
    ``delta_theta`` added to each joint angle)."""
    transform = _dh(q[0] + kinematics.delta_theta[0], kinematics.d[0], kinematics.a[0],
                    kinematics.alpha[0])
    for i in range(1, 6):
        transform = _matmul4(transform, _dh(q[i] + kinematics.delta_theta[i], kinematics.d[i],
                                            kinematics.a[i], kinematics.alpha[i]))
    rotation = _rotvec_to_matrix(tcp[3:]).tolist()
    tool = [[*rotation[i], float(tcp[i])] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]
    transform = _matmul4(transform, tool)
    rv = _matrix_to_rotvec(np.array([row[:3] for row in transform[:3]]))
    return tuple(float(transform[i][3]) for i in range(3)) + tuple(float(x) for x in rv)


# ---- the compiler --------------------------------------------------------------------------

_PIN = re.compile(r"^([A-Za-z_]+)\[(\d+)\]$")
_SET_FUNCTIONS = {
    "digital_out": "set_standard_digital_out", "configurable_out": "set_configurable_digital_out",
    "tool_out": "set_tool_digital_out", "analog_out": "set_standard_analog_out",
    "config_out": "set_configurable_digital_out",
    # the general purpose registers (RTDE), as PolyScope writes them (seen: bool and int)
    "GP_bool_out": "write_output_boolean_register", "GP_int_out": "write_output_integer_register",
    "GP_float_out": "write_output_float_register",
}
_GET_FUNCTIONS = {
    "digital_in": "get_standard_digital_in", "digital_out": "get_standard_digital_out",
    "configurable_in": "get_configurable_digital_in", "config_in": "get_configurable_digital_in",
    "configurable_out": "get_configurable_digital_out",
    "config_out": "get_configurable_digital_out",
    "tool_in": "get_tool_digital_in", "tool_out": "get_tool_digital_out",
    "analog_in": "get_standard_analog_in", "tool_analog_in": "get_tool_analog_in",
    "analog_out": "get_standard_analog_out",
    "GP_bool_in": "read_input_boolean_register", "GP_bool_out": "read_output_boolean_register",
    "GP_int_in": "read_input_integer_register", "GP_int_out": "read_output_integer_register",
    "GP_float_in": "read_input_float_register", "GP_float_out": "read_output_float_register",
}
_DEFAULT_CASE = "2147483647"
"""The ``caseValue`` of a Switch's Default Case (Java's ``Integer.MAX_VALUE``; seen in files
of PolyScope 5.8 and 5.15)."""
_BASE_FEATURES = frozenset(("Joint_0_name", "Base", "base"))
"""Names PolyScope gives the base frame in a move's feature reference."""
_TOOL_FEATURES = frozenset(("Joint_6_name", "Tool", "tool"))
"""... and the tool flange."""


def _floats_or_none(text: str | None) -> tuple[float, ...] | None:
    if not text:
        return None
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        return None


def _blend_kept(move: Node, motion: Node) -> bool:
    """Whether a process move (MoveP) keeps the blend of ``motion``: always but at its last
    motion, which keeps it only when what follows in the program tree is another MoveP, into
    which it can blend. What follows is the next node beside the move; when the move is the
    last one of its parent (a Loop, If, Folder, Force, a Move ...), the node after that
    parent, and so on up. After the Robot Program's last node comes its first one again when
    the program loops. When nothing follows (the end of a program run once, of a
    subprogram, of a thread), the blend is kept: PolyScope drops it only for a node it finds
    (seen: 5.9, a MoveP that ends a Loop followed by a MoveL writes r=0; 5.12, a MoveP ending
    a MoveJ's children in a looping program whose first node is a MoveJ, r=0; 5.7, a MoveP
    ending a Force that ends a program run once, and 5.8, a MoveP ending a subprogram, keep
    theirs)."""
    if move.fields.get("motion_type") != "MoveP":
        return True
    motions = [child for child in move.children
               if child.kind in ("Waypoint", "CircleMove") and not child.suppressed]
    if not motions or motion is not motions[-1]:
        return True
    node = move
    while True:
        parent = node.parent
        if parent is None:
            return True
        siblings = [child for child in parent.children if not child.suppressed]
        index = siblings.index(node) if node in siblings else -1
        if 0 <= index < len(siblings) - 1:
            following = siblings[index + 1]
            break
        if parent.kind == "MainProgram":
            if parent.attrs.get("runOnlyOnce") != "true" and siblings:
                following = siblings[0]
                break
            return True
        if parent.kind == "SubProgram":
            return True
        node = parent
    return following.kind == "Move" and following.fields.get("motion_type") == "MoveP"


def _no_break(item: Item) -> Item:
    """``item`` with each ``$`` marker in it (nested blocks too) flagged ``noBreak``."""
    from dataclasses import fields, replace

    if isinstance(item, Marker):
        return Marker(item.number, item.text, "noBreak")
    changes: dict[str, object] = {}
    for f in fields(item):  # type: ignore[arg-type]
        value = getattr(item, f.name)
        if f.name in ("body", "orelse") and isinstance(value, tuple):
            changes[f.name] = tuple(_no_break(inner) for inner in value)
        elif f.name == "elifs" and isinstance(value, tuple):
            changes[f.name] = tuple(replace(e, body=tuple(_no_break(i) for i in e.body))
                                    for e in value)
    return replace(item, **changes) if changes else item  # type: ignore[type-var]


def _no_markers(item: Item) -> Item | None:
    """``item`` without the ``$`` markers in it (nested blocks too); None for a marker."""
    from dataclasses import fields, replace

    if isinstance(item, Marker):
        return None

    def kept(block: tuple[Item, ...]) -> tuple[Item, ...]:
        return tuple(inner for i in block if (inner := _no_markers(i)) is not None)

    changes: dict[str, object] = {}
    for f in fields(item):  # type: ignore[arg-type]
        value = getattr(item, f.name)
        if f.name in ("body", "orelse") and isinstance(value, tuple):
            changes[f.name] = kept(value)
        elif f.name == "elifs" and isinstance(value, tuple):
            changes[f.name] = tuple(replace(e, body=kept(e.body)) for e in value)
    return replace(item, **changes) if changes else item  # type: ignore[type-var]


def _direction_helper() -> list[Item]:
    """The function PolyScope defines for Direction nodes: the waypoint ``position_distance``
    (m) from the target along ``direction`` given in ``feature``."""
    posdir = List(tuple(Index(Name("direction"), (Number(i),)) for i in range(3)))
    normalized = "direction_vector_normalized"
    displacement = Pose(tuple(
        BinOp("*", Index(Name(normalized), (Number(i),)), Name("position_distance"))
        for i in range(3)) + (Number(0), Number(0), Number(0)))
    body: tuple[Item, ...] = (
        Declare("local", "posDir", posdir),
        If(Paren(BinOp("<", _call("norm", Name("posDir")), _num(1e-6))),
           (Return(_call("get_target_waypoint")),)),
        Declare("local", normalized, _call("normalize", Name("posDir"))),
        Declare("local", "displacement_pose", displacement),
        Declare("local", "wanted_displacement_in_base_frame",
                _call("pose_sub", _call("pose_trans", Name("feature"),
                                        Name("displacement_pose")), Name("feature"))),
        Return(_call("pose_add", _call("get_target_waypoint"),
                     Name("wanted_displacement_in_base_frame"))),
    )
    return [FunctionDef("calculate_point_to_move_towards",
                        (Param("feature"), Param("direction"), Param("position_distance")),
                        body)]
_POPUP_TITLES = {"Message": "Message", "Warning": "Warning", "Error": "Error"}


def compile_program(program: Program, installation: Installation | None = None,
                    variables: list[tuple[str, str]] | None = None,
                    files: FileReader | None = None, export: Export | None = None) -> Compiled:
    """Compile ``program`` as PolyScope does, with its installation and the installation's
    variables (``NAME.variables`` beside it: (name, value as written) pairs, see
    :func:`parse_variables`). ``files`` reads the script files the program's Script nodes
    name (see :func:`script_file_candidates`): PolyScope compiles a script file's current
    contents, and the copy the ``.urp`` keeps (``cachedContents``) only stands in when the
    file is not found. ``export``: what PolyScope's export beside the program defines (see
    :mod:`urdsl.polyscope.export`): an I/O the installation lacks and the export adds is an
    unknown value (:attr:`Compiled.exported`), not a node that cannot compile. Raises
    :class:`CompileError` naming the file and node for a node it cannot compile."""
    return _Compiler(program, installation, variables or [], files, export).run()


def script_file_candidates(program: Program, file: str) -> list[str]:
    """Where a script file a Script node names (``file``: its path on the robot, e.g.
    ``/programs/cell/scripts/init.script``) may be, as paths relative to the program's
    folder, most likely first: its path relative to the folder the program was saved in
    (``directory``), then ever shorter tails of its path beside the program (a copy of the
    robot's programs is often laid out differently: ``scripts/init.script``,
    ``init.script``)."""
    out: list[str] = []
    file = file.replace("\\", "/").strip()
    if not file:
        return out
    if program.directory and file.startswith("/") and program.directory.startswith("/"):
        out.append(posixpath.relpath(file, program.directory))
    parts = [part for part in file.split("/") if part and part not in (".", "..")]
    for index in range(len(parts)):
        tail = "/".join(parts[index:])
        if tail not in out:
            out.append(tail)
    return out


def parse_variables(data: bytes) -> list[tuple[str, str]]:
    """The installation variables of a ``.variables`` file's bytes, ``(name, value as
    written)`` in file order, as :func:`urdsl.polyscope.variables.parse_variables_file` reads
    them (lines that are not ``name=value`` with a URScript value are left out: ``urdsl lint``
    of the file reports them)."""
    return [(variable.name, variable.text)
            for variable in parse_variables_file(data, "<variables>").variables]


class _Compiler:
    def __init__(self, program: Program, installation: Installation | None,
                 variables: list[tuple[str, str]], files: FileReader | None = None,
                 export: Export | None = None) -> None:
        self.program = program
        self.files = files
        self.export = export
        self.exported: dict[str, str] = {}  # I/O names only the export gives: its file name
        self.installation = installation
        self.variables = variables
        self.numbers: dict[int, Node] = {}
        self.number_of: dict[int, int] = {}
        self.waypoints: dict[str, Node] = {}
        self.counter = 0
        self.labels: dict[int, str] = {}
        self.pins = dict(getattr(installation, "io_names", ()) or ())
        self.base_variable = bool(getattr(installation, "base_variable", False))
        self.version = program.major_version or 5
        self.pulses = 0  # single pulse threads written so far
        self.unknown: dict[str, str] = {}  # names of a missing installation's values, in order
        saved = _version(program.saved_in or program.created_in)
        # PolyScope before 3.12 (seen: 3.5.0, 3.8.0, 3.10.1 and 3.11.0; 3.12.1, 3.14.1,
        # 3.15 on write them) writes its markers without the breakAfter/noBreak flags, and
        # before 3.11 (seen: 3.10.1, alan1982br/gs1_carnaval_Photobooth_robot_arm_UR) none
        # for a Case node nor for the nodes in a Thread node, which it numbers all the same;
        # 3.11.0 (Grzegorr/Paper-Potato-UR5 kg_client) writes both, as 3.12 on do; 3.8.0
        # (not 3.5.0, 3.10.1, 3.11.0, 3.12.1, 3.14.1 or 3.15) writes no marker for the
        # Robot Program node [U: 3.9; Case and Thread markers before 3.10]
        # PolyScope 5 before 5.6 writes no flags either (seen: 5.4.2 and 5.5.1, waypoint
        # markers without "breakAfter"; 5.7.0 on with them); the flags came with breakpoints
        # and single step, 3.12 and 5.6 [U: 5.6, 5.0-5.3]
        early = (saved[0] == 3 and saved < (3, 12)) or (saved[0] == 5 and saved < (5, 6))
        self.flags = not early
        self.inner_markers = not (saved[0] == 3 and saved < (3, 11))
        self.main_marker = not ((3, 6) <= saved < (3, 10))
        # before breakpoints a suppressed node is numbered as one, whatever it holds (seen:
        # 3.5.4, jmtc7 7_4_pruebas_modbus: a suppressed MoveJ with its waypoint is one
        # number; 3.15, 5.x number every node in it) [U: 3.6-3.11, 5.0-5.5]
        self.suppressed_as_one = early
        # PolyScope 3.2 (seen: nedlecky/UR KeyenceRobotVisionSample, 3.2.20175) writes no
        # marker for a Script node of a file (3.4.0 does: ryanpennings/RTDE_UR rtde_2,
        # ``$ 8 "Script: int"``) and titles every Popup "Message" (an Error popup too:
        # ``popup("…", "Message", False, True, blocking=True)``); 3.5 on as now
        # [U: 3.3 for the marker, 3.3-3.4 for the title]
        self.old_polyscope3 = saved[0] == 3 and saved < (3, 5)
        self.script_file_marker = not (saved[0] == 3 and saved < (3, 4))

    # -- numbering
    def _number_tree(self, node: Node) -> None:
        stack = [node]
        while stack:
            current = stack.pop()
            self.counter += 1
            self.number_of[id(current)] = self.counter
            self.numbers[self.counter] = current
            if current.kind == "CallSubProgram":
                continue
            if current.suppressed and self.suppressed_as_one:
                continue
            stack.extend(reversed(current.children))

    def number(self, node: Node) -> int:
        return self.number_of.get(id(node), 0)

    def run(self) -> Compiled:
        program = self.program
        for node in program.top:
            self._number_tree(node)
        body: list[Item] = []
        body.extend(self.preamble())
        timers = [node.name for node in self._all_nodes(suppressed=True)
                  if node.kind == "Timer" and node.name and not node.suppressed]
        # each timer's global, by name, before the waypoint globals (seen: CA-Giken MAIN,
        # mswaidan modbustest), unless the preamble declares it (a timer in the variables
        # setup is written once, with that value: GapeCobot/Soudure)
        declared = {item.name for item in body if isinstance(item, Declare)}
        body.extend(Declare("global", name, Number(0)) for name in sorted(set(timers))
                    if name not in declared)
        timers = []
        direction_helper = False
        for node in self._all_nodes(suppressed=True):
            if node.suppressed:
                continue
            if node.kind == "Direction" and not direction_helper:
                direction_helper = True  # PolyScope defines it where the first one is
                body.extend(_direction_helper())
            if node.kind == "Waypoint" and node.fields.get("type") in ("Fixed", "Relative"):
                if (node.name or "Waypoint") not in self.waypoints:
                    self.waypoints[node.name or "Waypoint"] = node
                    body.extend(self.waypoint_globals(node))
            if node.kind == "Timer" and node.name and node.name not in timers:
                timers.append(node.name)
        body.extend(self.timer_thread(timers))
        for sub in program.subprograms:
            body.extend(self.subprogram(sub))
        if program.before_start is not None:
            body.extend(self.node(program.before_start))
        for thread in program.threads:
            body.extend(self.thread(thread))
        events = [node for node in program.others if node.kind == "Event" and not node.suppressed]
        body.extend(self.event_thread(events))
        main = self.node(program.main)
        if program.main.attrs.get("runOnlyOnce") == "true":
            body.extend(main)
        else:
            body.append(While(Paren(Bool(True)), tuple(main)))
        name = re.sub(r"[^A-Za-z0-9_]", "", program.name) or "program"
        if name[0].isdigit():
            name = "_" + name
        if name in keywords():
            # a program named with a word of the language: PolyScope prefixes a P
            # (5.13.1: ``run.urp`` is ``def Prun():``, Baxterminator/RoboTech-24)
            # [U: other words]
            name = "P" + name
        module = _ascii_names(Module((FunctionDef(name, (), tuple(body)),)))
        return Compiled(module, self.numbers, self.labels, dict(self.unknown),
                        dict(self.exported), self.export)

    def _all_nodes(self, suppressed: bool = False):
        """Nodes in program order; with ``suppressed``, suppressed subtrees too (each node in
        them has ``suppressed`` set)."""
        roots = [node for node in self.program.top if node is not self.program.init_variables]
        for root in roots:
            if root is None:
                continue
            stack = [root]
            while stack:
                node = stack.pop()
                if node.suppressed and not suppressed:
                    continue
                if node.suppressed:
                    for inner in node.walk():
                        inner.suppressed = True
                yield node
                stack.extend(reversed(node.children))

    # -- errors and user code
    def error(self, node: Node, message: str) -> CompileError:
        return CompileError(f"{self.program.path}: error: node {node.path}: {message}")

    def expr(self, text: str, node: Node) -> Expr:
        if not text.strip():
            raise self.error(node, "the node has no expression (PolyScope shows it as not "
                                   "defined and will not run the program)")
        try:
            module = parse(_ascii_code(text), self.program.path)
        except ScriptError as error:
            raise self.error(node, f"the expression {text.strip()!r} is not URScript "
                                   f"({str(error).splitlines()[0]})") from None
        items = [item for item in module.body if not isinstance(item, Comment)]
        if len(items) != 1 or not isinstance(items[0], ExprStmt):
            raise self.error(node, f"{text.strip()!r} is not one expression")
        return items[0].expr

    def script_of(self, expression: Expression, node: Node) -> str:
        """The URScript text of a PolyScope expression, its I/O pins read as PolyScope
        reads them."""
        out = []
        poses = dict(getattr(self.installation, "features", ()) or ())
        for kind, text in expression.parts:
            if kind == "io":
                out.append(print_tree(self.pin_read(text, node)))
            elif kind == "feature" and text in poses:
                # a feature as a constant: its installation pose (m, rad), written in place
                out.append(print_tree(Pose(tuple(_num(v) for v in poses[text]))))
            elif kind == "waypoint" and self.version < 5 and self._waypoint_literal(text):
                # PolyScope 3 has no waypoint globals: a fixed waypoint in an expression is its
                # pose, written in place (seen: 3.15.8, "first_p_wp≔first_p" is written
                # ``global first_p_wp=p[.431245807847, ...]``, samho_main_Fillet)
                out.append(self._waypoint_literal(text))
            else:
                out.append(Expression(((kind, text),)).script)
        return "".join(out)

    def _waypoint_literal(self, name: str) -> str | None:
        """The pose of the program's fixed waypoint ``name`` as URScript text, or None when
        the program has no such waypoint with a pose."""
        waypoint = self.waypoints.get(name)
        if waypoint is None or waypoint.fields.get("type") != "Fixed":
            return None  # a relative waypoint's form is not seen: its global's name stays
        pose = self.pose_of(waypoint)
        return print_tree(Pose(tuple(_num(v) for v in pose))) if pose is not None else None

    def code(self, text: str, node: Node) -> list[Item]:
        try:
            module = parse(text, self.program.path)
        except ScriptError as error:
            raise self.error(node, f"the script code is not URScript "
                                   f"({str(error).splitlines()[0]})") from None
        return list(module.body)

    def marker(self, node: Node, label: str, flag: str | None = None) -> Marker:
        label = label.replace('"', "'")
        self.labels[self.number(node)] = label
        return Marker(self.number(node), label, flag if self.flags else None)

    # -- preamble
    def preamble(self) -> list[Item]:
        """The installation's preamble (:func:`.preamble.preamble`)."""
        return preamble(self.program, self.installation, self.variables)

    def waypoint_globals(self, node: Node) -> list[Item]:
        """The globals PolyScope 5 writes for a fixed or relative waypoint."""
        name = node.name or "Waypoint"
        q = node.fields.get("q")
        pose = self.pose_of(node)
        if self.version < 5 or not q or pose is None:
            return []
        if node.fields.get("type") == "Relative":
            start = self.pose_of(node, "from_")
            if start is None:
                return []
            return [Declare("global", f"{name}_from_p", Pose(tuple(_num(v) for v in start))),
                    Declare("global", f"{name}_to_p", Pose(tuple(_num(v) for v in pose)))]
        return [Declare("global", f"{name}_p", Pose(tuple(_num(v) for v in pose))),
                Declare("global", f"{name}_q", List(tuple(_num(v) for v in q)))]

    def timer_thread(self, timers: list[str]) -> list[Item]:
        """The globals and the thread that count PolyScope's timers, in the order PolyScope
        keeps them (:func:`java_hash_order`)."""
        if not timers:
            return []
        timers = java_hash_order(timers)
        items: list[Item] = [Declare("global", f"{name}_is_counting", Bool(False))
                             for name in timers]
        body: list[Item] = [
            If(Paren(Name(f"{name}_is_counting")),
               (Assign(Name(name), BinOp("+", Name(name), _call("get_steptime"))),))
            for name in timers]
        body.append(_stmt("sync"))
        items.append(ThreadDef("Timer_Thread", (While(Paren(Bool(True)), tuple(body)),)))
        items.append(ExprStmt(Run("Timer_Thread")))
        return items

    def n_Timer(self, node: Node) -> list[Item]:
        name = node.name or "timer"
        action = str(node.fields.get("action", "Start"))
        label = f"{name}: {action}"
        if action == "Start":
            return [self.marker(node, label), Assign(Name(f"{name}_is_counting"), Bool(True))]
        if action == "Stop":
            return [self.marker(node, label), Assign(Name(f"{name}_is_counting"), Bool(False))]
        return [self.marker(node, label), Assign(Name(name), Number(0))]

    def pose_of(self, node: Node, prefix: str = "") -> tuple[float, ...] | None:
        """The waypoint's TCP pose: as stored (PolyScope 3), else by forward kinematics of its
        joint angles with the arm's calibration and the waypoint's TCP (PolyScope 5). The
        calibration is the one stored with those joints, else the waypoint's own (a relative
        waypoint's start may refer to a block PolyScope never filled in), else the
        program's."""
        stored = node.fields.get(prefix + "pose")
        if stored and len(stored) == 6:
            return tuple(stored)
        q = node.fields.get(prefix + "q")
        tcp = node.fields.get(prefix + "tcp_offset") or (0.0,) * 6
        kinematics = node.fields.get(prefix + "kinematics") or node.fields.get("kinematics") \
            or self.program.kinematics
        if not q or kinematics is None:
            return None
        return waypoint_pose(q, tcp, kinematics)

    # -- nodes
    def block(self, nodes: list[Node]) -> list[Item]:
        items: list[Item] = []
        index = 0
        while index < len(nodes):
            node = nodes[index]
            if node.suppressed:
                index += 1
                continue
            if node.kind == "If" and node.fields.get("type") == "If":
                chain = [node]
                index += 1
                while index < len(nodes) and nodes[index].kind == "If" and \
                        nodes[index].fields.get("type") in ("ElseIf", "Else"):
                    chain.append(nodes[index])
                    index += 1
                items.extend(self.if_chain(chain))
                continue
            items.extend(self.node(node))
            index += 1
        return items

    def node(self, node: Node) -> list[Item]:
        method = getattr(self, f"n_{node.kind}", None)
        if method is None:
            return self.n_unknown(node)
        return method(node)

    def n_unknown(self, node: Node) -> list[Item]:
        """A node type urdsl does not know: its marker, a comment naming it, its children."""
        return [self.marker(node, node.title),
                Comment(f" urdsl: PolyScope node <{node.kind}> is not compiled"),
                *self.block(node.children)]

    def n_MainProgram(self, node: Node) -> list[Item]:
        marker = [self.marker(node, "Robot Program")] if self.main_marker else []
        return [*marker, *self.block(node.children)]

    def n_SpecialSequence(self, node: Node) -> list[Item]:
        return [self.marker(node, node.attrs.get("type", "BeforeStart")),
                *self.block(node.children)]

    def n_Folder(self, node: Node) -> list[Item]:
        return [self.marker(node, node.name or "Folder"), *self.block(node.children)]

    def n_Comment(self, node: Node) -> list[Item]:
        text = f"'{node.fields.get('text', '')}'"
        return [self.marker(node, text), Comment(f" {text}")]

    def n_Switch(self, node: Node) -> list[Item]:
        """A Switch node: its value in ``switch_N``, then an if/elif chain over the cases.
        N is 1 for a Switch in no other Switch (seen: three Switch nodes in three functions
        of CA-Giken MAIN, and four one after another in one Robot Program of PolyScope 5.8,
        are all ``switch_1``); a Switch inside a case of another one needs its own variable
        to leave the outer value unchanged: N counts the enclosing Switch nodes [U]."""
        depth = 1
        parent = node.parent
        while parent is not None:
            depth += parent.kind == "Switch"
            parent = parent.parent
        variable = f"switch_{depth}"
        expression = node.fields["expression"]
        items: list[Item] = [self.marker(node, f"Switch {expression.label}"),
                             Assign(Name(variable),
                                    self.expr(self.script_of(expression, node), node))]
        cases = [child for child in node.children if not child.suppressed]
        tests: list[tuple[Expr, tuple[Item, ...]]] = []
        default: tuple[Item, ...] | None = None
        for case in cases:
            value = case.attrs.get("caseValue")
            if value == _DEFAULT_CASE:
                value = None  # the Default Case
            label = f"Case {value}" if value is not None else "Default Case"
            marker = self.marker(case, label)
            body = ((marker,) if self.inner_markers else ()) + tuple(self.block(case.children))
            if case.kind == "Case" and value is not None:
                tests.append((Paren(BinOp("==", self.expr(value, case), Name(variable))),
                              body))
            else:
                default = body
        if not tests:
            return items + list(default or ())
        first, *rest = tests
        # the first case's marker stands before the `if`, the others inside their branch
        if self.inner_markers:
            items.append(first[1][0])
            first = (first[0], first[1][1:])
        items.append(If(first[0], first[1], tuple(Elif(test, body) for test, body in rest),
                        default))
        return items

    def n_CircleMove(self, node: Node) -> list[Item]:
        move = self.move_of(node)
        points = [child for child in node.children if child.kind == "Waypoint"]
        items: list[Item] = [self.marker(node, "CircleMove")]
        if move is None or len(points) != 2:
            return items + self.block(node.children)
        via, end = points
        items.append(self.marker(via, via.name or "ViaPoint", "noBreak"))
        items.append(self.marker(end, end.name or "EndPoint", "breakAfter"))
        keywords = [(k, v) for k, v in self.motion_keywords(move, end) if k in ("a", "v")]
        blend = (end.fields.get("params") or {}).get("blendRadius", move.fields.get("blend"))
        if not _blend_kept(move, node):
            blend = 0.0
        keywords.append(("r", _num(blend or 0.0)))
        if node.attrs.get("OrientationMode") == "FIXED":
            keywords.append(("mode", Number(1)))
        items.append(ExprStmt(Call(Name("movec"), (self.target_of(via, move),
                                                    self.target_of(end, move)),
                                   tuple(Keyword(k, v) for k, v in keywords))))
        return items

    def target_of(self, node: Node, move: Node) -> Expr:
        if node.fields.get("type") == "Variable":
            target: Expr = Name(str(node.fields.get("variable") or node.name))
            feature = move.fields.get("feature")
            if feature and feature not in _BASE_FEATURES:
                target = _call("pose_trans", Name(str(feature)), target)
            elif self.in_variable_base(move):
                if move.attrs.get("motionType") != "MoveJ":
                    target = _call("pose_trans", Name("Base"), target)
            elif self.version < 5:
                # PolyScope 3 writes a variable waypoint in the base as relative to the
                # base's pose too (seen once, saved by 3.15)
                target = _call("pose_trans", Pose(tuple(_num(0.0) for _ in range(6))), target)
            return target
        return self.in_variable_feature(node, move, self.fixed_values(node)[0])

    def variable_feature(self, move: Node) -> str | None:
        """The name of the move's feature when it is a variable one (a program may move it):
        named, not the base or the tool, and variable in the installation (taken as
        variable when the installation is unknown: every feature seen in a move's feature
        reference in real programs was)."""
        feature = move.fields.get("feature")
        if not feature or feature in _BASE_FEATURES or feature in _TOOL_FEATURES:
            return None
        known = dict(getattr(self.installation, "feature_variable", ()) or ())
        if known.get(str(feature), True) is False:
            return None
        return str(feature)

    def in_variable_base(self, move: Node) -> bool:
        """A PolyScope 3 move in a variable base feature (seen: 3.14.1, ldalepfi/UR-
        Simulation-Prod): a MoveL goes to ``pose_trans(Base, p[…])`` and to
        ``pose_trans(Base, var)``, a MoveJ to a variable waypoint as it is [U: a fixed
        waypoint of a MoveJ, a MoveP]."""
        feature = move.fields.get("feature")
        return self.version < 5 and self.base_variable and (
            not feature or feature in _BASE_FEATURES)

    def in_variable_feature(self, node: Node, move: Node, pose: Expr) -> Expr:
        """A fixed waypoint's pose under a move in a variable feature, as PolyScope writes
        it: ``pose_trans(F, pose_trans(p[inverse of the feature's pose when taught], W_p))``,
        so that the waypoint follows the feature (``BaseToFeature``: the feature's pose in
        the base frame when the waypoint was taught; m, rad)."""
        feature = self.variable_feature(move)
        taught = node.fields.get("base_to_feature")
        if feature is None or not taught or len(taught) != 6:
            return pose
        rotation = _rotvec_to_matrix(taught[3:])
        inverse = tuple(-(rotation.T @ np.asarray(taught[:3], dtype=float))) + \
            tuple(_matrix_to_rotvec(rotation.T))
        return _call("pose_trans", Name(feature),
                     _call("pose_trans", Pose(tuple(_num(float(v)) for v in inverse)), pose))

    def fixed_values(self, node: Node) -> tuple[Expr, Expr]:
        """The pose and joints of a fixed waypoint: its globals (PolyScope 5), or literals
        written in place (PolyScope 3)."""
        name = node.name or "Waypoint"
        if self.version >= 5:
            return Name(f"{name}_p"), Name(f"{name}_q")
        shared = self.waypoints.get(name, node)
        q = shared.fields.get("q") or node.fields.get("q")
        pose = self.pose_of(shared) or self.pose_of(node)
        if not q or pose is None:
            raise self.error(node, "a fixed waypoint without joint angles or calibration")
        return Pose(tuple(_num(v) for v in pose)), List(tuple(_num(v) for v in q))

    def n_Halt(self, node: Node) -> list[Item]:
        return [self.marker(node, "Halt"), Halt()]

    def n_Contributed(self, node: Node) -> list[Item]:
        if node.attrs.get("strategyClass") == "ConveyorTracking":
            return self.conveyor_tracking(node)
        return [Comment(" begin: URCap Program Node"),
                Comment(f"   Source: {node.attrs.get('strategyURCapName', '?')}, "
                        f"{node.attrs.get('strategyURCapDeveloper', '?')}"),
                Comment(f"   Type: {node.title}"),
                self.marker(node, node.title),
                Comment(" end: URCap Program Node")]

    def conveyor_tracking(self, node: Node) -> list[Item]:
        """PolyScope 3's Conveyor Tracking node (``strategyClass="ConveyorTracking"``, saved
        as a URCap node of Universal Robots, compiled by PolyScope itself: no URCap block):
        marker "Tracking Conveyor N", the installation's ``start_conveyor_trackingK()``
        (K = N - 1), the children (their markers ``noBreak``), ``stop_conveyor_tracking()``
        (seen: 3.15, 14 scripts of one project, all conveyor 1; the key that selects conveyor
        2 is [U])."""
        data = {item.get("key"): item.get("value")
                for item in (node.element.find("dataModel") if node.element is not None and
                             node.element.find("dataModel") is not None else ())}
        number = data.get("conveyor") or "1"
        index = int(number) - 1 if number.isdigit() and int(number) > 0 else 0
        return [self.marker(node, f"Tracking Conveyor {index + 1}"),
                _stmt(f"start_conveyor_tracking{index}"),
                *(_no_break(item) for item in self.block(node.children)),
                _stmt("stop_conveyor_tracking")]

    def n_Wait(self, node: Node) -> list[Item]:
        kind = node.fields.get("type")
        if kind == "NoWait":  # a Wait not yet set: its marker only (seen: PolyScope 3.15)
            return [self.marker(node, "Wait: 0")]
        if kind == "Sleep":
            seconds = node.fields.get("seconds", 0.0)
            return [self.marker(node, f"Wait: {seconds}"), _stmt("sleep", _num(seconds))]
        if kind == "DigitalInput":
            pin = str(node.fields.get("pin"))
            value = node.fields.get("digital") in ("1", "true", "True")
            test = BinOp("==", self.pin_read(pin, node), Bool(not value))
            label = f"Wait {self.pin_label(pin)}={'HI' if value else 'LO'}"
            return [self.marker(node, label), While(Paren(test), (_stmt("sync"),))]
        if kind == "Condition":
            expression = node.fields["expression"]
            test = self.expr(self.script_of(expression, node), node)
            return [self.marker(node, f"Wait {expression.label}"),
                    While(Paren(UnaryOp("not", Paren(test))), (_stmt("sync"),))]
        return self.n_unknown(node)

    def pin_label(self, pin: str) -> str:
        for name, target in self.pins.items():
            if target == pin:
                return name
        return pin

    def installation_named(self) -> bool:
        """Whether the installation compiled with is the one the program names (see
        :func:`names_installation`), not another one found beside it: an I/O name only the
        named one may give is then a mistake of the program."""
        return self.installation is not None and names_installation(
            self.program, str(self.installation.path))

    def io_of_missing_installation(self, pin: str) -> bool:
        """Whether ``pin`` is a name only the installation could resolve, and it is not
        there: a user's name for a pin (``gripperopen``) or a Modbus signal. PolyScope writes
        the pin's or signal's own function, which nothing here says; urdsl reads the name
        as a value of its own (unknown to the check) and writes nothing for a Set of it.
        So too for a Modbus signal the installation beside the program lacks and PolyScope's
        export of the program adds (the installation it ran with had it)."""
        if pin in self.pins or _PIN.match(pin) or not pin.isidentifier():
            return False
        if self.installation is not None and self.installation_named():
            if self.export is None or pin not in self.export.signals:
                return False
            self.exported[pin] = self.export.path.name
        self.unknown[pin] = "an I/O"
        return True

    def resolve_pin(self, pin: str, node: Node) -> tuple[str, int]:
        target = self.pins.get(pin, pin)
        match = _PIN.match(target)
        if not match:
            raise self.error(node, f"the I/O {pin!r} is not named in the installation")
        return match.group(1), int(match.group(2))

    def modbus_signal(self, pin: str):
        """The installation's Modbus signal named ``pin`` (None when there is none)."""
        for signal in getattr(self.installation, "modbus", ()) or ():
            if signal.name == pin:
                return signal
        return None

    def pin_read(self, pin: str, node: Node) -> Expr:
        if self.io_of_missing_installation(pin):
            return Name(pin)
        if pin not in self.pins and self.modbus_signal(pin) is not None:
            return _call("modbus_get_signal_status", String(pin))
        kind, index = self.resolve_pin(pin, node)
        function = _GET_FUNCTIONS.get(kind)
        if function is None:
            raise self.error(node, f"cannot read the I/O {pin!r}")
        return _call(function, Number(index))

    def n_Set(self, node: Node) -> list[Item]:
        """A Set node: its action (an output), then the TCP it selects (``set_tcp``), as
        PolyScope writes them."""
        items = self.set_action(node)
        payload = _floats_or_none(node.attrs.get("payload"))
        if payload:
            # the payload the Set selects (kg): ``set_payload(m)`` after the action (seen:
            # PolyScope 3.12 and 3.15, ``tcpAsCog="true"``; with the centre of gravity given
            # otherwise, and in 5.x, not seen [U])
            items.append(_stmt("set_payload", _num(payload[0])))
        if node.fields.get("tcp"):
            items.extend(self.set_tcp(str(node.fields["tcp"])))
        return items

    def set_action(self, node: Node) -> list[Item]:
        kind = node.fields.get("type")
        if kind == "DigitalOutput":
            pin = str(node.fields.get("pin"))
            value = node.fields.get("digitalValue") in ("1", "true", "True")
            label = f"Set {self.pin_label(pin)}={'On' if value else 'Off'}"
            if self.io_of_missing_installation(pin):
                return [self.marker(node, label)]
            if pin not in self.pins and self.modbus_signal(pin) is not None:
                # a Modbus output signal of the installation (seen: 3.10.1,
                # alan1982br/gs1_carnaval_Photobooth_robot_arm_UR venosa draft3)
                return [self.marker(node, label),
                        _stmt("modbus_set_output_signal", String(pin), Bool(value))]
            bank, index = self.resolve_pin(pin, node)
            function = _SET_FUNCTIONS.get(bank)
            if function is None:
                raise self.error(node, f"cannot set the I/O {pin!r}")
            return [self.marker(node, label), _stmt(function, Number(index), Bool(value))]
        if kind == "AnalogOutput":
            pin = str(node.fields.get("pin"))
            value = float(str(node.fields.get("analogValue", "0")))
            if self.io_of_missing_installation(pin):
                return [self.marker(node, f"Set {pin}={value}")]
            bank, index = self.resolve_pin(pin, node)
            return [self.marker(node, f"Set {self.pin_label(pin)}={value}"),
                    _stmt("set_standard_analog_out", Number(index),
                          _num(value / self.analog_full_scale(index)))]
        if kind == "ExpressionOutput":
            return self.set_expression(node)
        if kind == "SingleDigitalPulseActionState":
            return self.set_pulse(node)
        if kind == "NoAction":
            return [self.marker(node, "Set")]
        if kind == "IncrementVariable" and node.fields.get("variable"):
            # adds one to a variable: marker "Set i_count=i_count+1", then
            # ``i_count = i_count + 1`` (seen: an installation variable, PolyScope 5.9.1,
            # manelpuig/Project_Assistive_Robotics 06_var_global_01)
            name = str(node.fields["variable"])
            return [self.marker(node, f"Set {name}={name}+1"),
                    Assign(Name(name), BinOp("+", Name(name), Number(1)))]
        return self.n_unknown(node)

    def n_SetPayload(self, node: Node) -> list[Item]:
        """A Set Payload node that selects one of the installation's payloads by name
        (``workpieceName``): marker "Set Payload: NAME", then the statement the preamble
        writes for a payload (seen: ``set_target_payload(mass, cog, inertia)``). Another
        variant, or a payload the installation does not have, stays an unknown node."""
        name = node.attrs.get("workpieceName")
        payloads = getattr(self.installation, "payloads", ()) or ()
        payload = next((p for p in payloads if p.name == name), None)
        if not name or payload is None or self.installation is None:
            return self.n_unknown(node)
        return [self.marker(node, f"Set Payload: {name}"),
                *payload_statements(self.installation, payload)]

    def set_pulse(self, node: Node) -> list[Item]:
        """A Set node's single digital pulse: a thread sets the output high, sleeps the
        pulse's length (s) and sets it low; the program starts it and goes on, as PolyScope
        writes it (seen: ``hiPulseInSeconds``, standard outputs and boolean output
        registers). PolyScope numbers these threads ``SinglePulseN`` from a counter it
        keeps across the programs it compiles (one project shows 2, 3 in one program and
        397-402 in another), which no file records: urdsl counts them in the program from
        1. A low pulse is not seen and stays an unknown node."""
        pulse = node.fields.get("pulse") or {}
        length = _floats_or_none(pulse.get("hiPulseInSeconds"))
        if not length:
            return self.n_unknown(node)
        pin = str(node.fields.get("pin"))
        if self.io_of_missing_installation(pin):
            return [self.marker(node, f"Set {pin}=HI:Pulse {length[0]}")]
        bank, index = self.resolve_pin(pin, node)
        function = _SET_FUNCTIONS.get(bank)
        if function is None:
            raise self.error(node, f"cannot set the I/O {pin!r}")
        self.pulses += 1
        name = f"SinglePulse{self.pulses}"
        body = (_stmt(function, Number(index), Bool(True)),
                _stmt("sleep", _num(length[0])),
                _stmt(function, Number(index), Bool(False)))
        return [self.marker(node, f"Set {self.pin_label(pin)}=HI:Pulse {length[0]}"),
                ThreadDef(name, body),
                Assign(Name(f"singlePulse{self.pulses}"), Run(name))]

    def analog_full_scale(self, index: int) -> float:
        """What an analog output's value (as the Set node stores it: V, or mA) is at the
        ratio 1 that ``set_standard_analog_out`` takes: 10 V in the voltage domain (seen);
        20 mA in the current domain [U]. The domain is the installation's
        (``IOs/analogOutputDomain``: 0 current, 1 voltage); voltage when it is unknown [U]."""
        settings = (getattr(self.installation, "settings", None) or {})
        text = settings.get("IOs/analogOutputDomain", {}).get("value", "")
        domains = [part.strip() for part in text.split(",")]
        if index < len(domains) and domains[index] == "0":
            return 20.0
        return 10.0

    def set_expression(self, node: Node) -> list[Item]:
        """A Set node whose output takes an expression's value: a Modbus output signal
        (``modbus_set_output_signal``, as PolyScope writes it), else the output's set
        function with the expression (a form inferred, not yet seen [U])."""
        pin = str(node.fields.get("pin"))
        expression = node.fields["expression"]
        value = self.expr(self.script_of(expression, node), node)
        label = f"Set {self.pin_label(pin)}={expression.label}"
        if self.io_of_missing_installation(pin):
            return [self.marker(node, label)]
        signal = self.modbus_signal(pin) if pin not in self.pins else None
        if signal is not None:
            if signal.kind != "DIGITAL_OUTPUT":
                return self.n_unknown(node)
            return [self.marker(node, label),
                    _stmt("modbus_set_output_signal", String(pin), value)]
        bank, index = self.resolve_pin(pin, node)
        function = _SET_FUNCTIONS.get(bank)
        if function is None:
            raise self.error(node, f"cannot set the I/O {pin!r}")
        return [self.marker(node, label), _stmt(function, Number(index), value)]

    def n_Assignment(self, node: Node) -> list[Item]:
        expression = node.fields["expression"]
        name = node.name or "var"
        if node.fields.get("source") == "Operator":
            # the operator types the value in (seen: Snupai/SZ, 5.9, integer and string:
            # '$ 3 "Artikel≔'Artikelnummer eingeben'"' then
            # ``global Artikel=request_string_from_primary_client("Artikelnummer eingeben")``)
            kind = str(node.fields.get("value_type") or "Integer").lower()
            message = str(node.fields.get("message", ""))
            return [self.marker(node, f"{name}≔'{message}'"),
                    Declare("global", name, _call(f"request_{kind}_from_primary_client",
                                                  String(message.replace('"', "'"))))]
        label = f"{name}≔{expression.label}"
        text = self.script_of(expression, node)
        try:
            value = self.expr(text, node)
        except CompileError:
            # PolyScope writes ``global NAME= TEXT`` whatever TEXT is: two calls typed one
            # after the other are a declaration and a statement (seen: o2ac/o2ac-ur 5.9,
            # "currentpose≔get_actual_tcp_pose()get_actual_joint_positions()")
            try:
                items = parse(_ascii_code(f"global {name}={text}\n"), self.program.path).body
            except ScriptError:
                items = ()
            if not items or not isinstance(items[0], Declare) or \
                    not all(isinstance(item, ExprStmt) for item in items[1:]):
                raise
            return [self.marker(node, label), *items]
        return [self.marker(node, label), Declare("global", name, value)]

    def n_Script(self, node: Node) -> list[Item]:
        kind = node.fields.get("type")
        if kind == "Line":
            expression = node.fields["expression"]
            return [self.marker(node, expression.label),
                    *self.code(self.script_of(expression, node), node)]
        contents = str(node.fields.get("contents", ""))
        if kind == "File":
            path = str(node.fields.get("file", ""))
            contents = self.script_file(path) or contents
            label = f"Script: {path.rsplit('/', 1)[-1]}"
            if not self.script_file_marker:
                return self.code(contents, node)
        else:
            label = "Script"
        return [self.marker(node, label), *self.code(contents, node)]

    def script_file(self, path: str) -> str | None:
        """The current contents of the script file at ``path`` (on the robot), when the
        file reader finds it."""
        if self.files is None:
            return None
        for candidate in script_file_candidates(self.program, path):
            try:
                data = self.files(candidate)
            except OSError:
                data = None
            if data is not None:
                return data.decode("utf-8", "replace")
        return None

    def n_Popup(self, node: Node) -> list[Item]:
        kind = str(node.fields.get("type", "Message"))
        message = str(node.fields.get("message", ""))
        halt = bool(node.fields.get("halt"))
        title = "Message" if self.old_polyscope3 else _POPUP_TITLES.get(kind, kind)
        text: Expr = String(message.replace('"', "'"))
        if node.fields.get("input") == "Variable" and node.fields.get("variable"):
            variable = str(node.fields["variable"])
            text = _call("str_cat", String(""), Name(variable))
            message = variable
        items: list[Item] = [
            self.marker(node, f"Popup: {message}"),
            _stmt("popup", text, String(title),
                  Bool(kind == "Warning"), Bool(kind == "Error"), blocking=Bool(not halt))]
        if halt:
            items.append(Halt())
        return items

    def n_CallSubProgram(self, node: Node) -> list[Item]:
        name = node.name or "subprogram"
        return [self.marker(node, f"Call {name}"), _stmt(name)]

    def subprogram(self, node: Node) -> list[Item]:
        name = node.name or "subprogram"
        body = [self.marker(node, name, "noBreak"), *self.block(node.children)]
        return [FunctionDef(name, (), tuple(body))]

    def thread(self, node: Node) -> list[Item]:
        name = node.name or "Thread"
        body = self.block(node.children)
        if not self.inner_markers:
            body = [inner for item in body if (inner := _no_markers(item)) is not None]
        if node.attrs.get("runOnlyOnce") != "true":
            body = [While(Paren(Bool(True)), tuple(body))]
        return [self.marker(node, name), ThreadDef(name, tuple(body)),
                Assign(Name(f"threadId_{name}"), Run(name))]

    def event_thread(self, events: list[Node]) -> list[Item]:
        """The Event nodes: one thread, ``EventThread``, checks their expressions in file
        order every control cycle and runs the children of the first that holds (an
        ``if``/``elif`` chain). The Event nodes have no marker. It is started after the
        threads, before the Robot Program (seen only in programs without threads or
        BeforeStart [U])."""
        tests: list[tuple[Expr, tuple[Item, ...]]] = []
        for node in events:
            expression = node.fields.get("expression")
            if not isinstance(expression, Expression) or not expression:
                raise self.error(node, "the Event has no expression (PolyScope shows it as "
                                       "not defined and will not run the program)")
            tests.append((Paren(self.expr(self.script_of(expression, node), node)),
                          tuple(self.block(node.children))))
        if not tests:
            return []
        (first, body), *rest = tests
        chain = If(first, body, tuple(Elif(test, inner) for test, inner in rest))
        return [ThreadDef("EventThread", (While(Paren(Bool(True)), (chain, _stmt("sync"))),)),
                Assign(Name("eventThread"), Run("EventThread"))]

    def n_Loop(self, node: Node) -> list[Item]:
        kind = node.fields.get("type")
        body = self.block(node.children)
        if kind == "Counting":
            count = int(node.fields.get("count", 1))
            variable = str(node.fields.get("variable") or f"Loop_{self.number(node)}")
            return [self.marker(node, f"Loop {count} times"),
                    Assign(Name(variable), Number(0)),
                    While(Paren(BinOp("<", Name(variable), Number(count))),
                          (*body, Assign(Name(variable),
                                         BinOp("+", Name(variable), Number(1)))))]
        if kind == "While":
            expression = node.fields["expression"]
            text = self.script_of(expression, node)
            marker = self.marker(node, f"Loop {expression.label}")
            if node.attrs.get("checkContinuously") != "true":
                return [marker, While(Paren(self.expr(text, node)), tuple(body))]
            # checked continuously: the body runs in a thread killed when the test fails
            number = self.number(node)
            thread, handler = f"Thread_while_{number}", f"thread_handler_{number}"
            return [marker,
                    ThreadDef(thread, (While(Paren(Bool(True)), tuple(body)),)),
                    If(Paren(self.expr(text, node)), (
                        Declare("global", handler, Run(thread)),
                        While(Paren(self.expr(text, node)), (_stmt("sync"),)),
                        Kill(Name(handler))))]
        return [self.marker(node, "Loop"), While(Paren(Bool(True)), tuple(body))]

    def if_chain(self, chain: list[Node]) -> list[Item]:
        head = chain[0]
        expression = head.fields["expression"]
        body = [self.marker(head, f"If {expression.label}"), ]
        test = self.expr(self.script_of(expression, head), head)
        inner = self.block(head.children)
        orelse: tuple[Item, ...] | None = None
        if len(chain) > 1:
            nxt = chain[1]
            if nxt.fields.get("type") == "Else":
                orelse = (self.marker(nxt, "Else", "noBreak"), *self.block(nxt.children))
            else:
                rest = [Node(nxt.kind, nxt.attrs, nxt.children, nxt.name,
                             {**nxt.fields, "type": "If"}, nxt.element, nxt.parent)]
                self.number_of[id(rest[0])] = self.number(nxt)
                orelse = tuple(self._elseif(nxt, rest[0], chain[2:]))
        if head.attrs.get("checkContinuously") != "true":
            return [*body, If(Paren(test), tuple(inner), (), orelse)]
        # checked continuously: the body runs in a thread killed when the test fails
        number = self.number(head)
        flag, thread, handler = (f"thread_flag_{number}", f"Thread_if_{number}",
                                 f"thread_handler_{number}")
        items: list[Item] = [
            *body,
            Declare("global", flag, Number(0)),
            ThreadDef(thread, (*inner, Assign(Name(flag), Number(1)))),
            If(Paren(test), (
                Declare("global", handler, Run(thread)),
                While(Paren(BinOp("==", Name(flag), Number(0))), (
                    If(UnaryOp("not", Paren(test)),
                       (Kill(Name(handler)), Assign(Name(flag), Number(2))), (),
                       (_stmt("sync"),)),)),
            ), (), (Assign(Name(flag), Number(2)),))]
        if orelse is not None:
            items.append(If(Paren(BinOp("==", Name(flag), Number(2))), orelse))
        return items

    def _elseif(self, original: Node, copy: Node, rest: list[Node]) -> list[Item]:
        items = self.if_chain([copy, *rest])
        first = items[0]
        assert isinstance(first, Marker)
        expression = original.fields["expression"]
        label = f"ElseIf {expression.label}".replace('"', "'")
        self.labels[first.number or 0] = label
        return [Marker(first.number, label), *items[1:]]

    # -- direction / until
    def n_Direction(self, node: Node) -> list[Item]:
        """A Direction node: a thread moves towards a far point while the program waits for
        its Until nodes (only the distance Until is compiled as PolyScope does)."""
        number = self.number(node)
        move = self.move_of(node)
        selected = node.attrs.get("selectedDirection")
        expression = node.fields.get("expression")
        feature = node.fields.get("feature")
        variable_feature = node.fields.get("feature_name")
        if "feature" not in node.fields and move is not None:
            # a Direction without its own <feature> moves in its Move's feature (seen: under
            # a MoveL in a plane feature PolyScope labels it and writes that feature's pose)
            feature = move.fields.get("feature")
        if feature and feature not in _BASE_FEATURES and feature not in _TOOL_FEATURES:
            # a named feature: its pose written in place, as for a variable one (PolyScope
            # never writes a feature's name here in the real scripts)
            variable_feature, feature = feature, None
        frame = "Tool" if feature in _TOOL_FEATURES else (
            "Base" if feature in (None, *_BASE_FEATURES) else str(feature))
        if selected:
            axis = {"X": 0, "Y": 1, "Z": 2}[selected[0]]
            sign = -1.0 if selected.endswith("Minus") else 1.0
            vector: Expr = List(tuple(_num(sign if i == axis else 0.0) for i in range(3)))
            label = f"Direction: {frame} {selected[0]}{'-' if sign < 0 else '+'}"
        elif expression:
            vector = self.expr(self.script_of(expression, node), node)
            label = f"Direction: {frame}"
        else:
            return self.n_unknown(node)
        if variable_feature:
            # a variable feature: its pose in the installation, written in place (seen); its
            # name when the installation does not have it [U]
            poses = dict(getattr(self.installation, "features", ()) or ())
            pose = poses.get(str(variable_feature))
            feature_pose: Expr = Pose(tuple(_num(v) for v in pose)) if pose else \
                Name(str(variable_feature))
            label = label.replace(f"{frame} ", f"{variable_feature} ", 1)
        elif frame == "Tool":
            feature_pose = _call("get_forward_kin")
        elif frame == "Base":
            feature_pose = Pose(tuple(_num(0.0) for _ in range(6)))
        else:
            feature_pose = Name(frame)
        untils = [child for child in node.children if child.kind == "Until"]
        distance = 1000.0
        blend = 0.0
        for until in untils:
            if until.attrs.get("type") == "DISTANCE" and until.element is not None:
                text = until.element.findtext("Distance")
                if text:
                    distance = float(text)
                params = until.element.find("motionParameters")
                radius = _floats_or_none(params.get("blendRadius")) if params is not None \
                    else None
                if radius and radius[0] > 0 and until.attrs.get("distanceNodeType") == "BLEND":
                    blend = radius[0]  # the move blends into what follows (a STOP keeps
                    # the radius it had when it was a blend, but does not write it)
        speed = move.fields.get("speed") if move is not None else None
        accel = move.fields.get("acceleration") if move is not None else None
        move_accel = accel
        params = _floats_or_none(node.attrs.get("toolParams"))
        if params is not None and len(params) == 2:
            speed, accel = params
        flag, thread, handle = (f"move_thread_flag_{number}", f"move_thread_{number}",
                                f"move_thread_han_{number}")
        keywords = []
        if accel is not None:
            keywords.append(Keyword("a", _num(accel)))
        if speed is not None:
            keywords.append(Keyword("v", _num(speed)))
        if blend > 0:
            keywords.append(Keyword("r", _num(blend)))
        thread_body: tuple[Item, ...] = (
            EnterCritical(),
            Assign(Name(flag), Number(1)),
            Declare("local", "towardsPos", _call("calculate_point_to_move_towards",
                                                 feature_pose, vector, _num(distance))),
            # a Direction under a MoveP moves with movep (5.12: Roma4286/UniversalRobots)
            ExprStmt(Call(Name("movep" if move is not None and move.attrs.get("motionType")
                               == "MoveP" else "movel"), (Name("towardsPos"),),
                          tuple(keywords))),
            Assign(Name(flag), Number(2)),
            ExitCritical(),
        )
        items: list[Item] = [
            self.marker(node, label),
            Declare("global", flag, Number(0)),
            ThreadDef(thread, thread_body),
            Assign(Name(flag), Number(0)),
            Assign(Name(handle), Run(thread)),
        ]
        items.append(self.until_loop(untils, flag, handle, accel, move_accel))
        others = [child for child in node.children if child.kind != "Until"]
        items.extend(self.block(others))
        return items

    def until_loop(self, untils: list[Node], flag: str, handle: str,
                   accel: float | None, move_accel: float | None = None,
                   reaches_end: bool = False) -> While:
        """The loop that waits, while a move thread runs, for the first of its Until
        conditions: tool contact (checked first, whatever the order), a condition (an
        expression: the move stops at the Until's ``deceleration``, m/s², else the move's
        acceleration; seen: PolyScope 5.10), and the end of the move (distance, reached
        waypoint), in the node order. ``accel`` is the motion's own acceleration (m/s²: a
        Direction's ``toolParams``), ``move_accel`` its Move node's (when it differs).
        ``reaches_end``: the motion ends by itself (a waypoint's move); when no Until waits
        for that end, the loop still ends with the move, with no marker (PolyScope 5.17,
        srs827/Robot-Cello-ResidualRL: a Waypoint with only an expression Until)."""
        loop: list[Item] = []
        ordered = sorted(untils, key=lambda u: u.attrs.get("type") != "TOOL_CONTACT_DETECTION")
        for until in ordered:
            kind = until.attrs.get("type", "")
            label = f"Until ({kind.lower()})"
            if kind == "TOOL_CONTACT_DETECTION":
                loop.extend(self._tool_contact(
                    until, handle, move_accel if move_accel is not None else accel))
                continue
            expression = until.fields.get("expression")
            if isinstance(expression, Expression) and expression:
                decel = _floats_or_none(until.attrs.get("deceleration"))
                stop = decel[0] if decel else (accel if accel is not None else 1.2)
                test = self.expr(self.script_of(expression, until), until)
                loop.append(If(Paren(test), (
                    Kill(Name(handle)), _stmt("stopl", _num(stop)),
                    self.marker(until, label), *self.block(until.children), Break())))
                continue
            done: list[Item] = [Join(Name(handle))]
            if kind not in ("DISTANCE", "REACHED_WAYPOINT"):
                done.append(Comment(f" urdsl: {label} is not compiled"))
            done.append(self.marker(until, label))
            done.extend(self.block(until.children))
            done.append(Break())
            loop.append(_stmt("sleep", _num(1e-10)))
            loop.append(If(Paren(BinOp(">", Name(flag), Number(1))), tuple(done)))
        if reaches_end and all(u.attrs.get("type") in ("EXPRESSION", "TOOL_CONTACT_DETECTION")
                               for u in untils):
            loop.append(_stmt("sleep", _num(1e-10)))
            loop.append(If(Paren(BinOp(">", Name(flag), Number(1))),
                           (Join(Name(handle)), Break())))
        loop.append(_stmt("sync"))
        return While(Paren(Bool(True)), tuple(loop))

    def _tool_contact(self, until: Node, handle: str, accel: float | None) -> list[Item]:
        """The wait of a Direction that stops on tool contact: back off along the way it
        came by ``retraction`` (m), decelerating at ``decelerationAcceleration`` (m/s²; older
        files have none: the Move node's acceleration, not a Direction's own ``toolParams``
        one: nedlecky/UR L03_Touchoff, PolyScope 5.9, ``toolParams="0.01, 0.8"`` under a
        MoveL of 1.2 writes ``stopl(1.2)`` and retracts at ``a=1.2``)."""
        decel = float(until.attrs.get("decelerationAcceleration",
                                      accel if accel is not None else 3.0))
        retraction_text = until.attrs.get("retraction", "0.0")
        if retraction_text == "NONE":  # no retraction: stop where the contact was found
            return [
                Declare("local", "targetTcpDirection", _call("get_target_tcp_speed")),
                Declare("local", "stepsToRetract", Call(Name("tool_contact"), (), (
                    Keyword("direction", Name("targetTcpDirection")),))),
                If(Paren(BinOp(">", Name("stepsToRetract"), Number(0))), (
                    Kill(Name(handle)), _stmt("stopl", _num(decel)),
                    self.marker(until, "Until (tool_contact_detection)"),
                    *self.block(until.children), Break()))]
        retraction = float(retraction_text)
        direction = Name("targetTcpDirection")
        normalized = Name("normalizedPosDir")
        retract = Pose(tuple(BinOp("*", Index(normalized, (Number(i),)), _num(retraction))
                             for i in range(3)) + (Number(0), Number(0), Number(0)))
        found: tuple[Item, ...] = (
            Kill(Name(handle)),
            _stmt("stopl", _num(decel)),
            Declare("local", "backTrackMovement",
                    _call("get_actual_joint_positions_history", Name("stepsToRetract"))),
            Declare("local", "contactPose", _call("get_forward_kin", Name("backTrackMovement"))),
            Declare("local", "posDir", List(tuple(Index(direction, (Number(i),))
                                                  for i in range(3)))),
            Declare("local", "retractTo", Name("contactPose")),
            If(Paren(BinOp(">", _call("norm", Name("posDir")), _num(1e-6))), (
                Declare("local", "normalizedPosDir", _call("normalize", Name("posDir"))),
                Declare("local", "additionalRetraction", retract),
                Assign(Name("retractTo"), _call("pose_sub", Name("contactPose"),
                                                Name("additionalRetraction"))),
            )),
            ExprStmt(Call(Name("movel"), (Name("retractTo"),),
                          (Keyword("a", _num(decel)), Keyword("v", _num(0.1))))),
            self.marker(until, "Until (tool_contact_detection)"),
            *self.block(until.children),
            Break(),
        )
        return [
            Declare("local", "targetTcpDirection", _call("get_target_tcp_speed")),
            Declare("local", "stepsToRetract",
                    Call(Name("tool_contact"), (), (Keyword("direction", direction),))),
            If(Paren(BinOp(">", Name("stepsToRetract"), Number(0))), found)]

    def n_SafeHome(self, node: Node) -> list[Item]:
        """A move to the installation's safe home joint positions (rad). Without the
        installation the program names, the position is :data:`SAFE_HOME`, a name of a value
        only that installation gives (unknown to the check, refused by send and sim)."""
        settings = (self.installation.settings or {}) if self.installation else {}
        position = settings.get("SafeHomeSettings", {}).get("position")
        joints: Expr
        if not position and not self.installation_named():  # missing, or a stand-in
            self.unknown[SAFE_HOME] = "the safe home position"
            joints = Name(SAFE_HOME)
        elif not position:
            raise self.error(node, "the installation's safe home position is unknown "
                                   "(no installation with SafeHomeSettings beside the program)")
        else:
            joints = List(tuple(_num(float(v)) for v in position.split(",")))
        keywords: list[Keyword] = []
        if node.attrs.get("positionOptionType") == "TIME" and node.attrs.get("nextMotionTime"):
            keywords.append(Keyword("t", _num(float(node.attrs["nextMotionTime"]))))
        else:
            for key, attr in (("a", "acceleration"), ("v", "speed")):
                if node.attrs.get(attr):
                    keywords.append(Keyword(key, _num(float(node.attrs[attr]))))
        return [self.marker(node, "Home"),
                ExprStmt(Call(Name("movej"), (joints,), tuple(keywords)))]

    def n_Force(self, node: Node) -> list[Item]:
        """Force mode around the node's children: selected axes are compliant (limited by
        the speed limits, m/s and rad/s), the others by the allowed deviation (m, rad)."""
        selection = node.fields.get("selection")
        wrench = node.fields.get("wrench")
        speeds = node.fields.get("limitsForce")
        deviations = node.fields.get("limitsMotion")
        if not (selection and wrench and speeds and deviations):
            return self.n_unknown(node)
        feature = node.fields.get("feature")
        frame: Expr
        if feature in _TOOL_FEATURES:
            frame = _call("tool_pose")
        elif feature in (None, *_BASE_FEATURES):
            frame = Pose(tuple(_num(0.0) for _ in range(6)))
        else:
            frame = Name(str(feature))
        kind = {"Point": 1, "Motion": 3}.get(str(node.fields.get("type")), 2)
        limits = [speeds[i] if selection[i] else deviations[i] for i in range(6)]
        if all(child.kind == "Placeholder" or child.suppressed for child in node.children):
            return []  # PolyScope writes nothing for a Force node with an empty body
        # in force mode the program may not stop at a node: every marker inside is noBreak
        body = [_no_break(item) if self.flags else item for item in self.block(node.children)]
        # PolyScope 5 zeroes the e-Series' own force/torque sensor first; PolyScope 3 (a CB3
        # has none) does not (seen: 3.15.6 ati-ia/ft-urcap, 3.15.8 ic-sw1821/UR_RTDE_2)
        zero = [_stmt("zero_ftsensor")] if self.version >= 5 else []
        return [self.marker(node, "Force"), _stmt("sleep", _num(0.02)), *zero,
                _stmt("force_mode", frame, List(tuple(Number(int(v)) for v in selection)),
                      List(tuple(_num(v) for v in wrench)), Number(kind),
                      List(tuple(_num(v) for v in limits))),
                *body, _stmt("end_force_mode"), _stmt("stopl", _num(5.0))]

    # -- moves
    def n_Move(self, node: Node) -> list[Item]:
        items: list[Item] = [self.marker(node, str(node.fields.get("motion_type", "Move")))]
        items.extend(self.block(node.children))
        return items

    def move_of(self, node: Node) -> Node | None:
        parent = node.parent
        while parent is not None and parent.kind != "Move":
            parent = parent.parent
        return parent

    def n_Waypoint(self, node: Node) -> list[Item]:
        move = self.move_of(node)
        name = node.name or "Waypoint"
        kind = node.fields.get("type")
        if move is None:
            return [self.marker(node, name, "breakAfter")]
        motion = str(move.fields.get("motion_type", "MoveJ"))
        if kind == "Variable":
            variable = str(node.fields.get("variable") or name)
            target: Expr = self.target_of(node, move)
            label = variable
        elif kind == "Fixed":
            label = name
            pose_expr, q_expr = self.fixed_values(node)
            pose_expr = self.in_variable_feature(node, move, pose_expr)
            if motion != "MoveJ" and self.in_variable_base(move):
                pose_expr = _call("pose_trans", Name("Base"), pose_expr)
            if motion == "MoveJ" and move.attrs.get("positionType") == "JointAngles":
                target = q_expr
            elif "positionType" not in move.attrs and motion in ("MoveJ", "MoveL") and \
                    move.attrs.get("useActiveTCP") == "false" and not move.fields.get("tcp"):
                # PolyScope 3 (no positionType): a move that uses no TCP goes to the
                # waypoint's joint angles, a MoveL too (seen: 3.5 ``movel([q], ...)``)
                target = q_expr
            else:
                if move.attrs.get("useActiveTCP") == "false" and not move.fields.get("tcp") \
                        and move.attrs.get("positionType") == "CartesianPose":
                    # "Ignore Active TCP" (PolyScope 5): the waypoint is a flange pose; the
                    # active TCP goes where the flange would be (seen: MoveJ, 5.9;
                    # [U] MoveL/MoveP the same). PolyScope 3 (no positionType) writes the
                    # pose as it is (3.5 MoveP, Sander-ONeil)
                    pose_expr = _call("pose_trans", pose_expr, _call("get_tcp_offset"))
                target = _call("get_inverse_kin", pose_expr, qnear=q_expr) \
                    if motion == "MoveJ" else pose_expr
        elif kind == "Relative":
            label = name
            to: Expr = Name(f"{name}_to_p")
            start: Expr = Name(f"{name}_from_p")
            if self.version < 5:
                # PolyScope 3 writes no waypoint globals: the two poses in place, as for a
                # fixed waypoint (seen: 3.15.6, 3.15.8)
                to_pose, from_pose = self.pose_of(node), self.pose_of(node, "from_")
                if to_pose is None or from_pose is None:
                    raise self.error(node, "a relative waypoint without its two positions")
                to = Pose(tuple(_num(v) for v in to_pose))
                start = Pose(tuple(_num(v) for v in from_pose))
            # from where the robot is: PolyScope 3 its forward kinematics, 5 its target
            # pose (seen: 3.15.6 ati-ia/ft-urcap, 3.15.8 ic-sw1821/UR_RTDE_2; 5.7 on)
            here = _call("get_forward_kin" if self.version < 5 else "get_target_tcp_pose")
            target = _call("pose_add", here, _call("pose_sub", to, start))
        else:
            return [self.marker(node, name, "breakAfter")]
        keywords = self.motion_keywords(move, node)
        function = {"MoveJ": "movej", "MoveL": "movel", "MoveP": "movep"}.get(motion, "movel")
        motion_call = ExprStmt(Call(Name(function), (target,),
                                    tuple(Keyword(k, v) for k, v in keywords)))
        untils = [child for child in node.children
                  if child.kind == "Until" and not child.suppressed]
        tcp = self.move_tcp(move, node)
        if not untils:
            return [self.marker(node, label, "breakAfter"), *tcp, motion_call]
        # a waypoint with Until conditions: the move runs in a thread the conditions end
        number = self.number(node)
        flag, thread, handle = (f"move_thread_flag_{number}", f"move_thread_{number}",
                                f"move_thread_han_{number}")
        accel = dict(keywords).get("a")
        return [self.marker(node, label, "breakAfter"), *tcp,
                Declare("global", flag, Number(0)),
                ThreadDef(thread, (EnterCritical(), Assign(Name(flag), Number(1)), motion_call,
                                   Assign(Name(flag), Number(2)), ExitCritical())),
                Assign(Name(flag), Number(0)),
                Assign(Name(handle), Run(thread)),
                self.until_loop(untils, flag, handle,
                                accel.value if isinstance(accel, Number) else None,
                                reaches_end=True)]

    def move_tcp(self, move: Node, waypoint: Node) -> list[Item]:
        """``set_tcp`` before a waypoint's motion when its move names its own TCP
        (``useActiveTCP="false"`` with a ``<tcp>``): the installation's offset of that TCP
        (m, rad), else the offset the waypoint was taught with. A move that ignores the
        TCP (no ``<tcp>``) writes nothing."""
        if move.attrs.get("useActiveTCP") != "false" or not move.fields.get("tcp") or \
                move.attrs.get("positionType") == "JointAngles":
            return []  # a move to joint angles does not need the TCP
        return self.set_tcp(str(move.fields["tcp"]), waypoint.fields.get("tcp_offset"))

    def set_tcp(self, name: str, taught=None) -> list[Item]:
        """``set_tcp`` of the installation's TCP ``name`` (offset in the flange frame: m,
        rad), else of ``taught`` (the offset a waypoint was taught with); nothing when
        neither is known."""
        offset = None
        for tcp in getattr(self.installation, "tcps", ()) or ():
            if tcp.name == name:
                offset = tcp.offset
        if offset is None:
            offset = taught
        if not offset or len(offset) != 6:
            return []
        return [_stmt("set_tcp", Pose(tuple(_num(v) for v in offset)))]

    def motion_keywords(self, move: Node, waypoint: Node) -> list[tuple[str, Expr]]:
        params = waypoint.fields.get("params") or {}
        motion = move.fields.get("motion_type")
        if "nextMotionTime" in params:
            out = [("t", _num(params["nextMotionTime"]))]
        else:
            joint = motion == "MoveJ"
            speed = params.get("jointSpeed" if joint else "cartesianSpeed",
                               move.fields.get("speed"))
            accel = params.get("jointAcceleration" if joint else "cartesianAcceleration",
                               move.fields.get("acceleration"))
            out = []
            if accel is not None:
                out.append(("a", _num(accel)))
            if speed is not None:
                out.append(("v", _num(speed)))
        blend = params.get("blendRadius", move.fields.get("blend"))
        if motion == "MoveP":
            out.append(("r", _num(blend if blend and _blend_kept(move, waypoint) else 0.0)))
        elif blend and blend > 0:
            out.append(("r", _num(blend)))
        return out

