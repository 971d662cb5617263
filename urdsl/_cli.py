"""What every ``urdsl`` command module shares: exit status, usage errors, reading input and
the one way to name a robot model or a controller version on the command line.

This module sits below every command module (``urdsl/*/command.py``) and below
:mod:`urdsl.cli`, which loads them: command modules import from here, never from ``cli``.

>>> robot_model("UR5e"), robot_model("ur8 long")
('ur5e', 'ur8long')
>>> str(controller_version("5.15"))
'5.15.0.0'
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

from .kinematics.errors import KinematicsError
from .kinematics.models import model_spec
from .versions import ControllerVersion

__all__ = ["EXIT_OK", "EXIT_PROBLEMS", "EXIT_USAGE", "UsageError", "InputFile", "read_input",
           "write_script", "load_cell", "error", "robot_model", "controller_version"]

EXIT_OK, EXIT_PROBLEMS, EXIT_USAGE = 0, 1, 2


class UsageError(Exception):
    """A problem with the command line or the files it names (exit status 2)."""


@dataclass
class InputFile:
    """A file read for a command: its name for messages, its text and its encoding."""

    name: str
    text: str
    encoding: str
    path: str | None  # None for standard input


def read_input(name: str) -> InputFile:
    """Read ``name`` (``-`` is standard input). URScript files are UTF-8; files that are not
    valid UTF-8 are read as Latin-1 (PolyScope's 8-bit text), and written back the same way."""
    if name == "-":
        data = sys.stdin.buffer.read()
        path = None
        label = "<stdin>"
    else:
        try:
            with open(name, "rb") as handle:
                data = handle.read()
        except OSError as failure:
            raise UsageError(f"cannot read {name}: {failure.strerror}") from None
        path = label = name
    try:
        return InputFile(label, data.decode("utf-8"), "utf-8", path)
    except UnicodeDecodeError:
        return InputFile(label, data.decode("latin-1"), "latin-1", path)


def write_script(text: str, output: str | None) -> None:
    """Write a compiled script to the file ``output`` (saying so on standard error), or to
    standard output when ``output`` is empty; raise :class:`UsageError` when it cannot."""
    if not output:
        sys.stdout.write(text)
        return
    from pathlib import Path

    try:
        Path(output).write_text(text, encoding="utf-8")
    except OSError as problem:
        raise UsageError(f"cannot write {output}: {problem.strerror}") from None
    print(f"wrote {output} ({text.count(chr(10))} lines)", file=sys.stderr)


def error(message: str) -> None:
    """Print ``urdsl: error: message`` on stderr."""
    print(f"urdsl: error: {message}", file=sys.stderr)


def robot_model(name: str) -> str:
    """The model name a ``--robot`` option gives (any case, ``UR8 Long``), as
    :data:`urdsl.kinematics.MODELS` names it; a UsageError naming the known models for an
    unknown one. Every command resolves ``--robot`` with this (see
    :func:`urdsl.kinematics.model_spec`)."""
    try:
        return model_spec(name).name
    except KinematicsError as failure:
        raise UsageError(str(failure)) from None


def controller_version(text: str) -> ControllerVersion:
    """The controller software version a ``--version`` option gives (``5.15``,
    ``3.15.7.106331``); a UsageError for anything else."""
    try:
        return ControllerVersion.parse(text)
    except ValueError as failure:
        raise UsageError(str(failure)) from None


def load_cell(robot: str, path: str):
    """The collision model of ``robot`` with the obstacles of the cell file ``path`` (see
    :mod:`urdsl.kinematics.collision`), or a :class:`UsageError` naming what is wrong."""
    from .kinematics import KinematicsError, Robot
    from .kinematics.collision import CollisionModel

    model = CollisionModel(Robot.model(robot))
    try:
        model.load_cell(path)
    except KinematicsError as error:
        raise UsageError(f"bad cell description: {error}") from None
    return model
