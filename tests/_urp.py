"""Small PolyScope programs (``.urp`` XML, uncompressed) for tests."""

from __future__ import annotations

from html import escape


def program(children: str, kinematics: str = "", *, installation: str = "default",
            version: str = "5.11.1", name: str = "t", loops: bool = False) -> str:
    """A program of the nodes ``children`` (XML), saved by PolyScope ``version``, naming
    ``installation``; ``loops``: "Program Loops Forever" on."""
    once = "false" if loops else "true"
    return (f'<URProgram name="{name}" installation="{installation}" createdIn="{version}" '
            f'lastSavedIn="{version}">{kinematics}<children><MainProgram runOnlyOnce="{once}">'
            f'<children>{children}</children></MainProgram></children></URProgram>')


def chars(text: str) -> str:
    """An expression as PolyScope stores it: one element a character (XML-escaped)."""
    return "".join(f'<ExpressionChar character="{escape(c, quote=True)}"/>' for c in text)


def script_line(code: str) -> str:
    """A Script node of one line of URScript."""
    return f'<Script type="Line"><expression>{chars(code)}</expression></Script>'
