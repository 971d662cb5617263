"""The URScript parser: text in, :class:`~urdsl.script.nodes.Module` out.

Lark compiles ``grammar/urscript.lark`` into LALR(1) tables. :class:`Parser` drives those
tables itself with the tokens of :class:`~urdsl.script.lexer.Lexer` and calls one small
builder per grammar rule (named by the rule's alias), so the syntax tree is built directly,
with no parse tree in between and no per-token objects beyond plain tuples. This is what makes
parsing large generated programs fast (see ``bench/parse_bench.py``).

Comments, blank lines and ``$`` labels are tokens that the grammar accepts wherever a
statement may stand. Where one appears elsewhere (a comment inside a call spread over several
lines, say), the parser sets it aside and afterwards puts it in front of the statement it was
written in, so nothing written is lost.
"""

from __future__ import annotations

import bisect
import functools
import itertools
import math
import re
import sys
from collections.abc import Generator
from dataclasses import replace
from importlib import resources
from typing import Any

from .._gc import gc_paused
from .diagnostics import ScriptSyntaxError
from .lexer import Lexer, Token
from .nodes import (
    BINARY_PRECEDENCE,
    PREFIX_PRECEDENCE,
    Assign,
    Attribute,
    BinOp,
    Blank,
    Bool,
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
    Node,
    NoneLit,
    Number,
    Param,
    Paren,
    Pose,
    Return,
    Run,
    SecDef,
    Source,
    Span,
    String,
    ThreadDef,
    UnaryOp,
    While,
)

__all__ = ["Parser", "parse", "grammar_text"]

_span = functools.partial(tuple.__new__, Span)
"""``_span((source, start, end))``: a :class:`Span` made at C speed."""


def grammar_text() -> str:
    """The text of ``grammar/urscript.lark`` (shipped as package data ``urdsl.grammar``)."""
    return resources.files("urdsl.grammar").joinpath("urscript.lark").read_text("utf-8")


_FLOAT_MAX = int(sys.float_info.max)
"""The largest float as an int: int literals above it have no float value."""

# Prefix operators that bind looser than comparisons (see _Builder.resolve).
_LOOSE_PREFIX = frozenset(("not", "!"))


# Tokens that may stand between statements; elsewhere they are set aside (see module doc).
_LAYOUT = frozenset(("COMMENT", "BLANK"))

_MARKER = re.compile(r"\$\s*(\d+)\s*(?:\"([^\"]*)\"\s*(?:\"([^\"]*)\")?\s*|(.*?))\s*$")


