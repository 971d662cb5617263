"""Laws of the language core, checked on generated input.

* print then parse gives back the tree, for random well-formed trees;
* printing is idempotent;
* random and truncated text never crashes the parser: it parses or raises ScriptSyntaxError.
"""

from __future__ import annotations

import keyword as python_keywords

import pytest
from _corpus import corpus_available, corpus_files
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from urdsl import ScriptSyntaxError, format, parse
from urdsl.script.build import binop, literal, unary
from urdsl.script.nodes import (
    Assign,
    Attribute,
    Blank,
    Break,
    Call,
    Comment,
    Continue,
    Declare,
    Elif,
    EnterCritical,
    ExitCritical,
    ExprStmt,
    FunctionDef,
    Halt,
    If,
    Index,
    Join,
    Keyword,
    Kill,
    List,
    Marker,
    Module,
    Name,
    Number,
    Param,
    Paren,
    Pose,
    Return,
    Run,
    SecDef,
    String,
    ThreadDef,
    While,
    precedence,
)
from urdsl.script.parser import _default_parser

URSCRIPT_KEYWORDS = set(_default_parser().lexer.keywords)
SETTINGS = settings(max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])

names = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,8}", fullmatch=True).filter(
    lambda n: n not in URSCRIPT_KEYWORDS and not python_keywords.iskeyword(n) or n == "p"
)
numbers = st.one_of(
    st.integers(min_value=0, max_value=2**31 - 1),
    st.floats(min_value=0, max_value=1e12, allow_nan=False, allow_infinity=False),
    st.floats(min_value=0, max_value=1e-3, allow_nan=False, allow_infinity=False),
).map(Number)
strings = st.text(
    st.characters(blacklist_categories=("Cs", "Cc"), blacklist_characters="\"\r\n\x85\u2028\u2029"),
    max_size=12,
).map(String)
atoms = st.one_of(
    numbers, strings, names.map(Name),
    st.sampled_from([True, False, None]).map(literal),
    names.map(Run),
)


def postfix_base(expr):
    """An expression fit to stand before '(' '[' '.': atoms as they are, others in parens."""
    if precedence(expr) == 8 and not isinstance(expr, Number):
        return expr
    return Paren(expr)


def extend(children):
    binary = st.builds(binop, st.sampled_from(
        ["or", "xor", "and", "==", "!=", "<", ">", "<=", ">=", "+", "-", "*", "/", "%"]),
        children, children)
    prefix = st.builds(unary, st.sampled_from(["-", "+", "not", "!"]), children)
    keywords = st.lists(st.tuples(names, children), max_size=3,
                        unique_by=lambda kv: kv[0]).map(
        lambda kvs: tuple(Keyword(k, v) for k, v in kvs))
    call = st.builds(
        Call,
        st.one_of(names.map(Name), st.builds(Attribute, children.map(postfix_base), names)),
        st.lists(children, max_size=3).map(tuple), keywords,
    )
    return st.one_of(
        binary, prefix, call,
        st.builds(Index, children.map(postfix_base), st.lists(children, min_size=1,
                                                              max_size=2).map(tuple)),
        st.builds(Attribute, children.map(postfix_base), names),
        st.lists(children, max_size=4).map(lambda items: List(tuple(items))),
        st.lists(children, min_size=6, max_size=6).map(lambda items: Pose(tuple(items))),
        children.map(Paren),
    )


expressions = st.recursive(atoms, extend, max_leaves=12)
calls = expressions.filter(lambda e: isinstance(e, Call))
targets = st.one_of(
    names.map(Name),
    st.builds(Index, names.map(Name), st.lists(expressions, min_size=1, max_size=2).map(tuple)),
    st.builds(Attribute, names.map(Name), names),
)
comment_text = st.text(
    st.characters(blacklist_categories=("Cs", "Cc", "Zl", "Zp")), max_size=15
).map(str.rstrip)
simple_statements = st.one_of(
    st.builds(Assign, targets, expressions),
    st.builds(ExprStmt, st.builds(Call, names.map(Name), st.lists(expressions, max_size=2)
                                  .map(tuple))),
    st.builds(Declare, st.sampled_from(["global", "local"]), names,
              st.one_of(st.none(), expressions)),
    st.builds(Return, expressions),
    st.sampled_from([Halt(), Break(), Continue(), EnterCritical(), ExitCritical()]),
    st.builds(Join, names.map(Name)), st.builds(Kill, names.map(Name)),
    st.builds(Marker, st.integers(0, 999), st.text(
        st.characters(blacklist_categories=("Cs", "Cc", "Zl", "Zp"), blacklist_characters='"'),
        max_size=10), st.one_of(st.none(), st.sampled_from(["breakAfter", "noBreak"]))),
)


