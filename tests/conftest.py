"""Shared test settings.

A file's project reaches up to three folders above it (a program that includes it as a
script file) and stops at a folder holding ``.git``. A test's ``tmp_path`` lies three levels
below the system's temporary folder, where other programs leave their own scripts; the
session's base temporary folder is marked as a repository so that no test's project reaches
beyond it.
"""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session", autouse=True)
def _projects_stay_in_the_tests_folder(tmp_path_factory: pytest.TempPathFactory) -> None:
    (tmp_path_factory.getbasetemp() / ".git").mkdir(exist_ok=True)
