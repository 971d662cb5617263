"""The PolyScope compile benchmark's comparison: numbers to 1e-9 (issue 13)."""

from __future__ import annotations

import pytest
from _bench import load_bench


@pytest.fixture(scope="module")
def bench():
    return load_bench("polyscope_compile.py", "polyscope_bench")


def test_numbers_compare_within_1e9_not_by_their_print(bench):
    # 0.1234567894 and 0.1234567896 are 2e-10 apart but print one 1e-9 step apart
    theirs = ["global posHome_p = p[0.123456789, 0.5, 0.2, 0, 3.14, 0]", "movej(posHome_p)"]
    ours = ["global posHome_p = p[0.12345679, 0.5, 0.2, 0, 3.14, 0]", "movej(posHome_p)"]
    assert bench.reconcile(ours, theirs) == theirs
    far = ["global posHome_p = p[0.123457, 0.5, 0.2, 0, 3.14, 0]", "movej(posHome_p)"]
    assert bench.reconcile(far, theirs) == far  # 2e-7 apart: a real difference
    other = ["global posHome_p = p[0.123456789, 0.5, 0.2, 0, 3.14, 0]", "movel(posHome_p)"]
    assert bench.reconcile(other, theirs) == other  # not only numbers differ
