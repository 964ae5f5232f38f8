"""numpy's standard normal drawn inside compiled code from a robot's own numpy Generator, bit for bit.

A compiled loop over thousands of robots cannot call each robot's ``Generator.standard_normal`` (one
Python call per robot and block, on one core, into an array as large as the fleet); instead it draws the
Generator's bits itself and turns them into normals with numpy's ziggurat (``random_standard_normal`` in
numpy's ``distributions.c``, as numba ports it). The Generator's state advances exactly as numpy's own
draws advance it, so a run may mix the two; ``tests/sim/test_sim_normals.py`` proves the numbers identical.
"""

# The bits come one of two ways, chosen per Generator when its handle is made (:func:`bitgen_address`):
# - numpy's PCG64 (what default_rng makes): its 128-bit LCG is stepped inline, in LLVM's i128 arithmetic,
#   on the generator's own state in memory (numpy/random/src/pcg64/pcg64.h: pcg64_next64 =
#   pcg_setseq_128_xsl_rr_64_random_r; next_double = uint64_to_double of numpy/random/_common.pxd). A call
#   through numpy's function pointer cannot be inlined and was ~12 ns of each normal.
# - any other bit generator: through the function pointers numpy publishes for this purpose (the ``bitgen_t``
#   struct of numpy/random/bitgen.h: state, next_uint64, next_uint32, next_double).
# The inline path depends on the memory layout of numpy's PCG64 object, which numpy does not promise: it is
# taken only once :func:`pcg64_inline` has checked this numpy's layout and arithmetic against numpy's own
# draws; a numpy that differs costs speed (the function-pointer path), never a wrong number.

from __future__ import annotations

import ctypes
import sys
from typing import TYPE_CHECKING

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

# numpy's ziggurat tables (numpy/random/src/distributions/ziggurat_constants.h), as numba ships them for its
# own Generator support; the test above fails if they ever stop giving numpy's numbers.
from numba.np.random._constants import fi_double, ki_double, wi_double, ziggurat_nor_inv_r, ziggurat_nor_r

from tablebot.jit import njit

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from numba.core.base import BaseContext
    from numba.core.typing import Signature
    from numba.core.typing.context import BaseContext as TypingContext

_capsule_pointer = ctypes.pythonapi.PyCapsule_GetPointer
_capsule_pointer.restype = ctypes.c_void_p
_capsule_pointer.argtypes = [ctypes.py_object, ctypes.c_char_p]

WORD = 8  # bytes per field of bitgen_t (pointers, on the 64-bit platforms numba supports)
_NEXT_UINT64, _NEXT_DOUBLE = 1, 3  # field numbers in bitgen_t (0 is the state)
INLINE = 1  # bit 0 of a handle: the address is of a PCG64's pcg64_random_t, stepped inline (addresses are even)

# PCG_DEFAULT_MULTIPLIER_128 of numpy/random/src/pcg64/pcg64.h
PCG64_MULTIPLIER = (2549297995355413924 << 64) + 4865540595714422341
_MASK128 = (1 << 128) - 1
_inline_offset: int | bool | None = False  # pcg64_inline's verdict: False until checked, then an offset or None


def _word_at(address: int) -> int:
    return ctypes.c_uint64.from_address(address).value


def _bitgen_t(bit_generator: object) -> int:
    return int(_capsule_pointer(bit_generator.capsule, b"BitGenerator"))  # type: ignore[attr-defined]


def _pcg64_words(bit_generator: np.random.PCG64) -> int:
    """Where ``bit_generator``'s ``pcg64_random_t`` is, as numpy's own next_uint64 finds it: bitgen_t.state
    points at a ``pcg64_state``, whose first field points at the ``pcg64_random_t``."""
    return _word_at(_word_at(_bitgen_t(bit_generator)))


def _step(state: int, inc: int) -> tuple[int, int]:
    """numpy's PCG64 step and XSL-RR output (pcg64.h), in Python's integers: (new state, next64)."""
    state = (state * PCG64_MULTIPLIER + inc) & _MASK128
    rot, word = state >> 122, ((state >> 64) ^ state) & 0xFFFFFFFFFFFFFFFF
    return state, ((word >> rot) | (word << (-rot & 63))) & 0xFFFFFFFFFFFFFFFF


