"""RTDE (Real-Time Data Exchange, port 30004), protocol versions 1 and 2, both sides.

Every package is ``uint16 size`` (the whole package, its 3-byte header included) · ``uint8
type`` · payload. The client (EE) sets up recipes — named lists of fields — then starts the
stream; the controller (CON) answers every setup request and streams DATA_PACKAGEs of the
output recipe; the client sends DATA_PACKAGEs of its input recipes when inputs change.

====  ========================  ===================================  ==========================
type  package                   request payload (EE → CON)           reply payload (CON → EE)
====  ========================  ===================================  ==========================
'V'   REQUEST_PROTOCOL_VERSION  uint16 version                       uint8 accepted
'v'   GET_URCONTROL_VERSION     —                                    uint32 major, minor,
                                                                     bugfix, build
'O'   SETUP_OUTPUTS             v2: double frequency; names (CSV)    v2: uint8 recipe id;
                                                                     types (CSV)
'I'   SETUP_INPUTS              names (CSV)                          uint8 recipe id; types
'S'   START / 'P' PAUSE         —                                    uint8 accepted
'U'   DATA_PACKAGE              uint8 recipe id; values              v2: uint8 recipe id;
                                                                     values (v1: values)
'M'   TEXT_MESSAGE              v2: uint8 n, message, uint8 n,       same (v1 from CON:
                                source, uint8 level                  uint8 level, message)
====  ========================  ===================================  ==========================

A name the controller does not know comes back with the type ``NOT_FOUND``; an input that
another client already controls comes back as ``IN_USE``. Either makes the recipe unusable:
an output recipe with a NOT_FOUND name streams nothing at all.

This module has the packages as immutable values (requests, replies and
:class:`RtdeTextMessage` frozen dataclasses; :class:`DataPackage`, the streamed one, a named
tuple), :class:`Recipe` (encode/decode data by recipe, each with its own generated reader and
packer), and two state
machines without sockets: :class:`RtdeClient` (what to send, what replies mean) and
:class:`RtdeServer` (the virtual controller: parse requests, produce replies, track
recipes, refuse inputs another client owns via a shared :class:`InputOwnership`).
"""

from __future__ import annotations

import math
import struct
from collections import deque
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import ClassVar, NamedTuple

from ._binary import read_text, text_bytes
from .errors import ProtocolError
from .rtde_fields import FIELDS, TYPES, field_available

__all__ = [
    "PORT", "MAX_NAMES_BYTES", "NOT_FOUND", "IN_USE", "Recipe",
    "RequestProtocolVersion", "GetControllerVersion", "SetupOutputs", "SetupInputs", "Start",
    "Pause", "ProtocolVersionReply", "ControllerVersion", "OutputSetupReply",
    "InputSetupReply", "StartReply", "PauseReply", "DataPackage", "RtdeTextMessage",
    "decode_rtde", "encode_rtde", "RtdeFramer", "RtdeClient", "RtdeServer", "InputOwnership",
    "EXCEPTION", "ERROR", "WARNING", "INFO", "CB3_MAX_FREQUENCY", "E_SERIES_MAX_FREQUENCY",
]

PORT = 30004

_HEADER = struct.Struct(">HB")
MAX_PACKAGE = 0xFFFF
"""The size field is a uint16: no package can be longer than 65535 bytes."""

MAX_NAMES_BYTES = 2048
"""Longest comma-separated name list in a setup request, per UR's RTDE guide."""

NOT_FOUND = "NOT_FOUND"
IN_USE = "IN_USE"

EXCEPTION, ERROR, WARNING, INFO = 0, 1, 2, 3
"""Text message levels."""

CB3_MAX_FREQUENCY = 125.0
"""CB3 control loop rate [Hz]; output frequencies above it are refused."""
E_SERIES_MAX_FREQUENCY = 500.0
"""e-Series control loop rate [Hz]."""


def _error(message: str, offset: int | None = None) -> ProtocolError:
    return ProtocolError(message, interface="rtde", offset=offset)


# --- recipes --------------------------------------------------------------------------------


def _reader(plan: list[tuple[str, int, int]], body: str, with_id: bool):
    """The fast decoder of one recipe's data packages (with or without the recipe id byte):
    a function from a whole package (header included) to its :class:`DataPackage`, or
    ``None`` when the package is not one of this recipe's (wrong size, size field or type;
    the caller then takes the general path, which names the problem).

    One ``struct.unpack`` of the whole package — it requires the exact length — and one
    dict display, as a hand-written decoder would have; generated from the recipe's plan.
    The generated source holds only identifiers and integers: the names (which a remote
    client chose) are bound as default values ``k0``, ``k1``, ..., never written into it;
    so are the vectors' slices (``s0``, ...: built once, not per package)."""
    whole = struct.Struct((">HBB" if with_id else ">HB") + body)
    skip = 3 if with_id else 2
    keys: dict[str, object] = {f"k{number}": name for number, (name, _, _) in enumerate(plan)}
    keys.update({f"s{number}": slice(skip + index, skip + index + count)
                 for number, (_, index, count) in enumerate(plan) if count > 1})
    items = ", ".join(
        f"k{number}: flat[{skip + index}]" if count == 1 else f"k{number}: flat[s{number}]"
        for number, (_, index, count) in enumerate(plan))
    defaults = "".join(f", {key}={key}" for key in keys)
    source = (
        f"def read(package{defaults}):\n"
        "    try:\n"
        "        flat = unpack(package)\n"
        "    except error:\n"
        "        return None\n"
        f"    if flat[0] != {int(whole.size)} or flat[1] != 85:\n"
        "        return None\n"
        f"    return new(DataPackage, ({'flat[2]' if with_id else 'None'}, {{{items}}}))\n")
    namespace = {"unpack": whole.unpack, "error": struct.error, "new": tuple.__new__,
                 "DataPackage": DataPackage, **keys}
    exec(source, namespace)  # noqa: S102 - identifiers and integers only (see above)
    return namespace["read"]


