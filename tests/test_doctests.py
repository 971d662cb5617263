"""The examples in urdsl's docstrings (``>>>``) run and show what they say.

Every module of the package is imported by name and its docstrings are run with
:mod:`doctest`, so ``make test`` (pytest over tests/) runs them all. An example that needs a
robot on the network is marked ``# doctest: +SKIP`` where it stands.
"""

from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent / "urdsl"


def _modules() -> list[str]:
    """Every module under urdsl/, packages with and without ``__init__`` alike."""
    names = []
    for path in ROOT.rglob("*.py"):
        parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        if parts[-1] != "__main__":  # running it is running the command
            names.append(".".join(parts))
    return sorted(names)


MODULES = _modules()


def test_every_module_is_visited():
    assert {"urdsl.rules", "urdsl.versions", "urdsl.motion.trace", "urdsl.kinematics"} <= set(
        MODULES)
    assert len(MODULES) > 80


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for test in finder.find(module, name):  # each example sees a copy of its module
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"


def test_the_examples_are_found():
    finder = doctest.DocTestFinder(exclude_empty=True)
    found = sum(len(test.examples) for test in
                finder.find(importlib.import_module("urdsl.versions"), "urdsl.versions"))
    assert found >= 4
