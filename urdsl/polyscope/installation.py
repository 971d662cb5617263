"""A minimal reader of PolyScope installations (``.installation``): TCPs, payload, mounting.

An installation is XML, gzip-compressed as PolyScope saves it (plain XML is accepted too).
Three layouts are known:

* PolyScope 3.x and 5.x: root ``<Installation>``; ``<TCPSettings activePose="NAME">`` with
  ``<tcp name=".." offset="x, y, z, rx, ry, rz"/>`` entries (3.x also carries the payload
  mass as ``toolPayload="kg"`` on ``TCPSettings``); 5.x ``<PayloadSettings>`` with
  ``<Payload name=".." mass="kg" centerOfGravity="x, y, z" defaultPayload="true"/>``; the
  mounting as ``<WorldtoMarshal baseAngle="rad" tiltAngle="rad"/>``; the software version
  as ``<Version major= minor= bugfix=/>``.
* PolyScope 1.x (CB2, a serialised Java object): root ``<gui.installation.RobotInstallation>``
  with ``<tcpTransform>`` (six ``<double>``), ``<toolPayload>``, ``<mountingTiltAngle>`` and
  ``<mountingBaseAngle>``.

Also read: the safety limits and planes, I/O names, point and plane features, Modbus
signals, the conveyors of UR's built-in conveyor tracking and the raw attributes of the
settings a program's preamble is written from (:mod:`.preamble`). Other URCap data is not
read. Lengths in m, angles in rad, masses in kg.

A file that is not an installation, is truncated, corrupt or not XML raises
:class:`InstallationError` naming the file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree

from .gz import InflateError, inflate

__all__ = ["Installation", "InstallationError", "Tcp", "Payload", "read_installation",
           "ModbusSignal", "Conveyor",
           "Safety", "SafetyPlane", "parse_safety",
           "parse_installation", "find_installation", "GRAVITY"]

GRAVITY = 9.82
"""The gravity magnitude [m/s²] PolyScope writes in ``set_gravity``."""

class InstallationError(Exception):
    """An installation file that cannot be read; the message names the file."""

    def __init__(self, path: str, message: str) -> None:
        super().__init__(f"{path}: {message}")
        self.path = path
        self.reason = message


@dataclass(frozen=True)
class Tcp:
    """A named TCP: ``offset`` is the TCP pose in the flange frame (x, y, z m; rotation
    vector rad)."""

    name: str
    offset: tuple[float, ...]


@dataclass(frozen=True)
class Payload:
    """A named payload: ``mass`` in kg, ``cog`` the centre of gravity in the flange frame [m]
    (``None`` when the installation does not say)."""

    name: str
    mass: float
    cog: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class ModbusSignal:
    """A Modbus signal of the installation's ``<ModbusUnits>``: the unit's ``ip`` address,
    ``slave`` (unit id), ``address`` (register or coil number), ``kind`` as written
    (``DIGITAL_INPUT``, ``DIGITAL_OUTPUT``, ``REGISTER_INPUT``, ``REGISTER_OUTPUT``),
    ``name``, ``frequency`` (update frequency, Hz), ``choice`` (what an output does when the
    program stops, PolyScope's number) and the unit's ``sequential`` mode."""

    ip: str
    slave: int
    address: int
    kind: str
    name: str
    frequency: float | None = None
    choice: int | None = None
    sequential: bool = False


@dataclass(frozen=True)
class Conveyor:
    """One conveyor of UR's built-in conveyor tracking (the installation's ``Conveyor
    Tracking`` node, ``<data key="NAME_N">`` entries for conveyor N), as written.

    ``index``: the conveyor (and encoder) number N; ``kind``: ``conveyorType_N`` (``"1"``
    linear, the only kind seen); ``encoder``: ``encoderType_N`` (``"1"`` incremental, seen);
    ``decoder``: ``incrementalMode_N``, the pulse decoder of an incremental encoder;
    ``pins``: the digital inputs of its A and B signals; ``ticks_per_meter`` (linear) and
    ``ticks_per_revolution`` (circular); ``direction``: the two points (poses: m, rad) of the
    line feature ``direction_N`` names, in the order the user taught them, ``None`` when the
    installation lacks it; ``switch``: the direction reversed; ``rotate_tool`` (circular)."""

    index: int
    kind: str
    encoder: str
    decoder: int | None
    pins: tuple[int, int] | None
    ticks_per_meter: float | None
    ticks_per_revolution: float | None
    direction: tuple[tuple[float, ...], tuple[float, ...]] | None
    switch: bool = False
    rotate_tool: bool = False


@dataclass(frozen=True)
class SafetyPlane:
    """A safety plane: the TCP (and the elbow, when ``elbow``) must stay where
    ``normal·x + distance ≥ 0`` (x in the base frame, m). ``mode`` as written: ``NORMAL``,
    ``REDUCED``, ``BOTH`` or ``TRIGGER`` (switches to reduced mode, restricts nothing).
    The side is inferred [U]: with it, the robot's base is on the allowed side of every plane
    of the real installations looked at."""

    name: str
    normal: tuple[float, float, float]
    distance: float
    mode: str
    elbow: bool = False


@dataclass(frozen=True)
class Safety:
    """Normal-mode safety limits: ``tcp_speed`` m/s, ``force`` N, ``power`` W,
    ``momentum`` kg·m/s, ``joint_speed`` rad/s per joint, ``q_min``/``q_max`` rad per joint
    (``None`` for a joint without position limits: PolyScope stores each limit as an angle
    in [0, 2π) and a number of whole revolutions), and the enabled planes."""

    tcp_speed: float | None = None
    force: float | None = None
    power: float | None = None
    momentum: float | None = None
    joint_speed: tuple[float, ...] | None = None
    q_min: tuple[float | None, ...] | None = None
    q_max: tuple[float | None, ...] | None = None
    planes: tuple[SafetyPlane, ...] = ()


def parse_safety(text: str) -> Safety | None:
    """The ``<SafetySettings>`` text (INI sections such as ``[SafetyLimits Normal
    Values]``) as :class:`Safety`; None when it holds no limits. Values that do not read
    as numbers are left out."""
    sections: dict[str, dict[str, str]] = {}
    current: dict[str, str] | None = None
    for raw in text.splitlines():
        line = raw.strip()
        if line.startswith("[") and line.endswith("]"):
            current = sections.setdefault(line[1:-1].strip(), {})
        elif current is not None and "=" in line:
            key, value = line.split("=", 1)
            current[key.strip()] = value.strip()
    if not sections:
        return None

    def number(section: str, key: str) -> float | None:
        try:
            value = float(sections.get(section, {})[key])
        except (KeyError, ValueError):
            return None
        return value if math.isfinite(value) else None

    def vector(section: str, key: str) -> tuple[float, ...] | None:
        text = sections.get(section, {}).get(key)
        if text is None:
            return None
        try:
            values = tuple(float(v) for v in text.strip("[]").split(","))
        except ValueError:
            return None
        return values if all(math.isfinite(v) for v in values) else None

    joints = "SafetyLimits Normal Joints"
    q_min = q_max = None
    low, high = vector(joints, "minJointPosition"), vector(joints, "maxJointPosition")
    low_turns = vector(joints, "minJointRevolutions")
    high_turns = vector(joints, "maxJointRevolutions")
    limited = (sections.get("SafetySetup", {}).get("withPositionLimits", "").strip("[]")
               .replace(" ", "").split(","))
    if low and high and low_turns and high_turns and all(
            len(v) == 6 for v in (low, high, low_turns, high_turns)):
        def bound(angle: float, turns: float, joint: int) -> float | None:
            if abs(turns) > 1000 or (len(limited) == 6 and limited[joint] == "false"):
                return None
            return turns * 2 * math.pi + angle

        q_min = tuple(bound(low[j], low_turns[j], j) for j in range(6))
        q_max = tuple(bound(high[j], high_turns[j], j) for j in range(6))
    planes = []
    for name, section in sections.items():
        if not name.startswith("SafetyLimits BoundaryPlane"):
            continue
        mode = section.get("mode", "DISABLED")
        normal = vector(name, "planeNormal")
        distance = number(name, "distanceToOrigin")
        if mode == "DISABLED" or normal is None or len(normal) != 3 or distance is None \
                or math.hypot(*normal) < 1e-9:
            continue
        planes.append(SafetyPlane(section.get("name", name), normal, distance, mode,
                                  section.get("elbowRestricted") == "true"))
    speeds = vector(joints, "maxJointSpeed")
    values = "SafetyLimits Normal Values"
    return Safety(number(values, "maxTcpSpeed"), number(values, "maxForce"),
                  number(values, "maxPower"), number(values, "maxMomentum"),
                  speeds if speeds and len(speeds) == 6 else None, q_min, q_max, tuple(planes))


@dataclass(frozen=True)
class Installation:
    """What urdsl reads from an installation so far.

    ``tcps`` in file order and the name of the active one; ``payloads`` and the name of the
    default one; ``mounting``: (base rotation, tilt) [rad] or ``None`` if absent; ``version``:
    ``"5.11.9"``-like when the file says.
    """

    path: str
    tcps: tuple[Tcp, ...] = ()
    active_tcp: str | None = None
    payloads: tuple[Payload, ...] = ()
    active_payload: str | None = None
    mounting: tuple[float, float] | None = None
    version: str | None = None
    settings: dict[str, dict[str, str]] | None = None
    """Raw attributes of the settings the program's preamble is written from: element tag
    (``SmoothTransitionSettings``, ``ToolCommSettings``, and ``IOs/NAME`` for the I/O
    settings such as ``IOs/analogInputRange``) → attributes as written."""
    features: tuple[tuple[str, tuple[float, ...]], ...] = ()
    """Named features a program sees as variables (point and plane features whose
    ``isVariable`` is not ``false``): (name, pose in the base frame: x, y, z in m, rotation
    vector in rad), in file order. A plane's pose is PolyScope's: origin at its first
    point, y along the first point to the second, z along the plane's normal on the side
    of the first point's tool z axis."""
    io_names: tuple[tuple[str, str], ...] = ()
    """The I/O names the user gave: (name, pin) pairs, pin as PolyScope refers to it
    (``digital_out[1]``, ``tool_in[0]``, ``configurable_in[3]``, ``analog_in[0]``, the
    general purpose registers ``GP_bool_in[0]``, ``GP_int_out[2]``, ``GP_float_in[1]``)."""
    safety: Safety | None = None
    """The safety configuration's normal-mode limits and planes (3.x and 5.x), when the
    file has them."""
    modbus: tuple[ModbusSignal, ...] = ()
    """The Modbus signals, in file order."""
    urcaps: tuple[tuple[str, str, str], ...] = ()
    """The URCaps contributing an installation node, in file order: (name, vendor, node
    title). UR's own conveyor tracking, EtherNet/IP, PROFINET and screwdriving nodes are
    left out: they write nothing before the program."""
    feature_variable: tuple[tuple[str, bool], ...] = ()
    """Every named feature (point, line, plane) and whether it is variable (a program may
    move it; PolyScope writes waypoints taught in it relative to it)."""
    conveyors: tuple[Conveyor, ...] = ()
    """The enabled conveyors of the built-in conveyor tracking, by number."""
    base_variable: bool = False
    """The base feature is variable (``<BaseView isVariable="true">``, seen in a 3.14
    installation): PolyScope 3 then writes ``global Base`` (its pose, ``p[0, 0, 0, 0, 0,
    0]``) and waypoints in the base relative to it."""

    @property
    def tcp(self) -> Tcp | None:
        """The active TCP (the first one if the file names none)."""
        for tcp in self.tcps:
            if tcp.name == self.active_tcp:
                return tcp
        return self.tcps[0] if self.tcps else None

    @property
    def payload(self) -> Payload | None:
        """The default payload (the first one if the file marks none)."""
        for payload in self.payloads:
            if payload.name == self.active_payload:
                return payload
        return self.payloads[0] if self.payloads else None

    @property
    def gravity(self) -> tuple[float, float, float] | None:
        """The ``set_gravity`` vector [m/s²] of the mounting: ``g·(sin t·cos b, −sin t·sin b,
        cos t)`` for tilt ``t`` and base rotation ``b``. Floor (t = 0): (0, 0, 9.82); ceiling
        (t = π): (0, 0, −9.82), as PolyScope writes them. The sign convention of ``b`` for a
        tilted arm is inferred from one real ceiling-mounted project [U]."""
        if self.mounting is None:
            return None
        base, tilt = self.mounting
        return (GRAVITY * math.sin(tilt) * math.cos(base) + 0.0,
                -GRAVITY * math.sin(tilt) * math.sin(base) + 0.0, GRAVITY * math.cos(tilt) + 0.0)


