"""benchmarks/engine.py keeps working: every contestant agrees with the engine (no timing asserted)."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from types import ModuleType

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "engine.py"


def load_benchmark() -> ModuleType:
    pytest.importorskip("transitions", reason="the engine benchmark compares with the transitions library (dev extra)")
    spec = importlib.util.spec_from_file_location("bench_engine", SCRIPT)
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


ROW = re.compile(
    r"^  (?P<name>[a-z ()]+?)\s+(?P<cpu>[\d.]+) s CPU\s+(?P<rate>[\d,]+) ticks/s"
    r"\s+(?P<ns>[\d.]+) ns/tick$",
    re.MULTILINE,
)
TARGET = re.compile(
    r"^  (?P<a>[a-z ]+?) vs (?P<b>[a-z ]+?)(?: \([^)]*\))?\s+(?P<ratio>[\d.]+)x "
    r"\((?P<low>[\d.]+)\.\.(?P<high>[\d.]+)\)\s+target >= (?P<want>[\d.]+)x\s+(?P<verdict>ok|MISSED)$",
    re.MULTILINE,
)


def test_a_short_run_reports_figures_that_agree_with_each_other(capsys: pytest.CaptureFixture[str]) -> None:
    """What a reader of the report checks (no timing asserted; main itself asserts that the contestants
    agree): the run it says it timed, every contestant's rate and time per tick agreeing, each target's ratio
    being the ratio of the two rates it names, and its verdict following from its figure."""
    bench = load_benchmark()
    bench.main(["--ticks", "3000", "--repeats", "1", "--transitions-ticks", "500"])
    out = capsys.readouterr().out
    assert out.startswith("BumberBot, 3,000 random input ticks (500 for transitions), median of 1,")
    rates = {m["name"]: float(m["rate"].replace(",", "")) for m in ROW.finditer(out)}
    assert set(rates) == {"step", "bare step", "linear scan", "transitions", "batch", "batch (array)", "bare loop"}
    for m in ROW.finditer(out):
        assert float(m["rate"].replace(",", "")) * float(m["ns"]) == pytest.approx(1e9, rel=0.002)
    targets = list(TARGET.finditer(out))
    assert [(t["a"], t["b"]) for t in targets] == [
        ("step", "bare step"),
        ("step", "linear scan"),
        ("step", "transitions"),
        ("batch", "bare loop"),
    ]
    for t in targets:
        ratio = float(t["ratio"])
        # one round: its own median; the rates are printed rounded, so a large ratio differs in its last digits
        assert ratio == pytest.approx(rates[t["a"]] / rates[t["b"]], rel=0.002, abs=0.006)
        assert float(t["low"]) == float(t["high"]) == ratio
        assert t["verdict"] == ("ok" if ratio >= float(t["want"]) else "MISSED")


def test_contestants_match_the_engine_tick_for_tick_state() -> None:
    bench = load_benchmark()
    machine = bench.compile_table(bench.load_table(bench.EXAMPLE))
    masks = bench.random_masks(machine, 5000)
    assert any(masks) and max(masks) < 32
    expected = bench.engine_step(machine, masks)
    for run in (bench.engine_batch, bench.linear_scan, bench.bare_loop, bench.bare_step):
        assert run(machine, masks) == expected
    assert bench.transitions_run(machine, masks[:700]) == bench.engine_step(machine, masks[:700])
