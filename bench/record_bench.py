"""Recorder cost: CPU time per RTDE sample written to CSV, urdsl's recorder vs a plain
``struct`` loop in the style of UR's record.py (socket → unpack → csv.writer), same server,
same bytes, in one run.

A server thread on 127.0.0.1 (the protocol's :class:`RtdeServer`) streams a recording of
actual_q, actual_qd, actual_TCP_pose and robot_mode at 500 Hz worth of control cycles as fast
as the client takes them. CPU is measured with ``time.thread_time`` in the client thread
only, so the server's work is not counted. The budget from issue 7: a 500 Hz recorder below
10 % of one core, i.e. below 200 µs per sample.

    python bench/record_bench.py [--samples 20000]
"""

from __future__ import annotations

import argparse
import csv
import os
import select
import socket
import struct
import tempfile
import threading
import time

from urdsl.protocol import rtde as r
from urdsl.robot.recorder import record

FIELDS = ["timestamp", "actual_q", "actual_qd", "actual_TCP_pose", "robot_mode"]


def _values(cycle: int) -> dict:
    return {"timestamp": cycle * 0.002, "actual_q": tuple(i + cycle * 1e-4 for i in range(6)),
            "actual_qd": (0.1,) * 6, "actual_TCP_pose": (0.4, -0.1, 0.3, 0.0, 3.1, 0.0),
            "robot_mode": 7}


def serve(listener: socket.socket, samples: int, done: threading.Event) -> None:
    """One RTDE connection: answer the setup, then stream ``samples`` packages in bursts."""
    sock, _ = listener.accept()
    server = r.RtdeServer((5, 11, 1, 0))
    sent = 0
    cycle = 0
    with sock:
        while not done.is_set():
            ready, _, _ = select.select([sock], [], [], 0 if server.running else 0.05)
            if ready:
                data = sock.recv(65536)
                if not data:
                    return
                server.receive_data(data)
                sock.sendall(server.data_to_send())
            if server.running and sent < samples:
                burst = b"".join(server.outputs(_values(cycle + i), cycle + i)
                                 for i in range(100))
                cycle += 100
                sent += 100
                sock.sendall(burst)
            elif sent >= samples:
                time.sleep(0.01)


def run_server(samples: int):
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)
    done = threading.Event()
    thread = threading.Thread(target=serve, args=(listener, samples, done), daemon=True)
    thread.start()
    return listener, done, thread


def bench_urdsl(samples: int, path: str) -> tuple[float, int]:
    listener, done, thread = run_server(samples)
    start = time.thread_time()
    result = record("127.0.0.1", path, FIELDS[1:], frequency=500, samples=samples,
                    port=listener.getsockname()[1])
    cpu = time.thread_time() - start
    done.set()
    thread.join(5)
    listener.close()
    return cpu, result.samples


def bench_plain(samples: int, path: str) -> tuple[float, int]:
    """The record.py way: blocking recv of header + payload, struct.unpack, csv.writer."""
    listener, done, thread = run_server(samples)
    start = time.thread_time()
    sock = socket.create_connection(listener.getsockname(), timeout=5)

    def request(code: str, payload: bytes = b"") -> bytes:
        sock.sendall(struct.pack(">HB", 3 + len(payload), ord(code)) + payload)
        while True:
            size, kind = struct.unpack(">HB", _exact(sock, 3))
            body = _exact(sock, size - 3)
            if kind == ord(code):
                return body

    request("V", struct.pack(">H", 2))
    request("v")
    names = ",".join(FIELDS).encode()
    request("O", struct.pack(">d", 500.0) + names)
    request("S")
    unpack = struct.Struct(">B" + "d" * 19 + "i").unpack
    header = ["timestamp"] + [f"{n}_{i}" for n in FIELDS[1:4] for i in range(6)] + ["robot_mode"]
    count = 0
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle, delimiter=" ")
        writer.writerow(header)
        while count < samples:
            size, kind = struct.unpack(">HB", _exact(sock, 3))
            body = _exact(sock, size - 3)
            if kind != ord("U"):
                continue
            writer.writerow(unpack(body)[1:])
            count += 1
    sock.close()
    cpu = time.thread_time() - start
    done.set()
    thread.join(5)
    listener.close()
    return cpu, count


def _exact(sock: socket.socket, count: int) -> bytes:
    data = b""
    while len(data) < count:
        chunk = sock.recv(count - len(data))
        if not chunk:
            raise ConnectionError("closed")
        data += chunk
    return data


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=20000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        ours_cpu, ours_n = bench_urdsl(args.samples, os.path.join(folder, "a.csv"))
        plain_cpu, plain_n = bench_plain(args.samples, os.path.join(folder, "b.csv"))
    ours = ours_cpu / ours_n * 1e6
    plain = plain_cpu / plain_n * 1e6
    print(f"urdsl recorder      {ours:7.1f} µs CPU per sample ({ours_n} samples); at 500 Hz "
          f"{ours * 500 / 1e4:5.2f} % of one core")
    print(f"plain struct loop   {plain:7.1f} µs CPU per sample ({plain_n} samples); at 500 Hz "
          f"{plain * 500 / 1e4:5.2f} % of one core")
    print(f"ratio urdsl / plain {ours / plain:5.2f}x")


if __name__ == "__main__":
    main()