class _Builder:
    """One method per grammar alias; each takes the rule's children and returns a node.

    Children are tokens ``(type, value, start, end)`` and the values of sub-rules, in the
    order the rule writes them.
    """

    def __init__(self, source: Source) -> None:
        self.src = source

    # -- helpers -----------------------------------------------------------------------------

    def span(self, start: int, end: int) -> Span:
        return _span((self.src, start, end))

    @staticmethod
    def start_of(value: Any) -> int:
        return value[2] if type(value) is tuple else value.span.start

    @staticmethod
    def end_of(value: Any) -> int:
        return value[3] if type(value) is tuple else value.span.end

    def error(self, start: int, end: int, message: str, hint: str | None = None) -> None:
        raise ScriptSyntaxError.at_offset(self.src, start, end, message, hint)

    @staticmethod
    def strip_blanks(items: list) -> tuple:
        begin, end = 0, len(items)
        while begin < end and type(items[begin]) is Blank:
            begin += 1
        while end > begin and type(items[end - 1]) is Blank:
            end -= 1
        return tuple(items[begin:end])

    # -- blocks ------------------------------------------------------------------------------

    def start(self, s: list) -> Module:
        return Module(self.strip_blanks(s[0]), self.span(0, len(self.src.text)))

    def block_empty(self, s: list) -> list:
        return []

    def block_add(self, s: list) -> list:
        block = s[0]
        block.append(s[1])
        return block

    def comment(self, s: list) -> Comment:
        _, (text, trailing), start, end = s[0]
        return Comment(text, trailing, _span((self.src, start, end)))

    def blank(self, s: list) -> Blank:
        return Blank(_span((self.src, s[0][2], s[0][3])))

    def marker(self, s: list) -> Marker:
        _, text, start, end = s[0]
        span = _span((self.src, start, end))
        match = _MARKER.match(text)
        if match is None:
            return Marker(None, text[1:].strip(), None, False, span)
        number, label, flag, bare = match.groups()
        if label is not None:
            return Marker(int(number), label, flag, True, span)
        return Marker(int(number), bare, None, False, span)

    # -- simple statements -------------------------------------------------------------------

    def assign(self, s: list) -> Assign:
        target, _, value = s
        if type(target) not in (Name, Index, Attribute):
            what = "a call" if type(target) is Call else "this expression"
            self.error(
                target.span.start, target.span.end, f"cannot assign to {what}",
                "the left of '=' must be a name, an element a[i] or a field s.f; "
                "to compare, write '=='",
            )
        return Assign(target, value, _span((self.src, target.span.start, value.span.end)))

    def expr_stmt(self, s: list) -> ExprStmt:
        expr = s[0]
        return ExprStmt(expr, expr.span)

    def declare(self, s: list) -> Declare:
        scope, name = s[0], s[1]
        if len(s) == 2:
            return Declare(scope[1], name[1], None, _span((self.src, scope[2], name[3])))
        value = s[3]
        return Declare(scope[1], name[1], value, _span((self.src, scope[2], value.span.end)))

    def return_stmt(self, s: list) -> Return:
        keyword = s[0]
        if len(s) == 1:
            return Return(None, _span((self.src, keyword[2], keyword[3])))
        return Return(s[1], _span((self.src, keyword[2], s[1].span.end)))

    def halt(self, s: list) -> Halt:
        return Halt(_span((self.src, s[0][2], s[0][3])))

    def break_stmt(self, s: list) -> Break:
        return Break(_span((self.src, s[0][2], s[0][3])))

    def continue_stmt(self, s: list) -> Continue:
        return Continue(_span((self.src, s[0][2], s[0][3])))

    def enter_critical(self, s: list) -> EnterCritical:
        return EnterCritical(_span((self.src, s[0][2], s[0][3])))

    def exit_critical(self, s: list) -> ExitCritical:
        return ExitCritical(_span((self.src, s[0][2], s[0][3])))

    def join(self, s: list) -> Join:
        return Join(s[1], _span((self.src, s[0][2], s[1].span.end)))

    def kill(self, s: list) -> Kill:
        return Kill(s[1], _span((self.src, s[0][2], s[1].span.end)))

    # -- compound statements -----------------------------------------------------------------

    def function_def(self, s: list) -> FunctionDef:
        params = tuple(s[3]) if len(s) == 8 else ()
        seen: set[str] = set()
        for param in params:
            if param.name in seen:
                self.error(
                    param.span.start, param.span.end, f"parameter {param.name!r} appears twice"
                )
            seen.add(param.name)
        return FunctionDef(
            s[1][1], params, self.strip_blanks(s[-2]), _span((self.src, s[0][2], s[-1][3]))
        )

    def thread_def(self, s: list) -> ThreadDef:
        return ThreadDef(s[1][1], self.strip_blanks(s[5]), _span((self.src, s[0][2], s[6][3])))

    def sec_def(self, s: list) -> SecDef:
        return SecDef(s[1][1], self.strip_blanks(s[5]), _span((self.src, s[0][2], s[6][3])))

    def if_stmt(self, s: list) -> If:
        orelse = self.strip_blanks(s[7]) if len(s) == 9 else None
        return If(
            s[1], self.strip_blanks(s[3]), tuple(s[4]), orelse,
            _span((self.src, s[0][2], s[-1][3])),
        )

    def elifs_empty(self, s: list) -> list:
        return []

    def elifs_add(self, s: list) -> list:
        elifs, keyword, test, colon, body = s
        end = body[-1].span.end if body else colon[3]
        elifs.append(Elif(test, self.strip_blanks(body), _span((self.src, keyword[2], end))))
        return elifs

    def while_stmt(self, s: list) -> While:
        return While(s[1], self.strip_blanks(s[3]), _span((self.src, s[0][2], s[4][3])))

    def list_new(self, s: list) -> list:
        return [s[0]]

    def list_add(self, s: list) -> list:
        items = s[0]
        items.append(s[2])
        return items

    def param(self, s: list) -> Param:
        name = s[0]
        if len(s) == 1:
            return Param(name[1], None, _span((self.src, name[2], name[3])))
        return Param(name[1], s[2], _span((self.src, name[2], s[2].span.end)))

    # -- expressions -------------------------------------------------------------------------

    def expr(self, s: list) -> Any:
        return self.resolve(s[0])

    def seq_pair(self, s: list) -> list:
        return s

    def seq_add(self, s: list) -> list:
        items = s[0]
        items.append(s[1])
        items.append(s[2])
        return items

    def unary(self, s: list) -> UnaryOp:
        op, operand = s
        return UnaryOp(op[1], operand, _span((self.src, op[2], operand.span.end)))

    def resolve(self, items: list) -> Any:
        """Operator precedence over a flat ``operand op operand ...`` sequence; all binary
        operators are left-associative. ``not x`` was built before its right neighbours were
        known: here it takes the comparison (or sum, product) that follows ``x`` under it,
        since ``not`` binds looser than those."""
        src = self.src
        count = len(items)
        position = 0

        def climb(min_precedence: int) -> Any:
            nonlocal position
            item = items[position]
            if type(item) is UnaryOp and item.op in _LOOSE_PREFIX:
                items[position] = item.operand
                operand = climb(PREFIX_PRECEDENCE[item.op])
                left = UnaryOp(item.op, operand, _span((src, item.span.start, operand.span.end)))
            else:
                left = item
                position += 1
            while position < count:
                op = items[position][1]
                strength = BINARY_PRECEDENCE[op]
                if strength < min_precedence:
                    break
                position += 1
                right = climb(strength + 1)
                left = BinOp(op, left, right, _span((src, left.span.start, right.span.end)))
            return left

        return climb(0)

    def call(self, s: list) -> Call:
        func = s[0]
        if type(func) not in (Name, Attribute):
            self.error(
                s[1][2], s[1][3], "only a function or a method can be called",
                "put an operator or a line break between two expressions",
            )
        positional: list = []
        keywords: list = []
        if len(s) == 4:
            for arg in s[2]:
                if type(arg) is Keyword:
                    if keywords and arg.name in {k.name for k in keywords}:
                        self.error(
                            arg.span.start, arg.span.end,
                            f"keyword argument {arg.name!r} given twice",
                        )
                    keywords.append(arg)
                elif keywords:
                    self.error(
                        arg.span.start, arg.span.end,
                        "positional argument after a keyword argument",
                        "give positional arguments first, then name=value arguments",
                    )
                else:
                    positional.append(arg)
        return Call(func, tuple(positional), tuple(keywords), _span((self.src, func.span.start,
                                                                   s[-1][3])))

    def keyword(self, s: list) -> Keyword:
        name, _, value = s
        return Keyword(name[1], value, _span((self.src, name[2], value.span.end)))

    def index(self, s: list) -> Index:
        value, bracket, indices, close = s
        if len(indices) > 2:
            self.error(
                indices[2].span.start, close[2], "too many indices",
                "a list takes a[i], a matrix m[i, j]",
            )
        return Index(value, tuple(indices), _span((self.src, value.span.start, close[3])))

    def attribute(self, s: list) -> Attribute:
        value, _, name = s
        return Attribute(value, name[1], _span((self.src, value.span.start, name[3])))

    def name(self, s: list) -> Name:
        _, value, start, end = s[0]
        return Name(value, _span((self.src, start, end)))

    def number(self, s: list) -> Number:
        _, text, start, end = s[0]
        value: int | float
        if text.isdigit():
            # an int must fit a float too (the tools compute with it as one); past 400
            # digits int() is slow, and refuses 4,300
            value = int(text) if len(text.lstrip("0")) <= 400 else math.inf
            if value != math.inf and value > _FLOAT_MAX:
                value = math.inf
        else:
            value = float(text)
        if value == math.inf:
            shown = text if len(text) <= 30 else f"{text[:12]}... ({len(text)} characters)"
            self.error(start, end, f"{shown} is larger than the largest number a controller "
                       "float holds (about 1.8e308)", "write a smaller number")
        return Number(value, _span((self.src, start, end)))

    def string(self, s: list) -> String:
        _, text, start, end = s[0]
        return String(text[1:-1], _span((self.src, start, end)))

    def true(self, s: list) -> Bool:
        return Bool(True, _span((self.src, s[0][2], s[0][3])))

    def false(self, s: list) -> Bool:
        return Bool(False, _span((self.src, s[0][2], s[0][3])))

    def none(self, s: list) -> NoneLit:
        return NoneLit(_span((self.src, s[0][2], s[0][3])))

    def pose(self, s: list) -> Pose | Index:
        """``p[...]``: six values make a pose literal; one or two are an element of a
        variable called ``p`` (ur_rtde's control script writes ``p[0] = p[0] * factor``)."""
        opener, items, close = s
        if len(items) == 6:
            return Pose(tuple(items), _span((self.src, opener[2], close[3])))
        if len(items) <= 2:
            name = Name("p", _span((self.src, opener[2], opener[2] + 1)))
            return Index(name, tuple(items), _span((self.src, opener[2], close[3])))
        self.error(
            opener[2], close[3],
            f"a pose has 6 values (x, y, z, rx, ry, rz); this one has {len(items)}",
            "positions in metres, then the rotation vector in radians",
        )

    def list_lit(self, s: list) -> List:
        items = tuple(s[1]) if len(s) == 3 else ()
        return List(items, _span((self.src, s[0][2], s[-1][3])))

    def paren(self, s: list) -> Paren:
        return Paren(s[1], _span((self.src, s[0][2], s[2][3])))

    def run(self, s: list) -> Run:
        return Run(s[1][1], _span((self.src, s[0][2], s[3][3])))


