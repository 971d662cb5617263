"""The builtin catalog: every URScript builtin of every UR controller generation with its
parameters, defaults, return type, controller versions and deprecation.

This is the one source that the linter, the DSL and the interpreter read. The data is
``builtins.tsv`` (package data): tab-separated, one header line, columns ``module``,
``name``, ``params_with_defaults`` (``name=default``, ``[name]`` optional without a stated
default, ``...`` any ``name=value``, ``-`` not callable), ``returns``, ``since_version``,
``deprecated``, ``replaced_by`` and ``remarks`` (the row's source; ``[S]`` one public source,
``[U]`` unconfirmed, ``[X]`` UR's own scripts; unmarked rows follow the e-Series/PolyScope X
manuals)::

    >>> from urdsl.script.builtins import catalog
    >>> movej = catalog()["movej"]
    >>> [(p.name, p.default) for p in movej.params]
    [('q', None), ('a', '1.4'), ('v', '1.05'), ('t', '0'), ('r', '0')]
    >>> movej.available_in("5.15"), catalog()["get_euromap_input"].available_in("5.15")
    (True, False)

A builtin may have several signature rows (the same name on several lines): the first is the
current one, the others are :attr:`Builtin.variants`, each with the versions it applies to.
``since_version`` is the first version (``5.15``, ``3.14/5.9`` per series, ``doc<=2020``
documented in the 2020-era manual, ``<=5.15`` documented by then, ``1.x``/``3.x`` CB-era,
``5.x`` e-Series, ``10.x`` PolyScope X, ``~`` approximate, ``?`` unknown), optionally followed
by ``..last`` for the last version the row applies to (``1.x..3.x``: CB2 and CB3 only)::

    >>> [row.signature for row in (catalog()["speedj"], *catalog()["speedj"].variants)]
    ['speedj(qd, a, [t])', 'speedj(qd, a, [t_min])']

Versions are PolyScope software versions: 1.x CB2, 3.x CB3 (together the CB-Series), 5.x
e-Series, 10.x and later PolyScope X.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from importlib import resources

from ..versions import ControllerVersion, parse_version
from .binder import Binding, Problem, Signature, problems

__all__ = ["BLOCKING_CALLS", "MOTION_CALLS", "BuiltinParam", "Builtin", "catalog", "lookup",
           "parse_version", "method", "methods"]

Version = tuple[int, int]

MOTION_CALLS = frozenset((
    "movej", "movel", "movep", "movec", "optimovej", "optimovel", "servoj", "servoc", "speedj",
    "speedl", "stopj", "stopl", "direct_torque", "mc_run_motion", "screw_driving",
))
"""Builtins that move the arm and take physical time (one frame at least)."""

BLOCKING_CALLS = MOTION_CALLS | frozenset((
    "sleep", "sync", "socket_read_ascii_float", "socket_read_binary_integer",
    "socket_read_byte_list", "socket_read_line", "socket_read_string", "socket_get_var",
    "socket_open", "interpreter_mode", "popup", "request_boolean_from_primary_client",
    "request_float_from_primary_client", "request_integer_from_primary_client",
    "request_string_from_primary_client", "tool_contact", "zero_ftsensor", "powerdown",
))
"""Builtins that take physical time, so that a loop calling them yields to other threads
(moves, ``sleep``, ``sync``, socket reads that wait for data, blocking popups)."""


def _series(version: Version) -> str:
    return ControllerVersion(*version).series


@dataclass(frozen=True)
class BuiltinParam:
    """A builtin's parameter. ``default`` is the default as URScript text (``None`` when the
    parameter has none); ``optional`` is true when the argument may be left out."""

    name: str
    default: str | None = None
    optional: bool = False


@dataclass(frozen=True)
class Builtin:
    """One row of the catalog (``docs/controller-facts.md`` §9 gives the meaning of each
    field)."""

    module: str
    name: str
    params: tuple[BuiltinParam, ...]
    returns: tuple[str, ...]
    since: str
    deprecated: bool
    replaced_by: tuple[str, ...]
    remarks: str
    callable: bool = True
    variadic_keywords: bool = False
    variants: tuple[Builtin, ...] = ()
    _bound: dict = field(default_factory=dict, init=False, compare=False, hash=False, repr=False)

    @property
    def min_args(self) -> int:
        """How many arguments a call needs at least."""
        return sum(1 for p in self.params if not p.optional)

    @property
    def max_args(self) -> int:
        """How many positional arguments a call may give at most."""
        return len(self.params)

    @property
    def is_method(self) -> bool:
        """A method of lists or RPC handles (``list.append``), not a free function."""
        return "." in self.name

    @property
    def confirmed(self) -> bool:
        """False when the catalog marks this row unconfirmed ([U], ``~`` or ``?``)."""
        return not (self.remarks.startswith("[U]") or self.since.startswith(("~", "?")))

    @property
    def signature(self) -> str:
        """``movej(q, a=1.4, v=1.05, t=0, r=0)``."""
        parts = []
        for p in self.params:
            if p.default is not None:
                parts.append(f"{p.name}={p.default}")
            elif p.optional:
                parts.append(f"[{p.name}]")
            else:
                parts.append(p.name)
        if self.variadic_keywords:
            parts.append("name=value, ...")
        return f"{self.name}({', '.join(parts)})"

    def param(self, name: str) -> BuiltinParam | None:
        """The parameter called ``name``, if there is one."""
        return next((p for p in self.params if p.name == name), None)

    @functools.cached_property
    def call_signature(self) -> Signature:
        """This row's parameters as the call binder sees them."""
        return Signature(self.name, tuple(p.name for p in self.params),
                         tuple(not p.optional for p in self.params), self.variadic_keywords,
                         self.signature)

    def rows(self, version: Version | None = None) -> tuple[Builtin, ...]:
        """The signature rows of this builtin that apply to controller ``version``: all of
        them without a version (code valid on SOME controller is accepted); with one, the
        rows not known to be absent there (all rows again when none is left, so that an
        unavailable builtin is reported once, as not available, not as a bad call)."""
        every = (self, *self.variants)
        if version is None or not self.variants:
            return every
        fitting = tuple(row for row in every if row.row_available_in(version) is not False)
        return fitting or every

    def bind(self, positional: int, keywords: Sequence[str],
             version: Version | None = None) -> tuple[Builtin, Binding] | Problem:
        """Bind a call giving ``positional`` arguments and the ``keywords`` names: the first
        applicable signature row that fits and its binding, or the problem of the first
        applicable row (see :meth:`rows`). A call site is bound once (cached per shape)."""
        keywords = tuple(keywords)
        key = (positional, keywords, version)
        cached = self._bound.get(key)
        if cached is not None:
            return cached
        rows = self.rows(version)
        result: tuple[Builtin, Binding] | Problem | None = None
        for row in rows:
            binding = row.call_signature.bind(positional, keywords)
            if isinstance(binding, Binding):
                result = (row, binding)
                break
        if result is None:
            result = rows[0].call_signature.bind(positional, keywords)
        self._bound[key] = result
        return result

    def call_problems(self, positional: int, keywords: Sequence[str],
                      version: Version | None = None) -> list[Problem]:
        """Every mistake of a call (for the linter); empty when one applicable signature row
        fits. The mistakes are those against the first applicable row (:meth:`rows`)."""
        if isinstance(self.bind(positional, keywords, version), Problem):
            return problems(self.rows(version)[0].call_signature, positional, keywords)
        return []

    def argument_problem(self, positional: int, keywords: Sequence[str],
                         version: Version | None = None) -> Problem | None:
        """What is wrong with a call giving ``positional`` arguments and the ``keywords``
        names (see :mod:`urdsl.script.binder`); None when it fits one applicable row."""
        result = self.bind(positional, keywords, version)
        return result if isinstance(result, Problem) else None

    @property
    def since_first(self) -> str:
        """The ``since`` column without its ``..last`` part: when the row starts to apply."""
        return self.since.split("..", 1)[0]

    @property
    def last(self) -> Version | None:
        """The last controller version this signature row applies to (``since`` written
        ``first..last``; ``3.x`` as last means "to the end of the CB-Series"); None when the
        row has no end."""
        if ".." not in self.since:
            return None
        text = self.since.split("..", 1)[1].strip().lstrip("~")
        if text.endswith(".x"):
            return int(text[:-2]), 999
        return parse_version(text)

    def first_versions(self) -> dict[str, Version | None]:
        """First version per series (``"cb"``, ``"e"``, ``"x"``) that has this row;
        a series missing from the dict does not have it; ``None`` means "from the first
        version we know of". CB2 (1.x) and CB3 (3.x) are the one CB series."""
        since = self.since_first.lstrip("~")
        if since.startswith("doc"):  # documented in the 2020-era (or 2022-23) manuals
            return {"cb": None, "e": None if "2020" in since else (5, 11), "x": None}
        if since.startswith("<="):
            result: dict[str, Version | None] = dict.fromkeys(self._seen_by(), None)
            if "e" in result:
                result["x"] = None
            return result
        if since in ("1.x", "3.x"):
            result = {"cb": None}
        elif since == "5.x":
            result = {"e": None, "x": None}
        elif since == "10.x":
            result = {"x": None}
        elif since == "?":
            return {}
        else:
            result = {}
            for part in since.split("/"):
                version = parse_version(part)
                result[_series(version)] = version
        last = self.last
        if last is not None:  # a row that ends does not reach the later series
            order = ("cb", "e", "x")
            final = order.index(_series((last[0], 0)))
            result = {series: first for series, first in result.items()
                      if order.index(series) <= final}
        elif "e" in result and "x" not in result:
            result["x"] = None  # PolyScope X carries the e-Series language forward
        return result

    def _seen_by(self) -> dict[str, Version]:
        """For ``since`` written ``<=A/B``: the version per series by which the row is known
        to exist (documented or seen in a program of that version)."""
        since = self.since_first.lstrip("~")
        if not since.startswith("<="):
            return {}
        bounds = {}
        for part in since[2:].split("/"):
            version = parse_version(part.removeprefix("<="))
            bounds[_series(version)] = version
        return bounds

    def row_available_in(self, version: Version) -> bool | None:
        """Whether controller software ``version`` has this signature row: True, False, or
        None when the catalog cannot tell (an unconfirmed or open-ended first version)."""
        since = self.since_first
        if since == "?":
            return None
        last = self.last
        if last is not None and version > last:
            return False
        firsts = self.first_versions()
        series = _series(version)
        if series not in firsts:
            if since in ("1.x", "3.x") and last is None and "CB3 only" not in self.remarks:
                return None  # a CB-era builtin whose fate on later series is not known
            return False
        first = firsts[series]
        if first is None:
            bound = self._seen_by().get(series)
            if bound is not None:  # documented by then; earlier versions cannot be told
                return True if version >= bound else None
            return True
        if version >= first:
            return True
        return None if since.startswith("~") else False

    def available_in(self, version: str | Version) -> bool | None:
        """Whether controller software ``version`` has this builtin under any of its
        signature rows: True, False, or None when the catalog cannot tell."""
        if isinstance(version, str):
            version = parse_version(version)
        answers = [row.row_available_in(version) for row in (self, *self.variants)]
        if True in answers:
            return True
        return None if None in answers else False


