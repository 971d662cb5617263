"""The preamble PolyScope writes before a program's tree: what the installation (and the
program's PolyScope version) generate.

:func:`preamble` builds it as URScript tree nodes; :mod:`.compile` puts it at the top of the
program's ``def``.
"""

from __future__ import annotations

import uuid

from ..script import parse
from ..script.build import literal
from ..script.diagnostics import ScriptError
from ..script.nodes import (
    Assign,
    BinOp,
    Bool,
    Call,
    Comment,
    Declare,
    Expr,
    ExprStmt,
    Item,
    Keyword,
    List,
    Name,
    Number,
    Paren,
    Pose,
    Run,
    String,
    ThreadDef,
    While,
)
from .installation import Installation
from .urp import Program

__all__ = ["preamble", "step_counter"]


def _call(name: str, *args: Expr, **keywords: Expr) -> Call:
    return Call(Name(name), tuple(args), tuple(Keyword(k, v) for k, v in keywords.items()))


def _stmt(name: str, *args: Expr, **keywords: Expr) -> ExprStmt:
    return ExprStmt(_call(name, *args, **keywords))


def _num(value: float) -> Expr:
    return literal(float(value))


def _value(text: str) -> Expr:
    """The expression of an installation variable's value; ValueError if it is not one
    URScript expression."""
    try:
        module = parse(text, "<variables>")
    except ScriptError:
        raise ValueError(text) from None
    items = [item for item in module.body if not isinstance(item, Comment)]
    if len(items) != 1 or not isinstance(items[0], ExprStmt):
        raise ValueError(text)
    return items[0].expr


def _generated_id(name: str, purpose: str) -> str:
    """A UUID in PolyScope's identifier form (``3f89b84f_1daa_4dd7_9152_f27885b7ee6c``),
    fixed for a program name and purpose."""
    return str(uuid.uuid5(uuid.NAMESPACE_URL, f"urdsl:{purpose}:{name}")).replace("-", "_")


def _ints(text: str | None) -> list[int]:
    try:
        return [int(v) for v in (text or "").split(",") if v.strip()]
    except ValueError:
        return []


_BAUD = {"BAUD_9600": 9600, "BAUD_19200": 19200, "BAUD_38400": 38400, "BAUD_57600": 57600,
         "BAUD_115200": 115200, "BAUD_1M": 1000000, "BAUD_2M": 2000000, "BAUD_5M": 5000000}
_PARITY = {"NONE": 0, "ODD": 1, "EVEN": 2}
_STOP_BITS = {"ONE": 1, "TWO": 2}
_OUTPUT_MODE = {"SINKING": 1, "SOURCING": 2, "PUSH_PULL": 3}
_VOLTAGE = {"ZERO": 0, "TWELVE": 12, "TWENTY_FOUR": 24}


def _tool_communication(attrs: dict[str, str] | None) -> list[Item]:
    """The tool connector's settings as PolyScope writes them (baud rate in bit/s, idle
    times in characters, voltage in V)."""
    if not attrs:
        return []
    items: list[Item] = [_stmt(
        "set_tool_communication", Bool(attrs.get("enabled") == "true"),
        Number(_BAUD.get(attrs.get("baudRate", ""), 115200)),
        Number(_PARITY.get(attrs.get("parity", ""), 0)),
        Number(_STOP_BITS.get(attrs.get("stopBits", ""), 1)),
        _num(float(attrs.get("rxIdleChars", "1.5"))), _num(float(attrs.get("txIdleChars", "3.5"))))]
    items.append(_stmt("set_tool_output_mode",
                       Number(0 if attrs.get("toolOutputMode", "OUTPUT") == "OUTPUT" else 1)))
    for index in range(2):
        mode = attrs.get(f"toolDigitalOutput{index}")
        if mode in _OUTPUT_MODE:
            items.append(_stmt("set_tool_digital_output_mode", Number(index),
                               Number(_OUTPUT_MODE[mode])))
    voltage = attrs.get("toolOutputVoltage")
    if voltage in _VOLTAGE:
        items.append(_stmt("set_tool_voltage", Number(_VOLTAGE[voltage])))
    return items


