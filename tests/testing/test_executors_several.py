"""The differential harness on robots of several tables (issue 36 §2, tablebot.testing.several_cases): random robots
of 2-3 tables with cross-table events, and the BumberBot with its lights, through every executor that runs several
tables, each equal to tablebot.engine.several tick for tick; and the engine's trace is the same in every order of
the tables."""

from __future__ import annotations

import itertools
import random
from pathlib import Path

import pytest

import tablebot.testing.executors  # noqa: F401  (registers the executors)
from tablebot.loading import Loaded
from tablebot.replay import replay_several
from tablebot.testing.harness import EXECUTORS, Run
from tablebot.testing.several_cases import (
    SeveralCase,
    check_several,
    random_several_case,
    several_differences,
    several_ticks,
)

STUB = Path(__file__).resolve().parents[1] / "txt4_stub"
LIGHTS = Path(__file__).resolve().parents[2] / "examples" / "bumberbot-lights"
#: The executors that run several tables; the others say they run one table only. The ROBO Interface counts
#: nothing: it takes the BumberBot with its lights, not the random robots (their tables load a counter).
SEVERAL = {"python step", "host C", "AVR firmware", "TXT 4.0 program", "ROBO TX", "ROBO Interface", "ROBO Pro program"}
NO_COUNTERS = {"ROBO Interface"}
#: The ROBO Pro program takes the document's speeds (0..6) only, which random robots seldom keep to: its own
#: random robots do (tests/robopro/test_robopro_several.py); here it runs where it fits and says why where it does not.
DOCUMENT_SPEEDS = {"ROBO Pro program"}


def test_the_registry_says_which_executors_run_several_tables() -> None:
    assert {name for name, executor in EXECUTORS.items() if executor.several} == SEVERAL


@pytest.mark.parametrize("seed", range(4))
def test_every_executor_of_several_tables_takes_the_engines_decisions(
    tmp_path: Path, seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("TABLEBOT_TXT4_STUB", str(STUB))
    case = random_several_case(seed, tmp_path / "robot")
    report = check_several(case, tmp_path / "runs")
    assert report.differ == {}
    assert set(report.agreed) - DOCUMENT_SPEEDS == SEVERAL - NO_COUNTERS - DOCUMENT_SPEEDS, report.skipped
    assert all(
        why == "runs one table only"
        for name, why in report.skipped.items()
        if name not in NO_COUNTERS | DOCUMENT_SPEEDS
    ), report.skipped
    assert all(why == "does not take this robot" for name, why in report.skipped.items() if name in DOCUMENT_SPEEDS)


def test_the_bumberbot_with_its_lights_through_every_executor(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("TABLEBOT_TXT4_STUB", str(STUB))
    tables = Loaded.open(LIGHTS).tables
    assert tables is not None
    case = SeveralCase(tables, tuple(several_ticks(random.Random(5), tables, 600, density=0.2)))
    lights = {line["lights.state"] for line in replay_several(tables, case.inputs)}
    assert len(lights) >= 3, lights  # the lights table went somewhere
    report = check_several(case, tmp_path)
    assert report.differ == {} and set(report.agreed) == SEVERAL, report.skipped


@pytest.mark.parametrize("seed", [1, 3])
def test_every_order_of_the_tables_gives_the_same_trace(tmp_path: Path, seed: int) -> None:
    case = random_several_case(seed, tmp_path)
    assert len(case.tables.machines) == 3
    run = EXECUTORS["python step"].several(case, tmp_path)  # type: ignore[misc]
    for order in itertools.permutations(range(3)):
        assert several_differences(case.tables, run, order) is None, order


def test_a_wrong_decision_of_another_table_is_found_at_its_tick(tmp_path: Path) -> None:
    """The comparison can fail: one other table's state changed in one tick's line, or left out, is named."""
    case = random_several_case(1, tmp_path)
    run = EXECUTORS["python step"].several(case, tmp_path)  # type: ignore[misc]
    assert several_differences(case.tables, run) is None
    bad = [dict(line) for line in run.lines]
    bad[57]["t1.state"] = "nowhere"
    found = several_differences(case.tables, Run(run.inputs, bad))
    assert found is not None and found.startswith("tick 57: t1.state is 'nowhere'"), found
    del bad[57]["t1.state"]
    assert several_differences(case.tables, Run(run.inputs, bad)) == "tick 57: no t1.state reported"
