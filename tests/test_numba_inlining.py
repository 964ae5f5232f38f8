"""numba's inliner, made to copy a callee's variables once per copy rather than once per block of it
(tablebot.jit_inlining): the same machine code, for fewer copies.

A function with an ``inline="always"`` callee of many blocks is compiled in a fresh process twice: with the
change, then with numba's own ``inline_ir`` put back. Both give the same results and the same assembly (symbol
names aside: numba numbers each compile's), and numba's way copies the callee's variables many times more."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tablebot.testing.processes import child_env

pytestmark = [pytest.mark.kernel_free]

BOTH_WAYS = r"""
import json, re, sys
import numpy as np
import tablebot.jit  # the change is made when numba's inliner is first imported

lazy = "numba.core.inline_closurecall" not in sys.modules  # a process that compiles nothing never imports it
from numba import njit
from numba.core import ir
from numba.core.inline_closurecall import InlineWorker


def callee(a, i):  # many blocks and variables: every branch and loop is a block of its own
    total = 0.0
    for k in range(i):
        x = a[k % a.size]
        if x > 3.0:
            total += x * 2.0
        elif x > 1.0:
            total -= x
        elif x < -2.0:
            total *= 0.5
        else:
            total += 1.0
        y = total * 0.25
        if y > 100.0:
            total = y
    return total


def caller(a):
    return inlined(a, 3) + inlined(a, 7) - inlined(a, 11)


copies = [0]
var_deepcopy = ir.Var.__deepcopy__


def counted(self, memo):
    copies[0] += 1
    return var_deepcopy(self, memo)


ir.Var.__deepcopy__ = counted


def compile_once():
    global inlined
    inlined = njit(inline="always")(callee)
    compiled = njit(caller)
    copies[0] = 0
    a = np.array([0.5, 4.0, -3.0, 2.0, 1.5, -0.5])
    result = compiled(a)
    asm = compiled.inspect_asm(compiled.signatures[0])
    return result, copies[0], re.sub(r"[_$.A-Za-z0-9]*(inlined|caller|callee)[_$.A-Za-z0-9]*", "SYM", asm)


changed = InlineWorker.inline_ir
ours = compile_once()
InlineWorker.inline_ir = changed.original
numbas = compile_once()
print(json.dumps({"lazy": lazy, "scopes_once": getattr(changed, "scopes_once", False), "results": [ours[0], numbas[0]],
                  "copies": [ours[1], numbas[1]], "same_asm": ours[2] == numbas[2], "asm_lines": ours[2].count("\n")}))
"""


def test_the_inliner_copies_each_scope_once_and_compiles_the_same_machine_code() -> None:
    done = subprocess.run(
        [sys.executable, "-c", BOTH_WAYS], env=child_env(), capture_output=True, text=True, timeout=180
    )
    assert done.returncode == 0, done.stderr
    found = json.loads(done.stdout.strip().splitlines()[-1])
    assert found["lazy"] is True and found["scopes_once"] is True
    assert found["results"][0] == found["results"][1]
    assert found["same_asm"] is True and found["asm_lines"] > 100
    ours, numbas = found["copies"]
    assert 0 < ours * 3 < numbas, found["copies"]  # numba's own: blocks × variables
