"""The Python implementations of URScript builtins, by name.

Each implementation module (:mod:`.builtins` for maths, strings, lists, I/O and messages,
:mod:`.motion_builtins` for motion, robot state and pose maths) registers its functions with
:func:`implements`; :class:`urdsl.runtime.builtins.BuiltinTable` calls them. This module
imports nothing, so the implementation modules do not import each other.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["IMPLEMENTATIONS", "implements"]

IMPLEMENTATIONS: dict[str, Callable[..., Any]] = {}
"""Every implemented builtin: name → ``impl(rt, node, **arguments)``."""


def implements(*names: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Register the decorated function as the implementation of the builtins ``names``."""

    def register(function: Callable[..., Any]) -> Callable[..., Any]:
        for name in names:
            IMPLEMENTATIONS[name] = function
        return function

    return register