def blocks(statements):
    """A block: statements with comments and blank lines placed as the parser keeps them."""
    items = st.lists(st.one_of(statements, comment_text.map(Comment)), max_size=5)

    def arrange(parts):
        out = []
        for index, part in enumerate(parts):
            if out and index % 3 == 2 and not isinstance(out[-1], Blank):
                out.append(Blank())
            out.append(part)
            if isinstance(part, Assign) and index % 2:
                out.append(Comment(" trailing", trailing=True))
        while out and isinstance(out[-1], Blank):
            out.pop()
        return tuple(out)

    return items.map(arrange)


def compound(statements):
    block = blocks(statements)
    return st.one_of(
        st.builds(If, expressions, block, st.lists(st.builds(Elif, expressions, block),
                                                   max_size=2).map(tuple),
                  st.one_of(st.none(), block)),
        st.builds(While, expressions, block),
        st.builds(FunctionDef, names, st.lists(st.builds(Param, names, st.one_of(
            st.none(), expressions)), max_size=3, unique_by=lambda p: p.name).map(tuple), block),
        st.builds(ThreadDef, names, block),
        st.builds(SecDef, names, block),
    )


statements = st.recursive(simple_statements, compound, max_leaves=8)
modules = blocks(statements).map(Module)


@SETTINGS
@given(modules)
def test_print_then_parse_gives_the_same_tree(module):
    text = format(module)
    assert parse(text) == module, text


@SETTINGS
@given(expressions)
def test_expressions_round_trip(expression):
    text = format(expression)
    assert parse(f"x = {text}").body[0].value == expression, text


@SETTINGS
@given(modules)
def test_printing_is_idempotent(module):
    once = format(module)
    assert format(parse(once)) == once


# ---- fuzzing: reject, never crash or hang -------------------------------------------------

FRAGMENTS = [
    "def", "end", "if", "elif", "else", "while", "thread", "sec", "run", "join", "kill",
    "global", "local", "return", "halt", "not", "and", "or", "True", "None", "p[", "[", "]",
    "(", ")", ",", ":", ".", "=", "==", "-", "+", "*", "/", "%", "!", "#c\n", "$ 1 \"x\"\n",
    "\n", " ", "\t", "\r\n", "x", "movej", "1.5", ".5", "1e-3", '"s"', "'t'", "{", ";", "\\",
]


def parses_or_rejects(text: str) -> None:
    try:
        tree = parse(text)
    except ScriptSyntaxError as error:
        assert error.line >= 1 and error.column >= 1
        assert str(error)
        return
    format(tree)  # whatever parses can be printed


@settings(max_examples=400, deadline=None)
@given(st.lists(st.sampled_from(FRAGMENTS), max_size=40).map(" ".join))
def test_random_token_soup(text):
    parses_or_rejects(text)


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=200).map(lambda b: b.decode("latin-1")))
def test_random_bytes(text):
    parses_or_rejects(text)


CORPUS_TEXTS = (
    [f.text() for f in corpus_files() if not f.templated] if corpus_available() else ["x = 1"]
)


@pytest.mark.skipif(not corpus_available(), reason="corpus not found (set URDSL_CORPUS)")
@settings(max_examples=150, deadline=None)
@given(st.sampled_from(CORPUS_TEXTS), st.floats(0, 1), st.floats(0, 1))
def test_truncated_and_spliced_corpus(text, cut, splice):
    prefix = text[: int(len(text) * cut)]
    parses_or_rejects(prefix)
    parses_or_rejects(prefix + text[int(len(text) * splice):])