def pcg64_inline() -> int | None:
    """The offset of a ``numpy.random.PCG64``'s ``pcg64_random_t`` from the object's address, when this numpy
    keeps it as the inline path reads it; None when not (checked once a process, on throwaway generators).

    Checked: the words sit inside the object (a member, so at the same offset in every PCG64), they hold
    state then increment as little-endian 128-bit integers (what ``PCG64.state`` reports), and numpy's own
    next_uint64 and next_double (``random_raw``, ``Generator.random``) give what the inline step gives
    and leave those words as it leaves them. Only such a numpy, on a 64-bit little-endian machine, gets
    the inline path."""
    global _inline_offset
    if _inline_offset is not False:
        return _inline_offset
    _inline_offset = None
    try:
        if sys.byteorder == "little" and ctypes.sizeof(ctypes.c_void_p) == WORD and _layout_holds():
            probe = np.random.PCG64(20240611)
            _inline_offset = _pcg64_words(probe) - id(probe)
    except Exception:  # whatever this numpy does differently: the function-pointer path
        _inline_offset = None
    return _inline_offset


def _layout_holds() -> bool:
    """The checks of :func:`pcg64_inline`, on two throwaway generators."""
    probes = [np.random.PCG64(seed) for seed in (20240611, 2**100 + 3)]
    offsets = {_pcg64_words(probe) - id(probe) for probe in probes}
    if len(offsets) != 1 or not 0 < next(iter(offsets)) <= type(probes[0]).__basicsize__ - 4 * WORD:
        return False
    for probe in probes:
        words = _pcg64_words(probe)
        for _ in range(3):
            state, inc = probe.state["state"]["state"], probe.state["state"]["inc"]
            memory = [_word_at(words + k * WORD) for k in range(4)]
            if memory != pcg64_words(state, inc):
                return False
            after, expected = _step(state, inc)
            if int(probe.random_raw()) != expected:
                return False
            after, expected = _step(after, inc)
            if np.random.Generator(probe).random() != (expected >> 11) * (1.0 / 9007199254740992.0):
                return False
            if _word_at(words) | _word_at(words + WORD) << 64 != after:
                return False
    return True


def bitgen_address(rng: np.random.Generator) -> np.uint64:
    """The handle :func:`standard_normal` draws ``rng``'s numbers through: when ``rng``'s bit generator is
    exactly numpy's PCG64 and :func:`pcg64_inline` holds, the address of its state words with bit 0 set
    (stepped inline), else the address of its ``bitgen_t``. The caller keeps ``rng`` alive while compiled code
    uses it, and no other thread draws from it meanwhile."""
    bit_generator = rng.bit_generator
    if type(bit_generator) is np.random.PCG64:
        offset = pcg64_inline()
        if offset is not None:
            return np.uint64(id(bit_generator) + offset + INLINE)  # a member: no pointer to follow per robot
    if ctypes.sizeof(ctypes.c_void_p) != WORD:
        raise RuntimeError("drawing numpy's normals in compiled code needs a 64-bit platform")
    return np.uint64(_bitgen_t(bit_generator))


def pcg64_words(state: int, inc: int) -> list[int]:
    """A PCG64's state and increment (``PCG64.state``'s integers) as its ``pcg64_random_t`` holds them in memory:
    four 64-bit words, each 128-bit integer low word first."""
    return [state & 2**64 - 1, state >> 64, inc & 2**64 - 1, inc >> 64]


def pcg64_ints(words: Sequence[int]) -> tuple[int, int]:
    """:func:`pcg64_words` back: the state and increment of four words in memory."""
    return words[1] << 64 | words[0], words[3] << 64 | words[2]


def bitgen_addresses(rngs: list[np.random.Generator]) -> np.ndarray:
    return np.array([bitgen_address(rng) for rng in rngs], dtype=np.uint64)


@intrinsic
def _word(typingctx: TypingContext, address: types.Type) -> tuple[Signature, Callable[..., ir.Value]]:
    """The 64-bit word stored at ``address``."""

    def codegen(context: BaseContext, builder: ir.IRBuilder, sig: Signature, args: Sequence[ir.Value]) -> ir.Value:
        return builder.load(builder.inttoptr(args[0], ir.IntType(64).as_pointer()))

    return types.uint64(types.uint64), codegen


