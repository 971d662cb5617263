"""Decode cost of realtime packets, primary robot-state messages and RTDE data packages.

Side by side in one run, on the same bytes, no network:

* realtime (1220-byte e-Series 5.10 packet): ``urdsl.protocol.realtime.RealtimeDecoder.feed``
  (every field by name, streaming framing) vs python-urx's ``URRTMonitor`` parser (its
  ``__recv_rt_data`` method fed from memory instead of its socket; it unpacks a prefix and
  keeps ~10 fields as NumPy arrays) vs a plain ``struct`` decode of every field without any
  check (one unpack, one ``itemgetter``: the floor of an eager decoder of every field) and of
  the two fields the course reads (q actual at 252, TCP pose at 444) — the least any decoder
  can do;
* primary (a CB3 3.2 robot-state message with nine sub-packages): ``decode_primary`` vs
  python-urx's ``ParserUtils.parse``;
* RTDE (a 500 Hz recorder recipe: timestamp, actual_q, actual_qd, actual_TCP_pose,
  robot_mode, runtime_state): ``decode_rtde`` with the recipe vs a plain ``struct`` unpack
  into a dict of name → value (what UR's ``rtde/serialize.py`` does, written out here because
  that library is not on PyPI).

The candidates of a row group are timed in turns (best of ``--repeat`` timings of
``--count`` calls), so that other load on the machine hits them alike. The clock is the
thread's CPU time, which time slices given to other processes do not inflate (``--wall``:
the wall clock instead). python-urx's realtime parser is shown as installed and, on a
second line, with ``notify_all`` for its deprecated ``notifyAll`` (which warns, ignored but
paid for, on every packet under Python 3.10+). urdsl's results are complete values (every
field decoded, nothing lazy).

Prints µs per packet, packets/s and ratios (> 1: urdsl is faster), plus the CPU share a
500 Hz recorder would use for decoding. Run: ``.venv/bin/python bench/protocol_bench.py``.
Not part of the test run.
"""

from __future__ import annotations

import argparse
import gc
import math
import operator
import struct
import time

from urdsl.protocol.primary import (
    AdditionalInfo,
    CartesianInfo,
    ConfigurationData,
    ForceModeData,
    JointData,
    KinematicsInfo,
    MasterboardData,
    RobotModeData,
    RobotState,
    ToolData,
    decode_primary,
)
from urdsl.protocol.realtime import LAYOUTS, RealtimeDecoder, encode_realtime, realtime_state
from urdsl.protocol.rtde import DataPackage, Recipe, decode_rtde, encode_rtde

Q = (0.1, -1.2, 1.3, -1.7, -1.5, 0.4)


def best_per_call(work, count: int, repeat: int) -> float:
    """Best-of-``repeat`` time of ``count`` calls, per call [s]."""
    return best_per_call_each([work], count, repeat)[0]


CLOCK = time.thread_time
"""The timer: this thread's CPU time (``main`` switches to ``time.perf_counter`` on
``--wall``)."""


def best_per_call_each(works: list, count: int, repeat: int) -> list[float]:
    """Best-of-``repeat`` time of ``count`` calls of each of ``works``, per call [s]. The
    candidates take turns within every repetition, so that a change of machine load (other
    processes) hits all of them alike and the ratios stay fair."""
    best = [math.inf] * len(works)
    clock = CLOCK
    for _ in range(repeat):
        for index, work in enumerate(works):
            gc.collect()
            start = clock()
            for _ in range(count):
                work()
            best[index] = min(best[index], (clock() - start) / count)
    return best


def realtime_packet() -> bytes:
    return encode_realtime(realtime_state(
        "5.10", time=12.5, q_actual=Q, q_target=Q, tool_vector_actual=(0.4, -0.1, 0.3, 2.2, 2.2, 0),
        robot_mode=7, joint_modes=(253,) * 6, safety_mode=1, digital_input_bits=5,
        program_state=2, safety_status=1))


