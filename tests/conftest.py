"""Shared test settings.

A file's project reaches up to three folders above it (a program that includes it as a
script file) and stops at a folder holding ``.git``. A test's ``tmp_path`` lies three levels
below the system's temporary folder, where other programs leave their own scripts; the
session's base temporary folder is marked as a repository so that no test's project reaches
beyond it, and so is each test's ``tmp_path`` (a fragment that no program includes sees its
repository's script files: each test is a repository of its own).

Hypothesis draws new examples on every run; with ``CI`` set (``.ci/run``) it draws the same
ones on every run (``derandomize``), so that a clean clone's result does not depend on luck:
laws are explored on developers' runs and a failing example found there becomes a fix.
"""

from __future__ import annotations

import os

import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


@pytest.fixture(scope="session", autouse=True)
def _projects_stay_in_the_tests_folder(tmp_path_factory: pytest.TempPathFactory) -> None:
    (tmp_path_factory.getbasetemp() / ".git").mkdir(exist_ok=True)


@pytest.fixture(autouse=True)
def _each_tmp_path_is_a_repository(request: pytest.FixtureRequest) -> None:
    if "tmp_path" in request.fixturenames:
        (request.getfixturevalue("tmp_path") / ".git").mkdir(exist_ok=True)
