"""The preamble PolyScope writes before a program's tree: what the installation (and the
program's PolyScope version) generate.

:func:`preamble` builds it as URScript tree nodes; :mod:`.compile` puts it at the top of the
program's ``def``.
"""

from __future__ import annotations

import uuid
from xml.etree import ElementTree

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
    FunctionDef,
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
from .installation import Conveyor, Installation, Payload
from .urp import Expression, Program

__all__ = ["BLOCKS", "initial_values", "preamble", "preamble_blocks", "step_counter"]

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
_VOLTAGE = {"ZERO": 0, "TWELVE": 12, "TWENTY_FOUR": 24, "0": 0, "12": 12, "24": 24}
"""The tool output voltage as installations write it (PolyScope 3.4-3.5: the volts)."""


def _baud(text: str) -> int:
    """Bit/s of PolyScope's ``BAUD_115200``, ``BAUD_1M`` or ``BAUD_1000000`` (115200 if
    unreadable)."""
    if text in _BAUD:
        return _BAUD[text]
    digits = text.removeprefix("BAUD_")
    return int(digits) if digits.isdigit() else 115200


def _tool_communication(attrs: dict[str, str] | None) -> list[Item]:
    """The tool connector's settings as PolyScope writes them (baud rate in bit/s, idle
    times in characters, voltage in V)."""
    if not attrs:
        return []
    voltage = attrs.get("toolOutputVoltage")
    if "enabled" not in attrs:  # PolyScope 3.x: the tool output voltage only
        return [_stmt("set_tool_voltage", Number(_VOLTAGE[voltage]))] \
            if voltage in _VOLTAGE else []
    items: list[Item] = [_stmt(
        "set_tool_communication", Bool(attrs.get("enabled") == "true"),
        Number(_baud(attrs.get("baudRate", ""))),
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
    if voltage in _VOLTAGE:
        items.append(_stmt("set_tool_voltage", Number(_VOLTAGE[voltage])))
    return items


def _version(text: str | None) -> tuple[int, int]:
    """(major, minor) of a ``"5.11.9.1010452"``-like version; (0, 0) when unknown."""
    parts = [int(p) if p.isdigit() else 0 for p in (text or "").split(".")[:2]] + [0, 0]
    return parts[0], parts[1]


_RUNSTATE = {"LOW_WHEN_PROGRAM_STOPPED": 1, "HIGH_WHEN_PROGRAM_STOPPED": 2,
             "HIGH_WHEN_PROGRAM_RUNNING_LOW_WHEN_STOPPED": 3}
"""Output actions when the program stops → the state number of ``set_runstate_*`` (1 and 2
seen; 3 as the URScript manual numbers it [U])."""
_GP_RUNSTATE = {"PROGRAM_RUNNING": 3}
"""A general purpose boolean output register's action → its run state number (seen: 3)."""
_RUNSTATE_BANKS = (("DigitalOutputActions", "standard"),
                   ("ConfigurableOutputActions", "configurable"),
                   ("ToolDigitalOutputActions", "tool"))
_MODBUS_KINDS = {"DIGITAL_INPUT": 0, "DIGITAL_OUTPUT": 1, "REGISTER_INPUT": 2,
                 "REGISTER_OUTPUT": 3}
_MOTION_VERSIONS = {"JERK_LIMITED": 2}
"""``MotionSettingsConfiguration motionVersion`` → ``motion_version_set`` (5.22 on; only
JERK_LIMITED seen)."""

BLOCKS = ("steps", "safety", "wrench", "motion", "tool", "gravity", "io", "modbus", "payload",
          "tcp")
"""The kinds of the preamble blocks whose order PolyScope does not keep: the same
installation saved twice gives them in two orders (a Java hash set's order). urdsl writes
them in this order."""


def preamble_blocks(program: Program, installation: Installation | None,
                    variables: list[tuple[str, str]]) -> list[tuple[str, list[Item]]]:
    """The preamble as (kind, statements) blocks in the order urdsl writes them. Kinds:
    ``verification`` (PolyScope 5.12 on: a hidden global, always first), the movable
    blocks of :data:`BLOCKS`, then ``variables`` (the installation variables) and
    ``features`` (feature poses, by name), ``conveyor`` (the built-in conveyor tracking:
    each conveyor's encoder and its ``start_conveyor_trackingN`` function), ``watchdog``
    (the EtherNet/IP adapter's watchdog when it is enabled), ``urcaps`` (a marked block per URCap
    installation node: its code only the URCap can generate, so the block is empty), then
    ``initial`` (the program's initial variable values, see :func:`initial_values`).
    Modbus signals' input/output actions are not written."""
    blocks: list[tuple[str, list[Item]]] = []
    saved = _version(program.saved_in or program.created_in)
    major = program.major_version or saved[0] or 5
    if saved >= (5, 12):  # seen from 5.12.4 on; 5.11.10 does not write it
        blocks.append(("verification", [Declare("global", "_hidden_verificationVariable",
                                                Number(0))]))
    movable: dict[str, list[Item]] = {"steps": step_counter(program)}
    if installation is not None:
        movable.update(_installation_blocks(installation, major, saved))
    for kind in BLOCKS:
        if movable.get(kind):
            blocks.append((kind, movable[kind]))
    values: list[Item] = []
    for name, value in variables:  # also beside a missing installation (its .variables)
        try:
            values.append(Declare("global", name, _value(value)))
        except ValueError:  # not a value URScript reads: PolyScope would not run it
            values.append(Comment(f" urdsl: installation variable {name} is not URScript"))
    if values:
        blocks.append(("variables", values))
    # a name beyond ASCII ("点_1") is written as the compiler writes every name
    # (``u28857_1``, seen), and sorted as written
    features = [Declare("global", name, Pose(tuple(_num(v) for v in pose)))
                for name, pose in sorted(installation.features if installation else ())]
    if installation is not None and installation.base_variable and major < 5:
        # a variable base (3.14: ldalepfi/UR-Simulation-Prod) is a global at the base's
        # own pose [U: 5.x not seen]
        features.insert(0, Declare("global", "Base", Pose(tuple(_num(0.0) for _ in range(6)))))
    if features:
        blocks.append(("features", features))
    conveyor = [item for c in (installation.conveyors if installation else ())
                for item in conveyor_statements(c)]
    if conveyor:
        blocks.append(("conveyor", conveyor))
    ethernet_ip = (installation.settings or {}).get("EthernetIP", {}) if installation else {}
    if ethernet_ip.get("enabled") == "true" and ethernet_ip.get("watchdogAction"):
        # the EtherNet/IP adapter enabled: a watchdog on the speed slider input (seen with
        # the action IGNORE; PAUSE and STOP written the same way [U])
        blocks.append(("watchdog", [_stmt("rtde_set_watchdog", String("speed_slider_mask"),
                                          _num(10.0),
                                          String(ethernet_ip["watchdogAction"].lower()))]))
    urcaps: list[Item] = []
    for name, vendor, title in installation.urcaps if installation else ():
        urcaps.extend((Comment(" begin: URCap Installation Node"),
                       Comment(f"   Source: {name}, {vendor}"), Comment(f"   Type: {title}"),
                       Comment(" end: URCap Installation Node")))
    if urcaps:
        blocks.append(("urcaps", urcaps))
    initial = initial_values(program)
    if initial:
        blocks.append(("initial", initial))
    return blocks


def _expression(element: ElementTree.Element) -> str | None:
    """The URScript text of an expression element of characters, tokens and named variables;
    None when it refers to anything else (a variable by reference, an I/O, a waypoint)."""
    parts = []
    for piece in element:
        if piece.tag == "ExpressionChar":
            parts.append(("char", piece.get("character", "")))
        elif piece.tag == "ExpressionToken":
            parts.append(("token", piece.get("token", "")))
        elif piece.tag == "ExpressionVariable" and len(piece) and piece[0].get("name"):
            parts.append(("var", piece[0].get("name", "")))
        else:
            return None
    return Expression(tuple(parts)).script


def initial_values(program: Program) -> list[Item]:
    """The globals PolyScope writes after the installation's code: each variable of the
    program's variables setup (``InitVariablesNode``) with its value, in file order, then
    each variable declared elsewhere with an initial value (``<initializeExpression>``, as
    URCap nodes declare them), in file order, each name once."""
    items: list[Item] = []
    seen: set[str] = set()

    def declare(name: str | None, expression: ElementTree.Element | None) -> None:
        if not name or name in seen or expression is None or not len(expression):
            return
        seen.add(name)
        text = _expression(expression)
        try:
            if text is None:
                raise ValueError(name)
            items.append(Declare("global", name, _value(text)))
        except ValueError:
            items.append(Comment(f" urdsl: the initial value of {name} is not compiled"))

    init = program.init_variables
    if init is not None and init.element is not None:
        for variable in init.element.iterfind("variables/variable"):
            declare(variable.get("name"), variable.find("expression"))
    for root in program.top:
        if root.element is None or root is init:
            continue
        for variable in root.element.iter("variable"):
            declare(variable.get("name"), variable.find("initializeExpression"))
    return items


def preamble(program: Program, installation: Installation | None,
             variables: list[tuple[str, str]]) -> list[Item]:
    """What PolyScope 3.x and 5.x write before the program tree, from the installation
    (and the program's PolyScope version): the blocks of :func:`preamble_blocks` in
    order."""
    return [item for _kind, items in preamble_blocks(program, installation, variables)
            for item in items]


def _installation_blocks(installation: Installation, major: int,
                        saved: tuple[int, int] = (0, 0)) -> dict[str, list[Item]]:
    settings = installation.settings or {}
    blocks: dict[str, list[Item]] = {}
    safety: list[Item] = []
    hardness = settings.get("SmoothTransitionSettings", {}).get("transitionHardness")
    if hardness is None and (3, 10) <= saved < (4, 0):
        # an installation saved before the setting existed (3.4.5) compiled by a PolyScope
        # that has it (3.11.0, Grzegorr/Paper-Potato-UR5 kg_client): the hard transition,
        # ``set_safety_mode_transition_hardness(0)``; 3.5.0 writes nothing (Sander-ONeil)
        # [U: 3.6-3.9, and 5.x with such an installation]
        hardness = "HARD"
    if hardness:
        safety.append(_stmt("set_safety_mode_transition_hardness",
                            Number(1 if hardness == "SOFT" else 0)))
    blocks["safety"] = safety
    wrench = settings.get("ToolWrenchConfiguration")
    if wrench is not None:
        if wrench.get("forceLimitEnabled") != "true" and wrench.get("momentLimitEnabled") \
                != "true":
            blocks["wrench"] = [_stmt("tool_wrench_limit_disable")]
        else:  # the call PolyScope writes for an enabled limit is not known
            blocks["wrench"] = [Comment(" urdsl: the tool wrench limit is not written")]
    motion = settings.get("MotionSettingsConfiguration", {}).get("motionVersion")
    if motion:
        blocks["motion"] = [_stmt("motion_version_set", Number(_MOTION_VERSIONS.get(motion, 1)))]
    blocks["tool"] = _tool_communication(settings.get("ToolCommSettings"))
    gravity = installation.gravity
    if gravity is not None:
        blocks["gravity"] = [_stmt("set_gravity", List(tuple(_num(v) for v in gravity)))]
    blocks["io"] = _io(settings, major)
    blocks["modbus"] = _modbus(installation)
    payload = installation.payload
    if payload is not None:
        blocks["payload"] = payload_statements(installation, _tcp_as_cog(installation, payload,
                                                                         saved))
    tcp = installation.tcp
    if tcp is not None:
        blocks["tcp"] = [_stmt("set_tcp", Pose(tuple(_num(v) for v in tcp.offset)))]
    return blocks


def _tcp_as_cog(installation: Installation, payload: Payload,
                saved: tuple[int, int]) -> Payload:
    """The payload a later PolyScope reads from an installation last saved before 3.5: one
    without a centre of gravity has it at the active TCP's position (seen: 3.11.0
    compiling an installation saved in 3.4.5, Grzegorr/Paper-Potato-UR5 kg_client:
    ``set_payload(0.0,[0.0,0.0,0.11])``, its active TCP at ``0, 0, 0.11``). PolyScope 3.2
    with its own installation writes the mass alone (nedlecky/UR KeyenceRobotVisionSample
    at c48f8df), and so does any PolyScope with an installation saved in 3.5 or later
    (3.5.0, 3.15.8, 5.7.0 seen) [U: 3.5-3.10 and 3.12 on with a 3.4 installation]."""
    old = _version(installation.version)
    if payload.cog is not None or old[0] != 3 or old >= (3, 5) or not (3, 5) <= saved < (4, 0):
        return payload
    tcp = installation.tcp
    if tcp is None or len(tcp.offset) < 3:
        return payload
    return Payload(payload.name, payload.mass, (tcp.offset[0], tcp.offset[1], tcp.offset[2]))


def _io(settings: dict[str, dict[str, str]], major: int = 5) -> list[Item]:
    """Analog domains (0: current, 1: voltage), input actions and the outputs' states
    when the program stops. PolyScope 5 names the outputs that have a state
    (``set_runstate_standard_digital_outputs([3, 5])``) before setting each one's;
    PolyScope 3 (3.15, Usaakm/UR10-Conveyor-Belt) sets each one's state only."""
    items: list[Item] = []
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
        actions = settings.get("IOs/ToolDigitalInputActions", {}).get("value", "").split(",")
        for index, action in enumerate(a.strip() for a in actions):
            if action and action != "NONE":
                items.append(_stmt("set_tool_digital_input_action", Number(index),
                                   String(action.lower().replace("_", " "))))
        # a general purpose boolean input register's freedrive action (seen in
        # CA-Giken/docker-noetic-capc's SUB_105 and SUB_161, 5.13: register 7); START, STOP
        # and PAUSE are the controller's (their installation has them at 0-2, no script
        # line); the value name FREEDRIVE as the tool inputs write it [U]
        actions = settings.get("IOs/GeneralPurposeBooleanRegisterInputActions", {}).get(
            "value", "").split(",")
        for index, action in enumerate(a.strip() for a in actions):
            if action == "FREEDRIVE":
                items.append(_stmt("set_gp_boolean_input_action", Number(index),
                                   String("freedrive")))
    states: list[tuple[str, int, int]] = []
    for key, bank in _RUNSTATE_BANKS:
        actions = settings.get(f"IOs/{key}", {}).get("value", "").split(",")
        pins = [(index, _RUNSTATE[a.strip()]) for index, a in enumerate(actions)
                if a.strip() in _RUNSTATE]
        if pins and major >= 5:
            items.append(_stmt(f"set_runstate_{bank}_digital_outputs",
                               List(tuple(Number(index) for index, _ in pins))))
        states.extend((bank, index, state) for index, state in pins)
    for bank, index, state in states:
        items.append(_stmt(f"set_runstate_{bank}_digital_output_to_value", Number(index),
                           Number(state)))
    # a general purpose boolean output register's action: only its state is written (seen:
    # PROGRAM_RUNNING at register 0 as ``set_runstate_gp_boolean_output_to_value(0, 3)``)
    actions = settings.get("IOs/GeneralPurposeBooleanRegisterOutputActions", {}).get("value", "")
    for index, action in enumerate(a.strip() for a in actions.split(",")):
        if action in _GP_RUNSTATE:
            items.append(_stmt("set_runstate_gp_boolean_output_to_value", Number(index),
                               Number(_GP_RUNSTATE[action])))
    return items


def _count(value: float) -> Expr:
    """A number as PolyScope writes a count it keeps as an integer (``13333``)."""
    return Number(int(value)) if value == int(value) else _num(value)


def conveyor_statements(conveyor: Conveyor) -> list[Item]:
    """What a conveyor of the built-in conveyor tracking writes after the features (seen:
    PolyScope 3.15, one linear conveyor on an incremental encoder, Usaakm/UR10-Conveyor-Belt):
    ``encoder_enable_pulse_decode(N, decoder, A, B)``, then ``def
    start_conveyor_trackingN(): track_conveyor_linear(pose_sub(P, Q), ticks_per_meter, N)
    end`` that the program's conveyor tracking node calls. P and Q are the two points of
    the direction line: the second minus the first, the first minus the second when the
    direction is switched (both seen). Another encoder or a circular conveyor: a comment,
    nothing written [U]."""
    index = Number(conveyor.index)
    items: list[Item] = []
    if conveyor.encoder == "1" and conveyor.decoder is not None and conveyor.pins:
        items.append(_stmt("encoder_enable_pulse_decode", index, Number(conveyor.decoder),
                           Number(conveyor.pins[0]), Number(conveyor.pins[1])))
    else:
        items.append(Comment(f" urdsl: conveyor {conveyor.index}'s encoder (type "
                             f"{conveyor.encoder or '?'}) is not written"))
    if conveyor.kind == "1" and conveyor.direction and conveyor.ticks_per_meter is not None:
        first, second = (Pose(tuple(_num(v) for v in point)) for point in conveyor.direction)
        ahead, behind = (first, second) if conveyor.switch else (second, first)
        track = _stmt("track_conveyor_linear", _call("pose_sub", ahead, behind),
                      _count(conveyor.ticks_per_meter), index)
        items.append(FunctionDef(f"start_conveyor_tracking{conveyor.index}", (), (track,)))
    else:
        items.append(Comment(f" urdsl: conveyor {conveyor.index} (type "
                             f"{conveyor.kind or '?'}) is not written"))
    return items


def _modbus(installation: Installation) -> list[Item]:
    """Each Modbus signal: added, its update frequency (Hz) set, and for an output what it
    does when the program stops."""
    items: list[Item] = []
    choices: list[Item] = []
    for signal in installation.modbus:
        if signal.kind not in _MODBUS_KINDS:
            items.append(Comment(f" urdsl: Modbus signal {signal.name} of type "
                                 f"{signal.kind} is not written"))
            continue
        name = String(signal.name)
        items.append(_stmt("modbus_add_signal", String(signal.ip), Number(signal.slave),
                           Number(signal.address), Number(_MODBUS_KINDS[signal.kind]), name,
                           Bool(signal.sequential)))
        if signal.frequency is not None:
            frequency = signal.frequency
            items.append(_stmt("modbus_set_signal_update_frequency", name,
                               Number(int(frequency)) if frequency == int(frequency)
                               else _num(frequency)))
        if signal.kind.endswith("OUTPUT") and signal.choice is not None:
            choices.append(_stmt("modbus_set_runstate_dependent_choice", name,
                                 Number(signal.choice)))
    # the outputs' choices come after all the signals (seen: mswaidan/finishing-line
    # modbustest, nine output signals among twenty-six)
    return items + choices


def step_counter(program: Program) -> list[Item]:
    """The thread PolyScope (3.12 and 5.7 on) starts in every program to count its
    controller steps; its names carry a generated id (here derived from the program's
    name, so that compiling twice gives the same text). Seen from 5.7.0 (o2ac/o2ac-ur's
    b_bot programs) and 3.12.1 (kg398/kg_ursim, build 90940, the series of 5.7.0's 90932); not
    in 3.8 and 3.5 scripts; 3.9-3.12.0 and 5.0-5.6 are not seen [U]."""
    major, minor = _version(program.saved_in or program.created_in)
    if not ((major == 3 and minor >= 12) or (major == 5 and minor >= 7) or major > 5):
        return []
    count = "step_count_" + _generated_id(program.name, "count")
    thread = "Step_Counter_Thread_" + _generated_id(program.name, "thread")
    return [
        Assign(Name(count), _num(0.0)),
        ThreadDef(thread, (While(Paren(Bool(True)), (
            Assign(Name(count), BinOp("+", Name(count), _num(1.0))),
            _stmt("sync"))),)),
        ExprStmt(Run(thread))]


def payload_statements(installation: Installation, payload: Payload) -> list[Item]:
    """What PolyScope writes to select one of the installation's payloads (mass kg, centre
    of gravity m, inertia kg m²): ``set_target_payload`` when the installation gives its
    inertia, else ``set_payload``; without a centre of gravity (the ``toolPayload`` of
    PolyScope 3 and of 5.x before named payloads: 5.7.0, o2ac/o2ac-ur) the mass alone.
    Used by the preamble (the default payload) and a Set Payload node."""
    raw = installation.settings.get(f"Payload/{payload.name}") if installation.settings \
        else None
    if raw is not None and raw.get("inertiaParameters"):
        inertia = tuple(float(v) for v in raw["inertiaParameters"].split(","))
        return [_stmt("set_target_payload", _num(payload.mass),
                      List(tuple(_num(v) for v in payload.cog or (0, 0, 0))),
                      List(tuple(_num(v) for v in inertia)))]
    if payload.cog is None:
        return [_stmt("set_payload", _num(payload.mass))]
    return [_stmt("set_payload", _num(payload.mass),
                  List(tuple(_num(v) for v in payload.cog or (0, 0, 0))))]
