"""Controller software versions: the one type and the one parser every layer uses.

PolyScope versions: 1.x CB2, 3.x CB3 (together the CB-Series), 5.x e-Series, 10.x and later
PolyScope X. A version is written ``MAJOR.MINOR[.BUGFIX[.BUILD]]``; the controller reports
all four parts (RTDE ``GET_URCONTROL_VERSION``, the primary interface's version message).

>>> version = ControllerVersion.parse("5.15.2")
>>> version, version.series, version.feature
(ControllerVersion(major=5, minor=15, bugfix=2, build=0), 'e', (5, 15))
>>> str(ControllerVersion.parse("3.15.7.106331"))
'3.15.7.106331'
>>> ControllerVersion.parse("3.14") < ControllerVersion.parse("5.4")
True
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["ControllerVersion", "parse_version"]

_VERSION = re.compile(r"\s*(\d{1,6})(?:\.(\d{1,6}))?(?:\.(\d{1,6}))?(?:\.(\d{1,9}))?\s*")


@dataclass(frozen=True, order=True)
class ControllerVersion:
    """A controller software version, e.g. 5.15 or 3.15.7.106331
    (major.minor.bugfix.build); ordered as the controller's releases are."""

    major: int
    minor: int = 0
    bugfix: int = 0
    build: int = 0

    @classmethod
    def parse(cls, text: str) -> ControllerVersion:
        """``"5"``, ``"5.15"``, ``"5.15.2"`` or ``"5.15.2.1234"``; raises ValueError naming
        the text for anything else."""
        match = _VERSION.fullmatch(str(text))
        if match is None:
            raise ValueError(f"not a controller version: {text!r} (expected e.g. 5.15 or 3.14)")
        return cls(*(int(part) if part else 0 for part in match.groups()))

    @property
    def series(self) -> str:
        """``"cb"`` (CB2, CB3: major ≤ 4), ``"e"`` (e-Series, 5.x) or ``"x"`` (PolyScope X)."""
        if self.major <= 4:
            return "cb"
        return "e" if self.major < 10 else "x"

    @property
    def e_series(self) -> bool:
        """True from software 5 on (e-Series and PolyScope X)."""
        return self.major >= 5

    @property
    def feature(self) -> tuple[int, int]:
        """``(major, minor)``: what the builtins catalog and the lint rules compare."""
        return self.major, self.minor

    def __str__(self) -> str:
        return f"{self.major}.{self.minor}.{self.bugfix}.{self.build}"


def parse_version(text: str) -> tuple[int, int]:
    """``"5.15"`` or ``"5.15.2"`` → ``(5, 15)`` (:attr:`ControllerVersion.feature`); raises
    ValueError for anything else.

    >>> parse_version("5.15.2")
    (5, 15)
    """
    return ControllerVersion.parse(text).feature
