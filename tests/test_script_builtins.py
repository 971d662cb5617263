"""The builtin catalog, as the linter, DSL and interpreter will read it."""

from __future__ import annotations

import pytest

from urdsl.script.builtins import catalog, lookup, method, methods, parse_version


def test_every_row_is_there():
    # 299 rows of the reference catalog + get_joint_positions, eip_reader_factory and
    # eip_writer_factory (added from UR's own scripts, see their remarks) + 7 CB-era builtins
    # (varmsg, tool_pose, set_runstate_outputs and four set_runstate_*_outputs) +
    # jump_to_label (written by PolyScope itself, seen in a 5.x export) + 5 list
    # methods of the manual's "Methods on List" (excess_capacity, extend, remove, slice,
    # to_string); its struct and matrix methods are found by receiver
    assert len(catalog()) + len(methods()) == 315
    assert method("struct", "length").returns == ("Int",)
    assert method("matrix", "get_column").params[0].name == "index"
    assert method("list", "shape") is None
    assert sum(b.deprecated for b in catalog().values()) == 16
    # 3 more signature rows of older generations: speedj, speedl (t_min), set_payload (CoG)
    assert sum(len(b.variants) for b in catalog().values()) == 3


def test_every_added_row_names_its_source_or_stays_unconfirmed():
    for builtin in catalog().values():
        for row in (builtin, *builtin.variants):
            if row.since_first in ("1.x", "3.x") or row.last is not None:
                assert row.remarks.startswith(("[S]", "[U]", "CB3 only")), row.name


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
        # CB-era builtins: there on CB2/CB3, unknown (never "absent") on later series
        ("varmsg", "1.8", True), ("varmsg", "3.15", True), ("varmsg", "5.15", None),
        ("set_runstate_outputs", "3.2", True), ("set_runstate_outputs", "10.11", None),
        ("get_euromap_input", "1.8", True), ("get_euromap_input", "10.11", False),
        # seen in a program of that version (<=3.5): later ones have it, earlier ones unknown
        ("enable_external_ft_sensor", "3.5", True), ("enable_external_ft_sensor", "3.2", None),
        ("ft_rtde_input_enable", "3.15", True), ("ft_rtde_input_enable", "5.15", True),
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


def test_a_builtin_has_one_signature_row_per_generation():
    speedj = lookup("speedj")
    assert speedj.signature == "speedj(qd, a, [t])"
    (cb,) = speedj.variants
    assert cb.signature == "speedj(qd, a, [t_min])" and cb.last == (3, 999)
    assert cb.row_available_in((3, 15)) and cb.row_available_in((5, 4)) is False
    assert speedj.rows() == (speedj, cb)
    assert speedj.rows((5, 15)) == (speedj,)
    assert speedj.rows((3, 15)) == (speedj, cb)


@pytest.mark.parametrize(("version", "fits"), [(None, True), ((3, 15), True), ((1, 8), True),
                                               ((5, 15), False), ((10, 11), False)])
def test_the_signature_of_the_version_applies(version, fits):
    problem = lookup("speedj").argument_problem(2, ("t_min",), version)
    assert (problem is None) is fits
    if not fits:
        assert problem.message == "speedj() has no parameter 't_min'"
    assert lookup("speedj").argument_problem(2, ("t",), version) is None


def test_a_call_of_an_older_signature_binds_to_that_row():
    speedj = lookup("speedj")
    row, binding = speedj.bind(2, ("t_min",))
    assert row is speedj.variants[0] and binding.positional == ("qd", "a")
    row, _ = speedj.bind(3, ())
    assert row is speedj  # positional calls fit the current row first