def _numbers(text: str | None, count: int, what: str, path: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in (text or "").replace(";", ",").split(","))
    except ValueError:
        raise InstallationError(path, f"{what} is not {count} numbers: {text!r}") from None
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise InstallationError(path, f"{what} is not {count} finite numbers: {text!r}")
    return values


def _number(text: str | None, what: str, path: str) -> float:
    return _numbers(text, 1, what, path)[0]


def _decompress(data: bytes, path: str) -> bytes:
    try:
        return inflate(data)
    except InflateError as error:
        raise InstallationError(path, error.reason) from None


def parse_installation(data: bytes, path: str = "<installation>") -> Installation:
    """Read an installation from its bytes (gzip or plain XML); ``path`` names it in errors."""
    data = _decompress(data, path)
    if b"<!DOCTYPE" in data[:4096] or b"<!ENTITY" in data:
        raise InstallationError(path, "XML with a DOCTYPE or entities is not an installation")
    try:
        root = ElementTree.fromstring(data)
    except ElementTree.ParseError as error:
        raise InstallationError(path, f"not well-formed XML ({error})") from None
    if root.tag == "Installation":
        return _modern(root, path)
    if root.tag.endswith("RobotInstallation"):
        return _legacy(root, path)
    raise InstallationError(path, f"not a PolyScope installation (root element <{root.tag}>)")


