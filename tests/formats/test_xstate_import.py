"""``import --from xstate`` reads what ``export --to xstate`` wrote, the same table bytes back, and refuses anything
else, named by its JSON path (or line and column when it is not JSON at all)."""

from __future__ import annotations

import json
import random
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from tablebot.diagnostics import TableBotError
from tablebot.formats.statecharts.read_xstate import read_xstate
from tablebot.formats.statecharts.xstate import export_xstate
from tablebot.formats.table_read import load_table, resolve_table_path
from tablebot.formats.table_write import format_table
from tablebot.table import Table
from tablebot.testing.random_tables import Shape, random_table

EXAMPLES = ("bumberbot", "bumberbot-counters", "line-follower", "obstacle-avoider")


def _rows(table: Table) -> list[object]:
    return [replace(row, line=0) for row in table.rows]


@pytest.mark.parametrize("example", EXAMPLES)
def test_an_example_reads_back_as_the_same_table_bytes(example: str) -> None:
    table = load_table(resolve_table_path(Path("examples") / example))
    text = export_xstate([table])
    (back,) = read_xstate(text, "machine.json")
    assert format_table(back) == format_table(table) and _rows(back) == _rows(table)
    assert export_xstate([back]) == text


@pytest.mark.parametrize("seed", range(20))
def test_random_tables_read_back_as_the_same_table_bytes(seed: int) -> None:
    rng = random.Random(seed)
    table = random_table(rng, Shape(states=5, rows=12, lamps=seed % 3, counters=seed % 2))
    (back,) = read_xstate(export_xstate([table]), "machine.json")
    assert format_table(back) == format_table(table) and _rows(back) == _rows(table)


@pytest.fixture(scope="module")
def config() -> dict:
    return json.loads(export_xstate([load_table(Path("examples/bumberbot/table.csv"))]))


def _refused(value: object) -> str:
    with pytest.raises(TableBotError) as caught:
        read_xstate(value if isinstance(value, str) else json.dumps(value), "in.json")
    return caught.value.diagnostics[0].render()


def test_a_changed_guard_is_refused_at_its_json_path(config: dict) -> None:
    changed = json.loads(json.dumps(config))
    changed["states"]["s1"]["always"][0]["guard"]["params"]["some"] = {"flags": [], "cross": []}
    assert _refused(changed).startswith("in.json: error: $.states.s1.always[0].guard.params.some: is {")


def test_extra_keys_missing_keys_wrong_types_and_unknown_events_are_refused(config: dict) -> None:
    extra = {**config, "after": {"1000": "s2"}}
    assert "$: has a key 'after' tablebot does not write" in _refused(extra)
    missing = {k: v for k, v in config.items() if k != "on"}
    assert "$: has no key 'on'" in _refused(missing)
    typed = json.loads(json.dumps(config))
    typed["meta"]["tablebot"]["tickMs"] = "10"
    assert '$.meta.tablebot.tickMs: is "10", not a whole number' in _refused(typed)
    unknown = json.loads(json.dumps(config))
    unknown["states"]["s1"]["always"][0]["guard"]["params"]["flags"] = ["has_I9"]
    assert "$.states.s1.always[0].guard.params: names 'I9', which is no event column" in _refused(unknown)


def test_a_null_guard_and_no_tables_are_refused_not_crashed_on(config: dict) -> None:
    """Found by tests/formats/test_scxml_fuzz.py: a null guard was an AttributeError, an empty list of tables an
    IndexError."""
    null = json.loads(json.dumps(config))
    null["states"]["s21"]["always"][0]["guard"] = None
    assert _refused(null).startswith("in.json: error: $.states.s21.always[0].guard: is null")
    empty = json.loads(json.dumps(config))
    empty["meta"]["tablebot"]["tables"] = []
    assert "$.meta.tablebot.tables: names no table" in _refused(empty)


def test_text_that_is_not_json_is_located_by_line_and_column() -> None:
    assert _refused('{\n  "id": }').startswith("in.json:2:9: error: not JSON")
    assert "nested too deep" in _refused("[" * 100_000)


def test_the_import_command_writes_the_table(tmp_path: Path, config: dict) -> None:
    source = tmp_path / "machine.json"
    source.write_text(json.dumps(config), encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "import", str(source), "--from", "xstate"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout == format_table(load_table(Path("examples/bumberbot/table.csv")))
