"""Reading PolyScope programs (``.urp``) into a typed, named program tree.

A ``.urp`` file is XML, gzip-compressed as PolyScope saves it (plain XML is accepted too).
PolyScope 3.x (from about 3.3) and 5.x write the same layout: a root ``<URProgram>`` with the
arm's calibration (``<kinematics>``) and ``<children>`` holding ``<SpecialSequence
type="BeforeStart">``, ``<MainProgram>``, ``<Thread>`` nodes and ``<SubProgram reference=../>``
entries. Each program node is one XML element named after its type (``Move``, ``Waypoint``,
``Loop``, ``If``, ``Wait``, ``Set``, ``Assignment``, ``Script``, ``Popup``, ...), its children
inside ``<children>``. The XML is written by XStream: an element that appeared before is not
repeated but written ``<Tag reference="../../path[2]/to"/>``, a path relative to the element
itself; :func:`read_urp` resolves these.

Expressions are stored one character at a time (``<ExpressionChar character="x"/>``) with
tokens (``<ExpressionToken token=" True "/>``), references to program variables, I/O pins,
waypoints and installation variables in between; :class:`Expression` keeps the pieces and gives
both the text PolyScope shows (with its symbols ``≔ ≟ ≠ ≤ ≥``) and the URScript text.

Older programs (PolyScope 1.x, root ``<gui.program.ProgramRootNode>``, a serialised Java
object) are refused with :class:`UrpError` naming the version; so is any file that is not a
program, truncated, corrupt or not XML. Node types this reader does not know, and URCap
nodes (``<Contributed>``), are kept as :class:`Node` with their XML tag and attributes, never
dropped.

Units as PolyScope stores them: lengths in m, angles in rad, speeds in m/s or rad/s,
accelerations in m/s² or rad/s², times in s.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree

from .gz import InflateError, inflate, is_gzip

__all__ = [
    "UrpError", "Expression", "Node", "Program", "read_urp", "parse_urp", "Kinematics",
]


class UrpError(Exception):
    """A ``.urp`` file that cannot be read: not a program, truncated, corrupt, an unsupported
    version or a broken reference. The message names the file (and the node when known)."""


class UnsupportedProgram(UrpError):
    """A PolyScope program urdsl cannot read though a controller may run it (PolyScope 1.x):
    not a mistake of the program."""


_SYMBOLS = {"≔": "=", "≟": "==", "≠": "!=", "≤": "<=", "≥": ">=", "∧": " and ", "∨": " or ",
            "⊕": " xor ", "¬": " not ", "≡": "=="}
"""PolyScope's expression editor symbols and their URScript spelling."""


@dataclass(frozen=True)
class Expression:
    """A PolyScope expression: ``parts`` are ``(kind, text)`` pairs in order, where kind is
    ``char`` (one character), ``token``, ``var`` (a program or installation variable name),
    ``io`` (a pin name), ``waypoint`` (a waypoint name), ``feature`` (an installation
    feature used as a constant: the compiler writes its pose; its name here). ``label`` is the
    text PolyScope shows, ``script`` the URScript text it generates."""

    parts: tuple[tuple[str, str], ...] = ()

    @property
    def label(self) -> str:
        return "".join(f"{text}_const" if kind == "feature" else text
                       for kind, text in self.parts)

    @property
    def script(self) -> str:
        out = []
        for kind, text in self.parts:
            if kind == "char":
                out.append(_SYMBOLS.get(text, text))
            elif kind == "waypoint":
                out.append(f"{text}_p")
            else:
                out.append(text)
        return "".join(out)

    def __bool__(self) -> bool:
        return bool(self.parts)


@dataclass(frozen=True)
class Kinematics:
    """The arm's calibrated Denavit-Hartenberg parameters as stored in the program (standard
    DH, per joint: ``delta_theta`` in rad added to the joint angle, ``a`` and ``d`` in m,
    ``alpha`` in rad)."""

    delta_theta: tuple[float, ...]
    a: tuple[float, ...]
    d: tuple[float, ...]
    alpha: tuple[float, ...]