def _modern(root: ElementTree.Element, path: str) -> Installation:
    """PolyScope 3.x and 5.x."""
    tcps: list[Tcp] = []
    active_tcp = None
    payloads: list[Payload] = []
    active_payload = None
    settings = root.find("TCPSettings")
    if settings is None:  # PolyScope 3.4-3.5: the class name as the tag
        settings = root.find("com.ur.view.tcp.domain.TCPSettingsImpl")
    if settings is not None:
        active_tcp = settings.get("activePose")
        for element in settings.iter("tcp"):
            name = element.get("name") or f"TCP {len(tcps) + 1}"
            tcps.append(Tcp(name, _numbers(element.get("offset"), 6, f"TCP {name!r} offset",
                                           path)))
        if settings.get("toolPayload") is not None:
            cog = settings.get("centerOfGravity")
            payloads.append(Payload("Payload", _number(settings.get("toolPayload"),
                                                       "toolPayload", path),
                                    _numbers(cog, 3, "payload centre of gravity", path)
                                    if cog else None))  # type: ignore[arg-type]
    for element in root.iter("Payload"):
        name = element.get("name") or f"Payload {len(payloads) + 1}"
        cog = element.get("centerOfGravity")
        payloads.append(Payload(
            name, _number(element.get("mass"), f"payload {name!r} mass", path),
            _numbers(cog, 3, f"payload {name!r} centre of gravity", path)  # type: ignore[arg-type]
            if cog is not None else None))
        if element.get("defaultPayload") == "true" and active_payload is None:
            active_payload = name
    mounting = None
    marshal = root.find(".//WorldtoMarshal")
    if marshal is not None and marshal.get("tiltAngle") is not None:
        mounting = (_number(marshal.get("baseAngle", "0"), "mounting base angle", path),
                    _number(marshal.get("tiltAngle"), "mounting tilt angle", path))
    version = None
    element = root.find("LastSavedInVersion")
    if element is None:
        element = root.find("Version")
    if element is not None and element.get("major") is not None:
        version = ".".join(element.get(k, "0") for k in ("major", "minor", "bugfix"))
    return Installation(path, tuple(tcps), active_tcp, tuple(payloads), active_payload,
                        mounting, version, _settings(root), _features(root, path),
                        _io_names(root), _safety(root), _modbus(root, path), _urcaps(root),
                        _feature_variable(root), _conveyors(root, path),
                        root.find("Features/BaseView/BaseView[@isVariable='true']") is not None)


