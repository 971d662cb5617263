"""Syntax error messages in words a URScript user understands.

The parser knows only "this token cannot come here"; this module looks at the tokens around
the place (open brackets, open blocks, habits from Python) and says what went wrong and what
to write instead. It runs only when parsing has already failed, so it may re-read the text.
"""

from __future__ import annotations

from .diagnostics import ScriptSyntaxError
from .lexer import Lexer, Token
from .nodes import Source

__all__ = ["explain"]

# How to name a token kind in a message.
_WORDS = {
    "NAME": "a name", "NUMBER": "a number", "STRING": "a string", "POSE_OPEN": "'p['",
    "COMMENT": "a comment", "MARKER": "a program label", "BLANK": "an empty line",
    "$END": "the end of the file", "LPAR": "'('", "RPAR": "')'", "LSQB": "'['", "RSQB": "']'",
    "COMMA": "','", "COLON": "':'", "DOT": "'.'", "ASSIGN": "'='",
}
_OPENERS = {"LPAR": "RPAR", "LSQB": "RSQB", "POSE_OPEN": "RSQB"}
_CLOSERS = {"RPAR", "RSQB"}
_BRACKET_NAMES = {"LPAR": "parenthesis", "LSQB": "list", "POSE_OPEN": "pose"}
_BLOCK_OPENERS = {"DEF", "THREAD", "SEC", "IF", "WHILE"}
# Kinds that can start an expression: when all of them are expected, say "an expression".
_EXPRESSION_START = {"NAME", "NUMBER", "STRING", "LPAR", "LSQB", "POSE_OPEN"}


def _describe(kind: str, value: object, lexer: Lexer) -> str:
    if kind in _WORDS and kind not in ("NAME", "NUMBER", "STRING"):
        return _WORDS[kind]
    if kind in lexer.keywords.values() or kind in lexer.operators.values():
        return f"'{value}'"
    if kind in ("NAME", "NUMBER", "STRING"):
        return f"{_WORDS[kind][2:]} {value!s}" if kind != "STRING" else f"string {value}"
    return _WORDS.get(kind, kind)


def _expected_words(expected: list[str], lexer: Lexer) -> str:
    kinds = set(expected) - {"COMMENT", "BLANK", "MARKER"}
    words: list[str] = []
    if _EXPRESSION_START <= kinds:
        words.append("an expression")
        kinds -= _EXPRESSION_START | {"MINUS", "PLUS", "NOT", "BANG", "TRUE", "FALSE", "NONE",
                                      "RUN"}
    spelled = {v: k for k, v in lexer.keywords.items()} | {v: k for k, v in
                                                            lexer.operators.items()}
    if len(kinds) > 6:
        return " or ".join(words) if words else "something else"
    for kind in sorted(kinds):
        if kind in _WORDS:
            words.append(_WORDS[kind])
        elif kind in spelled:
            words.append(f"'{spelled[kind]}'")
    if not words:
        return ""
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]


def _tokens_before(source: Source, offset: int, lexer: Lexer) -> list[Token]:
    """The tokens that start before ``offset`` (the text before it lexed cleanly)."""
    tokens = []
    for token in lexer.tokens(source):
        if token[2] >= offset:
            break
        tokens.append(token)
    return tokens


def _position(source: Source, offset: int) -> str:
    line, column = source.line_col(offset)
    return f"{line}:{column}"