@dataclass(frozen=True)
class Recipe:
    """A set-up recipe: ``id`` (``None`` for a v1 output recipe, which has none), the
    ``names`` asked for and the ``types`` the controller answered (``NOT_FOUND`` /
    ``IN_USE`` for names it refused). Packs and unpacks data packages' values."""

    id: int | None
    names: tuple[str, ...]
    types: tuple[str, ...]
    _struct: struct.Struct | None = field(default=None, init=False, repr=False, compare=False)
    _plan: tuple[tuple[str, int, int], ...] = field(default=(), init=False, repr=False,
                                                    compare=False)
    # the generated readers of whole data packages with / without (v1 output) a recipe id
    _read_id: Callable[[bytes], DataPackage | None] | None = field(
        default=None, init=False, repr=False, compare=False)
    _read_v1: Callable[[bytes], DataPackage | None] | None = field(
        default=None, init=False, repr=False, compare=False)
    _packers: tuple | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if len(self.names) != len(self.types):
            raise _error(f"recipe has {len(self.names)} names but {len(self.types)} types")
        if not self.valid:
            return
        fmt = [">"]
        plan = []
        index = 0
        for name, type_ in zip(self.names, self.types, strict=True):
            if type_ not in TYPES:
                raise _error(f"unknown RTDE type {type_!r} for {name!r}")
            code, count = TYPES[type_]
            fmt.append(f"{count}{code}")
            plan.append((name, index, count))
            index += count
        object.__setattr__(self, "_struct", struct.Struct("".join(fmt)))
        object.__setattr__(self, "_plan", tuple(plan))
        body = "".join(fmt[1:])
        object.__setattr__(self, "_read_v1", _reader(plan, body, False))
        object.__setattr__(self, "_read_id", _reader(plan, body, True))
        # whole data packages from the values (recipe id first when there is one): the
        # header's size and type are constants of the recipe
        object.__setattr__(self, "_packers", tuple(
            partial(whole.pack, whole.size, DataPackage.CODE)
            for whole in (struct.Struct(">HB" + body), struct.Struct(">HBB" + body))))

    @property
    def not_found(self) -> tuple[str, ...]:
        """Names the controller does not know."""
        return tuple(n for n, t in zip(self.names, self.types, strict=True) if t == NOT_FOUND)

    @property
    def in_use(self) -> tuple[str, ...]:
        """Input names another client already controls."""
        return tuple(n for n, t in zip(self.names, self.types, strict=True) if t == IN_USE)

    @property
    def valid(self) -> bool:
        """Can data flow with this recipe (no NOT_FOUND, no IN_USE)?"""
        return all(t not in (NOT_FOUND, IN_USE) for t in self.types)

    @property
    def size(self) -> int:
        """Bytes of the values in one data package (without the recipe id)."""
        return self._struct.size if self._struct else 0

    def _require_valid(self) -> struct.Struct:
        if self._struct is None:
            refused = ", ".join(f"{n} ({t})" for n, t in zip(self.names, self.types,
                                                             strict=True)
                                if t in (NOT_FOUND, IN_USE))
            raise _error(f"recipe {self.id} cannot carry data: {refused}")
        return self._struct

    def pack(self, values: Mapping[str, object]) -> bytes:
        """The values of one data package, in recipe order (no recipe id)."""
        packer = self._require_valid()
        flat: list[object] = []
        for name, _, count in self._plan:
            if name not in values:
                raise _error(f"data package for recipe {self.id}: no value for {name!r}")
            value = values[name]
            if count == 1:
                flat.append(value)
            else:
                if len(value) != count:  # type: ignore[arg-type]
                    raise _error(f"data package: {name!r} needs {count} values, got "
                                 f"{len(value)}")  # type: ignore[arg-type]
                flat.extend(value)  # type: ignore[arg-type]
        try:
            return packer.pack(*flat)
        except struct.error as exc:
            raise _error(f"data package for recipe {self.id}: {exc}") from None

    def unpack(self, data: bytes | memoryview, offset: int = 0) -> dict[str, object]:
        """The values at ``offset`` (exactly :attr:`size` bytes must follow)."""
        unpacker = self._require_valid()
        if len(data) - offset != unpacker.size:
            raise _error(f"data package for recipe {self.id} has {len(data) - offset} bytes of "
                         f"values; the recipe ({len(self.names)} fields) needs "
                         f"{unpacker.size}", _HEADER.size + offset)
        values = unpacker.unpack_from(data, offset)
        out: dict[str, object] = {}
        for name, index, count in self._plan:
            out[name] = values[index] if count == 1 else values[index:index + count]
        return out