def _feature_variable(root: ElementTree.Element) -> tuple[tuple[str, bool], ...]:
    block = root.find("Features")
    if block is None:
        return ()
    return tuple((element.get("name", ""), element.get("isVariable") == "true")
                 for element in block.iter() if element.get("name")
                 and element.get("isVariable") is not None
                 and element.get("hiddenSubFeature") != "true")


def _safety(root: ElementTree.Element) -> Safety | None:
    element = root.find("SafetySettings")
    return parse_safety(element.text or "") if element is not None else None


_IO_BANKS = {
    "DigitalInputNames": "digital_in", "DigitalOutputNames": "digital_out",
    "ConfigurableInputNames": "configurable_in", "ConfigurableOutputNames": "configurable_out",
    "ToolDigitalInputNames": "tool_in", "ToolDigitalOutputNames": "tool_out",
    "AnalogInputNames": "analog_in", "AnalogOutputNames": "analog_out",
    "ToolAnalogInputNames": "tool_analog_in",
    "GeneralPurposeBooleanRegisterInputNames": "GP_bool_in",
    "GeneralPurposeBooleanRegisterOutputNames": "GP_bool_out",
    "GeneralPurposeIntRegisterInputNames": "GP_int_in",
    "GeneralPurposeIntRegisterOutputNames": "GP_int_out",
    "GeneralPurposeFloatRegisterInputNames": "GP_float_in",
    "GeneralPurposeFloatRegisterOutputNames": "GP_float_out",
}
"""``<IOs>`` name lists (comma-separated, empty for an unnamed pin) and the pins they name."""