@dataclass(eq=False)
class Node:
    """One node of the program tree.

    ``kind`` is PolyScope's node type (the XML tag: ``Move``, ``Waypoint``, ``Loop``, ... and
    ``Contributed`` for URCap nodes; a ``gui.program.direction.MoveDirectionNode`` is kind
    ``Direction``). ``attrs`` holds the XML attributes as written, ``children`` the program
    child nodes, ``name`` the node's own name where it has one (waypoint, folder, subprogram,
    thread, variable). ``fields`` carries what the reader parsed for the node's type (see
    :func:`parse_urp`), with SI units. ``element`` is the XML element (after reference
    resolution), for details no field covers.
    """

    kind: str
    attrs: dict[str, str]
    children: list[Node] = field(default_factory=list)
    name: str | None = None
    fields: dict[str, object] = field(default_factory=dict)
    element: ElementTree.Element | None = field(default=None, repr=False)
    parent: Node | None = field(default=None, repr=False)
    suppressed: bool = False
    position: tuple[int, int] | None = None
    """(line, column), 1-based, of the node's element in the program's XML (decompressed),
    when known."""

    @property
    def path(self) -> str:
        """The node path as PolyScope shows it: ``Robot Program > Loop > MoveL > Waypoint_1``."""
        parts = []
        node: Node | None = self
        while node is not None:
            parts.append(node.title)
            node = node.parent
        return " > ".join(reversed(parts))

    @property
    def title(self) -> str:
        if self.kind == "MainProgram":
            return "Robot Program"
        if self.kind == "Move":
            return self.attrs.get("motionType", "Move")
        if self.kind == "SpecialSequence":
            return self.attrs.get("type", "BeforeStart")
        if self.kind == "Contributed":
            return self.attrs.get("strategyProgramNodeType", "URCap node")
        return self.name or self.kind

    def walk(self):
        """This node and its descendants, depth first, in program order."""
        stack = [self]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(node.children))


@dataclass(eq=False)
class Program:
    """A PolyScope program: ``name``, the installation it names, the version that saved it,
    the arm's calibration, and its top-level nodes (``before_start``, ``main``, ``threads``,
    ``subprograms``, other nodes in ``others``)."""

    path: str
    name: str
    installation: str | None
    created_in: str | None
    saved_in: str | None
    kinematics: Kinematics | None
    main: Node
    before_start: Node | None = None
    init_variables: Node | None = None
    threads: list[Node] = field(default_factory=list)
    subprograms: list[Node] = field(default_factory=list)
    others: list[Node] = field(default_factory=list)
    top: list[Node] = field(default_factory=list)
    """Every top-level node in the order the file lists them (PolyScope numbers them so)."""
    installation_path: str | None = None
    """The installation's path relative to the program's folder, without ``.installation``
    (``installationRelativePath``: ``../default`` for one in the parent folder)."""
    directory: str | None = None
    """The folder the program was saved in on the robot (``directory``: ``/programs/LE``);
    script files the program names are found relative to it."""
    feature_variables: frozenset[str] = frozenset()
    """Installation features the program's expressions read: as variables (a feature made a
    variable in the installation: ``pose_trans(Plane_3, p)``; the preamble defines them) or
    as constants (``Point_1_const``: PolyScope writes the installation's pose in place)."""
    installation_names: frozenset[str] = frozenset()
    """Every name the program takes from its installation: installation variables
    (``<installationVariable name="i_count"/>``) and the features its moves and expressions
    refer to (``referencedName``); the installation's preamble and ``.variables`` define
    them."""

    def subprogram_files(self) -> frozenset[str]:
        """The file names (without folders, lower case) of the subprogram programs this
        program calls or holds (``<programFile>/programs/GD/SUB_104.urp</programFile>``),
        suppressed calls included: a subprogram saved as its own program is written to be
        run from here."""
        found: set[str] = set()
        nodes = [*self.subprograms]
        for top in self.top:
            nodes.extend(node.fields.get("subprogram") for node in top.walk()  # type: ignore
                         if node.kind == "CallSubProgram")
        for node in nodes:
            file = node.fields.get("file") if isinstance(node, Node) else None
            if isinstance(file, str) and file:
                found.add(re.split(r"[\\/]", file)[-1].lower())
        return frozenset(found)

    @property
    def major_version(self) -> int | None:
        version = self.saved_in or self.created_in
        if not version:
            return None
        head = version.split(".")[0]
        return int(head) if head.isdigit() else None


# ---- reading -------------------------------------------------------------------------------