@intrinsic
def _next_uint64(
    typingctx: TypingContext, function: types.Type, state: types.Type
) -> tuple[Signature, Callable[..., ir.Value]]:
    """Call the bit generator's ``uint64_t next_uint64(void *state)`` at address ``function``."""

    def codegen(context: BaseContext, builder: ir.IRBuilder, sig: Signature, args: Sequence[ir.Value]) -> ir.Value:
        kind = ir.FunctionType(ir.IntType(64), [ir.IntType(64)])
        return builder.call(builder.inttoptr(args[0], kind.as_pointer()), [args[1]])

    return types.uint64(types.uint64, types.uint64), codegen


@intrinsic
def _next_double(
    typingctx: TypingContext, function: types.Type, state: types.Type
) -> tuple[Signature, Callable[..., ir.Value]]:
    """Call the bit generator's ``double next_double(void *state)`` at address ``function``."""

    def codegen(context: BaseContext, builder: ir.IRBuilder, sig: Signature, args: Sequence[ir.Value]) -> ir.Value:
        kind = ir.FunctionType(ir.DoubleType(), [ir.IntType(64)])
        return builder.call(builder.inttoptr(args[0], kind.as_pointer()), [args[1]])

    return types.float64(types.uint64, types.uint64), codegen


@intrinsic
def _pcg64_next64(typingctx: TypingContext, address: types.Type) -> tuple[Signature, Callable[..., ir.Value]]:
    """numpy's ``pcg64_next64`` on the ``pcg64_random_t`` (state, inc: 128-bit each) at ``address``
    (numpy/random/src/pcg64/pcg64.h, pcg_setseq_128_xsl_rr_64_random_r): state = state * multiplier + inc,
    stored back; the output is the XSL-RR of the new state."""

    def codegen(context: BaseContext, builder: ir.IRBuilder, sig: Signature, args: Sequence[ir.Value]) -> ir.Value:
        i64, i128 = ir.IntType(64), ir.IntType(128)
        words = builder.inttoptr(args[0], i128.as_pointer())
        inc_words = builder.gep(words, [ir.Constant(ir.IntType(32), 1)])
        state = builder.add(
            builder.mul(builder.load(words, align=8), ir.Constant(i128, PCG64_MULTIPLIER)),
            builder.load(inc_words, align=8),
        )
        builder.store(state, words, align=8)
        xored = builder.xor(builder.trunc(builder.lshr(state, ir.Constant(i128, 64)), i64), builder.trunc(state, i64))
        rot = builder.trunc(builder.lshr(state, ir.Constant(i128, 122)), i64)
        back = builder.and_(builder.neg(rot), ir.Constant(i64, 63))  # pcg_rotr_64: (v >> rot) | (v << (-rot & 63))
        return builder.or_(builder.lshr(xored, rot), builder.shl(xored, back))

    return types.uint64(types.uint64), codegen


@njit(nogil=True, refcounts=False, inline="always")
def _next64(handle: np.uint64) -> np.uint64:
    """The bit generator's next_uint64 (see :func:`bitgen_address` for ``handle``)."""
    # the ignores here and below: numba's stubs type an @intrinsic's call as its typing function's (typingctx first)
    if handle & np.uint64(INLINE):
        return _pcg64_next64(handle - np.uint64(INLINE))  # type: ignore[call-arg,arg-type]
    return _next_uint64(  # type: ignore[call-arg]
        _word(handle + np.uint64(_NEXT_UINT64 * WORD)),  # type: ignore[call-arg,arg-type]
        _word(handle),  # type: ignore[call-arg,arg-type]
    )


@njit(nogil=True, refcounts=False, inline="always")
def _next_uniform(handle: np.uint64) -> float:
    """The bit generator's next_double: for PCG64 numpy's ``uint64_to_double`` of next_uint64 (_common.pxd)."""
    if handle & np.uint64(INLINE):
        return float(
            _pcg64_next64(handle - np.uint64(INLINE))  # type: ignore[call-arg,arg-type]  # as above
            >> np.uint64(11)
        ) * (1.0 / 9007199254740992.0)
    return _next_double(  # type: ignore[call-arg]
        _word(handle + np.uint64(_NEXT_DOUBLE * WORD)),  # type: ignore[call-arg,arg-type]
        _word(handle),  # type: ignore[call-arg,arg-type]
    )