def primary_message() -> bytes:
    six = (0.0,) * 6
    state = RobotState((
        RobotModeData(variant="3.2", timestamp=1, is_robot_power_on=True, robot_mode=7,
                      target_speed_fraction=1.0, speed_scaling=1.0,
                      target_speed_fraction_limit=1.0),
        JointData(variant="3.0", q_actual=Q, q_target=Q, qd_actual=six, i_actual=six,
                  v_actual=(48.0,) * 6, t_motor=(30.0,) * 6, t_micro=(31.0,) * 6,
                  joint_mode=(253,) * 6),
        ToolData(variant="3.0", tool_voltage_48v=24.0, tool_temperature=30.0, tool_mode=253),
        MasterboardData(variant="3.2", safety_mode=1, operational_mode_selector_input=0,
                        three_position_enabling_device_input=False),
        CartesianInfo(variant="3.2", tcp_pose=(0.4, -0.1, 0.3, 2.2, 2.2, 0.0), tcp_offset=six),
        KinematicsInfo(variant="3.0", checksum=(1,) * 6, dh_theta=six, dh_a=six, dh_d=six,
                       dh_alpha=six, calibration_status=1),
        ConfigurationData(variant="3.0", joint_min_limit=six, joint_max_limit=six,
                          joint_max_speed=six, joint_max_acceleration=six, dh_a=six,
                          dh_d=six, dh_alpha=six, dh_theta=six, robot_type=1),
        ForceModeData(variant="3.0", wrench=six, robot_dexterity=1.0),
        AdditionalInfo(variant="3.2"),
    ))
    return state.encode()


RTDE_NAMES = ("timestamp", "actual_q", "actual_qd", "actual_TCP_pose", "robot_mode",
              "runtime_state")
RTDE_TYPES = ("DOUBLE", "VECTOR6D", "VECTOR6D", "VECTOR6D", "INT32", "UINT32")


def every_field_floor(packet: bytes):
    """The least an eager decoder of every field can do: one ``unpack`` of the whole 5.10
    packet and one C-level ``itemgetter`` handing out each field (vectors as tuples) in a
    plain tuple — no size or integer checks, integers left as doubles, no named tuple."""
    layout = LAYOUTS["5.10"]
    whole = struct.Struct(f">i{layout.doubles}d").unpack
    keys = []
    for name in layout.names:
        where = layout.slot(name)
        keys.append(where.start + 1 if where.stop - where.start == 1
                    else slice(where.start + 1, where.stop + 1))
    fields = operator.itemgetter(*keys)

    def floor() -> tuple:
        return fields(whole(packet))

    return floor