# --- packages -------------------------------------------------------------------------------


@dataclass(frozen=True)
class RequestProtocolVersion:
    """'V' request: use protocol ``version`` (1 or 2)."""

    CODE: ClassVar[int] = ord("V")
    version: int = 2


@dataclass(frozen=True)
class GetControllerVersion:
    """'v' request: ask for the controller's software version."""

    CODE: ClassVar[int] = ord("v")


@dataclass(frozen=True)
class SetupOutputs:
    """'O' request: the output recipe — ``names`` and (v2) the ``frequency`` [Hz]."""

    CODE: ClassVar[int] = ord("O")
    names: tuple[str, ...] = ()
    frequency: float | None = 125.0


@dataclass(frozen=True)
class SetupInputs:
    """'I' request: an input recipe of ``names``."""

    CODE: ClassVar[int] = ord("I")
    names: tuple[str, ...] = ()


@dataclass(frozen=True)
class Start:
    """'S' request: start streaming."""

    CODE: ClassVar[int] = ord("S")


@dataclass(frozen=True)
class Pause:
    """'P' request: pause streaming."""

    CODE: ClassVar[int] = ord("P")


@dataclass(frozen=True)
class ProtocolVersionReply:
    """'V' reply: was the requested protocol version accepted?"""

    CODE: ClassVar[int] = ord("V")
    accepted: bool = True


@dataclass(frozen=True)
class ControllerVersion:
    """'v' reply: the controller's software version."""

    CODE: ClassVar[int] = ord("v")
    major: int = 0
    minor: int = 0
    bugfix: int = 0
    build: int = 0

    @property
    def version(self) -> tuple[int, int, int, int]:
        return (self.major, self.minor, self.bugfix, self.build)


@dataclass(frozen=True)
class OutputSetupReply:
    """'O' reply: the output recipe's id (v2; ``None`` in v1) and the type of each name."""

    CODE: ClassVar[int] = ord("O")
    recipe_id: int | None = None
    types: tuple[str, ...] = ()


@dataclass(frozen=True)
class InputSetupReply:
    """'I' reply: the input recipe's id and the type of each name."""

    CODE: ClassVar[int] = ord("I")
    recipe_id: int = 0
    types: tuple[str, ...] = ()


@dataclass(frozen=True)
class StartReply:
    """'S' reply: did streaming start?"""

    CODE: ClassVar[int] = ord("S")
    accepted: bool = True


@dataclass(frozen=True)
class PauseReply:
    """'P' reply: did streaming pause?"""

    CODE: ClassVar[int] = ord("P")
    accepted: bool = True


class _DataPackageFields(NamedTuple):
    recipe_id: int | None = None
    values: dict[str, object] = {}  # noqa: RUF012 - replaced by a fresh dict in __new__


class DataPackage(_DataPackageFields):
    """'U': one sample of a recipe. ``values`` maps each recipe name to its value (vectors
    as tuples). ``recipe_id`` is ``None`` for v1 output packages, which carry none.

    Immutable and tuple-backed (a named tuple, so a decoder builds it in one step); equal
    only to another :class:`DataPackage` with the same id and values."""

    __slots__ = ()
    CODE: ClassVar[int] = ord("U")

    def __new__(cls, recipe_id: int | None = None,
                values: dict[str, object] | None = None) -> DataPackage:
        return tuple.__new__(cls, (recipe_id, {} if values is None else values))

    def __eq__(self, other: object) -> bool:
        return type(other) is DataPackage and tuple.__eq__(self, other)

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)

    def __hash__(self) -> int:
        return hash((self.recipe_id,))  # the values (a dict) are not hashed


@dataclass(frozen=True)
class RtdeTextMessage:
    """'M': a log message with ``level`` (0 exception, 1 error, 2 warning, 3 info) and the
    ``source`` that sent it (empty in protocol v1, which has no source field)."""

    CODE: ClassVar[int] = ord("M")
    message: str = ""
    source: str = ""
    level: int = INFO


Request = (RequestProtocolVersion | GetControllerVersion | SetupOutputs | SetupInputs | Start
           | Pause | DataPackage | RtdeTextMessage)
Reply = (ProtocolVersionReply | ControllerVersion | OutputSetupReply | InputSetupReply
         | StartReply | PauseReply | DataPackage | RtdeTextMessage)


# --- encoding -------------------------------------------------------------------------------


def _names_bytes(names: Iterable[str]) -> bytes:
    names = tuple(names)
    for name in names:
        if not name or "," in name:
            raise _error(f"recipe name {name!r} is empty or contains a comma")
    data = text_bytes(",".join(names), "recipe names", "rtde")
    if len(data) > MAX_NAMES_BYTES:
        raise _error(f"recipe names take {len(data)} bytes; the controller accepts at most "
                     f"{MAX_NAMES_BYTES}")
    return data