def _decompress(data: bytes, path: str) -> bytes:
    try:
        return inflate(data)
    except InflateError as error:
        raise UrpError(f"{path}: error: not a readable PolyScope program: "
                       f"{error.reason}") from None


def read_urp(path: str | Path) -> Program:
    """Read the ``.urp`` file at ``path``. Raises :class:`UrpError` (naming the file) for a
    file that cannot be read as a program."""
    try:
        data = Path(path).read_bytes()
    except OSError as error:
        raise UrpError(f"{path}: error: cannot read: {error.strerror}") from None
    return parse_urp(data, str(path))


def parse_urp(data: bytes, path: str = "<urp>") -> Program:
    """Parse the bytes of a ``.urp`` file (gzip or plain XML) into a :class:`Program`."""
    xml = _decompress(data, path)
    if not xml.strip():
        raise UrpError(f"{path}: error: empty{' once decompressed' if xml != data else ''}: "
                       "not a PolyScope program (PolyScope saves a program as XML); the "
                       "controller cannot load it")
    try:
        root = ElementTree.fromstring(xml)
    except ElementTree.ParseError as error:
        if not xml.lstrip().startswith(b"<") and _looks_like_urscript(xml):
            raise UrpError(f"{path}: error: not a PolyScope program but URScript text (a "
                           "program saved by PolyScope is XML); check it as a script: "
                           "`urdsl check` of a copy named .script") from None
        what = "truncated" if "no element found" in str(error) or "unclosed" in str(error) \
            else "not well-formed XML"
        raise UrpError(f"{path}: error: not a readable PolyScope program ({what}: "
                       f"{error})") from None
    if root.tag.startswith("gui.program."):
        raise UnsupportedProgram(
            f"{path}: error: a PolyScope 1.x program (<{root.tag}>); urdsl reads programs "
            "saved by PolyScope 3.x and 5.x (root <URProgram>): open and save it in "
            "PolyScope 3 or later")
    if root.tag != "URProgram":
        raise UrpError(f"{path}: error: not a PolyScope program (root element <{root.tag}>, "
                       "expected <URProgram>)")
    reader = _Reader(root, path)
    reader.positions = _positions(xml, root)
    return reader.program()


def is_text_file(path: str | Path) -> bool:
    """Whether the ``.urp`` at ``path`` is plain text that is not XML (a script file given the
    extension: seen in projects that keep URScript templates as ``.urp``): PolyScope saves
    a program as gzip-compressed or plain XML. False when the file cannot be read."""
    try:
        with open(path, "rb") as handle:
            head = handle.read(4096)
    except OSError:
        return False
    if is_gzip(head):
        return False
    try:
        text = head.decode("utf-8")
    except UnicodeDecodeError as error:  # a multi-byte character cut at the end of head
        if error.start < len(head) - 3:
            return False
        text = head[:error.start].decode("utf-8")
    text = text.lstrip("\ufeff \t\r\n")
    return bool(text) and not text.startswith("<") and "\x00" not in text


def _looks_like_urscript(data: bytes) -> bool:
    """Whether text that is not XML reads as URScript (seen: script files saved as
    ``.urp``)."""
    from ..script import parse
    from ..script.diagnostics import ScriptError

    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    try:
        parse(text, "<urp>")
    except ScriptError:
        return False
    return True


def _positions(xml: bytes, root: ElementTree.Element) -> dict[ElementTree.Element, tuple[int, int]]:
    """Element → (line, column) of its start tag, 1-based: expat reports the start tags in
    document order, the order ``root.iter()`` walks the tree."""
    from xml.parsers import expat

    starts: list[tuple[int, int]] = []
    parser = expat.ParserCreate()

    def start(_name, _attrs) -> None:
        starts.append((parser.CurrentLineNumber, parser.CurrentColumnNumber + 1))

    parser.StartElementHandler = start
    try:
        parser.Parse(xml, True)
    except expat.ExpatError:
        return {}
    elements = list(root.iter())
    if len(elements) != len(starts):
        return {}
    return dict(zip(elements, starts, strict=True))


_INDEX = re.compile(r"^(.+)\[(\d+)\]$")


