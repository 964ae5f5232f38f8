"""``tablebot evolve``'s parts without the fleet: the operators keep the user's limits, the proof cache's
canonical form, the repair of the BumberBot's front_bumper_stops, and bad options as clear errors."""

from __future__ import annotations

import shutil
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from tablebot.analysis.check import run_check
from tablebot.analysis.properties import find_property_files, load_properties
from tablebot.cli import app
from tablebot.evolve import space
from tablebot.evolve.operators import Space, vary
from tablebot.evolve.proofs import Prover, canonical
from tablebot.evolve.repair import repair
from tablebot.evolve.report import as_table
from tablebot.formats.table_read import load_table, parse_table
from tablebot.formats.table_write import format_table
from tablebot.machine import compile_table
from tablebot.table import Table

ROOT = Path(__file__).resolve().parents[2]
BUMBERBOT = ROOT / "examples" / "bumberbot" / "table.csv"
PROPERTIES = find_property_files(BUMBERBOT)


def bumberbot_space(**limits: Any) -> tuple[Table, Space]:
    table = load_table(BUMBERBOT)
    made = space.Limits(max_rows=space.default_max_rows(table), timer_max=space.default_timer_max(table))
    return table, Space(table.states, table.robot.motors, replace(made, **limits))


def test_variation_keeps_the_states_the_row_limit_and_every_frozen_cell() -> None:
    table, sp = bumberbot_space(
        max_rows=40, frozen_states=frozenset({20, 21}), frozen_cells=frozenset({(5, "timer"), (9, "*"), (15, "M1")})
    )
    rng = np.random.default_rng(3)
    start = space.start(table)
    frozen = [g for g in start if g.state in (20, 21) or g.origin == 9]
    changed = 0
    for _ in range(300):
        child = vary(start, sp, rng)
        assert child is not None
        assert len(child) <= 40 and {g.state for g in child} == set(table.states)
        assert [g for g in child if g.state in (20, 21)] == [g for g in start if g.state in (20, 21)]
        by_origin = {g.origin: g for g in child if g.origin is not None}
        assert all(g.origin is not None and by_origin[g.origin] == g for g in frozen)  # never removed, never changed
        assert by_origin[5].timer == 895 and by_origin[15].motors[0] == 3
        assert all(set(g.events) <= set(table.events) and g.next in table.states for g in child)
        changed += child != start
    assert changed == 300


def test_the_canonical_form_ignores_words_and_order_that_change_nothing() -> None:
    table = load_table(BUMBERBOT)
    key = canonical(compile_table(table))
    rows = list(table.rows)
    # Rows of different states never compete: state 2's rows first (which renumbers the states inside
    # the compiled machine), and every description changed, is the same machine.
    moved = [*rows[4:8], *rows[:4], *rows[8:]]
    moved = [replace(r, index=k, description=f"renamed {k}") for k, r in enumerate(moved)]
    assert canonical(compile_table(replace(table, rows=tuple(moved)))) == key
    slower = [replace(r, timer=r.timer + 1) if r.line == 5 else r for r in rows]
    assert canonical(compile_table(replace(table, rows=tuple(slower)))) != key


def test_verdicts_are_cached_on_disk_and_read_back(tmp_path: Path) -> None:
    table = load_table(BUMBERBOT)
    cache = tmp_path / "proofs.jsonl"
    prover = Prover(PROPERTIES, cache)
    key, verdict = prover.verdict(table)
    assert not verdict.ok and verdict.failed == ("front_bumper_stops",)
    assert prover.verdict(table) == (key, verdict) and (prover.proved, prover.hits) == (1, 1)
    again = Prover(PROPERTIES, cache)
    assert again.verdict(table) == (key, verdict) and (again.proved, again.hits) == (0, 1)