def _split_params(text: str) -> list[str]:
    """Split ``a, b=[1, 2], c='x'`` at the commas that are not inside brackets or quotes."""
    parts, depth, quote, current = [], 0, "", []
    for char in text:
        if quote:
            if char == quote:
                quote = ""
        elif char in "\"'":
            quote = char
        elif char in "([":
            depth += 1
        elif char in ")]":
            depth -= 1
        elif char == "," and depth == 0:
            parts.append("".join(current).strip())
            current = []
            continue
        current.append(char)
    if "".join(current).strip():
        parts.append("".join(current).strip())
    return parts


def _row(fields: list[str]) -> Builtin:
    module, name, params_text, returns, since, deprecated, replaced_by, remarks = fields
    params: list[BuiltinParam] = []
    variadic = False
    is_callable = params_text.strip() != "-"
    if is_callable:
        for part in _split_params(params_text):
            if part == "...":
                variadic = True
            elif part.startswith("[") and part.endswith("]"):
                params.append(BuiltinParam(part[1:-1].strip(), None, True))
            elif "=" in part:
                pname, default = part.split("=", 1)
                if name == "struct":
                    variadic = True
                    continue
                params.append(BuiltinParam(pname.strip(), default.strip(), True))
            else:
                params.append(BuiltinParam(part, None, False))
    return Builtin(
        module=module, name=name, params=tuple(params),
        returns=tuple(returns.split("|")) if returns not in ("", "-") else (),
        since=since, deprecated=deprecated == "yes",
        replaced_by=tuple(r for r in replaced_by.split(",") if r),
        remarks=remarks, callable=is_callable, variadic_keywords=variadic,
    )


