"""numpy's standard normal drawn inside compiled code from a robot's own numpy Generator, bit for bit.

A compiled loop over thousands of robots cannot call each robot's ``Generator.standard_normal`` (one
Python call per robot and block, on one core, into an array as large as the fleet); instead it calls
the Generator's own C bit generator through the pointers numpy publishes for this purpose (the
``bitgen_t`` struct of ``numpy/random/bitgen.h``: state, next_uint64, next_uint32, next_double), and
turns the bits into normals with numpy's ziggurat (``random_standard_normal`` in numpy's
``distributions.c``, as numba ports it). The Generator's state advances exactly as numpy's own draws
advance it, so a run may mix the two; ``tests/test_sim_normals.py`` proves the numbers identical.
"""

from __future__ import annotations

import ctypes

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

# numpy's ziggurat tables (numpy/random/src/distributions/ziggurat_constants.h), as numba ships them for its
# own Generator support; the test above fails if they ever stop giving numpy's numbers.
from numba.np.random._constants import fi_double, ki_double, wi_double, ziggurat_nor_inv_r, ziggurat_nor_r

from tablebot.jit import njit

_capsule_pointer = ctypes.pythonapi.PyCapsule_GetPointer
_capsule_pointer.restype = ctypes.c_void_p
_capsule_pointer.argtypes = [ctypes.py_object, ctypes.c_char_p]

WORD = 8  # bytes per field of bitgen_t (pointers, on the 64-bit platforms numba supports)
_NEXT_UINT64, _NEXT_DOUBLE = 1, 3  # field numbers in bitgen_t (0 is the state)


def bitgen_address(rng: np.random.Generator) -> np.uint64:
    """The address of ``rng``'s ``bitgen_t``, for :func:`standard_normal`. The caller keeps ``rng`` alive
    while compiled code uses it, and no other thread draws from it meanwhile."""
    if ctypes.sizeof(ctypes.c_void_p) != WORD:
        raise RuntimeError("drawing numpy's normals in compiled code needs a 64-bit platform")
    return np.uint64(_capsule_pointer(rng.bit_generator.capsule, b"BitGenerator"))


def bitgen_addresses(rngs: list[np.random.Generator]) -> np.ndarray:
    return np.array([bitgen_address(rng) for rng in rngs], dtype=np.uint64)


@intrinsic
def _word(typingctx, address):  # type: ignore[no-untyped-def]
    """The 64-bit word stored at ``address``."""
    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        return builder.load(builder.inttoptr(args[0], ir.IntType(64).as_pointer()))
    return types.uint64(types.uint64), codegen


@intrinsic
def _next_uint64(typingctx, function, state):  # type: ignore[no-untyped-def]
    """Call the bit generator's ``uint64_t next_uint64(void *state)`` at address ``function``."""
    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        kind = ir.FunctionType(ir.IntType(64), [ir.IntType(64)])
        return builder.call(builder.inttoptr(args[0], kind.as_pointer()), [args[1]])
    return types.uint64(types.uint64, types.uint64), codegen


@intrinsic
def _next_double(typingctx, function, state):  # type: ignore[no-untyped-def]
    """Call the bit generator's ``double next_double(void *state)`` at address ``function``."""
    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        kind = ir.FunctionType(ir.DoubleType(), [ir.IntType(64)])
        return builder.call(builder.inttoptr(args[0], kind.as_pointer()), [args[1]])
    return types.float64(types.uint64, types.uint64), codegen


@njit(nogil=True, refcounts=False, inline="always")
def standard_normal(bitgen):  # type: ignore[no-untyped-def]
    """One draw of ``Generator.standard_normal()`` from the Generator whose ``bitgen_t`` is at ``bitgen``
    (numpy's ``random_standard_normal``, line for line)."""
    base = np.uint64(bitgen)
    state = _word(base)
    next_uint64 = _word(base + np.uint64(_NEXT_UINT64 * WORD))
    next_double = _word(base + np.uint64(_NEXT_DOUBLE * WORD))
    while True:
        r = _next_uint64(next_uint64, state)
        idx = r & np.uint64(0xFF)
        r >>= np.uint64(8)
        sign = r & np.uint64(1)
        rabs = (r >> np.uint64(1)) & np.uint64(0x000FFFFFFFFFFFFF)
        x = float(rabs) * wi_double[idx]
        if sign:
            x = -x
        if rabs < ki_double[idx]:
            return x  # 99.3 % of the draws end here
        if idx == 0:  # the tail beyond the last layer
            while True:
                xx = -ziggurat_nor_inv_r * np.log1p(-_next_double(next_double, state))
                yy = -np.log1p(-_next_double(next_double, state))
                if yy + yy > xx * xx:
                    return -(ziggurat_nor_r + xx) if (rabs >> np.uint64(8)) & np.uint64(1) else ziggurat_nor_r + xx
        elif ((fi_double[idx - np.uint64(1)] - fi_double[idx]) * _next_double(next_double, state) + fi_double[idx]
              < np.exp(-0.5 * x * x)):
            return x


@njit(nogil=True, refcounts=False)
def fill(bitgen, out):  # type: ignore[no-untyped-def]
    """``Generator.standard_normal(out=out)`` for a one-dimensional ``out``."""
    for k in range(out.shape[0]):
        out[k] = standard_normal(bitgen)