def test_the_bumberbot_is_repaired_where_the_document_forgot_its_bumpers() -> None:
    """docs/checking.md: states 29 and 12 never look at the front bumpers, and the back-off states turn
    forward when their timer runs out with a bumper pressed. The repair guards exactly those states, and
    the repaired table, written and read back, satisfies every shipped property by check itself."""
    table, sp = bumberbot_space()
    repaired = repair(space.start(table), table, Prover(PROPERTIES), sp, "keep")
    assert repaired.ok, repaired.failing
    assert {step.state for step in repaired.steps} == {22, 24, 26, 29, 12}
    assert all(step.prop == "front_bumper_stops" for step in repaired.steps)
    text = format_table(as_table(repaired.candidate, table, Path("repaired.csv")))
    back = parse_table(text, "repaired.csv", table.robot)
    machine = compile_table(back)
    report = run_check(machine, load_properties(machine, PROPERTIES))
    assert [r.status for r in report.results] == ["holds"] * 6
    assert "keep going (guard for front_bumper_stops)" in text


def evolve(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(app, ["evolve", *args])
    return result.exit_code, result.output


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--objective", "laps"], "--objective laps: the worlds cannot measure it"),
        (["--objective", "speed"], "--objective speed: unknown objective"),
        (["--descriptors", "wiggles"], "--descriptors wiggles: unknown descriptor"),
        (["--descriptors", "distance=3..1"], "the range must be LOW..HIGH"),
        (["--descriptors", "distance,collisions,laps"], "the worlds cannot measure it"),
        (["--freeze-cell", "line 99 timer"], "line 99 of"),
        (["--freeze-cell", "line 5 I3"], "'I3' is not a cell evolution changes"),
        (["--freeze-state", "7"], "the table has no state 7"),
        (["--max-rows", "10"], "--max-rows 10 is fewer than the 37 rows"),
        (["--batch", "50", "--budget", "10"], "--batch 50 is more than --budget 10"),
        (["--descriptors", ""], "--descriptors needs one or two descriptors, not 0"),
    ],
)
def test_bad_options_are_clear_errors_naming_the_option(tmp_path: Path, args: list[str], words: str) -> None:
    code, output = evolve(str(BUMBERBOT), "--out", str(tmp_path / "o"), "--seeds", "0..1", *args)
    assert code == 2, output
    assert words in output and "Traceback" not in output
    assert not (tmp_path / "o").exists()  # refused before anything is written


def test_a_property_naming_a_file_line_is_refused(tmp_path: Path) -> None:
    props = tmp_path / "p.toml"
    props.write_text('[seek]\ntext = "x"\nnever = "I3 and line==5"\n', encoding="utf-8")
    code, output = evolve(str(BUMBERBOT), "--out", str(tmp_path / "o"), "--properties", str(props))
    assert code == 2, output
    assert "property seek names a file line" in output and "p.toml" in output


def test_out_may_not_be_the_folder_the_table_is_read_from(tmp_path: Path) -> None:
    """It was taken: examples/bumberbot filled with tables, reports and records beside the robot's files."""
    bot = tmp_path / "bot"
    shutil.copytree(BUMBERBOT.parent, bot)
    before = sorted(p.name for p in bot.iterdir())
    code, output = evolve(str(bot / "table.csv"), "--out", str(bot), "--seeds", "0..1")
    assert code == 2 and "--out" in output and "is the folder of table.csv" in output, output
    assert sorted(p.name for p in bot.iterdir()) == before


def test_the_before_after_change_is_weighed_against_its_spread() -> None:
    """One scenario printed "± nan" and called it no clear difference; two or more weigh the change."""
    from tablebot.evolve.measures import MEASURES
    from tablebot.evolve.report import paired

    lamp = MEASURES["time_to_lamp"]  # low is better
    assert (
        paired(lamp, np.array([30.0]), np.array([20.0]))
        == "-10.000 (one scenario, so no standard error): no clear difference"
    )
    assert paired(lamp, np.array([30.0, 31.0, 29.0]), np.array([20.0, 22.0, 19.0])).endswith(": better")
    assert paired(lamp, np.array([30.0, 10.0, 29.0]), np.array([20.0, 40.0, 19.0])).endswith("no clear difference")
    assert "nan" not in paired(lamp, np.array([5.0, 5.0]), np.array([5.0, 5.0]))