class Parser:
    """A URScript parser. Build one (or use :func:`parse`, which keeps one) and call
    :meth:`parse` as often as needed; it holds no per-parse state."""

    def __init__(self) -> None:
        from lark import Lark
        from lark.parsers.lalr_analysis import Shift

        grammar = Lark(grammar_text(), parser="lalr", lexer="basic")
        self.lexer = Lexer(grammar)
        table = grammar.parser.parser.parser.parse_table
        self.start_state = table.start_states["start"]
        self.terminals = {t.name for t in grammar.terminals} | {"BLANK", "$END"}
        # actions[state][terminal]: an int is "shift to that state"; a str is "reduce a
        # one-child rule that passes its child up (`?rule`), then go to gotos[state][str]";
        # a tuple is "reduce (size, builder function, rule name)".
        # gotos[state][rule name]: the state after reducing to that rule.
        self.actions: dict[int, dict[str, Any]] = {}
        self.gotos: dict[int, dict[str, int]] = {}
        # (state below, top state, token kind) -> state after a chain of `?rule` reductions
        self.chains: dict[tuple[int, int, str], int] = {}
        for state, entries in table.states.items():
            actions: dict[str, Any] = {}
            gotos: dict[str, int] = {}
            for symbol, (action, arg) in entries.items():
                # Lark's names are str subclasses with a slow __eq__: keep plain strings.
                symbol = str(symbol)
                if symbol.isupper() or symbol == "$END":
                    if action is Shift:
                        actions[symbol] = arg
                        continue
                    rule = str(arg.origin.name)
                    if arg.alias is None and arg.options.expand1 and len(arg.expansion) == 1:
                        actions[symbol] = rule
                        continue
                    function = getattr(_Builder, str(arg.alias or rule), None)
                    if function is None:  # pragma: no cover - grammar and builder disagree
                        raise ValueError(f"no builder for grammar rule {arg}")
                    actions[symbol] = (len(arg.expansion), function, rule)
                else:
                    gotos[symbol] = arg
            self.actions[state] = actions
            self.gotos[state] = gotos

    def parse(self, text: str, filename: str = "<string>") -> Module:
        """Parse URScript ``text``; ``filename`` is used in messages.

        Raises :class:`~urdsl.script.diagnostics.ScriptSyntaxError` (with line, column and a
        hint) when the text is not URScript.
        """
        # The tree is acyclic and the parser makes no cycles: pausing the cyclic garbage
        # collector, which would otherwise rescan the growing tree again and again, makes
        # large files parse about a third faster.
        with gc_paused():
            return self._parse(text, filename)

    def _parse(self, text: str, filename: str) -> Module:
        source = Source(text, filename)
        builder = _Builder(source)
        set_aside: list[Token] = []
        actions = self.actions
        gotos = self.gotos
        chains = self.chains
        stack = [self.start_state]
        values: list[Any] = []
        push_state = stack.append
        push_value = values.append
        end_token: Token = ("$END", "", len(text), len(text))
        for token in itertools.chain(self.lexer.tokens(source), (end_token,)):
            kind = token[0]
            if kind in _LAYOUT and not self._accepts(stack, kind):
                if kind == "COMMENT":
                    set_aside.append(token)
                continue
            while True:
                try:
                    action = actions[stack[-1]][kind]
                except KeyError:
                    raise self._syntax_error(source, stack, token) from None
                kind_of_action = type(action)
                if kind_of_action is int:
                    push_state(action)
                    push_value(token)
                    break
                if kind_of_action is str:  # `?rule` passing its only child up
                    # A chain of such reductions pops and pushes one state each, so where
                    # it ends depends only on the state below, the top state and the token.
                    key = (stack[-2], stack[-1], kind)
                    target = chains.get(key)
                    if target is None:
                        target = chains[key] = self._unit_chain(stack[-2], action, kind)
                    stack[-1] = target
                    continue
                size, function, rule = action
                if size:
                    children = values[-size:]
                    del values[-size:]
                    del stack[-size:]
                else:
                    children = []
                push_value(function(builder, children))
                if rule == "start":
                    module = values[-1]
                    if set_aside:
                        module = _place_comments(module, set_aside, source)
                    return module
                push_state(gotos[stack[-1]][rule])
        raise AssertionError("parser ran past the end of input")  # pragma: no cover

    def _unit_chain(self, below: int, rule: str, kind: str) -> int:
        """The state reached by reducing ``rule`` (a one-child ``?rule``) over ``below`` and
        every one-child reduction that lookahead ``kind`` triggers after it."""
        state = self.gotos[below][rule]
        while type(action := self.actions[state].get(kind)) is str:
            state = self.gotos[below][action]
        return state

    def _accepts(self, stack: list[int], kind: str) -> bool:
        """Whether ``kind`` can be shifted after the reductions it would trigger (simulated
        with no tree building, and without copying ``stack``: a comment deep in nested blocks
        costs what one at the top does)."""
        actions = self.actions
        gotos = self.gotos
        kept = len(stack)  # stack[:kept] is still below the simulated states
        pushed: list[int] = []  # the simulated states above stack[:kept]
        while True:
            action = actions[pushed[-1] if pushed else stack[kept - 1]].get(kind)
            if action is None:
                return False
            if type(action) is int:
                return True
            if type(action) is str:  # `?rule` passing its child up: replace the top state
                size, rule = 1, action
            else:
                size, _, rule = action
            from_pushed = min(size, len(pushed))
            del pushed[len(pushed) - from_pushed:]
            kept -= size - from_pushed
            pushed.append(gotos[pushed[-1] if pushed else stack[kept - 1]][rule])

    def _syntax_error(self, source: Source, stack: list[int], token: Token) -> ScriptSyntaxError:
        from .errors import explain

        expected = sorted(
            name for name in self.actions[stack[-1]] if name in self.terminals
        )
        return explain(source, token, expected, self.lexer)