def _short_text(text: str, what: str) -> bytes:
    data = text_bytes(text, what, "rtde")
    if len(data) > 255:
        raise _error(f"{what} is {len(data)} bytes; its size byte holds at most 255")
    return bytes([len(data)]) + data


def _package(code: int, payload: bytes) -> bytes:
    size = _HEADER.size + len(payload)
    if size > MAX_PACKAGE:
        raise _error(f"package of {size} bytes exceeds the uint16 size field ({MAX_PACKAGE})")
    return _HEADER.pack(size, code) + payload


def _byte(value: int, what: str) -> bytes:
    if not 0 <= value <= 255:
        raise _error(f"{what} {value} does not fit in a byte")
    return bytes([value])


def encode_rtde(message: Request | Reply, protocol: int = 2,
                recipe: Recipe | None = None) -> bytes:
    """The bytes of one package. ``protocol`` (1 or 2) selects the v1/v2 layouts;
    a :class:`DataPackage` needs its ``recipe``."""
    match message:
        case RequestProtocolVersion(version):
            if not 0 <= version <= 0xFFFF:
                raise _error(f"protocol version {version} does not fit in a uint16")
            return _package(message.CODE, struct.pack(">H", version))
        case GetControllerVersion() | Start() | Pause():
            return _package(message.CODE, b"")
        case SetupOutputs(names, frequency):
            payload = _names_bytes(names)
            if protocol >= 2:
                if frequency is None:
                    raise _error("protocol 2 output setup needs a frequency")
                payload = struct.pack(">d", frequency) + payload
            return _package(message.CODE, payload)
        case SetupInputs(names):
            return _package(message.CODE, _names_bytes(names))
        case ProtocolVersionReply(accepted) | StartReply(accepted) | PauseReply(accepted):
            return _package(message.CODE, bytes([1 if accepted else 0]))
        case ControllerVersion(major, minor, bugfix, build):
            try:
                return _package(message.CODE, struct.pack(">IIII", major, minor, bugfix, build))
            except struct.error as exc:
                raise _error(f"controller version: {exc}") from None
        case OutputSetupReply(recipe_id, types):
            payload = text_bytes(",".join(types), "types", "rtde")
            if protocol >= 2:
                payload = _byte(recipe_id or 0, "recipe id") + payload
            return _package(message.CODE, payload)
        case InputSetupReply(recipe_id, types):
            return _package(message.CODE, _byte(recipe_id, "recipe id")
                            + text_bytes(",".join(types), "types", "rtde"))
        case DataPackage(recipe_id, values):
            if recipe is None:
                raise _error("encoding a data package needs its recipe")
            head = b"" if recipe_id is None else _byte(recipe_id, "recipe id")
            return _package(message.CODE, head + recipe.pack(values))
        case RtdeTextMessage(text, source, level):
            if protocol >= 2:
                payload = (_short_text(text, "message") + _short_text(source, "source")
                           + _byte(level, "level"))
            else:
                payload = _byte(level, "level") + text_bytes(text, "message", "rtde")
            return _package(message.CODE, payload)
    raise _error(f"cannot encode {type(message).__name__}")


# --- decoding -------------------------------------------------------------------------------

_REQUEST_CODES = {ord(c) for c in "VvOISPUM"}
_REPLY_CODES = _REQUEST_CODES


def _exact(payload: bytes, size: int, what: str) -> None:
    if len(payload) != size:
        raise _error(f"{what} payload has {len(payload)} bytes; it must have {size}",
                     _HEADER.size)


def _csv(payload: bytes) -> tuple[str, ...]:
    text = read_text(payload)
    return tuple(text.split(",")) if text else ()


def _names(payload: bytes) -> tuple[str, ...]:
    """The names of a setup request. Empty entries are dropped and blanks around a name
    stripped, as the controller does: ur_rtde ends its list with a comma."""
    return tuple(name for name in (n.strip(" \t\r\n\x00") for n in _csv(payload)) if name)


def _decode_text_message(payload: bytes, protocol: int) -> RtdeTextMessage:
    if protocol >= 2:
        pos = 0
        parts = []
        for what in ("message", "source"):
            if len(payload) <= pos:
                raise _error(f"text message ends before its {what} size byte", 3 + pos)
            size = payload[pos]
            if len(payload) < pos + 1 + size:
                raise _error(f"text message {what} of {size} bytes does not fit in the "
                             f"{len(payload) - pos - 1} bytes left", 3 + pos)
            parts.append(read_text(payload[pos + 1:pos + 1 + size]))
            pos += 1 + size
        if len(payload) != pos + 1:
            raise _error(f"text message has {len(payload) - pos} bytes after its source; "
                         "expected exactly the level byte", 3 + pos)
        return RtdeTextMessage(parts[0], parts[1], payload[pos])
    if not payload:
        raise _error("text message has no level byte", 3)
    return RtdeTextMessage(read_text(payload[1:]), "", payload[0])


