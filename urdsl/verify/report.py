"""The verifier's report: findings, executed moves, cycle time; as text, JSON and a plot.

JSON shape (``urdsl check --json``), one document::

    {"file": "pick.script", "robot": "ur5e", "ok": false, "cycle_time": 4.182,
     "loop": {"line": 12, "column": 3, "passes": 1505, "pass_time": 4.182,
              "first_pass": 5.31, "shortest": 4.182, "longest": 4.182},
     "summary": {"error": 1, "warning": 0, "info": 0},
     "findings": [{"code": "URS303", "severity": "error", "message": "...",
                   "file": "pick.script", "line": 7, "column": 1, "hint": "...",
                   "time": 2.31, "count": 1}],
     "moves": [{"kind": "movej", "line": 3, "column": 1, "start": 0.0,
                "duration": 2.094}],
     "slowed": {"moves": 1, "up_to": 0.35},
     "events": [{"time": 0.0, "kind": "textmsg", "message": "hello", "line": 2}],
     "inferred": {"robot": {"model": "ur10e", "source": "inferred", "pairs": 14, ...},
                  "start": {"joints": [...], "source": "inferred", "from": "Waypoint_1_q",
                            "line": 40}, "text": ["robot ur10e inferred from ..."]}}

Times in s of robot time. ``loop`` is there only for a program that loops forever (PolyScope's
"Loop forever", a ``while True`` of the main thread still running when the check stopped):
``cycle_time`` is then the mean time of one pass of that loop after the first (``first_pass``
includes the way from where the arm started), ``passes`` the complete passes checked;
otherwise ``cycle_time`` is the robot time from the start to the end of the program.
``slowed`` is there only when the controller slows moves to keep a joint or the TCP within its
limit (URS304 and URS306 warnings): ``cycle_time`` is the program as planned, and those
``moves`` (of one pass, for a loop) add up to about ``up_to`` s to it (:class:`Slowed`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

from ..script.nodes import Span
from .findings import Finding

__all__ = ["Report", "Move", "Slowed", "dumps"]


@dataclass(frozen=True)
class Move:
    """One executed move: its kind, the statement, start time and duration (s)."""

    kind: str
    span: Span
    start: float
    duration: float
    lead_joint: int | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "line": self.span.line, "column": self.span.column,
                "start": round(self.start, 6), "duration": round(self.duration, 6)}


@dataclass(frozen=True)
class Loop:
    """The loop a program runs forever, as far as the check followed it: ``passes`` complete
    passes, the first taking ``first_pass`` s (with the way from the start), the others
    ``pass_time`` s on average, ``shortest`` to ``longest`` s (s of robot time).
    ``averaged``: the robot time (s) from the start of the first pass ``pass_time`` averages
    to the end of the last, and how many passes that is."""

    span: Span
    passes: int
    first_pass: float
    pass_time: float
    shortest: float
    longest: float
    averaged: tuple[float, float, int] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"line": self.span.line, "column": self.span.column, "passes": self.passes,
                "pass_time": round(self.pass_time, 6), "first_pass": round(self.first_pass, 6),
                "shortest": round(self.shortest, 6), "longest": round(self.longest, 6)}

    def describe(self) -> str:
        """``one pass of the loop at line 2, which runs forever: 1505 passes checked, the
        first 5.310 s``."""
        extra = [f"{self.passes} pass{'es' if self.passes != 1 else ''} checked"]
        if abs(self.first_pass - self.pass_time) > 5e-4:
            extra.append(f"the first {self.first_pass:.3f} s")
        if self.longest - self.shortest > 5e-4:
            extra.append(f"from {self.shortest:.3f} to {self.longest:.3f} s")
        return (f"one pass of the loop at line {self.span.line}, which runs forever: "
                + ", ".join(extra))


@dataclass(frozen=True)
class Slowed:
    """Moves the controller slows to keep a joint or the TCP within its speed limit, and the
    time (s) that adds at most to the cycle time, or to one pass of the loop a program runs
    forever: each move slowed evenly by the factor its fastest joint or TCP exceeds the limit
    (:attr:`Finding.slowed`). The controller's own speed scaling slows only where it must and
    is not documented [U], so the real cost lies between nothing and this bound."""

    moves: int
    up_to: float

    def to_dict(self) -> dict[str, Any]:
        return {"moves": self.moves, "up_to": round(self.up_to, 6)}

    def describe(self) -> str:
        """``the controller slows 2 moves: up to 0.35 s longer``."""
        plural = "s" if self.moves != 1 else ""
        return f"the controller slows {self.moves} move{plural}: up to {self.up_to:.3f} s longer"


@dataclass
class Report:
    """Everything ``urdsl check`` found out about one program."""

    file: str
    robot: str
    findings: list[Finding] = field(default_factory=list)
    moves: list[Move] = field(default_factory=list)
    events: list = field(default_factory=list)
    cycle_time: float = 0.0
    loop: Loop | None = None  # the loop the program runs forever: cycle_time is one pass
    slowed: Slowed | None = None  # moves the controller slows: cycle_time is as planned
    trace: Any = field(default=None, repr=False)
    inferred: Any = None  # urdsl.verify.infer.Inference: robot, start, TCP the check used
    context: str | None = None  # the project context the program ran in, if any
    checked: bool = True  # False: the program could not be compiled, nothing ran (URS001)

    def sort(self) -> None:
        """Order findings by position in the file, then by time, with one finding per
        statement, rule and cause (:meth:`Finding.identity`): a problem met on every pass of
        a loop is reported once, the first time, saying how often it happened
        ("... (12 times, first at t=3.210 s)")."""
        self.findings.sort(key=lambda f: (f.span.line, f.span.column, f.time or 0.0, f.code))
        first: dict[tuple, int] = {}
        counts: list[int] = []
        unique: list[Finding] = []
        for finding in self.findings:
            identity = finding.identity()
            index = first.get(identity)
            if index is None:
                first[identity] = len(unique)
                unique.append(finding)
                counts.append(finding.count)
            else:
                counts[index] += finding.count
        self.findings = [finding.repeated(count) for finding, count in zip(unique, counts,
                                                                           strict=True)]

    def count(self, severity: str) -> int:
        return sum(1 for f in self.findings if f.severity == severity)

    @property
    def has_errors(self) -> bool:
        return self.count("error") > 0

    def codes(self) -> list[str]:
        return [f.code for f in self.findings]

    # ---- outputs ---------------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        return {
            "file": self.file,
            "robot": self.robot,
            "ok": self.checked and not self.has_errors,
            **({} if self.checked else {"checked": False}),
            "cycle_time": round(self.cycle_time, 6),
            **({"loop": self.loop.to_dict()} if self.loop is not None else {}),
            "context": self.context,
            "summary": {s: self.count(s) for s in ("error", "warning", "info")},
            "findings": [f.to_dict() for f in self.findings],
            "moves": _move_dicts(self.moves),
            **({"slowed": self.slowed.to_dict()} if self.slowed is not None else {}),
            "events": [{"time": round(e.time, 6), "kind": e.kind, "message": e.message,
                        "line": e.span.line} for e in self.events],
            **({"inferred": self.inferred.to_dict()} if self.inferred is not None else {}),
        }

    def to_json(self) -> str:
        return dumps(self.to_dict())

    def render_text(self, moves: bool = True, max_moves: int = 20) -> str:
        """Plain-text report: each finding with its source line, then the moves and the
        cycle time."""
        lines = [f.diagnostic().render() for f in self.findings]
        if moves and self.moves:
            lines.append(f"moves ({len(self.moves)}):")
            for move in self.moves[:max_moves]:
                lines.append(f"  line {move.span.line:>4}  {move.kind:<6} "
                             f"start {move.start:8.3f} s  duration {_seconds(move.duration):>7} s")
            if len(self.moves) > max_moves:
                lines.append(f"  ... {len(self.moves) - max_moves} more")
        if self.context:
            lines.append(self.context)
        if self.inferred is not None:
            lines.extend(self.inferred.lines())
        lines.append(self.summary())
        return "\n".join(lines) + "\n"

    def summary(self) -> str:
        if not self.checked:
            return (f"{self.file}: not checked: {self.count('error')} error(s), "
                    f"{self.count('warning')} warning(s)")
        verdict = "FAILED" if self.has_errors else "ok"
        about = [part.describe() for part in (self.loop, self.slowed) if part is not None]
        return (f"{self.file}: {verdict} on {self.robot}: {self.count('error')} error(s), "
                f"{self.count('warning')} warning(s), {self.count('info')} info; "
                f"{len(self.moves)} move(s), cycle time {self.cycle_time:.3f} s"
                + (f" ({'; '.join(about)})" if about else ""))

    def print_rich(self, console, moves: bool = True, max_moves: int = 20) -> None:
        """The report on a rich console: coloured findings, a table of moves."""
        from rich.table import Table
        from rich.text import Text

        colours = {"error": "bold red", "warning": "yellow", "info": "cyan"}
        for finding in self.findings:
            rendered = finding.diagnostic().render().split("\n")
            console.print(Text(rendered[0], style=colours.get(finding.severity, "")))
            for rest in rendered[1:]:
                console.print(Text(rest))
        if moves and self.moves:
            table = Table(title=f"moves ({len(self.moves)})", show_edge=False)
            for column in ("line", "move", "start s", "duration s"):
                table.add_column(column, justify="right" if column != "move" else "left")
            for move in self.moves[:max_moves]:
                table.add_row(str(move.span.line), move.kind, f"{move.start:.3f}",
                              _seconds(move.duration))
            if len(self.moves) > max_moves:
                table.add_row("…", f"{len(self.moves) - max_moves} more", "", "")
            console.print(table)
        if self.context:
            console.print(Text(self.context))
        for line in self.inferred.lines() if self.inferred is not None else ():
            console.print(Text(line, style="cyan"))
        style = "bold green" if self.checked and not self.has_errors else "bold red"
        console.print(Text(self.summary(), style=style))

    def plot(self, path, robot_model=None) -> None:
        """Joint positions and speeds against the limits, and the TCP path (PNG, SVG or PDF
        by the file's suffix)."""
        from .plot import plot_report

        plot_report(self, path, robot_model)


def _seconds(value: float) -> str:
    """A time in s for the move table: milliseconds, or a power of ten for absurd lengths
    (``movej(q, t=1e300)``)."""
    return f"{value:.3f}" if abs(value) < 1e9 else f"{value:.3e}"


def _move_dicts(moves: list[Move]) -> list[dict[str, Any]]:
    """:meth:`Move.to_dict` of every move, each statement's line and column looked up once
    (a loop's moves share a few statements)."""
    where: dict[tuple, tuple[int, int]] = {}
    out = []
    for move in moves:
        span = move.span
        key = (id(span.source), span.start)
        place = where.get(key)
        if place is None:
            place = where[key] = (span.line, span.column)
        out.append({"kind": move.kind, "line": place[0], "column": place[1],
                    "start": round(move.start, 6), "duration": round(move.duration, 6)})
    return out


_ROWS = ("moves", "events")
"""Lists of a report's JSON document that :func:`dumps` writes one entry a line."""


def dumps(document: Any) -> str:
    """A report's JSON document (or a list of them) as text, indented by two spaces, with
    each entry of its ``moves`` and ``events`` on one line: a cell program's report lists
    hundreds of thousands of moves, which Python's indenting encoder takes tens of seconds
    to write, its compact one well under one."""
    rows: dict[str, list] = {}
    key_of: dict[str, str] = {}

    def hollow(item: Any) -> Any:
        if isinstance(item, list):
            return [hollow(entry) for entry in item]
        if not isinstance(item, dict):
            return item
        out = {}
        for key, value in item.items():
            if key in _ROWS and isinstance(value, list) and value:
                marker = f"\x00rows-{len(rows)}\x00"
                rows[json.dumps(marker)] = value
                key_of[json.dumps(marker)] = key
                out[key] = marker
            else:
                out[key] = value
        return out

    text = json.dumps(hollow(document), indent=2)
    for marker, value in rows.items():
        at = text.index(marker)
        line = text[text.rindex("\n", 0, at) + 1:at]
        indent = line[:len(line) - len(line.lstrip())]
        if key_of[marker] == "moves" and "}" not in "".join({m["kind"] for m in value}):
            # numbers and a move's kind, no brace in any text: one call of the encoder,
            # split between entries
            inner = indent + "  " + json.dumps(value)[1:-1].replace(
                "}, {", "},\n" + indent + "  {")
        else:
            inner = ",\n".join(indent + "  " + json.dumps(entry) for entry in value)
        text = text[:at] + "[\n" + inner + "\n" + indent + "]" + text[at + len(marker):]
    return text