class _Reader:
    def __init__(self, root: ElementTree.Element, path: str) -> None:
        self.root = root
        self.path = path
        self.parents: dict[ElementTree.Element, ElementTree.Element] = {
            child: parent for parent in root.iter() for child in parent}
        self.nodes: dict[ElementTree.Element, Node] = {}
        self.positions: dict[ElementTree.Element, tuple[int, int]] = {}
        self.feature_variables: set[str] = set()

    def installation_names(self) -> set[str]:
        """The names of installation variables and features the program refers to."""
        names = set(self.feature_variables)
        for element in self.root.iter():
            if element.tag == "installationVariable" and element.get("name"):
                names.add(element.get("name", ""))
            elif element.get("class", "").startswith("GeomFeature") and \
                    element.get("referencedName"):
                names.add(element.get("referencedName", ""))
        return names

    # -- references
    def resolve(self, element: ElementTree.Element) -> ElementTree.Element:
        """The element an XStream ``reference`` attribute points to (or ``element``)."""
        seen = 0
        while "reference" in element.attrib and seen < 100:
            seen += 1
            target = element
            for step in element.attrib["reference"].split("/"):
                if step == "..":
                    target = self.parents.get(target)
                    if target is None:
                        break
                    continue
                if step in ("", "."):
                    continue
                match = _INDEX.match(step)
                tag, index = (match.group(1), int(match.group(2))) if match else (step, 1)
                found = [child for child in target if child.tag == tag]
                if len(found) < index:
                    target = None
                    break
                target = found[index - 1]
            if target is None:
                raise UrpError(f"{self.path}: error: broken reference "
                               f"{element.attrib['reference']!r} in <{element.tag}>")
            element = target
        return element

    # -- the program
    def program(self) -> Program:
        root = self.root
        kinematics = None
        block = root.find("kinematics")
        if block is not None:
            kinematics = _kinematics(block)
        children = root.find("children")
        if children is None:
            raise UrpError(f"{self.path}: error: a PolyScope program without <children>; the "
                           "file is truncated or not a program")
        main = before = init = None
        threads: list[Node] = []
        subs: list[Node] = []
        others: list[Node] = []
        top: list[Node] = []
        for element in children:
            target = self.resolve(element)
            node = self.node(target, None)
            if element.tag == "MainProgram":
                main = node
            elif element.tag == "SpecialSequence" and node.attrs.get("type") == "BeforeStart":
                before = node
            elif element.tag == "InitVariablesNode":
                init = node
            elif element.tag == "Thread":
                threads.append(node)
            elif element.tag == "SubProgram":
                if target.tag == "subprogram":  # the subprogram's body lives in its Call
                    node = self.node(target, None)
                subs.append(node)
            else:
                others.append(node)
            top.append(node)
        if main is None:
            raise UrpError(f"{self.path}: error: the program has no <MainProgram> (Robot "
                           "Program) node")
        return Program(self.path, root.get("name", Path(self.path).stem),
                       root.get("installation"), root.get("createdIn"),
                       root.get("lastSavedIn"), kinematics, main, before, init, threads, subs,
                       others, top, root.get("installationRelativePath") or None,
                       root.get("directory") or None, frozenset(self.feature_variables),
                       frozenset(self.installation_names()))

    def node(self, element: ElementTree.Element, parent: Node | None) -> Node:
        element = self.resolve(element)
        known = self.nodes.get(element)
        if known is not None:
            return known
        kind = element.tag
        suppressed = False
        if kind == "SuppressedNode":  # a suppressed node: the node itself is inside
            inner = element.find("suppressedNode")
            if inner is None:
                raise UrpError(f"{self.path}: error: an empty <SuppressedNode> in "
                               f"{parent.path if parent else 'the program'}")
            node = self.node(inner, parent)
            node.suppressed = True
            self.nodes[element] = node
            return node
        if kind == "suppressedNode":
            kind = element.get("class", "Unknown").rsplit(".", 1)[-1]
        if kind.endswith("MoveDirectionNode"):
            kind = "Direction"
        elif kind == "subprogram":
            kind = "SubProgram"
        node = Node(kind, dict(element.attrib), name=element.get("name"), element=element,
                    parent=parent, suppressed=suppressed, position=self.positions.get(element))
        self.nodes[element] = node
        try:
            _FIELDS.get(kind, _no_fields)(self, node, element)
        except UrpError:
            raise
        except (ValueError, TypeError, IndexError) as error:
            raise UrpError(f"{self.path}: error: node {node.path}: {error}") from None
        children = element.find("children")
        if children is not None:
            for child in children:
                node.children.append(self.node(child, node))
        return node

    # -- expressions
    def expression(self, element: ElementTree.Element | None) -> Expression:
        parts: list[tuple[str, str]] = []
        if element is None:
            return Expression()
        for piece in element:
            tag = piece.tag
            if tag == "ExpressionChar":
                parts.append(("char", piece.get("character", "")))
            elif tag == "ExpressionToken":
                parts.append(("token", piece.get("token", "")))
            elif tag in ("ExpressionVariable", "ExpressionIO", "ExpressionWaypoint",
                         "ExpressionFeature", "ExpressionGeomFeature"):
                parts.append(self._reference_part(piece))
            else:
                parts.append(("token", piece.get("token", piece.get("name", ""))))
        return Expression(tuple(parts))

    def _reference_part(self, piece: ElementTree.Element) -> tuple[str, str]:
        for inner in piece:
            target = self.resolve(inner)
            name = (target.get("name") or target.get("featureName")
                    or target.get("referencedName") or "")
            if piece.tag == "ExpressionIO":
                return ("io", name or inner.get("referencedName", ""))
            if piece.tag == "ExpressionWaypoint":
                return ("waypoint", name)
            if piece.tag == "ExpressionGeomFeature" and name == "Joint_0_name":
                # the base feature in an expression is its pose (seen: "UF:=Base" is
                # written ``global UF=p[0.0,0.0,0.0,0.0,0.0,0.0]``)
                return ("token", "p[0.0,0.0,0.0,0.0,0.0,0.0]")
            if piece.tag == "ExpressionGeomFeature" and name == "Joint_6_name":
                # PolyScope's built-in Tool feature: where the tool is [U: no script
                # PolyScope wrote for it seen; its pose in Base is the TCP's]
                return ("token", "get_actual_tcp_pose()")
            if piece.tag == "ExpressionGeomFeature" and name:
                # another feature as a constant: its pose in the installation (seen:
                # "Base_var:=Base_1_const" is written ``global Base_var=p[...]``, the
                # installation's pose of Base_1; PolyScope 5.8, loukjeab/WS2223...); a name
                # only the installation gives (seen: 3.12.1, "pose_add(Point_1_const, p)" in
                # an Assignment of project 126, whose installation is not in the repository)
                self.feature_variables.add(name)
                return ("feature", name)
            if target.tag == "GeomFeatureVariable" and name:
                self.feature_variables.add(name)
            return ("var", name)
        return ("token", piece.get("name", ""))

    def variable_name(self, element: ElementTree.Element | None) -> str | None:
        """The name of the variable ``element`` refers to. A ``featureName`` names a feature
        of the installation made a variable there (seen: a Variable waypoint's
        ``<variable featureName="Control_Standby"/>``, 5.9.5): it is recorded as one of the
        installation's names the program refers to (:meth:`installation_names`)."""
        if element is None:
            return None
        target = self.resolve(element)
        if target.get("name"):
            return target.get("name")
        feature = target.get("featureName")
        if feature:
            self.feature_variables.add(feature)
        return feature


