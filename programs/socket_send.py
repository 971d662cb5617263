"""The course's "Python program for network communication", done the urdsl way.

The course builds the command by string concatenation (``"movej([" + str(q1) + "," ...``)
and writes it to a raw socket on port 30002. Here the DSL builds the move from Joints.deg
(six angles, checked; degrees at the call, radians in the script), urdsl checks the program
offline, and urdsl's sender (urdsl.robot.send) sends it and follows the primary interface
until it finished or failed — with a runtime error shown at this file's line.

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

    from urdsl.robot import CheckFailedError, RobotError, send

    parser = argparse.ArgumentParser(description="check and send the course's movej")
    parser.add_argument("--host", default="127.0.0.1", help="robot address (default: "
                        "urdsl sim on this machine)")
    parser.add_argument("--port", type=int, default=30002)
    parser.add_argument("--primary-port", type=int, default=30001)
    parser.add_argument("--robot", default="ur5e")
    args = parser.parse_args()
    try:  # check offline, send, follow on the primary interface until it ends
        result = send(program, args.host, args.port, timeout=60, robot=args.robot,
                      monitor_port=args.primary_port)
    except CheckFailedError as error:
        print(error)
        return 1
    except RobotError as error:
        print(f"error: {error}")
        return 1
    print(result.summary())
    return 0 if result.ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
