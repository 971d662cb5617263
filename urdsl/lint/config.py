"""Lint settings: the ``[tool.urdsl.lint]`` table of the nearest ``pyproject.toml``, and the
command line on top of it.

    [tool.urdsl.lint]
    select = ["URS1"]          # codes, prefixes or rule names; default: every rule
    ignore = ["URS113"]
    robot = "ur5e"             # limits for URS110
    version = "5.15"           # controller software version for URS103

The file is found as ruff finds its own: walking up from the linted file's folder (or the
working directory for standard input), the first ``pyproject.toml`` that has a
``[tool.urdsl.lint]`` table wins.
"""

from __future__ import annotations

import functools
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ..script.builtins import Version, parse_version
from .registry import RULES, expand_codes

__all__ = ["ConfigError", "LintSettings", "find_config", "load_settings", "settings_for"]

_KEYS = {"select", "ignore", "robot", "version"}


class ConfigError(ValueError):
    """A setting that urdsl cannot use (unknown rule, robot, version or key)."""


@dataclass(frozen=True)
class LintSettings:
    """Which rules run and for which arm and controller version.

    ``codes`` is the set of rule codes that run; ``model`` a
    :class:`urdsl.kinematics.ModelSpec` or None; ``version`` ``(major, minor)`` or None;
    ``config`` the ``pyproject.toml`` the settings came from, if any.
    """

    codes: frozenset[str]
    model: object | None = None
    version: Version | None = None
    config: Path | None = None


def _codes(select: list[str] | None, ignore: list[str]) -> frozenset[str]:
    try:
        chosen = expand_codes(select) if select else set(RULES)
        return frozenset(chosen - expand_codes(ignore))
    except ValueError as error:
        raise ConfigError(str(error)) from None


def _model(robot: str | None):
    if robot is None:
        return None
    from ..kinematics.errors import KinematicsError
    from ..kinematics.models import model_spec

    try:
        return model_spec(robot)
    except KinematicsError as error:
        raise ConfigError(str(error)) from None


def _version(text: str | None) -> Version | None:
    if text is None:
        return None
    try:
        return parse_version(str(text))
    except ValueError as error:
        raise ConfigError(str(error)) from None


def build_settings(select: list[str] | None = None, ignore: list[str] | None = None,
                   robot: str | None = None, version: str | None = None,
                   config: Path | None = None) -> LintSettings:
    """Settings from plain values (``select``/``ignore`` are codes, prefixes or names)."""
    return LintSettings(_codes(select, ignore or []), _model(robot), _version(version), config)


def find_config(start: Path) -> Path | None:
    """The nearest ``pyproject.toml`` with a ``[tool.urdsl.lint]`` table, walking up from
    folder ``start``."""
    start = start.resolve()
    for folder in (start, *start.parents):
        candidate = folder / "pyproject.toml"
        if candidate.is_file() and _table(candidate) is not None:
            return candidate
    return None


@functools.lru_cache(maxsize=64)
def _read(path: Path, mtime: float) -> dict | None:
    try:
        with open(path, "rb") as handle:
            data = tomllib.load(handle)
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise ConfigError(f"{path}: {error}") from None
    table = data.get("tool", {}).get("urdsl", {}).get("lint")
    return table if isinstance(table, dict) else None


def _table(path: Path) -> dict | None:
    try:
        mtime = path.stat().st_mtime
    except OSError:
        return None
    return _read(path, mtime)


def _strings(path: Path, key: str, value: object) -> list[str]:
    if isinstance(value, str):
        return [value]
    if isinstance(value, list) and all(isinstance(v, str) for v in value):
        return list(value)
    raise ConfigError(f"{path}: [tool.urdsl.lint] {key} must be a list of rule codes")


def _raw(path: Path) -> dict:
    table = _table(path) or {}
    unknown = set(table) - _KEYS
    if unknown:
        raise ConfigError(f"{path}: unknown key(s) in [tool.urdsl.lint]: "
                          f"{', '.join(sorted(unknown))} (known: {', '.join(sorted(_KEYS))})")
    robot, version = table.get("robot"), table.get("version")
    return {
        "select": _strings(path, "select", table["select"]) if "select" in table else None,
        "ignore": _strings(path, "ignore", table.get("ignore", [])),
        "robot": None if robot is None else str(robot),
        "version": None if version is None else str(version),
    }


def load_settings(path: Path) -> LintSettings:
    """The settings of ``[tool.urdsl.lint]`` in ``path``."""
    raw = _raw(path)
    try:
        return build_settings(raw["select"], raw["ignore"], raw["robot"], raw["version"], path)
    except ConfigError as error:
        raise ConfigError(f"{path}: {error}") from None


def settings_for(file: str | None, *, select: list[str] | None = None,
                 ignore: list[str] | None = None, robot: str | None = None,
                 version: str | None = None, use_config: bool = True) -> LintSettings:
    """Settings for linting ``file`` (None: standard input): the nearest configuration, then
    the command line. ``select`` replaces the configured selection; ``ignore`` adds to the
    configured ignores; ``robot`` and ``version`` replace the configured ones."""
    start = Path(file).parent if file else Path.cwd()
    path = find_config(start) if use_config else None
    raw = _raw(path) if path is not None else {"select": None, "ignore": [], "robot": None,
                                                  "version": None}
    where = f"{path}: " if path is not None else ""
    try:
        codes = _codes(select or raw["select"], raw["ignore"] + list(ignore or []))
        model = _model(robot) if robot else _model_from(raw["robot"], where)
        target = _version(version) if version else _version_from(raw["version"], where)
    except ConfigError as error:
        raise ConfigError(str(error)) from None
    return LintSettings(codes, model, target, path)


def _model_from(robot: str | None, where: str):
    try:
        return _model(robot)
    except ConfigError as error:
        raise ConfigError(f"{where}{error}") from None


def _version_from(text: str | None, where: str) -> Version | None:
    try:
        return _version(text)
    except ConfigError as error:
        raise ConfigError(f"{where}{error}") from None
