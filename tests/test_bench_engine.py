"""benchmarks/engine.py keeps working: every contestant agrees with the engine (no timing asserted)."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

if TYPE_CHECKING:
    from types import ModuleType

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "engine.py"


def load_benchmark() -> ModuleType:
    pytest.importorskip("transitions", reason="the engine benchmark compares with the transitions library (dev extra)")
    spec = importlib.util.spec_from_file_location("bench_engine", SCRIPT)
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def test_contestants_agree_on_a_short_run(capsys: pytest.CaptureFixture[str]) -> None:
    bench = load_benchmark()
    bench.main(["--ticks", "3000", "--repeats", "1", "--transitions-ticks", "500"])  # asserts agreement
    out = capsys.readouterr().out
    for name in ("batch", "step", "bare step", "linear scan", "bare loop", "transitions", "targets", "closed loop"):
        assert name in out


def test_contestants_match_the_engine_tick_for_tick_state() -> None:
    bench = load_benchmark()
    machine = bench.compile_table(bench.load_table(bench.EXAMPLE))
    masks = bench.random_masks(machine, 5000)
    assert any(masks) and max(masks) < 32
    expected = bench.engine_step(machine, masks)
    for run in (bench.engine_batch, bench.linear_scan, bench.bare_loop, bench.bare_step):
        assert run(machine, masks) == expected
    assert bench.transitions_run(machine, masks[:700]) == bench.engine_step(machine, masks[:700])
