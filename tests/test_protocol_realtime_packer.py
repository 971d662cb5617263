"""Realtime encoder for the simulator's own objects (``RealtimeLayout.packer``): one layout
table, one generated pack per layout, the same bytes as encoding a RealtimeState."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.protocol.errors import ProtocolError
from urdsl.protocol.realtime import (
    LAYOUTS,
    decode_realtime,
    encode_realtime,
    layout_for_version,
    realtime_state,
)

VERSIONS = ["1.6", "1.8", "3.0", "3.2", "3.5", "3.10", "5.4", "5.10"]
finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
integer = st.integers(min_value=-(2**53), max_value=2**53)


@st.composite
def carried_values(draw):
    """A version and values for a random subset of its layout's fields."""
    version = draw(st.sampled_from(VERSIONS))
    layout = layout_for_version(version)
    chosen = draw(st.lists(st.sampled_from(layout.table), unique_by=lambda f: f.name))
    values = {}
    for item in chosen:
        element = integer if item.kind == "int" else finite
        values[item.name] = (draw(element) if item.count == 1 else
                             tuple(draw(st.lists(element, min_size=item.count,
                                                 max_size=item.count))))
    return version, values


@settings(max_examples=120, deadline=None)
@given(carried_values())
def test_a_packer_sends_what_it_carries_and_zeros_elsewhere(case):
    version, values = case
    snapshot = SimpleNamespace(**values)
    pack = layout_for_version(version).packer(
        {name: (lambda s, name=name: getattr(s, name)) for name in values})
    data = pack(snapshot)
    # the same bytes as the protocol's encoder of a RealtimeState with those fields
    assert data == encode_realtime(realtime_state(version, **values))
    decoded = decode_realtime(data, version=version)
    for name, value in values.items():
        assert getattr(decoded, name) == value


def test_names_the_layout_does_not_send_are_left_out_and_unknown_names_refused():
    pack = LAYOUTS["3.0"].packer({"time": lambda s: 1.5, "payload_mass": lambda s: 2.0})
    state = decode_realtime(pack(None))
    assert state.time == 1.5 and state.payload_mass is None and state.size == 1044
    with pytest.raises(KeyError, match="no realtime layout has the field.*q_actaul"):
        LAYOUTS["3.0"].packer({"q_actaul": lambda s: (0.0,) * 6})


def test_numpy_arrays_and_numbers_of_other_types_are_packed():
    q = np.array([0.1, -1.2, 1.3, -1.7, -1.5, 0.4])
    pack = LAYOUTS["5.10"].packer({"q_actual": lambda s: q, "robot_mode": lambda s: np.int64(7),
                                   "speed_scaling": lambda s: "0.5"})
    state = decode_realtime(pack(None))
    assert state.q_actual == tuple(q.tolist())
    assert state.robot_mode == 7 and state.speed_scaling == 0.5


@pytest.mark.parametrize(("value", "message"), [
    ((0.0,) * 5, "field q_actual needs 6 values, got 5"),
    ((0.0,) * 7, "field q_actual needs 6 values, got 7"),
    (1.0, "field q_actual needs 6 numbers, got 1.0"),
    (("a",) * 6, "field q_actual needs 6 numbers"),
])
def test_a_value_that_does_not_fit_is_refused_naming_its_field(value, message):
    pack = LAYOUTS["3.10"].packer({"q_actual": lambda s: value, "time": lambda s: 0.0})
    with pytest.raises(ProtocolError, match=message) as raised:
        pack(None)
    assert raised.value.offset == 252


def test_a_short_vector_beside_a_long_one_is_refused_though_the_total_fits():
    pack = LAYOUTS["3.10"].packer({"q_target": lambda s: (0.0,) * 5,
                                   "qd_target": lambda s: (0.0,) * 7})
    with pytest.raises(ProtocolError, match="field q_target needs 6 values, got 5"):
        pack(None)
