"""`tablebot tests`: golden input sequences that fire every row that can fire, with expected traces."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from tablebot.analysis.testgen import generate, write_golden
from tablebot.cli import app
from tablebot.formats.inputs_csv import load_inputs
from tablebot.formats.table_read import load_table
from tablebot.formats.trace_lines import dumps
from tablebot.machine import compile_table
from tablebot.replay import replay

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from typing import Any

    from tablebot.machine import Machine

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "analysis"
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bumberbot"
runner = CliRunner()


def golden_files(table: Path, out: Path) -> tuple[Machine, dict[str, Any]]:
    machine = compile_table(load_table(table))
    write_golden(generate(machine), out)
    return machine, json.loads((out / "coverage.json").read_text())


def test_bumberbot_every_row_fires_and_traces_match(tmp_path: Path) -> None:
    machine, cov = golden_files(EXAMPLE / "table.csv", tmp_path)
    assert cov["rows_total"] == cov["rows_fireable"] == cov["rows_covered"] == 37
    fired = set()
    for seq in cov["sequences"]:
        ticks = load_inputs(tmp_path / seq["inputs"], machine)
        expected = (tmp_path / seq["trace"]).read_text().splitlines()
        lines = list(replay(machine, ticks))
        assert [dumps(line) for line in lines] == expected  # the reference engine agrees byte for byte
        fired |= {line["row"] for line in lines if line["row"] is not None}
    assert fired == set(range(37))
    assert all(row["covered"] and row["fired_by"] for row in cov["rows"])


def test_rows_that_cannot_fire_are_explained(tmp_path: Path) -> None:
    _, cov = golden_files(FIX / "shadowed.csv", tmp_path)
    assert cov["rows_covered"] == cov["rows_fireable"] == 3 and cov["rows_total"] == 4
    (missing,) = [row for row in cov["rows"] if not row["covered"]]
    assert missing["line"] == 4 and "earlier row on line 3" in missing["why_not"]


def test_unreachable_state_and_busy_timer_reasons(tmp_path: Path) -> None:
    _, cov = golden_files(FIX / "unreachable.csv", tmp_path / "u")
    assert [r["why_not"] for r in cov["rows"] if not r["covered"]] == [
        "state 3 (Lost) can never be reached from the initial state 1 (Drive): no row leads to it; "
        "its rows (line 4) are dead"
    ]
    _, cov = golden_files(FIX / "busy.csv", tmp_path / "b")
    (why,) = [r["why_not"] for r in cov["rows"] if not r["covered"]]
    assert "timer never runs out" in why


def test_counter_tables_get_pulse_columns(tmp_path: Path) -> None:
    _, cov = golden_files(FIX / "counters.csv", tmp_path)
    assert cov["rows_covered"] == 4
    header = (tmp_path / cov["sequences"][0]["inputs"]).read_text().splitlines()[0]
    assert header == "A,C1"


def test_command_reports_coverage(tmp_path: Path) -> None:
    result = runner.invoke(app, ["tests", str(FIX / "shadowed.csv"), "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert "row coverage: 3 of 4 rows fired (3 can fire at all)" in result.stdout
    assert "line 4: not covered: row on line 4 can never fire" in result.stdout
    assert (tmp_path / "seq-01.csv").is_file() and (tmp_path / "seq-01.jsonl").is_file()
