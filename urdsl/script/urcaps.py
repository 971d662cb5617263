"""Functions that URCaps add to PolyScope programs: names only, for messages.

A URCap's installation node writes its functions (Robotiq's ``rq_activate_and_wait``,
OnRobot's ``rg_grip``, ...) into the preamble of every program PolyScope runs on a robot with
the URCap installed. A file that calls one without that preamble (a script file a Script node
includes, a program sent over a socket) is judged as any other name defined nowhere in the
project: the controller rejects it when the preamble is not there. What this module adds is
the hint that says whose function it is and how to give urdsl the definitions.

The data is ``urcap_functions.tsv`` (package data; ``#`` comment lines, then a header line and
the columns ``name``, ``urcap`` as the preamble names its source, ``evidence``: one public
PolyScope export that defines it, as ``repository@commit:path``). It was harvested from the
exports of ``bench/realworld``; a URCap none of them uses is not in it::

    >>> from urdsl.script.urcaps import urcap_of
    >>> urcap_of("rq_activate_and_wait")[0]
    'Robotiq_2-Finger_Adaptive_Gripper'
    >>> urcap_of("textmsg") is None
    True
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable
from importlib import resources
from typing import TypeVar

from . import nodes as n

__all__ = ["by_urcap_block", "urcap_blocks", "urcap_hint", "urcap_of"]


@functools.cache
def _table() -> dict[str, tuple[str, ...]]:
    text = resources.files("urdsl.script").joinpath("urcap_functions.tsv").read_text("utf-8")
    lines = [line for line in text.splitlines() if line and not line.startswith("#")]
    if not lines or lines[0].split("\t")[:2] != ["name", "urcap"]:
        raise ValueError("urcap_functions.tsv: expected the header 'name<TAB>urcap<TAB>...'")
    table: dict[str, list[str]] = {}
    for number, line in enumerate(lines[1:], start=2):
        fields = line.split("\t")
        if len(fields) != 3:
            raise ValueError(f"urcap_functions.tsv: row {number}: expected 3 columns")
        table.setdefault(fields[0], []).append(fields[1])
    return {name: tuple(urcaps) for name, urcaps in table.items()}


def urcap_of(name: str) -> tuple[str, ...] | None:
    """The URCaps (as their preambles name themselves) whose preamble defines function
    ``name``, or None when no known URCap does."""
    return _table().get(name)


def urcap_hint(name: str) -> str | None:
    """A hint for a call of ``name`` that nothing in the project defines, when ``name`` is a
    known URCap function; None otherwise."""
    urcaps = urcap_of(name)
    if urcaps is None:
        return None
    which = f"the URCap {urcaps[0]}"
    if len(urcaps) > 1:
        which = f"the URCaps {', '.join(urcaps[:-1])} and {urcaps[-1]}"
    return (f"a function of {which}, which PolyScope adds to programs on a robot with the "
            "URCap installed; to check this file as it runs there, --include a .script "
            "PolyScope exported on that robot")


def urcap_blocks(module) -> list[tuple[str, int, int]]:
    """The code a URCap wrote into the program (PolyScope's ``# begin: URCap Installation
    Node`` / ``Program Node`` … ``# end: …`` comments): (the URCap's name from its
    ``#   Source:`` line, first line, last line) for each block."""
    comments = sorted((c for c in n.walk(module) if type(c) is n.Comment),
                      key=lambda c: c.span.line)
    blocks: list[tuple[str, int, int]] = []
    begun: tuple[str, int] | None = None
    for comment in comments:
        text = comment.text.strip()
        if text.startswith("begin: URCap"):
            begun = ("a URCap", comment.span.line)
        elif begun is not None and text.startswith("Source:"):
            name = text[len("Source:"):].split(",")[0].strip()
            begun = (name or begun[0], begun[1])
        elif begun is not None and text.startswith("end: URCap"):
            blocks.append((begun[0], begun[1], comment.span.line))
            begun = None
    return blocks


Item = TypeVar("Item")
Block = tuple[str, int, int]


def by_urcap_block(blocks: list[Block], items: Iterable[Item], line: Callable[[Item], int],
                   wanted: Callable[[Item], bool] = lambda item: True
                   ) -> tuple[list[Item], dict[Block, list[Item]]]:
    """``items`` (findings) split into those outside URCap code and those inside, by the
    block (:func:`urcap_blocks`) that holds their ``line``; an item ``wanted`` rejects stays
    outside wherever it is."""
    outside: list[Item] = []
    inside: dict[Block, list[Item]] = {}
    for item in items:
        at = line(item)
        block = next((b for b in blocks if b[1] <= at <= b[2]), None) if wanted(item) \
            else None
        if block is None:
            outside.append(item)
        else:
            inside.setdefault(block, []).append(item)
    return outside, inside
