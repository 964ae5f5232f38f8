"""numba's inliner, made to copy a callee's variables once per copy of the callee rather than once per block of it.

To inline a call (``inline="always"``) numba copies the callee's IR block by block, each block with a ``deepcopy``
of its own, and each of those copies the function's whole scope -- every variable of the callee -- again: blocks ×
variables, for every call inlined (numba issues #8989 and #9204; numba-cuda #688 measured the same). The simulator's
tick loops inline the whole physics, and a first compile spent most of its time there: ``run_ticks`` 29 s, 7 s with
this; the simulator's kernels the tests warm (one process, an empty cache) 91 s, 46 s with this. While one call is
inlined (``InlineWorker.inline_ir``), every block's copy of a scope is the one copy the first block made, as the
blocks shared the original (numba's inliner keeps one scope of them anyway). The machine code is the same:
tests/test_numba_inlining.py compiles an inlined function both ways, and every function of the kernels
disassembled the same both ways.

The change is made when numba's inliner module is first imported (:func:`copy_each_scope_once`), which numba does
for its first compile: a process that only loads cached machine code never imports it (~30 ms). Another numba
(without ``inline_ir``, or whose scopes copy themselves) is left as it is.
"""

from __future__ import annotations

import copy
import importlib.abc
import importlib.util
import sys
from collections.abc import Callable, Sequence
from importlib.machinery import ModuleSpec
from types import ModuleType
from typing import Any

INLINER = "numba.core.inline_closurecall"
# While numba inlines one call: each scope's one copy. One table for the process, not per thread: numba compiles,
# and so inlines, under its global compiler lock, one call at a time.
_scope_copies: dict[int, tuple[Any, Any]] | None = None


def copy_each_scope_once() -> None:
    """Change numba's inliner now if it is imported, else right after its first import."""
    if INLINER in sys.modules:
        _change_inliner()
    elif not any(isinstance(finder, _AfterImport) for finder in sys.meta_path):
        sys.meta_path.insert(0, _AfterImport(INLINER, _change_inliner))


class _AfterImport(importlib.abc.MetaPathFinder):
    """Runs ``then`` right after module ``name`` is first executed; asks nothing of any other import."""

    def __init__(self, name: str, then: Callable[[], None]) -> None:
        self.name, self.then = name, then

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if fullname != self.name:
            return None
        sys.meta_path.remove(self)  # once, and the search below finds the module as it would have
        spec = importlib.util.find_spec(fullname)
        loader = spec.loader if spec is not None else None
        if loader is None or not hasattr(loader, "exec_module"):
            return spec
        run = loader.exec_module

        def exec_module(module: ModuleType) -> None:
            run(module)
            self.then()

        loader.exec_module = exec_module  # type: ignore[method-assign]  # this spec's own loader
        return spec


def _change_inliner() -> None:
    from numba.core import ir
    from numba.core.inline_closurecall import InlineWorker

    original = getattr(InlineWorker, "inline_ir", None)
    if original is None or getattr(original, "scopes_once", False) or "__deepcopy__" in vars(ir.Scope):
        return

    def scope_deepcopy(self: Any, memo: dict[int, Any]) -> Any:
        made = _scope_copies.get(id(self)) if _scope_copies is not None else None
        if made is not None:
            memo[id(self)] = made[1]
            return made[1]
        new = object.__new__(type(self))  # what deepcopy does for a plain object: new, remembered, its state copied
        memo[id(self)] = new
        new.__dict__.update(copy.deepcopy(self.__dict__, memo))
        if _scope_copies is not None:
            _scope_copies[id(self)] = (self, new)  # the original is held: its id stays its own meanwhile
        return new

    def inline_ir(self: Any, *args: Any, **kwargs: Any) -> Any:
        global _scope_copies
        outer, _scope_copies = _scope_copies, {}  # per call: a callee inlined again gets copies of its own
        try:
            return original(self, *args, **kwargs)
        finally:
            _scope_copies = outer

    inline_ir.scopes_once = True  # type: ignore[attr-defined]
    inline_ir.original = original  # type: ignore[attr-defined]  # numba's own (the tests compare the two)
    ir.Scope.__deepcopy__ = scope_deepcopy  # type: ignore[attr-defined]
    InlineWorker.inline_ir = inline_ir  # type: ignore[method-assign]