def decode_rtde(package: bytes, *, sender: str, protocol: int = 2,
                recipes: Mapping[int | None, Recipe] | None = None) -> Request | Reply:
    """Decode exactly one package sent by ``sender`` (``"client"`` or ``"server"``: the
    package codes are the same in both directions, the payloads are not).

    Data packages are decoded with ``recipes`` (recipe id → :class:`Recipe`; a v1 output
    recipe is under ``None``).
    """
    if sender == "server":
        with_id = protocol >= 2
    elif sender == "client":
        with_id = True
    else:
        raise ValueError(f"sender must be 'client' or 'server', not {sender!r}")
    if recipes:  # a data package of a known recipe: the fast path
        try:
            read = (recipes[package[3]]._read_id if with_id  # type: ignore[index]
                    else recipes[None]._read_v1)
        except (KeyError, IndexError, TypeError):  # no such recipe, too short
            read = None
        if read is not None:  # None: an unusable recipe
            message = read(package)
            if message is not None:
                return message
    if len(package) < _HEADER.size:
        raise _error(f"{len(package)} bytes cannot hold the 3-byte package header", 0)
    size, code = _HEADER.unpack_from(package)
    if size != len(package):
        raise _error(f"size field says {size} bytes but the package has {len(package)}", 0)
    return _decode_payload(code, bytes(package[_HEADER.size:]), sender, protocol, recipes)


def _decode_payload(code: int, payload: bytes, sender: str, protocol: int,
                    recipes: Mapping[int | None, Recipe] | None) -> Request | Reply:
    char = chr(code)
    if char == "U":
        return _decode_data(payload, sender, protocol, recipes)
    if char == "M":
        return _decode_text_message(payload, protocol)
    if sender == "client":
        if char == "V":
            _exact(payload, 2, "protocol version request")
            return RequestProtocolVersion(struct.unpack(">H", payload)[0])
        if char in "vSP":
            _exact(payload, 0, f"'{char}' request")
            return {"v": GetControllerVersion, "S": Start, "P": Pause}[char]()
        if char == "O":
            frequency = None
            if protocol >= 2:
                if len(payload) < 8:
                    raise _error(f"output setup has {len(payload)} bytes; protocol 2 needs "
                                 "an 8-byte frequency first", 3)
                (frequency,) = struct.unpack_from(">d", payload)
                payload = payload[8:]
            if len(payload) > MAX_NAMES_BYTES:
                raise _error(f"output setup names take {len(payload)} bytes; at most "
                             f"{MAX_NAMES_BYTES} are allowed", 3)
            return SetupOutputs(_names(payload), frequency)
        if char == "I":
            if len(payload) > MAX_NAMES_BYTES:
                raise _error(f"input setup names take {len(payload)} bytes; at most "
                             f"{MAX_NAMES_BYTES} are allowed", 3)
            return SetupInputs(_names(payload))
    else:
        if char in "VSP":
            _exact(payload, 1, f"'{char}' reply")
            cls = {"V": ProtocolVersionReply, "S": StartReply, "P": PauseReply}[char]
            return cls(payload[0] != 0)
        if char == "v":
            _exact(payload, 16, "controller version reply")
            return ControllerVersion(*struct.unpack(">IIII", payload))
        if char == "O":
            if protocol >= 2:
                if not payload:
                    raise _error("output setup reply has no recipe id", 3)
                return OutputSetupReply(payload[0], _csv(payload[1:]))
            return OutputSetupReply(None, _csv(payload))
        if char == "I":
            if not payload:
                raise _error("input setup reply has no recipe id", 3)
            return InputSetupReply(payload[0], _csv(payload[1:]))
    raise _error(f"unknown package type {code} ({char!r}) from the {sender}", 2)


def _decode_data(payload: bytes, sender: str, protocol: int,
                 recipes: Mapping[int | None, Recipe] | None) -> DataPackage:
    with_id = sender == "client" or protocol >= 2
    recipe_id = None
    offset = 0
    if with_id:
        if not payload:
            raise _error("data package has no recipe id", 3)
        recipe_id = payload[0]
        offset = 1
    recipe = (recipes or {}).get(recipe_id)
    if recipe is None:
        what = "the v1 output recipe" if recipe_id is None else f"recipe {recipe_id}"
        raise _error(f"data package for {what}, which was never set up", 3)
    return DataPackage(recipe_id, recipe.unpack(payload, offset))


class RtdeFramer:
    """Cuts the RTDE byte stream into packages (header included), whatever the chunking.

    A size field below 3 cannot be a package and loses the framing: the framer then refuses
    further input. Sizes are at most 65535 by construction (uint16), which bounds the buffer.
    """

    def __init__(self) -> None:
        self._buffer = bytearray()
        self._broken: ProtocolError | None = None

    @property
    def pending(self) -> int:
        return len(self._buffer)

    def feed(self, data: bytes) -> list[bytes]:
        if self._broken is not None:
            raise _error(f"stream already failed ({self._broken.message}); reconnect")
        self._buffer += data
        packages = []
        pos = 0
        buffer = self._buffer
        while len(buffer) - pos >= _HEADER.size:
            size, code = _HEADER.unpack_from(buffer, pos)
            if size < _HEADER.size:
                self._broken = _error(f"package size field says {size} bytes, less than the "
                                      "3-byte header", 0)
                raise self._broken
            if len(buffer) - pos < size:
                break
            packages.append(bytes(buffer[pos:pos + size]))
            pos += size
        del buffer[:pos]
        return packages


