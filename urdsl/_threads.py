"""A small shared thread pool for NumPy work split into blocks.

NumPy releases Python's interpreter lock inside its loops, so blocks of an array handled by
two threads run side by side on the two cores that urdsl's machines have.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

__all__ = ["WORKERS", "shared_pool"]

WORKERS = 2
"""Threads in the shared pool."""

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