def _point(element: ElementTree.Element, name: str, path: str) -> tuple[float, ...] | None:
    """The pose (position m, rotation vector rad) of a ``GeomPoseNode``; None when it has
    none."""
    position, axis = element.find("toolPosition"), element.find("toolAxisAngle")
    if position is None or axis is None:
        return None
    return (_numbers(position.get("value"), 3, f"feature {name!r}", path)
            + _numbers(axis.get("value"), 3, f"feature {name!r}", path))


def _rotation(rv: tuple[float, ...]) -> list[list[float]]:
    angle = math.sqrt(sum(v * v for v in rv))
    if angle < 1e-300:
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    x, y, z = (v / angle for v in rv)
    c, s, t = math.cos(angle), math.sin(angle), 1 - math.cos(angle)
    return [[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c]]


def _rotvec(m: list[list[float]]) -> tuple[float, float, float]:
    """The rotation vector (rad, angle in [0, π]) of a rotation matrix (rows)."""
    axis = (m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1])
    sin2 = math.sqrt(sum(v * v for v in axis))
    angle = math.atan2(sin2 / 2.0, (m[0][0] + m[1][1] + m[2][2] - 1.0) / 2.0)
    if angle < 1e-12:
        return (0.0, 0.0, 0.0)
    if math.pi - angle < 1e-6:
        # as PolyScope (to the last digit: eggsu/comp4320_ass2's plane letter_start): the
        # angle from the acos of the trace, the axis from the symmetric part
        cos = min(1.0, max(-1.0, (m[0][0] + m[1][1] + m[2][2] - 1.0) / 2.0))
        angle = math.acos(cos)
        sym = [[((m[i][j] + m[j][i]) / 2.0 - (cos if i == j else 0.0)) / (1.0 - cos)
                for j in range(3)] for i in range(3)]
        column = max(range(3), key=lambda i: sym[i][i])
        vector = [sym[i][column] for i in range(3)]
        norm = math.sqrt(sum(v * v for v in vector))
        vector = [v / norm for v in vector]
        if sum(a * b for a, b in zip(vector, axis, strict=True)) < 0:
            vector = [-v for v in vector]
        return tuple(v * angle for v in vector)  # type: ignore[return-value]
    return tuple(v / sin2 * angle for v in axis)  # type: ignore[return-value]


