"""How fast do urdsl's decoders read the controller's packets, next to python-urx?

In the same run, on the same bytes: realtime packets (1116 bytes, software 3.10–5.9 layout)
and primary robot-state messages (as urdsl sim sends them). python-urx decodes realtime data
inside its socket thread with one ``struct.unpack`` of the first 692 bytes and picks four
fields by index; that unpack is what is timed for it. Its secondary-interface parser
(``ParserUtils.parse``) is timed whole. urdsl decodes every field by name.

    .venv/bin/python bench/protocol_bench.py
"""

from __future__ import annotations

import logging
import time

from urdsl.protocol import primary, realtime

ROUNDS = 20_000


def rate(function, data, rounds: int = ROUNDS) -> float:
    start = time.perf_counter()
    for _ in range(rounds):
        function(data)
    return rounds / (time.perf_counter() - start)


def robot_state_message() -> bytes:
    """A robot state with the sub-packages python-urx parses (CB3/e-Series layouts)."""
    q = (0.0, -1.57, 1.57, -1.57, -1.57, 0.0)
    state = primary.RobotState({
        0: primary.RobotModeData(1, True, True, True, False, False, False, False, 7, 0, 1.0,
                                 1.0, 1.0, b"\x00"),
        1: primary.JointData(q, q, (0.0,) * 6, (0.0,) * 6, (48.0,) * 6, (30.0,) * 6,
                             (0.0,) * 6, (253,) * 6),
        2: primary.ToolData((0, 0), (0.0, 0.0), 24.0, 0, 0.0, 30.0, 253),
        3: primary.MasterboardData(0, 0, (0, 0), (0.0, 0.0), (0, 0), (0.0, 0.0), 30.0, 48.0,
                                   1.0, 0.1, 1, False, b"\x00" * 15),
        4: primary.CartesianInfo((0.4, 0.1, 0.3, 0.0, 3.14, 0.0), (0.0,) * 6),
    })
    return primary.encode_robot_state(state)


def main() -> None:
    logging.disable(logging.CRITICAL)
    packet = realtime.encode({"q_actual": (0.1,) * 6, "tool_vector_actual": (0.2,) * 6,
                              "robot_mode": 7}, 1116)
    message = robot_state_message()
    ours_rt = rate(realtime.decode, packet)
    ours_primary = rate(primary.decode_message, message)
    print(f"realtime packet ({len(packet)} B), urdsl, all {len(realtime.decode(packet).fields)}"
          f" fields by name: {ours_rt:12,.0f} packets/s")
    print(f"primary robot state ({len(message)} B), urdsl, 5 sub-packages typed:"
          f" {ours_primary:10,.0f} messages/s")
    try:
        from urx.urrtmon import URRTMonitor
        from urx.ursecmon import ParserUtils
    except ImportError as error:
        print(f"python-urx is not installed ({error}); no comparison")
        return
    unpack = URRTMonitor.rtstruct692.unpack

    def urx_realtime(data: bytes):
        return unpack(data[4:4 + URRTMonitor.rtstruct692.size])

    parser = ParserUtils()
    urx_rt = rate(urx_realtime, packet)
    print(f"realtime, python-urx's unpack of 692 bytes (4 fields used): {urx_rt:12,.0f} "
          f"packets/s -> urdsl/urx = {ours_rt / urx_rt:.2f}x")
    try:
        urx_primary = rate(parser.parse, message, ROUNDS // 4)
        print(f"primary, python-urx ParserUtils.parse: {urx_primary:12,.0f} messages/s -> "
              f"urdsl/urx = {ours_primary / urx_primary:.2f}x")
    except Exception as error:  # urx's parser rejects layouts it does not know
        print(f"primary: python-urx's ParserUtils cannot parse this e-Series robot state "
              f"({type(error).__name__}: {error}); no ratio")


if __name__ == "__main__":
    main()