@njit(nogil=True, refcounts=False, inline="always")
def standard_normal(bitgen: np.uint64) -> float:
    """One draw of ``Generator.standard_normal()`` from the Generator whose handle (:func:`bitgen_address`)
    is ``bitgen`` (numpy's ``random_standard_normal``, line for line)."""
    handle = np.uint64(bitgen)
    while True:
        r = _next64(handle)
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
                xx = -ziggurat_nor_inv_r * np.log1p(-_next_uniform(handle))
                yy = -np.log1p(-_next_uniform(handle))
                if yy + yy > xx * xx:
                    return -(ziggurat_nor_r + xx) if (rabs >> np.uint64(8)) & np.uint64(1) else ziggurat_nor_r + xx
        elif (fi_double[idx - np.uint64(1)] - fi_double[idx]) * _next_uniform(handle) + fi_double[idx] < np.exp(
            -0.5 * x * x
        ):
            return x


@njit(nogil=True, refcounts=False)
def fill(bitgen: np.uint64, out: np.ndarray) -> None:
    """``Generator.standard_normal(out=out)`` for a one-dimensional ``out``."""
    for k in range(out.shape[0]):
        out[k] = standard_normal(bitgen)


@njit(nogil=True, refcounts=False)
def normal_rows(handles: np.ndarray, out: np.ndarray) -> None:
    """``out[k] = Generator.standard_normal(out.shape[1])`` from the Generator whose handle is ``handles[k]``,
    for every row k: a fleet's robots draw their first numbers in one call, not one Python call each."""
    for k in range(out.shape[0]):
        fill(handles[k], out[k])


# --- robots' PCG64 states kept in an array, seeded as numpy seeds them ---------------------------------------


@intrinsic
def _pcg64_seed(
    typingctx: TypingContext,
    address: types.Type,
    state_high: types.Type,
    state_low: types.Type,
    seq_high: types.Type,
    seq_low: types.Type,
) -> tuple[Signature, Callable[..., ir.Value]]:
    """numpy's ``pcg64_set_seed`` into the ``pcg64_random_t`` at ``address`` (numpy/random/src/pcg64/pcg64.c;
    pcg_setseq_128_srandom_r of pcg64.h): inc = initseq << 1 | 1, state = 0, one step, state += initstate,
    one step. The 128-bit initstate and initseq each come as their high and low words."""

    def codegen(context: BaseContext, builder: ir.IRBuilder, sig: Signature, args: Sequence[ir.Value]) -> ir.Value:
        i128 = ir.IntType(128)

        def wide(high: ir.Value, low: ir.Value) -> ir.Value:
            return builder.or_(builder.shl(builder.zext(high, i128), ir.Constant(i128, 64)), builder.zext(low, i128))

        words = builder.inttoptr(args[0], i128.as_pointer())
        inc = builder.or_(builder.shl(wide(args[3], args[4]), ir.Constant(i128, 1)), ir.Constant(i128, 1))
        state = builder.add(inc, wide(args[1], args[2]))  # the first step from 0 leaves inc; then + initstate
        state = builder.add(builder.mul(state, ir.Constant(i128, PCG64_MULTIPLIER)), inc)
        builder.store(state, words, align=8)
        builder.store(inc, builder.gep(words, [ir.Constant(ir.IntType(32), 1)]), align=8)
        return context.get_dummy_value()

    return types.void(types.uint64, types.uint64, types.uint64, types.uint64, types.uint64), codegen


@njit(nogil=True, refcounts=False)
def seed_pcg64(states: np.ndarray, words: np.ndarray) -> None:
    """Row k of ``states`` (an (N, 4) uint64 array: state then increment, low word first, as numpy's PCG64 keeps
    them) becomes what ``PCG64`` seeded with ``words[k]`` holds (its seed sequence's ``generate_state(4,
    np.uint64)``: initstate's high and low words, then initseq's)."""
    base = states.ctypes.data
    for k in range(states.shape[0]):
        row, seed = np.uint64(base + k * 4 * WORD), words[k]
        _pcg64_seed(row, seed[0], seed[1], seed[2], seed[3])  # type: ignore[call-arg,arg-type]  # as above


def state_handles(states: np.ndarray) -> np.ndarray:
    """The inline handles (see :func:`bitgen_address`) of the PCG64 states in the rows of ``states`` (an (N, 4)
    C-ordered uint64 array the caller keeps alive, and in place, while compiled code draws from it)."""
    assert states.flags.c_contiguous and states.dtype == np.uint64 and states.shape[1] == 4
    return np.uint64(states.ctypes.data + INLINE) + np.arange(len(states), dtype=np.uint64) * np.uint64(4 * WORD)
