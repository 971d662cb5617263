"""Run work on syntax trees on a thread with a deep stack.

Syntax trees are as deep as the program nests: a sum of 20,000 terms is a tree 20,000 levels
deep, and so is a program of deeply nested blocks. The parser, the printer and the JSON
writer walk trees with explicit stacks; the interpreter's compiler and some lint rules still
recurse once per level. Python's default limit of 1,000 levels (and the main thread's 8 MiB
C stack, which ``json`` and ``==`` on dataclasses use) would end those with a
``RecursionError``. :func:`run_deep` runs them on a thread whose stack is large enough for
:data:`RECURSION_LIMIT` levels, and a tree deeper than that still ends with a
``RecursionError`` the caller turns into a message, never a crash of the process.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable
from typing import TypeVar

__all__ = ["FOLLOWED_DEPTH", "RECURSION_LIMIT", "STACK_BYTES", "run_deep"]

T = TypeVar("T")

RECURSION_LIMIT = 200_000
"""Python frames allowed while :func:`run_deep` runs (the default is 1,000)."""

FOLLOWED_DEPTH = 10_000
"""Nesting (blocks and expressions) that ``parse``, ``fmt``, ``lint``, ``check`` and ``send``
are tested to follow under :func:`run_deep` (tests/test_script_hostile.py)."""

STACK_BYTES = 1 << 30
"""Stack of the worker thread: 1 GiB of address space, of which only what a deep tree
touches is ever backed by memory (about 5 KiB per level of the deepest C recursion,
``json``'s encoder and dataclass ``==``)."""

_lock = threading.Lock()


def run_deep(function: Callable[..., T], *args, **kwargs) -> T:
    """``function(*args, **kwargs)`` on a thread with a deep stack; its result, or the
    exception it raised (re-raised here). Ctrl-C in the calling thread ends the wait (the
    worker is a daemon thread and ends with the process)."""
    outcome: dict[str, object] = {}

    def work() -> None:
        try:
            outcome["value"] = function(*args, **kwargs)
        except BaseException as error:  # noqa: BLE001 - handed to the caller as it is
            outcome["error"] = error

    with _lock:  # the recursion limit is the process's: one deep run at a time
        previous_size = threading.stack_size()
        previous_limit = sys.getrecursionlimit()
        # raised before the worker starts: it may run (and recurse) at once
        sys.setrecursionlimit(max(previous_limit, RECURSION_LIMIT))
        try:
            threading.stack_size(STACK_BYTES)
            try:
                worker = threading.Thread(target=work, name="urdsl-deep", daemon=True)
                worker.start()
            finally:
                threading.stack_size(previous_size)
            while worker.is_alive():
                worker.join(0.1)  # in slices, so that Ctrl-C reaches this thread
        finally:
            sys.setrecursionlimit(previous_limit)
    if "error" in outcome:
        raise outcome["error"]  # type: ignore[misc]
    return outcome["value"]  # type: ignore[return-value]
