"""Does ``urdsl sim`` keep its memory flat over many programs and clients?

Starts ``urdsl sim`` in its own process (loopback only, ``--speed 100``), sends it
``--programs`` generated programs of ``--lines`` lines each on the primary interface, one
after the other (each ends with a ``textmsg`` the bench waits for), and meanwhile connects
and disconnects ``--clients`` clients spread over the dashboard, realtime, secondary and RTDE
ports. Prints the simulator's resident memory (VmRSS) every 100 programs and, at the end,
its change since the value after the first 100. Target: within 10 % (exit status 1 if not).

    .venv/bin/python bench/sim_soak.py                      # 1,000 programs of 1,000 lines
    .venv/bin/python bench/sim_soak.py --programs 200 --lines 200

Bounded: every program must finish within ``--program-timeout`` s of wall time, or the
bench stops the simulator and fails.
"""

from __future__ import annotations

import argparse
import socket
import struct
import subprocess
import sys
import time

from sim_bench import _command  # bench/ is on sys.path when this runs as a script

from urdsl.protocol.primary import PrimaryDecoder, RuntimeExceptionMessage, TextMessage

OFFSET = 3300
HOST = "127.0.0.1"


def rss_mib(pid: int) -> float:
    """Resident memory of process ``pid`` (MiB), from /proc."""
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS")


def program(index: int, lines: int) -> str:
    """A ``def`` program of about ``lines`` lines: lists, arithmetic, strings, a function,
    a loop and a short move every 100 lines; it ends with ``textmsg("soak <index>")``."""
    body = [f"def soak{index}():", "  def twice(v):", "    return v * 2", "  end",
            "  total = 0", "  pts = [0, 0, 0, 0]"]
    k = 0
    while len(body) < lines - 2:
        k += 1
        if k % 100 == 0:
            angle = 0.05 * (k // 100 % 4)
            body.append(f"  movej([{angle}, -1.5708, 1.5708, -1.5708, -1.5708, 0], a=14, v=3)")
        elif k % 25 == 0:
            body += ["  i = 0", "  while i < 3:", "    total = total + twice(i)",
                     "    i = i + 1", "  end"]
        elif k % 10 == 0:
            body.append(f'  name = str_cat("step ", {k})')
        else:
            body.append(f"  pts[{k % 4}] = pts[{(k + 1) % 4}] + {k}.5 - total / 1000")
    body += [f'  textmsg("soak {index}")', "end"]
    return "\n".join(body) + "\n"


def _touch(port: int, kind: str) -> None:
    """Connect one client, speak a little, disconnect."""
    with socket.create_connection((HOST, port), timeout=10) as sock:
        sock.settimeout(10)
        if kind == "dashboard":
            sock.recv(4096)
            sock.sendall(b"robotmode\n")
            sock.recv(4096)
        elif kind == "rtde":
            payload = struct.pack(">H", 2)
            sock.sendall(struct.pack(">HB", len(payload) + 3, ord("V")) + payload)
            sock.recv(4096)
        else:
            sock.recv(4096)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--programs", type=int, default=1000)
    parser.add_argument("--lines", type=int, default=1000)
    parser.add_argument("--clients", type=int, default=50)
    parser.add_argument("--every", type=int, default=100, help="print memory every N programs")
    parser.add_argument("--program-timeout", type=float, default=120.0, metavar="S")
    args = parser.parse_args()
    ports = {"dashboard": 29999 + OFFSET, "primary": 30001 + OFFSET,
             "secondary": 30002 + OFFSET, "realtime": 30003 + OFFSET, "rtde": 30004 + OFFSET}
    process = subprocess.Popen(_command("--port-offset", str(OFFSET), "--quiet", "--speed", "100"),
                               stdout=subprocess.PIPE, text=True)
    try:
        ready = process.stdout.readline() if process.stdout else ""
        if not ready.startswith("urdsl sim:"):
            print("urdsl sim did not start", file=sys.stderr)
            return 1
        print(f"urdsl sim pid {process.pid}: {args.programs} programs of {args.lines} lines, "
              f"{args.clients} client connects; start {rss_mib(process.pid):.1f} MiB",
              flush=True)
        primary = socket.create_connection((HOST, ports["primary"]), timeout=10)
        primary.settimeout(1.0)
        decoder = PrimaryDecoder()
        kinds = ["dashboard", "realtime", "secondary", "rtde"]
        touch_every = max(args.programs // max(args.clients, 1), 1)
        touched = 0
        reference = None
        started = time.monotonic()
        for index in range(args.programs):
            primary.sendall(program(index, args.lines).encode())
            deadline = time.monotonic() + args.program_timeout
            done = False
            while not done:
                if time.monotonic() > deadline:
                    print(f"program {index} did not finish within {args.program_timeout:g} s",
                          file=sys.stderr)
                    return 1
                try:
                    data = primary.recv(65536)
                except TimeoutError:
                    continue
                if not data:
                    print("the simulator closed the primary connection", file=sys.stderr)
                    return 1
                for message in decoder.feed(data):
                    if isinstance(message, RuntimeExceptionMessage):
                        print(f"program {index}: {message.text}", file=sys.stderr)
                        return 1
                    if isinstance(message, TextMessage) and message.text == f"soak {index}":
                        done = True
            if touched < args.clients and index % touch_every == 0:
                kind = kinds[touched % len(kinds)]
                _touch(ports[kind], kind)
                touched += 1
            count = index + 1
            if count % args.every == 0 or count == args.programs:
                rss = rss_mib(process.pid)
                if reference is None and count >= args.every:
                    reference = rss
                change = f" ({(rss / reference - 1) * 100:+.1f} % since program " \
                         f"{args.every})" if reference else ""
                print(f"{count:6d} programs  {rss:8.1f} MiB{change}  "
                      f"{time.monotonic() - started:7.1f} s", flush=True)
        primary.close()
        if reference is None:
            return 0
        final = rss_mib(process.pid)
        growth = final / reference - 1
        verdict = "within" if growth <= 0.10 else "NOT within"
        print(f"resident memory {final:.1f} MiB after {args.programs} programs, "
              f"{growth * 100:+.1f} % since program {args.every}: {verdict} 10 %; "
              f"{touched} clients connected and left")
        return 0 if growth <= 0.10 else 1
    finally:
        process.terminate()
        try:
            process.wait(20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


if __name__ == "__main__":
    sys.exit(main())