def _plane(points: list[tuple[float, ...]]) -> tuple[float, ...] | None:
    """PolyScope's pose of a plane feature taught by three points (each a pose): origin
    at the first point, y towards the second, z along the normal on the side of the first
    point's tool z axis, x = y × z. Three points at one place (a plane never taught: all
    zero, ``userHasPoints="false"``) give the first point's pose, as PolyScope writes it
    (srs827/Robot-Cello-ResidualRL's ``Plane_4``: ``p[0, 0, 0, 0, 0, 0]``) [U: only the
    zero pose seen]; None for other collinear points [U: not seen]."""
    p1, p2, p3 = (p[:3] for p in points)
    if all(math.dist(p1, q) < 1e-12 for q in (p2, p3)):
        return tuple(points[0])
    u = [b - a for a, b in zip(p1, p2, strict=True)]
    v = [b - a for a, b in zip(p1, p3, strict=True)]
    normal = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    nu, nn = math.sqrt(sum(c * c for c in u)), math.sqrt(sum(c * c for c in normal))
    if nu < 1e-12 or nn < 1e-12:
        return None
    y = [c / nu for c in u]
    z = [c / nn for c in normal]
    tool_z = [row[2] for row in _rotation(points[0][3:])]
    if sum(a * b for a, b in zip(z, tool_z, strict=True)) < 0:
        z = [-c for c in z]
    x = [y[1] * z[2] - y[2] * z[1], y[2] * z[0] - y[0] * z[2], y[0] * z[1] - y[1] * z[0]]
    matrix = [[x[i], y[i], z[i]] for i in range(3)]
    return tuple(p1) + _rotvec(matrix)


def _line(points: list[tuple[float, ...]]) -> tuple[float, ...]:
    """PolyScope's pose of a line feature taught by two points (each a pose): origin at the
    first point, y along the line towards the second, z the first point's tool z axis made
    perpendicular to y, x = y × z (seen: creativity-software/ur10-robot-draw-circle's
    ``Line_1``). Two points at one place (a line never taught: both zero) give the first
    point's pose [U: only the zero pose seen]."""
    p1, p2 = points[0][:3], points[1][:3]
    u = [b - a for a, b in zip(p1, p2, strict=True)]
    nu = math.sqrt(sum(c * c for c in u))
    tool_z = [row[2] for row in _rotation(points[0][3:])]
    if nu < 1e-12:
        return tuple(points[0])
    y = [c / nu for c in u]
    along = sum(a * b for a, b in zip(tool_z, y, strict=True))
    z = [a - along * b for a, b in zip(tool_z, y, strict=True)]
    nz = math.sqrt(sum(c * c for c in z))
    if nz < 1e-12:  # the tool points along the line [U]: not seen
        return tuple(points[0])
    z = [c / nz for c in z]
    x = [y[1] * z[2] - y[2] * z[1], y[2] * z[0] - y[0] * z[2], y[0] * z[1] - y[1] * z[0]]
    matrix = [[x[i], y[i], z[i]] for i in range(3)]
    return tuple(p1) + _rotvec(matrix)


def _features(root: ElementTree.Element, path: str) -> tuple[tuple[str, tuple[float, ...]], ...]:
    features: list[tuple[str, tuple[float, ...]]] = []
    block = root.find("Features")
    if block is None:
        return ()
    for wrapper in block:
        for element in wrapper:
            name = element.get("name")
            if not name or element.get("hiddenSubFeature") == "true" \
                    or element.get("isVariable") == "false":
                continue
            if element.tag == "GeomPoseNode":
                pose = _point(element, name, path)
            elif element.tag == "GeomPlaneNode":
                points = _points(element, ("firstPoint", "secondPoint", "thirdPoint"), name,
                                 path)
                pose = _plane(points) if len(points) == 3 else None
            elif element.tag == "GeomLineNode":
                points = _points(element, ("firstPoint", "secondPoint"), name, path)
                pose = _line(points) if len(points) == 2 else None
            else:
                continue
            if pose is not None:
                features.append((name, pose))
    return tuple(features)