def explain(source: Source, token: Token, expected: list[str], lexer: Lexer) -> ScriptSyntaxError:
    """The syntax error for ``token`` arriving where only ``expected`` kinds could."""
    kind, value, start, end = token
    before = _tokens_before(source, start, lexer)
    previous = before[-1] if before else None
    brackets: list[Token] = []
    blocks: list[Token] = []
    last_closed: tuple[Token, Token] | None = None
    for tok in before:
        if tok[0] in _OPENERS:
            brackets.append(tok)
        elif tok[0] in _CLOSERS and brackets:
            last_closed = (brackets.pop(), tok)
        elif tok[0] in _BLOCK_OPENERS:
            blocks.append(tok)
        elif tok[0] == "END" and blocks:
            blocks.pop()
    line_text = source.line_text(source.line_col(start)[0]).lstrip()
    wanted = _expected_words(expected, lexer)
    hint: str | None = None

    def fail(message: str, hint: str | None = None, at: tuple[int, int] = (start, end)):
        return ScriptSyntaxError.at_offset(source, at[0], at[1], message, hint)

    if kind == "$END":
        if brackets:
            opener = brackets[-1]
            return fail(
                f"the {_BRACKET_NAMES[opener[0]]} opened at {_position(source, opener[2])} "
                f"is never closed",
                f"add '{')' if opener[0] == 'LPAR' else ']'}'",
                (opener[2], opener[3]),
            )
        if blocks:
            opener = blocks[-1]
            return fail(
                f"'{opener[1]}' at {_position(source, opener[2])} is never closed by 'end'",
                "every def, thread, sec, if and while block ends with 'end'",
                (opener[2], opener[3]),
            )
        return fail(f"unexpected end of the file; expected {wanted}")

    described = _describe(kind, value, lexer)
    line_number = source.line_col(start)[0]
    for_token = next(
        (t for t in reversed(before) if t[1] == "for" and t[0] == "NAME"
         and source.line_col(t[2])[0] == line_number),
        None,
    )
    if for_token is not None and line_text.startswith("for"):
        return fail(
            "URScript has no 'for' loop",
            "count with a variable: i = 0 / while i < n: ... i = i + 1 / end",
            (for_token[2], for_token[3]),
        )
    if kind in _CLOSERS:
        if not brackets:
            if last_closed is not None:
                opener = last_closed[0]
                return fail(
                    f"unexpected '{value}': the {_BRACKET_NAMES[opener[0]]} opened at "
                    f"{_position(source, opener[2])} is already closed",
                    f"delete this '{value}'",
                )
            return fail(f"unexpected '{value}': no bracket is open", f"delete this '{value}'")
        opener = brackets[-1]
        closer = ")" if opener[0] == "LPAR" else "]"
        if closer != value:
            return fail(
                f"'{value}' does not close the {_BRACKET_NAMES[opener[0]]} opened at "
                f"{_position(source, opener[2])}",
                f"close it with '{closer}'",
            )
    if kind == "ASSIGN" and previous is not None:
        if previous[0] in ("PLUS", "MINUS", "STAR", "SLASH", "PERCENT"):
            return fail(
                f"URScript has no '{previous[1]}='",
                f"write x = x {previous[1]} value",
                (previous[2], end),
            )
        if "COLON" in expected or "RPAR" in expected or "COMMA" in expected:
            hint = "to compare, write '=='; '=' only assigns"
            if line_text.startswith(("if", "elif", "while")) and "COLON" in expected:
                return fail("'=' in a condition: '=' assigns, it does not compare", hint)
    if (kind == "STRING" and previous is not None and previous[0] == "NAME"
            and previous[3] == start and previous[1].lower() in ("f", "rf", "fr")):
        return fail("URScript has no f-strings",
                    'build the text with str_cat and to_str: str_cat("x = ", to_str(x))',
                    (previous[2], end))
    if (kind == "STRING" and previous is not None and previous[0] == "NAME"
            and previous[3] == start and previous[1].lower() in ("r", "b", "u", "rb", "br")):
        return fail(f"URScript strings have no '{previous[1]}' prefix",
                    "write the string without it: URScript has no escape sequences anyway",
                    (previous[2], end))
    if kind == "STAR" and previous is not None and previous[0] == "STAR":
        return fail("URScript has no '**' operator", "use pow(base, exponent)",
                    (previous[2], end))
    if kind == "IF" and previous is not None and previous[0] == "ELSE":
        return fail("'else if' is written 'elif' in URScript", "write 'elif condition:'",
                    (previous[2], end))
    if kind == "END" and not blocks:
        return fail("'end' without a block to close",
                    "delete it, or check the block above for an extra 'end'")
    if kind == "NAME" and value in ("is", "in", "elseif", "elsif", "then", "do", "pass"):
        hints = {
            "is": "compare with '==' or '!='",
            "in": "URScript has no 'in' operator",
            "elseif": "write 'elif'", "elsif": "write 'elif'",
            "then": "write ':' after the condition", "do": "write ':' after the condition",
            "pass": "an empty block needs no statement",
        }
        return fail(f"'{value}' is not URScript", hints[value])
    if kind == "NAME" and "RPAR" in expected and any(t[0] in ("THREAD", "SEC") for t in
                                                      before[-3:]):
        hint = "threads and sec programs take no parameters; share data through globals"
    if "COLON" in expected and kind != "COLON" and hint is None:
        hint = "a condition or a def line ends with ':'"
    if kind == "COLON" and previous is not None:
        hint = "':' only ends the line of def, thread, sec, if, elif, else and while"
    message = f"unexpected {described}"
    if wanted:
        message += f"; expected {wanted}"
    return fail(message, hint)
