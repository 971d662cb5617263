"""A PolyScope project: the files that make up one program (host programs, included script
files, subprograms, installation variables) and the names each file can see.

>>> from urdsl.project import Project
>>> # Project.discover("cell/").context("cell/pick.script").resolve_call("rq_open")
"""

from .model import (
    SCRIPT_SUFFIXES,
    Definition,
    FileContext,
    Project,
    ProjectError,
    Resolution,
    ScriptFile,
    configured_includes,
)

__all__ = [
    "SCRIPT_SUFFIXES", "Definition", "FileContext", "Project", "ProjectError", "Resolution",
    "ScriptFile", "configured_includes",
]