def _floats(text: str | None) -> tuple[float, ...]:
    if not text:
        return ()
    return tuple(float(x) for x in text.replace(" ", "").split(",") if x)


def _kinematics(element: ElementTree.Element) -> Kinematics | None:
    values = {}
    for key in ("deltaTheta", "a", "d", "alpha"):
        child = element.find(key)
        values[key] = _floats(child.get("value") if child is not None else None)
    if not all(len(v) == 6 for v in values.values()):
        return None
    if not any(values["a"]) and not any(values["d"]):
        # a block PolyScope never filled in (``status="NOT_INITIALIZED"``, every value 0:
        # seen as a program's top-level block that a relative waypoint's start refers to,
        # underautomation/UniversalRobots.NET): no arm, so no kinematics
        return None
    return Kinematics(values["deltaTheta"], values["a"], values["d"], values["alpha"])


def _no_fields(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    if element.find("expression") is not None:
        node.fields["expression"] = reader.expression(element.find("expression"))


def _float_attr(element: ElementTree.Element | None, name: str) -> float | None:
    if element is None:
        return None
    value = element.get(name)
    return float(value) if value not in (None, "") else None


def _move(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["motion_type"] = element.get("motionType", "MoveJ")
    node.fields["speed"] = _float_attr(element, "speed")
    node.fields["acceleration"] = _float_attr(element, "acceleration")
    node.fields["blend"] = _float_attr(element, "blendRadius")
    feature = element.find("feature")
    if feature is not None:
        node.fields["feature"] = reader.resolve(feature).get("referencedName")
    tcp = element.find("tcp")
    if tcp is not None:
        node.fields["tcp"] = reader.resolve(tcp).get("referencedName")


def _waypoint(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["type"] = element.get("type", "Fixed")
    params = element.find("motionParameters")
    if params is not None:
        node.fields["params"] = {key: float(value) for key, value in params.attrib.items()
                                 if re.fullmatch(r"-?[0-9.Ee+-]+", value)}
        node.fields["params_attrs"] = dict(params.attrib)
    for tag, prefix in (("position", ""), ("relativeFromPosition", "from_")):
        _read_position(reader, element.find(tag), node.fields, prefix)
    flange = element.find("outputFlangePose")
    if "tcp_offset" not in node.fields and flange is not None and "pose" in node.fields:
        # PolyScope 3 keeps no TCP offset with a waypoint, but the flange pose beside the
        # TCP pose: the offset is the TCP pose seen from the flange
        offset = _offset_between(_floats(reader.resolve(flange).get("pose")),
                                 node.fields["pose"])
        if offset is not None:
            node.fields["tcp_offset"] = offset
    base = element.find("BaseToFeature")
    if base is not None:
        node.fields["base_to_feature"] = _floats(reader.resolve(base).get("pose"))
    variable = element.find("variable")
    if variable is not None:
        node.fields["variable"] = reader.variable_name(variable)



def _offset_between(flange: list[float] | None, tcp: list[float]) -> list[float] | None:
    """The pose (m, rad) of ``tcp`` in the frame of ``flange`` (both poses in Base, six
    values), or None when either is not a pose."""
    from ..kinematics.pose import pose_inv, pose_trans

    if flange is None or len(flange) != 6 or len(tcp) != 6:
        return None
    offset = pose_trans(pose_inv(flange), tcp)  # URScript's pose_trans(pose_inv(f), t)
    return [round(float(v), 9) + 0.0 for v in offset]  # + 0.0: no -0.0


def _read_position(reader, position, fields: dict, prefix: str) -> None:
    """A waypoint's ``position`` (or ``relativeFromPosition``, with ``prefix`` "from_"):
    joints and TCP pose (PolyScope 3 attributes, PolyScope 5 elements), TCP offset and the
    arm's kinematics, into ``fields`` as ``q``/``pose``/``tcp_offset``/``kinematics``."""
    if position is None:
        return
    position = reader.resolve(position)
    if position.get("joints"):  # PolyScope 3: joints and the TCP pose as attributes
        fields[prefix + "q"] = _floats(position.get("joints"))
    if position.get("pose"):
        fields[prefix + "pose"] = _floats(position.get("pose"))
    angles = position.find("JointAngles")
    if angles is not None:
        fields[prefix + "q"] = _floats(reader.resolve(angles).get("angles"))
    offset = position.find("TCPOffset")
    if offset is not None:
        fields[prefix + "tcp_offset"] = _floats(reader.resolve(offset).get("pose"))
    kin = position.find("Kinematics")
    if kin is not None:
        fields[prefix + "kinematics"] = _kinematics(reader.resolve(kin))

def _loop(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["type"] = element.get("type", "Forever")
    if element.get("count"):
        node.fields["count"] = int(element.get("count"))
    node.fields["variable"] = reader.variable_name(element.find("loopVariable"))
    node.fields["expression"] = reader.expression(element.find("expression"))


def _if(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["type"] = element.get("type", "If")
    node.fields["expression"] = reader.expression(element.find("expression"))


def _wait(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["type"] = element.get("type", "Sleep")
    wait_time = element.find("waitTime")
    if wait_time is not None and wait_time.text:
        node.fields["seconds"] = float(wait_time.text)
    pin = element.find("pin")
    if pin is not None:
        node.fields["pin"] = reader.resolve(pin).get("referencedName")
    value = element.find("digitalValue")
    if value is not None and value.text:
        node.fields["digital"] = value.text.strip()
    node.fields["expression"] = reader.expression(element.find("expression"))


def _set(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["type"] = element.get("type", "NoAction")
    pin = element.find("pin")
    pulse = element.find("SingleDigitalPulseActionState")
    if pulse is not None:
        # a single pulse: the pin and the pulse's length (s) are in this child
        pin = pulse.find("pin")
        node.fields["pulse"] = {key: value for key, value in pulse.attrib.items()}
    if pin is not None:
        node.fields["pin"] = reader.resolve(pin).get("referencedName")
    for key in ("digitalValue", "analogValue"):
        value = element.find(key)
        if value is not None and value.text:
            node.fields[key] = value.text.strip()
    tcp = element.find("tcp")
    if tcp is not None:
        node.fields["tcp"] = reader.resolve(tcp).get("referencedName")
    # the variable an IncrementVariable Set adds one to: an installation variable (seen:
    # ``<installationVariable name="i_count"/>``, 5.9.1) or a program variable [U]
    for tag in ("installationVariable", "variable"):
        if element.find(tag) is not None:
            node.fields["variable"] = reader.variable_name(element.find(tag))
            break
    node.fields["expression"] = reader.expression(element.find("expression"))


def _assignment(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    variable = element.find("variable")
    if variable is not None:
        target = reader.resolve(variable)
        node.name = reader.variable_name(variable)
        node.fields["persistent"] = target.get("prefersPersistentValue") == "true"
    node.fields["source"] = element.get("valueSource", "Expression")
    node.fields["message"] = element.get("message", "")
    node.fields["value_type"] = element.get("valueType", "")
    node.fields["expression"] = reader.expression(element.find("expression"))


def _script(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["type"] = element.get("type", "Line")
    node.fields["expression"] = reader.expression(element.find("expression"))
    contents = element.find("cachedContents")
    if contents is not None:
        node.fields["contents"] = contents.text or ""
    file = element.find("file")
    if file is not None:
        node.fields["file"] = (file.text or "").strip()


def _popup(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["type"] = element.get("type", "Message")
    node.fields["message"] = element.get("message", "")
    node.fields["halt"] = element.get("haltProgram") == "true"
    node.fields["input"] = element.get("inputType", "Text")
    node.fields["variable"] = reader.variable_name(element.find("variable"))
    node.fields["expression"] = reader.expression(element.find("expression"))


def _comment(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["text"] = element.get("comment", "")


def _direction(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    feature = element.find("feature")
    if feature is not None:
        feature = reader.resolve(feature)
        node.fields["feature"] = feature.get("referencedName")
        if feature.get("referencedName") is None and feature.get("featureName"):
            node.fields["feature_name"] = feature.get("featureName")  # a variable feature
    node.fields["expression"] = reader.expression(element.find("expression"))


def _force(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["type"] = element.get("type", "Frame")
    feature = element.find("feature")
    if feature is not None:
        node.fields["feature"] = reader.resolve(feature).get("referencedName")
    for key in ("selection", "wrench", "limitsForce", "limitsMotion"):
        child = element.find(key)
        if child is not None:
            node.fields[key] = _floats(reader.resolve(child).get("value"))


def _timer(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["action"] = element.get("action", "Start")
    node.name = reader.variable_name(element.find("variable"))


def _subprogram(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    file = element.find("programFile")
    node.fields["file"] = (file.text or "").strip() if file is not None else None


def _call(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    sub = element.find("subprogram")
    if sub is not None:
        target = reader.resolve(sub)
        node.name = target.get("name")
        node.fields["subprogram"] = reader.node(target, None)


def _event(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    node.fields["expression"] = reader.expression(element.find("expression"))


def _until(reader: _Reader, node: Node, element: ElementTree.Element) -> None:
    """An Until node: an EXPRESSION Until keeps its condition in ``<ExpressionBranch>``
    (seen: PolyScope 5.10, o2ac/o2ac-ur), older files in ``<expression>`` [U]."""
    branch = element.find("ExpressionBranch")
    if branch is None:
        branch = element.find("expression")
    if branch is not None:
        node.fields["expression"] = reader.expression(branch)


_FIELDS = {
    "Move": _move, "Waypoint": _waypoint, "Loop": _loop, "If": _if, "Wait": _wait,
    "Set": _set, "Assignment": _assignment, "Script": _script, "Popup": _popup,
    "Comment": _comment, "Timer": _timer, "Direction": _direction, "Force": _force,
    "SubProgram": _subprogram, "CallSubProgram": _call, "Event": _event, "Until": _until,
}
