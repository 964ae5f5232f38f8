"""Issue 4's proof in the simulator: turns counted in encoder pulses do not drift as the battery drains."""

from __future__ import annotations

import importlib.util
import json
import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tablebot.sim.runner import simulate
from tablebot.sim.summary import summarise
from tablebot.testing.turn_drift import turns
from test_sim_helpers import ROOT, scene_of, trace_text

if TYPE_CHECKING:
    from types import ModuleType

EXAMPLE = ROOT / "examples" / "bumberbot-counters"
TURN = EXAMPLE / "turn90"


def load_script(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    sys.modules[name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def test_the_timed_turn_drifts_to_80_degrees_and_below() -> None:
    found = {t.charge: t.degrees for t in turns(TURN / "timed.csv", [1.0, 0.5, 0.2], [1])}
    assert abs(found[1.0] - 90.0) < 3.0
    assert found[1.0] > found[0.5] > found[0.2]
    assert found[0.5] <= 80.0 and found[0.2] < 75.0


def test_the_counted_turn_stays_within_3_degrees_of_90() -> None:
    for turn in turns(TURN / "counted.csv", [1.0, 0.5, 0.0], [1, 2, 3]):
        assert abs(turn.degrees - 90.0) <= 3.0, turn


def test_the_counter_event_fires_on_the_tick_the_encoder_pulses_reach_the_load() -> None:
    scene = scene_of(TURN / "counted.csv", None)
    result = simulate(scene, 4.0)
    lines = [json.loads(line) for line in trace_text(result).splitlines()]
    assert lines[0]["row"] == 0 and lines[0]["C1"] == lines[0]["C2"] == 35  # loaded on tick 0
    pulses = result.pulses[:, 0].cumsum()  # pulses of C1's motor handed to the engine, tick by tick
    zero = next(i for i, line in enumerate(lines) if line["C1"] == 0)
    assert pulses[zero] >= 35 > pulses[zero - 1]
    assert lines[zero]["row"] in (1, 2) and lines[zero]["M1"] == 0  # the stop row fires on that very tick


def spin_degrees(folder: Path, charge: float) -> float:
    """Degrees turned during the BumberBot's first 270° spin (state 2, entered from state 1)."""
    scene = scene_of(folder / "table.csv", None, battery={"charge": charge})
    result = simulate(scene, 20.0, seed=1)
    states = [scene.machine.states[s] for s in result.states.tolist()]
    begin = next(t for t in range(1, len(states)) if states[t] == 2 and states[t - 1] == 1)
    end = next(t for t in range(begin, len(states)) if states[t] != 2)
    heading = result.heading_deg()
    return float(heading[end + 1] - heading[begin + 1])


@pytest.mark.parametrize("charge", [1.0, 0.2])
def test_the_counters_bumberbot_spins_270_degrees_whatever_the_battery(charge: float) -> None:
    assert abs(spin_degrees(EXAMPLE, charge) + 270.0) < 5.0
    timed = spin_degrees(ROOT / "examples" / "bumberbot", charge)
    assert (abs(timed + 270.0) < 5.0) if charge == 1.0 else (timed > -220.0)


def test_a_drained_bumberbot_finds_the_lamp_only_with_counters() -> None:
    drained = {"battery": {"charge": 0.2}}
    timed = summarise(simulate(scene_of(ROOT / "examples" / "bumberbot" / "table.csv", None, **drained), 120.0))
    counted = summarise(simulate(scene_of(EXAMPLE / "table.csv", None, **drained), 120.0))
    assert timed.reached_s is None
    assert counted.reached_s is not None


def test_turn_drift_script_writes_plot_and_tables(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    script = load_script("turn_drift")
    assert script.main(["--out", str(tmp_path), "--seeds", "1"]) == 0
    out = capsys.readouterr().out
    assert "| 100% |" in out and "| 0% |" in out
    for name in ("turn_drift.png", "turn_drift.csv", "turn_drift.md"):
        assert (tmp_path / name).stat().st_size > 0
    rows = (tmp_path / "turn_drift.csv").read_text().splitlines()
    assert len(rows) == 12 and rows[0].startswith("charge,volts,timed_mean")


def test_sim_benchmark_reports_figures_that_agree_with_each_other(capsys: pytest.CaptureFixture[str]) -> None:
    """What a reader of benchmarks/sim.py checks (no timing asserted): the run it says it timed, each way's
    time per tick and speed against real time agreeing (a 10 ms tick), the ratio between the two ways of
    running the loop, and a target's verdict that follows from its figure."""
    load_script("sim").main(["--repeat", "1", "--seconds", "5", "--no-commands"])
    out = capsys.readouterr().out
    assert "one BumberBot in BumberBot arena, 5 s simulated (500 ticks), median of 1" in out
    rows = {
        m["name"].strip(): (float(m["us"]), float(m["times"].replace(",", "")))
        for m in re.finditer(
            r"^  (?P<name>.+?)\s+(?P<wall>[\d.]+)\s+(?P<us>[\d.]+)\s+(?P<times>[\d,]+)$", out, re.MULTILINE
        )
    }
    assert set(rows) == {
        "run loop, compiled block path",
        "run loop, tick by tick from Python (baseline)",
        "engine alone, Engine.step on recorded inputs",
    }
    for us, times in rows.values():  # × real time is the 10,000 µs tick over µs a tick (both rounded)
        assert us > 0 and times == pytest.approx(10_000 / us, rel=0.06, abs=1)
    compiled, python = rows["run loop, compiled block path"], rows["run loop, tick by tick from Python (baseline)"]
    ratio = float(re.search(r"compiled loop vs tick-by-tick: ([\d.]+)×", out)[1])  # type: ignore[index]
    assert ratio == pytest.approx(python[0] / compiled[0], rel=0.06)
    verdict = re.search(r"run loop ≥ 10,000× real time\s+(ok|MISSED)", out)[1]  # type: ignore[index]
    assert verdict == ("ok" if compiled[1] >= 10_000 else "MISSED")
