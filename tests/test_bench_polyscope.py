"""The PolyScope compile benchmark's comparison: numbers to 1e-9 (issue 13)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parent.parent / "bench" / "polyscope_compile.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("polyscope_bench", BENCH)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_numbers_compare_within_1e9_not_by_their_print(bench):
    # 0.1234567894 and 0.1234567896 are 2e-10 apart but print one 1e-9 step apart
    theirs = ["global posHome_p = p[0.123456789, 0.5, 0.2, 0, 3.14, 0]", "movej(posHome_p)"]
    ours = ["global posHome_p = p[0.12345679, 0.5, 0.2, 0, 3.14, 0]", "movej(posHome_p)"]
    assert bench.reconcile(ours, theirs) == theirs
    far = ["global posHome_p = p[0.123457, 0.5, 0.2, 0, 3.14, 0]", "movej(posHome_p)"]
    assert bench.reconcile(far, theirs) == far  # 2e-7 apart: a real difference
    other = ["global posHome_p = p[0.123456789, 0.5, 0.2, 0, 3.14, 0]", "movel(posHome_p)"]
    assert bench.reconcile(other, theirs) == other  # not only numbers differ
