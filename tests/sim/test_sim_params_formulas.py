"""Planning runs the physics core's ``duty`` and ``pack_volts`` as plain Python (no compiled code to load): the
same bits as the compiled functions the simulator runs, so a motor constant and a start voltage planned in
Python are the ones the compiled code would have given."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tablebot.sim.model import params as P
from tablebot.sim.physics.step import duty, pack_volts

pytestmark = [pytest.mark.kernel_free]

VOLTS = st.floats(0.0, 60.0, allow_nan=False)


def bits(x: float) -> bytes:
    return struct.pack("<d", x)


@settings(max_examples=200, deadline=None)
@given(level=st.integers(-64, 64), levels=st.integers(1, 64))
def test_duty_in_python_has_the_compiled_bits(level: int, levels: int) -> None:
    assert bits(duty.py_func(level, levels)) == bits(duty(level, levels))


@settings(max_examples=200, deadline=None)
@given(full=VOLTS, empty=VOLTS, charge=st.floats(0.0, 1.0), amps=st.floats(0.0, 20.0), ohms=st.floats(0.0, 20.0))
def test_pack_volts_in_python_has_the_compiled_bits(
    full: float, empty: float, charge: float, amps: float, ohms: float
) -> None:
    args = (full, empty, charge, amps, ohms)
    assert bits(pack_volts.py_func(*args)) == bits(pack_volts(*args))


@settings(max_examples=50, deadline=None)
@given(friction=st.floats(0.0, 1.0), ohms=st.floats(0.0, 2.0), level=st.integers(1, 8), full=st.floats(8.0, 12.0))
def test_the_motor_constant_is_the_compiled_formulas(friction: float, ohms: float, level: int, full: float) -> None:
    params = P.merged(
        {
            "motor": {"friction_volts": friction, "spin_level": level},
            "battery": {"internal_ohms": ohms, "full_volts": full},
        }
    )
    m, b = params["motor"], params["battery"]
    amps = b["idle_amps"] + b["motor_amps"] * sum(duty(v, m["levels"]) for v in (level, level))
    volts = pack_volts(b["full_volts"], b["empty_volts"], 1.0, amps, b["internal_ohms"])
    drive = duty(level, m["levels"]) * volts - m["friction_volts"]
    assert bits(P.terminal_volts(params, 1.0, (level, level))) == bits(volts)
    if drive > 0:
        assert bits(P.speed_per_volt(params)) == bits(P.spin_speed(params) / drive)
