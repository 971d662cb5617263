"""The URScript interpreter: values, scopes, threads, builtins bound to a robot."""

from __future__ import annotations

from .environment import Environment
from .errors import ScriptRuntimeError
from .interpreter import Event, Interpreter, RunResult, RuntimeConfig

__all__ = ["Environment", "Event", "Interpreter", "RunResult", "RuntimeConfig",
           "ScriptRuntimeError"]
