"""A robot's rows by name (sim.physics.layout): the record types lie exactly over sim.columns' columns, are
aligned as numba compiles them, and a compiled function that views a float64 row as a record reads and writes
that row itself, not a copy."""

from __future__ import annotations

import numpy as np
import pytest

from tablebot.jit import njit, numba
from tablebot.sim import columns as L
from tablebot.sim.physics.layout import PARAMS, STATE, as_params, as_state


def test_every_state_and_parameter_field_is_its_column() -> None:
    s, p = np.arange(L.N_STATE, dtype=np.float64), np.arange(L.N_PARAM, dtype=np.float64)
    row, params = as_state(s), as_params(p)
    assert (row.x, row.th, row.v_l, row.pul_r, row.soc, row.gain_l, row.light_r, row.bump_rear, row.mask) == (
        L.X,
        L.TH,
        L.V_L,
        L.PUL_R,
        L.SOC,
        L.GAIN_L,
        L.LIGHT_R,
        L.BUMP_REAR,
        L.MASK,
    )
    assert list(row.reading) == list(range(L.READING, L.READING + L.MAX_SENSORS))
    assert (params.dt, params.wheel_r, params.gyr2, params.levels, params.toe, params.nlight, params.dres) == (
        L.P_DT,
        L.P_WHEEL_R,
        L.P_GYR2,
        L.P_LEVELS,
        L.P_TOE,
        L.P_NLIGHT,
        L.P_DRES,
    )
    assert params.sensor[3, L.F_AIM] == L.P_SENSOR + 3 * L.SENSOR_FIELDS + L.F_AIM
    assert (STATE.itemsize, PARAMS.itemsize) == (8 * L.N_STATE, 8 * L.N_PARAM)
    for dtype in (STATE, PARAMS):  # one name per column, nothing left over
        assert sum(int(np.prod(dtype[name].shape or (1,))) for name in dtype.names or ()) * 8 == dtype.itemsize


def test_numba_compiles_the_records_aligned() -> None:
    """An unaligned record's fields are loaded and stored with alignment 1 (numba's record_getattr): the
    types must be aligned structs, as numba sees them."""
    for dtype in (STATE, PARAMS):
        assert dtype.isalignedstruct
        assert numba.typeof(np.zeros(1, dtype)).dtype.aligned


@njit(cache=False)
def _nudge(s: np.ndarray, p: np.ndarray) -> float:
    row, params = as_state(s), as_params(p)
    row.x += params.dt
    row.reading[2] = params.sensor[1, 0]
    return as_state(row).th  # a record passes through unchanged


def test_compiled_code_reads_and_writes_the_row_itself() -> None:
    s, p = np.zeros(L.N_STATE), np.zeros(L.N_PARAM)
    s[L.TH], p[L.P_DT], p[L.P_SENSOR + L.SENSOR_FIELDS] = 0.5, 0.01, 3.0
    assert _nudge(s, p) == 0.5
    assert (s[L.X], s[L.READING + 2]) == (0.01, 3.0)
    assert np.count_nonzero(s) == 3  # nothing else written


@njit(cache=False)
def _x_of(s: np.ndarray) -> float:
    return as_state(s).x


def test_compiled_code_refuses_a_row_of_another_width() -> None:
    """Compiled code reads a row's memory as a record without numba's view (whose checks cost the physics-only
    loop x1.04): the width is still checked, since a record would read past a shorter row's end."""
    assert _x_of(np.full(L.N_STATE, 2.0)) == 2.0
    with pytest.raises(ValueError, match="wrong width"):
        _x_of(np.zeros(L.N_STATE - 1))
    with pytest.raises(ValueError, match="wrong width"):
        _x_of(np.zeros(2 * L.N_STATE)[::2])  # a strided row
