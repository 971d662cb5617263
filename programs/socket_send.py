"""The course's "Python program for network communication", done the urdsl way.

The course builds the command by string concatenation (``"movej([" + str(q1) + "," ...``)
and writes it to a raw socket on port 30002. Here the DSL builds the move from Joints.deg
(six angles, checked; degrees at the call, radians in the script), urdsl checks the program
offline, and urdsl's sender sends it and follows the primary interface until it finished
or failed — with a runtime error shown at this file's line.

    urdsl compile programs/socket_send.py                  # the URScript it sends
    urdsl sim &                                            # a robot on 127.0.0.1
    python programs/socket_send.py                         # check, send, follow
    python programs/socket_send.py --host 192.168.0.10     # your robot
"""

from urdsl.dsl import Joints, Program

program = Program("network_move")
program.movej(Joints.deg(0, -90, 90, 0, 90, 0))  # the course's q1 … q6


def main() -> int:
    import argparse

    from urdsl.robot.sender import run_program
    from urdsl.verify.run import CheckOptions, check_tree

    parser = argparse.ArgumentParser(description="check and send the course's movej")
    parser.add_argument("--host", default="127.0.0.1", help="robot address (default: "
                        "urdsl sim on this machine)")
    parser.add_argument("--port", type=int, default=30002)
    parser.add_argument("--primary-port", type=int, default=30001)
    parser.add_argument("--robot", default="ur5e")
    args = parser.parse_args()
    report = check_tree(program.tree(), __file__, CheckOptions(robot=args.robot))
    print(report.render_text(), end="")
    if report.has_errors:
        return 1
    result = run_program(program.script(), args.host, args.port, timeout=60,
                         primary_port=args.primary_port)
    print(f"{args.host}:{args.port}: {result.status}")
    return 0 if result.status in ("finished", "not observed") else 1


if __name__ == "__main__":
    raise SystemExit(main())
