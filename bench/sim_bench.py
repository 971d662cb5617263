"""How steadily does ``urdsl sim`` publish RTDE at 500 Hz?

Starts ``urdsl sim`` in its own process, runs a program that keeps the arm moving, and
connects three RTDE clients that record timestamp and actual_q at 500 Hz for the given time
(``--realtime N`` adds N clients of the realtime interface, port 30003, which sends a packet
every controller step). Prints, per client: packages received, the arrival interval (p50,
p99, max, in ms), the jitter (|interval - 2 ms|, p99), dropped samples (gaps in the
controller's timestamps), and the simulator process's CPU use. Target: p99 jitter < 1 ms,
no drops.

There is no peer to run side by side: URSim (the official simulator) is a Docker image that
does not run here. The numbers are absolute.

    .venv/bin/python bench/sim_bench.py                 # 60 s, 3 clients
    .venv/bin/python bench/sim_bench.py --seconds 10 --clients 5
    .venv/bin/python bench/sim_bench.py --seconds 20 --realtime 3   # + 3 realtime readers
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from urdsl.protocol.realtime import RealtimeDecoder
from urdsl.protocol.rtde import DataPackage, RtdeClient

OFFSET = int(os.environ.get("SIM_BENCH_OFFSET", "3100"))
PROGRAM = """def bench():
  while True:
    movej([0.8, -1.3, 1.2, -1.5, -1.5, 0.5], a=2, v=1.5)
    movej([-0.8, -1.8, 1.8, -1.6, -1.6, -0.5], a=2, v=1.5)
  end
end
"""


def _command(*args: str) -> list[str]:
    script = Path(sys.executable).with_name("urdsl")
    found = str(script) if script.exists() else shutil.which("urdsl")
    return [found, "sim", *args] if found else [sys.executable, "-m", "urdsl.cli", "sim", *args]


def _cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as handle:
        fields = handle.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _exchange(sock: socket.socket, client: RtdeClient, request: bytes) -> list:
    """Send one request of the protocol's RTDE client; the events until its reply."""
    sock.sendall(request)
    events: list = []
    while client.awaiting:
        data = sock.recv(65536)
        if not data:
            raise ConnectionError("closed")
        events += client.receive_data(data)
    return events


def _collect(sock: socket.socket, seconds: float, times, kind: str, out) -> None:
    """Receive for ``seconds``: the arrival time (s, perf_counter) and controller time of
    every sample ``times(data)`` finds in the received bytes, put on the queue ``out``."""
    arrivals, stamps = [], []
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        data = sock.recv(65536)
        if not data:
            break
        now = time.perf_counter()
        for stamp in times(data):
            arrivals.append(now)
            stamps.append(stamp)
    sock.close()
    out.put({"kind": kind, "arrivals": np.array(arrivals), "stamps": np.array(stamps)})


def record(port: int, seconds: float, out) -> None:
    """One recording client (its own process), on :class:`urdsl.protocol.rtde.RtdeClient`:
    timestamps of the data packages."""
    sock = socket.create_connection(("127.0.0.1", port), timeout=5)
    client = RtdeClient()
    _exchange(sock, client, client.request_protocol_version(2))
    _exchange(sock, client, client.setup_outputs(["timestamp", "actual_q"], 500.0))
    _exchange(sock, client, client.start())
    _collect(sock, seconds, lambda data: [event.values["timestamp"] for event
                                          in client.receive_data(data)
                                          if isinstance(event, DataPackage)], "rtde", out)


def record_realtime(port: int, seconds: float, out) -> None:
    """One realtime-interface reader (its own process): the controller time of every packet,
    decoded by :class:`urdsl.protocol.realtime.RealtimeDecoder`."""
    sock = socket.create_connection(("127.0.0.1", port), timeout=5)
    decoder = RealtimeDecoder()
    _collect(sock, seconds, lambda data: [state.time for state in decoder.feed(data)],
             "realtime", out)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--clients", type=int, default=3)
    parser.add_argument("--realtime", type=int, default=0,
                        help="realtime-interface (30003) readers beside the RTDE clients")
    args = parser.parse_args()

    process = subprocess.Popen(_command("--port-offset", str(OFFSET), "--quiet"),
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                with socket.create_connection(("127.0.0.1", 29999 + OFFSET), timeout=1):
                    break
            except OSError:
                if time.monotonic() > deadline or process.poll() is not None:
                    print("urdsl sim did not start", file=sys.stderr)
                    return 1
                time.sleep(0.2)
        with socket.create_connection(("127.0.0.1", 30002 + OFFSET), timeout=5) as sender:
            sender.sendall(PROGRAM.encode())
        time.sleep(0.5)
        queue = multiprocessing.Queue()
        clients = [multiprocessing.Process(target=record,
                                           args=(30004 + OFFSET, args.seconds, queue))
                   for _ in range(args.clients)]
        clients += [multiprocessing.Process(target=record_realtime,
                                            args=(30003 + OFFSET, args.seconds, queue))
                    for _ in range(args.realtime)]
        cpu0, wall0 = _cpu_seconds(process.pid), time.perf_counter()
        for client in clients:
            client.start()
        results = [queue.get(timeout=args.seconds + 60) for _ in clients]
        cpu = (_cpu_seconds(process.pid) - cpu0) / (time.perf_counter() - wall0)
        for client in clients:
            client.join(10)
    finally:
        process.terminate()
        try:
            process.wait(20)
        except subprocess.TimeoutExpired:
            process.kill()

    print(f"urdsl sim RTDE at 500 Hz, {args.clients} clients, {args.realtime} realtime "
          f"readers, {args.seconds:g} s "
          f"(no peer controller to compare against: URSim does not run here)")
    print(f"{'client':>6} {'kind':>8} {'packages':>9} {'p50 ms':>7} {'p99 ms':>7} "
          f"{'max ms':>7} {'jitter p99 ms':>13} {'dropped':>8}")
    results.sort(key=lambda result: result["kind"] != "rtde")
    worst = 0.0
    drops = 0
    for index, result in enumerate(results):
        intervals = np.diff(result["arrivals"]) * 1000
        steps = np.diff(result["stamps"])
        dropped = int(np.sum(np.round(steps / 0.002) - 1))
        jitter = np.percentile(np.abs(intervals - 2.0), 99)
        worst, drops = max(worst, jitter), drops + dropped
        print(f"{index:>6} {result['kind']:>8} {len(result['stamps']):>9} "
              f"{np.percentile(intervals, 50):7.3f} "
              f"{np.percentile(intervals, 99):7.3f} {intervals.max():7.3f} {jitter:13.3f} "
              f"{dropped:>8}")
    print(f"simulator CPU: {cpu * 100:.1f}% of one core; worst p99 jitter {worst:.3f} ms "
          f"(target < 1 ms): {'met' if worst < 1 else 'NOT met'}; dropped {drops} "
          f"(target 0): {'met' if drops == 0 else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