def preamble(program: Program, installation: Installation | None,
             variables: list[tuple[str, str]]) -> list[Item]:
    """What PolyScope 5 writes from the installation before the program: safety
    transition, tool communication and output, gravity, analog domains, input actions,
    payload and TCP. (PolyScope writes these blocks in an order that changes from one
    save to the next; this is one of them.) Installation variables, features, Modbus
    signals and URCap installation code are not written."""
    items: list[Item] = step_counter(program)
    if installation is None or (program.major_version or 5) < 5:
        return items
    settings = installation.settings or {}
    hardness = settings.get("SmoothTransitionSettings", {}).get("transitionHardness")
    if hardness:
        items.append(_stmt("set_safety_mode_transition_hardness",
                           Number(1 if hardness == "SOFT" else 0)))
    items.extend(_tool_communication(settings.get("ToolCommSettings")))
    gravity = installation.gravity
    if gravity is not None:
        items.append(_stmt("set_gravity", List(tuple(_num(v) for v in gravity))))
    ranges = _ints(settings.get("IOs/analogInputRange", {}).get("value"))
    if len(ranges) == 4:
        for index in range(2):
            items.append(_stmt("set_standard_analog_input_domain", Number(index),
                               Number(ranges[index])))
        for index in range(2):
            items.append(_stmt("set_tool_analog_input_domain", Number(index),
                               Number(ranges[2 + index])))
    domains = _ints(settings.get("IOs/analogOutputDomain", {}).get("value"))
    for index, domain in enumerate(domains):
        items.append(_stmt("set_analog_outputdomain", Number(index), Number(domain)))
    if "IOs/DigitalInputActions" in settings:
        items.append(_stmt("set_input_actions_to_default"))
        # only the tool inputs' actions are written (seen: "freedrive"); the controller
        # keeps the standard and configurable inputs' actions itself
        for key, function in (("ToolDigitalInputActions", "set_tool_digital_input_action"),):
            actions = settings.get(f"IOs/{key}", {}).get("value", "").split(",")
            for index, action in enumerate(a.strip() for a in actions):
                if action and action != "NONE":
                    items.append(_stmt(function, Number(index),
                                       String(action.lower().replace("_", " "))))
    payload = installation.payload
    if payload is not None:
        raw = settings.get(f"Payload/{payload.name}")
        cog = payload.cog or (0.0, 0.0, 0.0)
        if raw is not None and raw.get("inertiaParameters"):
            inertia = tuple(float(v) for v in raw["inertiaParameters"].split(","))
            items.append(_stmt("set_target_payload", _num(payload.mass),
                               List(tuple(_num(v) for v in cog)),
                               List(tuple(_num(v) for v in inertia))))
        else:
            items.append(_stmt("set_payload", _num(payload.mass),
                               List(tuple(_num(v) for v in cog))))
    tcp = installation.tcp
    if tcp is not None:
        items.append(_stmt("set_tcp", Pose(tuple(_num(v) for v in tcp.offset))))
    for name, value in variables:
        try:
            items.append(Declare("global", name, _value(value)))
        except ValueError:  # not a value URScript reads: PolyScope would not run it
            items.append(Comment(f" urdsl: installation variable {name} is not URScript"))
    for name, pose in sorted(installation.features or ()):
        items.append(Declare("global", name, Pose(tuple(_num(v) for v in pose))))
    return items


def step_counter(program: Program) -> list[Item]:
    """The thread PolyScope (3.15 and 5.8 on) starts in every program to count its
    controller steps; its names carry a generated id (here derived from the program's
    name, so that compiling twice gives the same text)."""
    version = program.saved_in or program.created_in or ""
    parts = [int(p) if p.isdigit() else 0 for p in version.split(".")[:2]] + [0, 0]
    major, minor = parts[0], parts[1]
    if not ((major == 3 and minor >= 15) or (major == 5 and minor >= 8) or major > 5):
        return []
    count = "step_count_" + _generated_id(program.name, "count")
    thread = "Step_Counter_Thread_" + _generated_id(program.name, "thread")
    return [
        Assign(Name(count), _num(0.0)),
        ThreadDef(thread, (While(Paren(Bool(True)), (
            Assign(Name(count), BinOp("+", Name(count), _num(1.0))),
            _stmt("sync"))),)),
        ExprStmt(Run(thread))]