def urx_realtime_parser(packet: bytes, quiet: bool = False):
    """python-urx's realtime parser, fed from memory. Returns a zero-argument callable that
    parses one packet, or None if urx is not installed.

    As installed, the parser ends every packet with ``Condition.notifyAll()``, which Python
    3.10+ deprecates: each call goes through the warnings machinery (ignored, but paid for).
    ``quiet`` swaps in ``notify_all`` — the same wake-up without the warning — to show the
    parser's own cost."""
    try:
        from urx.urrtmon import URRTMonitor
    except ImportError:
        return None
    monitor = URRTMonitor("127.0.0.1")  # creates an unconnected socket object only
    monitor._rtSock.close()
    chunks = [packet[:4], packet[4:]]
    state = {"i": 0}

    def recv_bytes(count: int) -> bytes:
        data = chunks[state["i"] % 2]
        state["i"] += 1
        return data

    monitor._URRTMonitor__recv_bytes = recv_bytes
    monitor._URRTMonitor__recvTime = 0.0
    if quiet:
        monitor._dataEvent.notifyAll = monitor._dataEvent.notify_all
    parse = monitor._URRTMonitor__recv_rt_data

    def check() -> None:
        parse()
        assert tuple(monitor._qActual) == Q, "urx read q actual wrongly"

    check()
    return parse


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=2000, help="calls per timing")
    parser.add_argument("--repeat", type=int, default=50, help="timings; the best is kept")
    parser.add_argument("--wall", action="store_true",
                        help="time with the wall clock, not the thread's CPU time")
    args = parser.parse_args()
    global CLOCK
    if args.wall:
        CLOCK = time.perf_counter
    n, r = args.count, args.repeat
    rows = []

    # --- realtime ---
    packet = realtime_packet()
    decoder = RealtimeDecoder()
    state = decoder.feed(packet)[0]
    assert state.q_actual == Q
    # decoded eagerly: the state holds every field of the layout as a value (no lazy views)
    assert all(getattr(state, name) is not None for name in LAYOUTS["5.10"].names)
    plain_struct = struct.Struct(">i")
    six = struct.Struct(">6d")

    def plain():
        (size,) = plain_struct.unpack_from(packet, 0)
        return six.unpack_from(packet, 252), six.unpack_from(packet, 444)

    assert plain()[0] == Q
    every = every_field_floor(packet)
    assert every()[LAYOUTS["5.10"].names.index("q_actual")] == Q
    urx = urx_realtime_parser(packet)
    urx_quiet = urx_realtime_parser(packet, quiet=True)
    works = [lambda: decoder.feed(packet), plain, every] + ([urx, urx_quiet] if urx else [])
    times = best_per_call_each(works, n, r)
    rows.append(("realtime 5.10 packet (1220 B)", "urdsl RealtimeDecoder.feed", times[0]))
    if urx is not None:
        rows.append(("", "python-urx URRTMonitor parser", times[3]))
        rows.append(("", "  the same, notify_all for its notifyAll", times[4]))
    else:
        rows.append(("", "python-urx: NOT INSTALLED (pip install urx)", math.nan))
    rows.append(("", "plain struct: every field, no checks (floor)", times[2]))
    rows.append(("", "plain struct: q at 252, pose at 444 only", times[1]))
    ours = times[0]

    # --- primary ---
    message = primary_message()
    assert decode_primary(message).joint_data.q_actual == Q
    works = [lambda: decode_primary(message)]
    try:
        from urx.ursecmon import ParserUtils

        urx_parser = ParserUtils()
        parsed = urx_parser.parse(message)
        assert [parsed["JointData"][f"q_actual{i}"] for i in range(6)] == list(Q)
        works.append(lambda: urx_parser.parse(message))
    except ImportError:
        pass
    times = best_per_call_each(works, n // 4, r)
    rows.append((f"primary robot state ({len(message)} B)", "urdsl decode_primary", times[0]))
    rows.append(("", "python-urx ParserUtils.parse", times[1]) if len(times) > 1
                else ("", "python-urx: NOT INSTALLED", math.nan))

    # --- RTDE ---
    recipe = Recipe(1, RTDE_NAMES, RTDE_TYPES)
    values = {"timestamp": 1.0, "actual_q": Q, "actual_qd": (0.0,) * 6,
              "actual_TCP_pose": (0.4, -0.1, 0.3, 2.2, 2.2, 0.0), "robot_mode": 7,
              "runtime_state": 2}
    data = encode_rtde(DataPackage(1, values), recipe=recipe)
    recipes = {1: recipe}
    assert decode_rtde(data, sender="server", recipes=recipes).values == values
    record_struct = struct.Struct(">HBBd6d6d6diI")

    def record_py_style():
        flat = record_struct.unpack_from(data, 0)
        return {"timestamp": flat[3], "actual_q": flat[4:10], "actual_qd": flat[10:16],
                "actual_TCP_pose": flat[16:22], "robot_mode": flat[22],
                "runtime_state": flat[23]}

    assert record_py_style() == values
    rtde_ours, rtde_plain = best_per_call_each(
        [lambda: decode_rtde(data, sender="server", recipes=recipes), record_py_style], n, r)
    rows.append((f"RTDE data package ({len(data)} B)", "urdsl decode_rtde", rtde_ours))
    rows.append(("", "plain struct to dict (record.py style)", rtde_plain))

    print(f"{'packet':32} {'decoder':44} {'µs/packet':>10} {'packets/s':>11} {'ratio':>7}")
    reference = None
    for label, name, seconds in rows:
        if label:
            reference = seconds
        ratio = "" if label else f"{seconds / reference:7.2f}"
        rate = f"{1 / seconds:11,.0f}" if seconds == seconds else f"{'-':>11}"
        micro = f"{seconds * 1e6:10.2f}" if seconds == seconds else f"{'-':>10}"
        print(f"{label:32} {name:44} {micro} {rate} {ratio:>7}")
    print("ratio = peer time / urdsl time (> 1: urdsl is faster)")
    print(f"500 Hz RTDE recorder, decoding only: {500 * rtde_ours * 100:.2f} % of one core; "
          f"500 Hz realtime reader: {500 * ours * 100:.2f} %")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
