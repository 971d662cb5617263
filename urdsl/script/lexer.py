"""The URScript lexer: the grammar's terminals compiled into one regular expression.

The terminals are defined once, in ``grammar/urscript.lark``; this module reads them from the
Lark grammar and builds a scanner from them. It is faster than Lark's own lexer for this
language because it produces plain tuples ``(type, value, start, end)`` (offsets into the
text; lines and columns are computed only when a message needs them) and looks keywords up in
a dictionary instead of trying each keyword pattern.

Besides the grammar's terminals it makes ``BLANK`` tokens (a run of two or more line breaks
between tokens) and marks each ``COMMENT`` as trailing or not, so that the parser can keep a
program's layout.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import TYPE_CHECKING

from .diagnostics import ScriptSyntaxError
from .nodes import Source

if TYPE_CHECKING:
    from lark import Lark

__all__ = ["Lexer", "Token"]

Token = tuple  # (type: str, value: str | tuple[str, bool], start: int, end: int)

# Terminals matched by a regular expression of their own, in the order they are tried.
_REGEX_TERMINALS = ("COMMENT", "MARKER", "STRING", "NUMBER", "POSE_OPEN", "NAME")

# Characters that are not URScript, with what to write instead.
_BAD_CHARACTER_HINTS = {
    ";": "URScript needs no ';' between statements: delete it",
    "{": "'{' is not URScript; if this is a template, fill in its placeholders first",
    "}": "'}' is not URScript; if this is a template, fill in its placeholders first",
    "&": "URScript writes 'and' for '&&' and '&'",
    "|": "URScript writes 'or' for '||' and '|'",
    "^": "URScript has no '^': use 'xor' for booleans or pow(a, b) for powers",
    "`": "'`' is not URScript",
    "@": "'@' is not URScript",
    "?": "URScript has no '?:' operator: use if/else",
    "~": "URScript has no '~' operator",
    '"': "a string must close on the line where it opens (URScript strings have no escapes)",
    "'": "a string must close on the line where it opens (URScript strings have no escapes)",
    "\\": "a backslash is only allowed inside a string",
}


def _line_breaks(text: str, start: int, end: int) -> int:
    """How many line breaks (LF, CRLF or a lone CR) ``text[start:end]`` holds."""
    return text.count("\n", start, end) + text.count("\r", start, end) \
        - text.count("\r\n", start, end)


class Lexer:
    """A scanner for the terminals of a Lark grammar (see the module docstring)."""

    def __init__(self, grammar: Lark) -> None:
        patterns: dict[str, str] = {}
        keywords: dict[str, str] = {}
        operators: dict[str, str] = {}
        for terminal in grammar.terminals:
            pattern = terminal.pattern
            if terminal.name in _REGEX_TERMINALS:
                patterns[terminal.name] = pattern.to_regexp()
            elif pattern.type == "str" and re.fullmatch(r"[A-Za-z_]\w*", pattern.value):
                keywords[pattern.value] = terminal.name
            elif pattern.type == "str":
                operators[pattern.value] = terminal.name
            else:  # pragma: no cover - a grammar change the lexer does not know
                raise ValueError(f"lexer: no rule for terminal {terminal.name}")
        missing = [name for name in _REGEX_TERMINALS if name not in patterns]
        if missing:  # pragma: no cover - grammar and lexer out of step
            raise ValueError(f"lexer: grammar lacks terminals {missing}")
        ops = "|".join(re.escape(op) for op in sorted(operators, key=len, reverse=True))

        def scanner(comment: str) -> re.Pattern[str]:
            parts = [f"(?P<{name}>{comment if name == 'COMMENT' else patterns[name]})"
                     for name in _REGEX_TERMINALS]
            parts += [f"(?P<OP>{ops})", r"(?P<ERROR>[^ \t\f\r\n\v])"]
            # Each match is the white space before a token (group 1) and the token: one
            # match per token, and white space costs no loop turn of its own.
            return re.compile(r"([ \t\f\r\n\v]*)(?:" + "|".join(parts) + ")", re.DOTALL)

        self._regex = scanner(patterns["COMMENT"])
        # In a file whose lines end with LF (or CRLF), a lone CR inside a comment is part of
        # the comment: PolyScope writes the OnRobot URCap's preamble comment
        # "#======    OnRobot FT Search Part<CR>    ======#" into every program that uses
        # it, and the controller runs those programs [U]. A file of CR-only lines (classic
        # Mac) still ends its comments at a CR.
        self._regex_lf = scanner(r"#(?:[^\r\n]|\r(?!\n))*")
        self.keywords = keywords
        self.operators = operators

    def tokens(self, source: Source) -> Iterator[Token]:
        """Yield the tokens of ``source`` as ``(type, value, start, end)`` tuples.

        Raises :class:`ScriptSyntaxError` at the first character that starts no token.
        """
        text = source.text
        keywords = self.keywords
        operators = self.operators
        last_end = -1  # end of the last token that is not a comment; -1 before the first
        # A UTF-8 byte-order mark (editors on Windows write one) is no token.
        regex = self._regex_lf if "\n" in text else self._regex
        for match in regex.finditer(text, 1 if text.startswith("\ufeff") else 0):
            kind = match.lastgroup
            start = match.end(1)
            end = match.end()
            space = match.start()  # the white space before this token starts here
            if start - space > 1 and space > 0 and _line_breaks(text, space, start) >= 2:
                yield ("BLANK", "", space, start)
            if kind == "NUMBER" or kind == "STRING":
                last_end = end
                yield (kind, text[start:end], start, end)
            elif kind == "POSE_OPEN":
                if last_end > 0 and text[last_end - 1] == ".":  # field `s.p[0]`: no pose
                    yield ("NAME", "p", start, start + 1)
                    yield (operators["["], "[", start + 1, end)
                else:
                    yield (kind, text[start:end], start, end)
                last_end = end
            elif kind == "OP":
                value = text[start:end]
                last_end = end
                yield (operators[value], value, start, end)
            elif kind == "NAME":
                value = text[start:end]
                last_end = end
                yield (keywords.get(value, "NAME"), value, start, end)
            elif kind == "COMMENT":
                # trailing: on the line of the last token (a lone CR ends a line too)
                trailing = last_end >= 0 and _line_breaks(text, last_end, start) == 0
                yield ("COMMENT", (text[start + 1:end].rstrip(), trailing), start, end)
            elif kind == "MARKER":
                last_end = end
                yield (kind, text[start:end], start, end)
            else:  # ERROR
                char = text[start]
                hint = _BAD_CHARACTER_HINTS.get(char)
                message = (
                    "string not closed" if char in "\"'" else f"unexpected character {char!r}"
                )
                raise ScriptSyntaxError.at_offset(source, start, start + 1, message, hint)
