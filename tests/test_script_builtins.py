"""The builtin catalog, as the linter, DSL and interpreter will read it."""

from __future__ import annotations

import pytest

from urdsl.script.builtins import catalog, lookup, methods, parse_version


def test_every_row_is_there():
    # 299 rows of the reference catalog + get_joint_positions, eip_reader_factory and
    # eip_writer_factory (added from UR's own scripts, see their remarks)
    assert len(catalog()) + len(methods()) == 302
    assert sum(b.deprecated for b in catalog().values()) == 16


def test_movej_signature_and_defaults():
    movej = lookup("movej")
    assert movej.signature == "movej(q, a=1.4, v=1.05, t=0, r=0)"
    assert (movej.min_args, movej.max_args) == (1, 5)
    assert movej.param("a").default == "1.4" and movej.param("q").default is None
    assert movej.returns == ("None",) and movej.module == "motion"


def test_optional_without_default_and_variadic_struct():
    speedl = lookup("speedl")
    assert [p.name for p in speedl.params] == ["xd", "a", "t", "aRot"]
    assert speedl.min_args == 2 and speedl.param("t").optional
    assert lookup("struct").variadic_keywords and lookup("struct").max_args == 0
    assert lookup("freedrive_mode").param("feature").default == "p[0,0,0,0,0,0]"


def test_deprecations_name_their_replacement():
    assert lookup("set_payload").replaced_by == ("set_target_payload",)
    assert lookup("set_digital_out").deprecated


def test_socket_commands_are_not_callable():
    assert not lookup("abort").callable and lookup("movel").callable


def test_methods():
    assert methods()["append"].params[0].name == "value"
    assert methods()["closeXMLRPCClientConnection"].module == "language-rpc-method"


@pytest.mark.parametrize(
    ("name", "version", "expected"),
    [
        ("movej", "3.15", True), ("movej", "5.24", True),
        ("make_list", "5.15", True), ("make_list", "5.14", False), ("make_list", "3.15", False),
        ("get_euromap_input", "3.15", True), ("get_euromap_input", "5.11", False),
        ("add_frame", "5.24", False), ("add_frame", "10.11", True),
        ("tool_contact", "5.15", True), ("tool_contact", "5.4", None),
        ("direct_torque", "5.22", False), ("direct_torque", "5.23", True),
        ("get_jacobian", "5.23", True), ("get_jacobian", "5.20", None),
        ("assert", "5.15", None),
    ],
)
def test_availability_by_controller_version(name, version, expected):
    assert lookup(name).available_in(version) is expected


def test_confirmed_flags_unconfirmed_rows():
    assert lookup("movej").confirmed
    assert not lookup("servoc").confirmed


def test_version_parsing():
    assert parse_version("5.15.2") == (5, 15)
    with pytest.raises(ValueError, match="controller version"):
        parse_version("five")
