"""One bounded reader for PolyScope's gzip-compressed files (.urp, .installation,
.variables): what PolyScope writes comes back whole; damaged or oversized data is refused
with a reason, never read without bound."""

from __future__ import annotations

import gzip

import pytest
from hypothesis import given
from hypothesis import strategies as st

from urdsl.polyscope import gz
from urdsl.polyscope.gz import InflateError, inflate
from urdsl.polyscope.installation import InstallationError, parse_installation
from urdsl.polyscope.urp import UrpError, parse_urp
from urdsl.polyscope.variables import parse_variables_file


@given(st.binary(max_size=4096))
def test_inflate_undoes_gzip(data):
    assert inflate(gzip.compress(data)) == data


@given(st.binary(max_size=64).filter(lambda b: b[:2] != b"\x1f\x8b"))
def test_plain_data_is_returned_as_it_is(data):
    assert inflate(data) == data


def test_every_member_of_a_stream_and_zero_padding():
    assert inflate(gzip.compress(b"a=1\n") + gzip.compress(b"b=2\n") + b"\x00" * 8) == \
        b"a=1\nb=2\n"


@given(st.binary(min_size=1, max_size=2048), st.data())
def test_a_cut_stream_is_refused_with_a_reason(data, draw):
    packed = gzip.compress(data)
    cut = draw.draw(st.integers(2, len(packed) - 1))
    with pytest.raises(InflateError, match="truncated|corrupt"):
        inflate(packed[:cut])


def test_corrupt_data_says_so():
    with pytest.raises(InflateError, match="the gzip data is corrupt"):
        inflate(b"\x1f\x8b not gzip at all")


def test_more_than_the_limit_is_refused_at_the_limit():
    bomb = gzip.compress(b" " * 100_000)
    assert inflate(bomb, 100_000) == b" " * 100_000
    with pytest.raises(InflateError, match="larger than"):
        inflate(bomb, 99_999)
    # a second member that would pass the limit
    with pytest.raises(InflateError, match="larger than"):
        inflate(bomb + gzip.compress(b"x"), 100_000)


def test_each_reader_refuses_a_bomb_with_its_files_name(monkeypatch):
    monkeypatch.setattr(gz, "LIMIT", 1_000_000)
    bomb = gzip.compress(b"<URProgram>" + b" " * 2_000_000 + b"</URProgram>")
    with pytest.raises(UrpError, match=r"big\.urp: error: not a readable PolyScope program: "
                       r"larger than 0.954 MiB uncompressed"):
        parse_urp(bomb, "big.urp")
    with pytest.raises(InstallationError, match="larger than"):
        parse_installation(bomb, "big.installation")
    found = parse_variables_file(gzip.compress(b"a=1\n" + b"#" * 2_000_000), "big.variables")
    assert found.variables == []
    assert found.diagnostics[0].message == ("big.variables cannot be read: larger than 0.954 "
                                            "MiB uncompressed")
