"""A small shared thread pool for NumPy work split into blocks.

NumPy releases Python's interpreter lock inside its loops, so blocks of an array handled by
several threads run side by side on the machine's cores. The pool has one thread per core
the process may use (``os.process_cpu_count()`` on Python 3.13+, else ``os.cpu_count()``),
or as many as the environment variable ``URDSL_THREADS`` says (a positive whole number; 1
runs every block on one worker thread, e.g. on a machine shared with other work).

>>> thread_count({"URDSL_THREADS": "3"})
3
>>> thread_count({}) >= 1
True
"""

from __future__ import annotations

import os
import threading
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor

__all__ = ["WORKERS", "ENV_VARIABLE", "thread_count", "shared_pool"]

ENV_VARIABLE = "URDSL_THREADS"
MAX_WORKERS = 64
"""More threads than this gain nothing for blocks of 32768 rows; a larger setting is capped."""


def thread_count(environ: Mapping[str, str] | None = None) -> int:
    """Threads for the shared pool: ``URDSL_THREADS`` from ``environ`` (default
    ``os.environ``) if it is a positive whole number, else the cores this process may use
    (at least 1, at most :data:`MAX_WORKERS`). A setting that is not a positive whole number
    is ignored, with a warning on stderr, rather than stopping a check."""
    environ = os.environ if environ is None else environ
    text = environ.get(ENV_VARIABLE, "").strip()
    if text:
        try:
            value = int(text)
        except ValueError:
            value = 0
        if value >= 1:
            return min(value, MAX_WORKERS)
        import sys

        print(f"urdsl: warning: {ENV_VARIABLE}={text!r} is not a positive whole number; "
              "using the machine's core count", file=sys.stderr)
    counter = getattr(os, "process_cpu_count", None) or os.cpu_count
    return max(1, min(counter() or 1, MAX_WORKERS))


WORKERS = thread_count()
"""Threads in the shared pool (read once, when urdsl is imported)."""

_pool: ThreadPoolExecutor | None = None
_lock = threading.Lock()


def _forget_in_child() -> None:
    """A forked child has none of the parent's threads: it starts a pool of its own."""
    global _pool, _lock
    _pool, _lock = None, threading.Lock()


os.register_at_fork(after_in_child=_forget_in_child)


def shared_pool() -> ThreadPoolExecutor:
    """The process's pool of :data:`WORKERS` threads, started on first use."""
    global _pool
    with _lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(WORKERS, thread_name_prefix="urdsl-numpy")
        return _pool