def _points(element: ElementTree.Element, tags: tuple[str, ...], name: str,
            path: str) -> list:
    """The poses of a plane's or line's taught points (``tags``) that are there and read."""
    points = []
    for tag in tags:
        point = element.find(f"{tag}/GeomPoseNode")
        value = _point(point, name, path) if point is not None else None
        if value is not None:
            points.append(value)
    return points


_BUILT_IN = frozenset((
    "ConveyorTracking", "EthernetIP", "com.ur.urcap.profinet",
    "com.ur.polyscope.screwdriving.installation.ScrewdrivingInstallationNodeService"))
"""Installation contributions PolyScope ships whose code is not in a program's preamble."""


def _conveyors(root: ElementTree.Element, path: str) -> tuple[Conveyor, ...]:
    """The enabled conveyors of the built-in ``ConveyorTracking`` contribution (PolyScope 3.x
    and 5.x write ``enabled_N``, ``apin_N`` … for conveyor N = 0, 1)."""
    element = None
    for candidate in root.iterfind("Contributions/URCaps/Contributed"):
        if candidate.get("id") == "ConveyorTracking":
            element = candidate
    if element is None:
        return ()
    data = {d.get("key", ""): d.get("value", "") for d in element.iterfind("data")}
    lines: dict[str, tuple[tuple[float, ...], tuple[float, ...]]] = {}
    for line in root.iterfind("Features//GeomLineNode"):
        name = line.get("name")
        if not name:
            continue
        points = _points(line, ("firstPoint", "secondPoint"), name, path)
        if len(points) == 2:
            lines.setdefault(name, (points[0], points[1]))
    conveyors = []
    indices = sorted({int(key.rsplit("_", 1)[1]) for key in data
                      if key.startswith("enabled_") and key.rsplit("_", 1)[1].isdigit()})
    for index in indices:
        if data.get(f"enabled_{index}") != "true":
            continue

        def number(key: str, index=index) -> float | None:
            text = data.get(f"{key}_{index}")
            return _number(text, f"conveyor {index} {key}", path) if text else None

        a, b, decoder = number("apin"), number("bpin"), number("incrementalMode")
        conveyors.append(Conveyor(
            index, data.get(f"conveyorType_{index}", ""), data.get(f"encoderType_{index}", ""),
            int(decoder) if decoder is not None else None,
            (int(a), int(b)) if a is not None and b is not None else None,
            number("tpm"), number("tpr"), lines.get(data.get(f"direction_{index}", "")),
            data.get(f"switchDirection_{index}") == "true",
            data.get(f"rotateTool_{index}") == "true"))
    return tuple(conveyors)


def _urcaps(root: ElementTree.Element) -> tuple[tuple[str, str, str], ...]:
    return tuple((element.get("name", "?"), element.get("vendor", "?"),
                  element.get("installationContributionTitle", element.get("name", "?")))
                 for element in root.iterfind("Contributions/URCaps/Contributed")
                 if element.get("id") not in _BUILT_IN)


def _modbus(root: ElementTree.Element, path: str) -> tuple[ModbusSignal, ...]:
    signals = []
    for unit in root.iterfind("IOs/ModbusUnits/Unit"):
        ip = unit.get("ipAddress", "")
        sequential = unit.get("sequentialMode") == "true"
        for element in unit.iter("ModbusSignal"):
            name = element.get("name") or ""
            what = f"Modbus signal {name!r}"
            frequency = element.get("updateFrequency")
            choice = element.get("modificationChoice")
            signals.append(ModbusSignal(
                ip, int(_number(element.get("slaveAddress", "255"), f"{what} slave", path)),
                int(_number(element.get("signalAddress"), f"{what} address", path)),
                element.get("type", ""), name,
                _number(frequency, f"{what} frequency", path) if frequency else None,
                int(_number(choice, f"{what} choice", path)) if choice else None, sequential))
    return tuple(signals)