@functools.cache
def _load() -> tuple[dict[str, Builtin], dict[str, Builtin]]:
    text = resources.files("urdsl.script").joinpath("builtins.tsv").read_text("utf-8")
    functions: dict[str, Builtin] = {}
    method_rows: dict[str, Builtin] = {}
    lines = text.splitlines()
    header = lines[0].split("\t")
    if len(header) != 8:  # pragma: no cover - package data damaged
        raise ValueError(f"builtins.tsv: expected 8 columns, found {len(header)}")
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = line.split("\t")
        if len(fields) != 8:  # pragma: no cover - package data damaged
            raise ValueError(f"builtins.tsv:{number}: expected 8 columns, found {len(fields)}")
        builtin = _row(fields)
        if builtin.is_method:
            method_rows[builtin.name] = builtin
        elif builtin.name in functions:  # another signature row of the same builtin
            first = functions[builtin.name]
            functions[builtin.name] = replace(first, variants=(*first.variants, builtin))
        else:
            functions[builtin.name] = builtin
    return functions, method_rows


def catalog() -> dict[str, Builtin]:
    """All free builtins (functions, ``struct``, interpreter-socket commands) by name."""
    return _load()[0]


@functools.cache
def methods() -> dict[str, Builtin]:
    """List and RPC-handle methods by method name (``append``, ``pop``, ...); the struct and
    matrix methods of the same names are found with :func:`method`."""
    return {name.split(".", 1)[1]: row for name, row in _load()[1].items()
            if not name.startswith(("struct.", "matrix."))}


def method(receiver: str, name: str) -> Builtin | None:
    """The method ``name`` of a ``receiver`` kind (``list``, ``struct``, ``matrix``: the
    manual's "Methods in URScript", 5.15 and later), or None."""
    return _load()[1].get(f"{receiver}.{name}")


def lookup(name: str) -> Builtin | None:
    """The builtin function called ``name``, or None."""
    return _load()[0].get(name)