# --- client state machine -------------------------------------------------------------------


class RtdeClient:
    """The client's side of an RTDE connection, without the socket.

    Methods that send (``request_protocol_version``, ``get_controller_version``,
    ``setup_outputs``, ``setup_inputs``, ``start``, ``pause``, ``send_inputs``,
    ``send_message``) return the bytes to write and remember which reply is due.
    ``receive_data(bytes)`` returns the events the received bytes complete: the replies
    (in request order), :class:`DataPackage` samples of the output recipe and
    :class:`RtdeTextMessage` logs, and updates ``protocol``, ``controller_version``,
    ``output_recipe``, ``input_recipes`` and ``running``.

    The usual handshake (as UR's record.py): ``request_protocol_version(2)`` →
    ``get_controller_version()`` → ``setup_outputs(names, frequency)`` → optional
    ``setup_inputs(names)`` → ``start()``.
    """

    def __init__(self) -> None:
        self._framer = RtdeFramer()
        self._pending: deque[Request] = deque()
        self.protocol = 1
        self.controller_version: ControllerVersion | None = None
        self.output_recipe: Recipe | None = None
        self.input_recipes: dict[int, Recipe] = {}
        self.running = False

    @property
    def awaiting(self) -> tuple[Request, ...]:
        """Requests sent whose replies have not arrived, oldest first."""
        return tuple(self._pending)

    def _send(self, request: Request) -> bytes:
        data = encode_rtde(request, self.protocol)
        self._pending.append(request)
        return data

    def request_protocol_version(self, version: int = 2) -> bytes:
        """Ask for protocol ``version``; the reply decides :attr:`protocol`."""
        return self._send(RequestProtocolVersion(version))

    def get_controller_version(self) -> bytes:
        return self._send(GetControllerVersion())

    def setup_outputs(self, names: Iterable[str], frequency: float = 125.0) -> bytes:
        """Set the output recipe (``frequency`` [Hz] is sent in protocol 2 only)."""
        if self.running:
            raise _error("pause before changing the output recipe")
        names = tuple(names)
        if not names:
            raise _error("an output recipe needs at least one name")
        if not (math.isfinite(frequency) and frequency > 0):
            raise _error(f"output frequency must be a positive number of Hz, not {frequency}")
        return self._send(SetupOutputs(names, frequency if self.protocol >= 2 else None))

    def setup_inputs(self, names: Iterable[str]) -> bytes:
        if self.running:
            raise _error("pause before setting up an input recipe")
        names = tuple(names)
        if not names:
            raise _error("an input recipe needs at least one name")
        return self._send(SetupInputs(names))

    def start(self) -> bytes:
        """Start streaming; refused here if no usable recipe is set up."""
        recipes = [r for r in [self.output_recipe, *self.input_recipes.values()] if r]
        if not recipes:
            raise _error("set up an output or input recipe before starting")
        if self.output_recipe is not None and not self.output_recipe.valid:
            raise _error(f"the output recipe is unusable: {_refusal(self.output_recipe)}")
        return self._send(Start())

    def pause(self) -> bytes:
        return self._send(Pause())

    def send_inputs(self, recipe_id: int, values: Mapping[str, object]) -> bytes:
        """A data package for input recipe ``recipe_id`` (no reply is due)."""
        recipe = self.input_recipes.get(recipe_id)
        if recipe is None:
            raise _error(f"input recipe {recipe_id} was never set up")
        if not recipe.valid:
            raise _error(f"input recipe {recipe_id} is unusable: {_refusal(recipe)}")
        return encode_rtde(DataPackage(recipe_id, dict(values)), self.protocol, recipe)

    def send_message(self, message: str, source: str = "urdsl", level: int = INFO) -> bytes:
        """A text message for the controller's log (no reply is due)."""
        return encode_rtde(RtdeTextMessage(message, source, level), self.protocol)

    def receive_data(self, data: bytes) -> list[Reply]:
        """Events completed by ``data``."""
        events: list[Reply] = []
        for package in self._framer.feed(data):
            events.append(self._handle(package))
        return events

    def _handle(self, package: bytes) -> Reply:
        code = package[2]
        if code == DataPackage.CODE:
            key = self.output_recipe.id if self.output_recipe else None
            recipes = {key: self.output_recipe} if self.output_recipe else {}
            event = decode_rtde(package, sender="server", protocol=self.protocol,
                                recipes=recipes)
            return event  # type: ignore[return-value]
        if code == RtdeTextMessage.CODE:
            return decode_rtde(package, sender="server", protocol=self.protocol)  # type: ignore
        if not self._pending:
            raise _error(f"reply {chr(code)!r} arrived but no request was sent")
        request = self._pending[0]
        if code != request.CODE:
            raise _error(f"reply {chr(code)!r} arrived while waiting for the reply to "
                         f"{type(request).__name__} ({chr(request.CODE)!r})")
        self._pending.popleft()
        reply = decode_rtde(package, sender="server", protocol=self.protocol)
        match reply:
            case ProtocolVersionReply(accepted):
                if accepted:
                    self.protocol = request.version  # type: ignore[union-attr]
            case ControllerVersion():
                self.controller_version = reply
            case OutputSetupReply(recipe_id, types):
                self.output_recipe = _recipe(recipe_id, request.names, types)  # type: ignore
            case InputSetupReply(recipe_id, types):
                recipe = _recipe(recipe_id, request.names, types)  # type: ignore[union-attr]
                if recipe.valid and recipe_id:
                    self.input_recipes[recipe_id] = recipe
            case StartReply(accepted):
                self.running = self.running or accepted
            case PauseReply(accepted):
                self.running = self.running and not accepted
        return reply  # type: ignore[return-value]