def _settings(root: ElementTree.Element) -> dict[str, dict[str, str]]:
    settings: dict[str, dict[str, str]] = {}
    for tag in ("SmoothTransitionSettings", "ToolCommSettings", "SafeHomeSettings",
                "ToolWrenchConfiguration", "MotionSettingsConfiguration"):
        element = root.find(tag)
        if element is not None:
            settings[tag] = dict(element.attrib)
    if "ToolCommSettings" not in settings and root.get("toolOutputVoltage") is not None:
        # PolyScope 3.4-3.5: the tool voltage (V) as an attribute of the root
        settings["ToolCommSettings"] = {"toolOutputVoltage": root.get("toolOutputVoltage", "")}
    ios = root.find("IOs")
    if ios is not None:
        for element in ios:
            if "value" in element.attrib:
                settings[f"IOs/{element.tag}"] = dict(element.attrib)
    for element in root.iter("Payload"):
        if element.get("inertiaParameters"):
            settings[f"Payload/{element.get('name', '')}"] = dict(element.attrib)
    for element in root.iterfind("Contributions/URCaps/Contributed"):
        if element.get("id") == "EthernetIP":  # the built-in EtherNet/IP adapter's data
            settings["EthernetIP"] = {data.get("key", ""): data.get("value", "")
                                      for data in element.iterfind("data")}
    return settings


def _io_names(root: ElementTree.Element) -> tuple[tuple[str, str], ...]:
    names: list[tuple[str, str]] = []
    ios = root.find("IOs")
    if ios is None:
        return ()
    for tag, bank in _IO_BANKS.items():
        element = ios.find(tag)
        if element is None:
            continue
        for index, name in enumerate((element.get("value") or "").split(",")):
            if name.strip():
                names.append((name.strip(), f"{bank}[{index}]"))
    return tuple(names)


def _legacy(root: ElementTree.Element, path: str) -> Installation:
    """PolyScope 1.x (CB2): a serialised ``RobotInstallation`` object."""
    tcps: tuple[Tcp, ...] = ()
    transform = root.find("tcpTransform")
    if transform is not None:
        values = ",".join((d.text or "") for d in transform.findall("double"))
        tcps = (Tcp("TCP", _numbers(values, 6, "tcpTransform", path)),)
    payloads: tuple[Payload, ...] = ()
    mass = root.find("toolPayload")
    if mass is not None:
        payloads = (Payload("Payload", _number(mass.text, "toolPayload", path)),)
    mounting = None
    tilt = root.find(".//mountingTiltAngle")
    if tilt is not None:
        base = root.find(".//mountingBaseAngle")
        mounting = (_number(base.text, "mountingBaseAngle", path) if base is not None else 0.0,
                    _number(tilt.text, "mountingTiltAngle", path))
    return Installation(path, tcps, "TCP" if tcps else None, payloads,
                        "Payload" if payloads else None, mounting, None)


def read_installation(path: str | Path) -> Installation:
    """Read the installation file at ``path``; :class:`InstallationError` if it cannot be."""
    try:
        data = Path(path).read_bytes()
    except OSError as error:
        raise InstallationError(str(path), f"cannot read: {error.strerror}") from None
    return parse_installation(data, str(path))


def find_installation(program: str | Path) -> Path | None:
    """The installation beside a program file: the only ``*.installation`` in its folder,
    else the one named like the program, else ``default.installation``; ``None`` if none."""
    program = Path(program)
    folder = program.parent
    try:
        candidates = sorted(p for p in folder.glob("*.installation") if p.is_file())
    except OSError:
        return None
    if len(candidates) == 1:
        return candidates[0]
    for name in (program.stem + ".installation", "default.installation"):
        for candidate in candidates:
            if candidate.name == name:
                return candidate
    return None
