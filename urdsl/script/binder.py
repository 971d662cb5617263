"""The one call binder: positional and keyword arguments against a parameter list.

The linter (URS105–URS107), the interpreter (builtins and the program's own ``def``s) and the
DSL all bind calls here, so one mistake reads the same everywhere::

    >>> from urdsl.script.binder import Signature, first_problem
    >>> movej = Signature("movej", ("q", "a", "v", "t", "r"), (True, False, False, False, False))
    >>> first_problem(movej, 1, ("speed",)).message
    "movej() has no parameter 'speed'"
    >>> first_problem(movej, 1, ("speed",)).hint
    'did you mean `v`? the signature is movej(q, a, v, t, r)'
    >>> movej.bind(2, ("v",)).positional
    ('q', 'a')

A mistake is one of four kinds, each with one wording: ``too-many`` (more positional
arguments than parameters), ``twice`` (a parameter given by position and by name),
``unknown-keyword`` (no parameter of that name, with a "did you mean"), ``missing`` (required
parameters not given, all named in one message). ``positional`` is the extra kind of
``struct(...)``, which takes names only.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

__all__ = ["Signature", "Problem", "Binding", "problems", "first_problem"]

# What people write for the move parameters a, v, t, r.
_SYNONYMS = {
    "speed": "v", "velocity": "v", "vel": "v", "acceleration": "a", "acc": "a", "accel": "a",
    "time": "t", "duration": "t", "radius": "r", "blend": "r", "blend_radius": "r",
}


@dataclass(frozen=True)
class Problem:
    """One binding mistake. ``kind`` is ``too-many``, ``twice``, ``unknown-keyword``,
    ``missing`` or ``positional``; ``index`` is the position of the first extra positional
    argument (``too-many``, ``positional``); ``keyword`` the keyword concerned (``twice``,
    ``unknown-keyword``); ``missing`` the required parameters left out."""

    kind: str
    message: str
    hint: str | None = None
    index: int | None = None
    keyword: str | None = None
    missing: tuple[str, ...] = ()


@dataclass(frozen=True)
class Binding:
    """How a call shape fits: the parameter names the positional arguments go to, and the
    parameters left to their defaults, in declared order (with their parameter index)."""

    positional: tuple[str, ...]
    defaulted: tuple[tuple[int, str], ...]


@dataclass(frozen=True)
class Signature:
    """What a call is bound against. ``required[i]`` tells whether ``params[i]`` must be
    given; ``any_keyword`` accepts any ``name=value`` and no positional argument
    (``struct``); ``text`` is the signature as shown in hints (built from the names when
    empty)."""

    name: str
    params: tuple[str, ...]
    required: tuple[bool, ...]
    any_keyword: bool = False
    text: str = ""
    _cache: dict = field(default_factory=dict, init=False, compare=False, hash=False, repr=False)

    @property
    def shown(self) -> str:
        """``movej(q, a=1.4, ...)``: the signature text for hints."""
        return self.text or f"{self.name}({', '.join(self.params)})"

    def bind(self, positional: int, keywords: Sequence[str]) -> Binding | Problem:
        """The binding of a call giving ``positional`` arguments and the ``keywords`` names
        (in call order), or its first problem. Cached per call shape: a call site is bound
        once however often it runs."""
        key = (positional, tuple(keywords))
        result = self._cache.get(key)
        if result is None:
            found = problems(self, positional, key[1])
            if found:
                result = found[0]
            else:
                given = set(self.params[:positional]) | set(key[1])
                result = Binding(
                    self.params[:positional],
                    tuple((i, p) for i, p in enumerate(self.params) if p not in given))
            self._cache[key] = result
        return result


def _plural(count: int, word: str) -> str:
    return f"{count} {word}{'' if count == 1 else 's'}"


def problems(signature: Signature, positional: int,
             keywords: Iterable[str]) -> list[Problem]:
    """Every mistake of a call giving ``positional`` arguments and the ``keywords`` names,
    in the order too-many, then per keyword (twice or unknown), then missing. Empty when the
    call fits."""
    keywords = tuple(keywords)
    name = f"{signature.name}()"
    shown = f"the signature is {signature.shown}"
    if signature.any_keyword:
        if positional:
            return [Problem("positional", f"{name} takes only name=value arguments", shown,
                            index=0)]
        return []
    params = signature.params
    found: list[Problem] = []
    if positional > len(params):
        found.append(Problem(
            "too-many", f"{name} takes at most {_plural(len(params), 'argument')}, "
            f"{positional} given", shown, index=len(params)))
    for keyword in keywords:
        if keyword in params[:positional]:
            found.append(Problem(
                "twice", f"argument '{keyword}' of {name} is given twice, by position and "
                "by name", "remove one of the two", keyword=keyword))
        elif keyword not in params:
            close = difflib.get_close_matches(keyword, params, n=1, cutoff=0.6)
            synonym = _SYNONYMS.get(keyword.lower())
            if synonym in params:
                close = [synonym]
            guess = f"did you mean `{close[0]}`? " if close else ""
            found.append(Problem("unknown-keyword", f"{name} has no parameter '{keyword}'",
                                 f"{guess}{shown}", keyword=keyword))
    given = set(params[:positional]) | set(keywords)
    missing = tuple(p for p, needed in zip(params, signature.required, strict=True)
                    if needed and p not in given)
    if missing:
        listed = ", ".join(f"'{m}'" for m in missing)
        found.append(Problem(
            "missing", f"{name} is missing the argument{'s' if len(missing) > 1 else ''} "
            f"{listed}", shown, missing=missing))
    return found


def first_problem(signature: Signature, positional: int,
                  keywords: Iterable[str]) -> Problem | None:
    """The first of :func:`problems`, or None when the call fits."""
    result = signature.bind(positional, tuple(keywords))
    return result if isinstance(result, Problem) else None