def _recipe(recipe_id: int | None, names: tuple[str, ...], types: tuple[str, ...]) -> Recipe:
    if len(types) != len(names):
        raise _error(f"setup reply lists {len(types)} types for {len(names)} names")
    return Recipe(recipe_id, names, types)


def _refusal(recipe: Recipe) -> str:
    parts = []
    if recipe.not_found:
        parts.append("not found: " + ", ".join(recipe.not_found))
    if recipe.in_use:
        parts.append("in use by another client: " + ", ".join(recipe.in_use))
    return "; ".join(parts)


# --- server state machine -------------------------------------------------------------------


class InputOwnership:
    """Which connection controls which input name, shared by all connections of one
    virtual controller: only one RTDE client may write an input at a time."""

    def __init__(self) -> None:
        self._owner: dict[str, object] = {}

    def owner(self, name: str) -> object | None:
        return self._owner.get(name)

    def claim(self, names: Iterable[str], owner: object) -> None:
        for name in names:
            self._owner[name] = owner

    def release(self, owner: object) -> None:
        for name in [n for n, o in self._owner.items() if o is owner]:
            del self._owner[name]


class RtdeServer:
    """The controller's side of one RTDE connection (the virtual controller), no socket.

    ``receive_data(bytes)`` parses the client's packages, updates the connection's state
    and returns them as events (the simulator acts on :class:`DataPackage` inputs and may log
    :class:`RtdeTextMessage`); the replies are queued: ``data_to_send()`` drains them.
    ``outputs(values, cycle)`` encodes the output recipe's sample for control cycle
    ``cycle`` when streaming is on and the recipe's frequency makes the cycle due.

    ``version`` is the controller software (``(5, 11, 1, 108318)``): it decides which names
    exist (:func:`~urdsl.protocol.rtde_fields.field_available`) and the control rate
    (125 Hz for CB3, 500 Hz for e-Series). Names another connection controls come back
    ``IN_USE`` (pass the same :class:`InputOwnership` to every connection).

    Choices where UR documents nothing: a refused setup gets recipe id 0 (valid ids start
    at 1); an output frequency outside (0, rate] is refused by answering every name
    ``NOT_FOUND`` plus an error text message; setups while streaming are answered the same
    way with an error text asking to pause first.
    """

    def __init__(self, version: tuple[int, int, int, int] = (5, 11, 1, 0),
                 ownership: InputOwnership | None = None) -> None:
        self.version = tuple(version)
        self.rate = CB3_MAX_FREQUENCY if self.version[0] < 5 else E_SERIES_MAX_FREQUENCY
        self.ownership = ownership if ownership is not None else InputOwnership()
        self.protocol = 1
        self.output_recipe: Recipe | None = None
        self.frequency = self.rate
        self.input_recipes: dict[int, Recipe] = {}
        self.running = False
        self._next_input_id = 1
        self._framer = RtdeFramer()
        self._out = bytearray()

    def data_to_send(self) -> bytes:
        """Reply bytes queued since the last call."""
        data = bytes(self._out)
        self._out.clear()
        return data

    def close(self) -> None:
        """The connection ended: release its inputs."""
        self.ownership.release(self)
        self.running = False

    def _reply(self, message: Reply, recipe: Recipe | None = None) -> None:
        self._out += encode_rtde(message, self.protocol, recipe)

    def _text(self, message: str, level: int = ERROR) -> None:
        self._reply(RtdeTextMessage(message, "urdsl sim", level))

    def receive_data(self, data: bytes) -> list[Request]:
        """Parse and handle every package ``data`` completes; raises :class:`ProtocolError`
        at the first malformed one (see :meth:`packages` and :meth:`refuse` to go on)."""
        return [self.receive_package(package) for package in self._framer.feed(data)]

    def packages(self, data: bytes) -> list[bytes]:
        """The whole packages ``data`` completes (header included), not yet handled; raises
        :class:`ProtocolError` when the framing is lost (a size field below 3)."""
        return self._framer.feed(data)

    def receive_package(self, package: bytes) -> Request:
        """Decode one whole package from the client, update the state, queue the reply."""
        event = decode_rtde(package, sender="client", protocol=self.protocol,
                            recipes=self.input_recipes)  # type: ignore[arg-type]
        self._handle(event)  # type: ignore[arg-type]
        return event  # type: ignore[return-value]

    def refuse(self, package: bytes, reason: str) -> None:
        """Answer a well-framed package that could not be decoded (``reason``): an error
        text message, then the refusal its request type expects (none for data packages,
        text messages and unknown types), so a client waiting for a reply gets one."""
        self._text(f"package ignored: {reason}")
        code = package[2] if len(package) > 2 else 0
        if code in (RequestProtocolVersion.CODE, Start.CODE):
            self._reply((ProtocolVersionReply if code == RequestProtocolVersion.CODE
                         else StartReply)(False))
        elif code == SetupOutputs.CODE:
            self._reply(OutputSetupReply(0 if self.protocol >= 2 else None, ()))
        elif code == SetupInputs.CODE:
            self._reply(InputSetupReply(0, ()))
        elif code == Pause.CODE:
            self._reply(PauseReply(False))
        elif code == GetControllerVersion.CODE:
            self._reply(ControllerVersion(*self.version))

    def _types(self, names: tuple[str, ...], want_input: bool) -> list[str]:
        types = []
        for name in names:
            spec = FIELDS.get(name)
            usable = spec is not None and (spec.input if want_input else spec.output)
            if not usable or not field_available(spec, self.version):  # type: ignore[arg-type]
                types.append(NOT_FOUND)
            elif want_input and self.ownership.owner(name) not in (None, self):
                types.append(IN_USE)
            else:
                types.append(spec.type)  # type: ignore[union-attr]
        return types

    def _handle(self, request: Request) -> None:
        match request:
            case RequestProtocolVersion(version):
                accepted = version in (1, 2) and not self.running
                self._reply(ProtocolVersionReply(accepted))
                if accepted:
                    self.protocol = version
            case GetControllerVersion():
                self._reply(ControllerVersion(*self.version))
            case SetupOutputs(names, frequency):
                types = self._types(names, want_input=False)
                if self.running:
                    self._text("output setup while streaming: pause first")
                    types = [NOT_FOUND] * len(names)
                elif self.protocol >= 2 and not (
                        frequency is not None and math.isfinite(frequency)
                        and 0 < frequency <= self.rate):
                    self._text(f"output frequency {frequency} Hz outside (0, {self.rate:g}]")
                    types = [NOT_FOUND] * len(names)
                recipe = Recipe(1 if self.protocol >= 2 else None, names, tuple(types))
                if not recipe.valid and recipe.id is not None:
                    recipe = Recipe(0, names, tuple(types))
                self.output_recipe = recipe
                if self.protocol >= 2 and frequency:
                    self.frequency = frequency
                self._reply(OutputSetupReply(recipe.id, recipe.types))
            case SetupInputs(names):
                types = self._types(names, want_input=True)
                if self.running:
                    self._text("input setup while streaming: pause first")
                    types = [NOT_FOUND] * len(names)
                recipe_id = 0
                if all(t not in (NOT_FOUND, IN_USE) for t in types):
                    if self._next_input_id > 255:
                        # refused with id 0, the types still named; earlier recipes live on
                        self._text("no more input recipe ids (255 per connection)")
                    else:
                        recipe_id = self._next_input_id
                        self._next_input_id += 1
                recipe = Recipe(recipe_id, names, tuple(types))
                if recipe.valid and recipe_id:
                    self.input_recipes[recipe_id] = recipe
                    self.ownership.claim(names, self)
                self._reply(InputSetupReply(recipe_id, recipe.types))
            case Start():
                usable = (self.output_recipe is not None and self.output_recipe.valid) or any(
                    r.valid for r in self.input_recipes.values())
                if self.output_recipe is not None and not self.output_recipe.valid:
                    usable = False
                self.running = self.running or usable
                self._reply(StartReply(usable))
            case Pause():
                self.running = False
                self._reply(PauseReply(True))
            case DataPackage() | RtdeTextMessage():
                pass  # inputs and logs are the simulator's business (returned as events)

    @property
    def decimation(self) -> int:
        """Control cycles per output package: ``floor(rate / frequency)``, at least 1 (the
        RTDE guide's rule for CB3; e-Series behaves the same at divisors of 500 Hz)."""
        return max(1, math.floor(self.rate / self.frequency + 1e-9))

    def output_package(self, values: Sequence[object]) -> bytes:
        """The data package of the output recipe from ``values`` in recipe order, vectors
        flattened (the simulator's fast path: no dict, no dataclass). Raises
        :class:`ProtocolError` without a usable output recipe or for values that do not fit."""
        recipe = self.output_recipe
        if recipe is None or recipe._packers is None:
            raise _error("no usable output recipe")
        try:
            if recipe.id is None:  # a v1 output package carries no recipe id
                return recipe._packers[0](*values)
            return recipe._packers[1](recipe.id, *values)
        except struct.error as exc:
            raise _error(f"data package for recipe {recipe.id}: {exc}") from None

    def outputs(self, values: Mapping[str, object], cycle: int) -> bytes | None:
        """The output data package for control cycle ``cycle`` (counting from 0), or
        ``None`` when not streaming, without a usable output recipe, or not due."""
        recipe = self.output_recipe
        if not self.running or recipe is None or not recipe.valid:
            return None
        if cycle % self.decimation:
            return None
        return encode_rtde(DataPackage(recipe.id, dict(values)), self.protocol, recipe)