def _place_comments(module: Module, comments: list[Token], source: Source) -> Module:
    """Put comments that stood inside a statement in front of that statement, in the
    innermost block that holds it.

    Blocks nest as deep as the program does, so the walk keeps its own stack (generators
    driven by :func:`_trampoline`) instead of recursing; each comment is found by bisection
    and taken once, so many comments in a large file cost no more than a few in a small one.
    """
    pending = sorted(comments, key=lambda token: token[2])
    offsets = [token[2] for token in pending]
    count = len(pending)
    # after[i]: a comment index >= i that may still be pending; count when none is
    # (a "next pending" chain with path compression, so taken comments are skipped at once)
    after = list(range(count + 1))

    def first_pending(index: int) -> int:
        root = index
        while after[root] != root:
            root = after[root]
        while after[index] != root:
            after[index], index = root, after[index]
        return root

    def has_pending(start: int, end: int) -> bool:
        index = first_pending(bisect.bisect_left(offsets, start))
        return index < count and offsets[index] < end

    def place(items: tuple) -> Generator[Any, Any, tuple]:
        result: list = []
        for item in items:
            start, end = item.span.start, item.span.end
            if has_pending(start, end):
                item = yield descend(item)
                index = first_pending(bisect.bisect_left(offsets, start))
                while index < count and offsets[index] < end:
                    _, (text, _trailing), c_start, c_end = pending[index]
                    result.append(Comment(text, False, Span(source, c_start, c_end)))
                    after[index] = index + 1
                    index = first_pending(index + 1)
            result.append(item)
        return tuple(result)

    def descend(item: Node) -> Generator[Any, Any, Node]:
        if isinstance(item, (FunctionDef, ThreadDef, SecDef, While, Elif)):
            return replace(item, body=(yield place(item.body)))
        if isinstance(item, If):
            body = yield place(item.body)
            elifs = []
            for branch in item.elifs:
                elifs.append((yield descend(branch)))
            orelse = None if item.orelse is None else (yield place(item.orelse))
            return replace(item, body=body, elifs=tuple(elifs), orelse=orelse)
        return item

    return Module(_trampoline(place(module.body)), module.span)


def _trampoline(work: Generator[Any, Any, Any]) -> Any:
    """Run a generator that yields the sub-generators whose results it needs (sent back to
    it), with an explicit stack instead of Python recursion; return its result."""
    stack = [work]
    value: Any = None
    while stack:
        try:
            stack.append(stack[-1].send(value))
            value = None
        except StopIteration as done:
            stack.pop()
            value = done.value
    return value


@functools.cache
def _default_parser() -> Parser:
    return Parser()


def keywords() -> frozenset[str]:
    """The words of the language (``def``, ``while``, ``True``, ...), as the grammar has them:
    no name may be one."""
    return frozenset(_default_parser().lexer.keywords)


def parse(text: str, filename: str = "<string>") -> Module:
    """Parse URScript text into a :class:`~urdsl.script.nodes.Module`.

    >>> parse("movej([0, -1.57, 0, -1.57, 0, 0], a=1.4)").body[0].expr.func.id
    'movej'
    """
    return _default_parser().parse(text, filename)
