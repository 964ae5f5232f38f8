"""A robot's state row and parameter row by name: numpy record types laid over the float64 rows of
:mod:`tablebot.sim.columns`, so the compiled physics reads ``s.x``, ``s.reading[k]``, ``p.wheel_r``.

The rows stay plain float64 arrays outside the compiled code (the runner, traces and pictures index them
with the column constants); a compiled entry point views its row as a record (:func:`as_state`,
:func:`as_params`: no copy, the same bytes) and everything below it reads fields. A field is a fixed offset
from the row's address, as a constant column index is, so the machine code is the flat rows' own
(benchmarks/kernel.py measures the whole kernel against the commit before, in one run). Two things keep it so:
the record types are aligned (``align=True``: numba emits an unaligned record's loads and stores with
alignment 1), and the physics keeps its order of work, writing a field as soon as it is
worked out (sim.physics.step.motor: returning three values for the caller to store cost x1.15).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, cast

import numpy as np

from tablebot.jit import numba
from tablebot.sim import columns as C

__all__ = ["PARAMS", "STATE", "Params", "State", "as_params", "as_state"]


def _record(constants: list[str], prefix: str, width: int, arrays: dict[str, tuple[int, tuple[int, ...]]]) -> np.dtype:
    """The record type of a row: a field per sim.columns constant in ``constants`` (named as it, less ``prefix``,
    in lower case) at its column, and one per block of columns in ``arrays`` (name: start, shape); checked to
    name every column of the row once."""
    fields: dict[int, tuple[str, tuple[int, ...]]] = {
        getattr(C, constant): (constant.removeprefix(prefix).lower(), ()) for constant in constants
    }
    fields.update({start: (name, shape) for name, (start, shape) in arrays.items()})
    order = sorted(fields)
    dtype = np.dtype(
        {
            "names": [fields[k][0] for k in order],
            "formats": [("f8", fields[k][1]) if fields[k][1] else "f8" for k in order],
            "offsets": [8 * k for k in order],
            "itemsize": 8 * width,
        },
        align=True,
    )
    columns = sorted(k + j for k in order for j in range(int(np.prod(fields[k][1], dtype=np.int64))))
    assert columns == list(range(width)), f"sim.columns does not name each column of a {width}-column row once"
    return dtype


_STATE_COLUMNS = [
    "X",
    "Y",
    "TH",
    "V_R",
    "V_L",
    "ENC_R",
    "ENC_L",
    "PUL_R",
    "PUL_L",
    "SOC",
    "VBAT",
    "AMPS",
    "DIST",
    "GAIN_R",
    "GAIN_L",
    "LIGHT_R",
    "LIGHT_L",
    "BUMP_FR",
    "BUMP_FL",
    "BUMP_REAR",
    "CONTACT",
    "MASK",
]
_PARAM_COLUMNS = [name for name in vars(C) if name.startswith("P_") and name != "P_SENSOR"]

#: A robot's state row (sim.columns X .. READING + MAX_SENSORS): ``x``, ``y``, ``th``, ``v_r`` .. ``mask`` and
#: ``reading[k]``, sensor slot k's reading.
STATE = _record(_STATE_COLUMNS, "", C.N_STATE, {"reading": (C.READING, (C.MAX_SENSORS,))})
#: A robot's parameter row (sim.columns P_*): ``dt``, ``base``, ``wheel_r`` .. ``dres`` and ``sensor[k, F]``,
#: sensor slot k's field F (sim.columns F_KIND .. F_SIGN).
PARAMS = _record(_PARAM_COLUMNS, "P_", C.N_PARAM, {"sensor": (C.P_SENSOR, (C.MAX_SENSORS, C.SENSOR_FIELDS))})


class State(Protocol):
    """A :data:`STATE` record as the physics reads it (what mypy checks the field names against)."""

    x: float
    y: float
    th: float
    v_r: float
    v_l: float
    enc_r: float
    enc_l: float
    pul_r: float
    pul_l: float
    soc: float
    vbat: float
    amps: float
    dist: float
    gain_r: float
    gain_l: float
    light_r: float
    light_l: float
    bump_fr: float
    bump_fl: float
    bump_rear: float
    contact: float
    mask: float
    reading: np.ndarray


class Params(Protocol):
    """A :data:`PARAMS` record as the physics reads it."""

    dt: float
    base: float
    wheel_r: float
    front: float
    rear: float
    half_w: float
    overlap: float
    wrap: float
    gap: float
    gyr2: float
    kv: float
    vf: float
    alpha: float
    levels: float
    vfull: float
    vempty: float
    rint: float
    cap: float
    iidle: float
    imotor: float
    ppr: float
    lx: float
    ly: float
    toe: float
    cos_fov: float
    exp: float
    dmin: float
    nmotor: float
    nlight: float
    drange: float
    dmin_range: float
    dbeam: float
    dres: float
    sensor: np.ndarray


for _protocol, _dtype in ((State, STATE), (Params, PARAMS)):  # one list of names, checked here
    assert list(_protocol.__annotations__) == list(_dtype.names or ()), f"{_protocol.__name__} and the dtype differ"


def as_state(s: np.ndarray | State) -> State:
    """Row ``s`` (float64, N_STATE) as a :data:`STATE` record, the same memory (a record is returned as it is;
    from Python a ``numpy.record``, whose fields read as attributes too)."""
    return cast(State, s.view(STATE).view(np.recarray)[0] if isinstance(s, np.ndarray) else s)


def as_params(p: np.ndarray | Params) -> Params:
    """Row ``p`` (float64, N_PARAM) as a :data:`PARAMS` record, the same memory (a record is returned as it is)."""
    return cast(Params, p.view(PARAMS).view(np.recarray)[0] if isinstance(p, np.ndarray) else p)


def _record_at(dtype: np.dtype) -> Any:
    """A compiled function: the record of type ``dtype`` at a float64 row's first element, the same memory.
    numba's ``row.view(dtype)[0]`` checks the row's layout and builds an array first, on every call: a fleet's
    physics-only loop (fleet.kernel.move_serial) views each robot's row every tick, and the checks cost it x1.04.
    The width is checked here alone (a row too short would have fields past its end)."""
    record = numba.from_dtype(dtype)
    width = dtype.itemsize // 8

    @numba.extending.intrinsic
    def cast(typingctx: Any, row: Any) -> Any:
        def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
            data = context.make_array(signature.args[0])(context, builder, args[0]).data
            return builder.bitcast(data, context.get_value_type(record))

        return record(row), codegen

    def at(row: Any) -> Any:
        if row.shape[0] != width or row.strides[0] != 8:
            raise ValueError("a robot row has the wrong width")
        return cast(row)

    return at


def _viewer(dtype: np.dtype) -> Callable[[Any], Callable[[Any], Any]]:
    """The compiled form of as_state/as_params: a record unchanged, a float64 row's memory as one record. (numba
    asks the implementations to be annotated as the typing function is.)"""
    at = numba.njit(inline="always")(_record_at(dtype))

    def unchanged(row: Any) -> Any:
        return row

    def viewed(row: Any) -> Any:
        return at(row)

    def typer(row: Any) -> Callable[[Any], Any]:
        return unchanged if isinstance(row, numba.types.Record) else viewed

    return typer


numba.extending.overload(as_state, inline="always")(_viewer(STATE))
numba.extending.overload(as_params, inline="always")(_viewer(PARAMS))
