"""Several tables as one SCXML ``<parallel>`` statechart, cross-table events as ``In()``, run in python-statemachine
tick by tick and equal to tablebot's engine (tablebot.engine.several): the shipped BumberBot with its lights (two
tables, state groups) and random robots of 2-3 tables, and each reads back as the same table bytes.

python-statemachine orders parallel regions by insertion, not by document order: read from an SCXML document, that
is document order (tested below, as docs/statecharts.md says); under one writer per output no order changes
anything, which is what these tests show: the trace is the engine's, whose tables' order changes nothing either."""

from __future__ import annotations

import random
import subprocess
import sys
from pathlib import Path

import pytest

from statechart_helpers import first_difference, random_several, random_ticks, run_statemachine, several
from tablebot.formats.statecharts.read_scxml import read_scxml
from tablebot.formats.statecharts.scxml import export_scxml
from tablebot.formats.table_write import format_table
from tablebot.loading import Loaded
from tablebot.replay import replay_several


def test_the_bumberbot_with_its_lights_runs_in_python_statemachine_as_in_the_engine() -> None:
    tables = Loaded.open(Path("examples/bumberbot-lights")).tables
    assert tables is not None
    inputs = random_ticks(random.Random(7), tables, 300)
    got = run_statemachine(several(tables), export_scxml(tables.tables), inputs)
    assert first_difference(got, list(replay_several(tables, inputs))) is None
    assert len({line["lights.state"] for line in got}) > 2, "the lights table hardly moved: the case proves little"


@pytest.mark.parametrize("seed", range(6))
def test_random_robots_of_several_tables_run_in_python_statemachine_as_in_the_engine(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    tables = random_several(rng, tmp_path, 2 + seed % 2)
    inputs = random_ticks(rng, tables, 100)
    got = run_statemachine(several(tables), export_scxml(tables.tables), inputs)
    assert first_difference(got, list(replay_several(tables, inputs))) is None


@pytest.mark.parametrize("seed", range(6))
def test_several_tables_read_back_as_the_same_table_bytes(tmp_path: Path, seed: int) -> None:
    tables = random_several(random.Random(seed), tmp_path, 2 + seed % 2)
    back = read_scxml(export_scxml(tables.tables), "machine.scxml")
    assert [format_table(t) for t in back] == [format_table(t) for t in tables.tables]
    assert [t.name for t in back] == list(tables.names) and export_scxml(back) == export_scxml(tables.tables)


def test_the_import_command_writes_tables_a_robot_file_reads_again(tmp_path: Path) -> None:
    """export the BumberBot with its lights, import it into a folder: the lights table comes back byte for byte,
    the drive table (table.csv) with its group rows once; beside the original robot file, the robot runs as the
    original does."""
    original = Path("examples/bumberbot-lights")
    run = [sys.executable, "-m", "tablebot"]
    subprocess.run(
        [*run, "export", str(original), str(tmp_path / "out"), "--to", "scxml"], check=True, capture_output=True
    )
    done = subprocess.run(
        [*run, "import", str(tmp_path / "out" / "machine.scxml"), "--from", "scxml", "--out", str(tmp_path / "back")],
        check=True,
        capture_output=True,
        text=True,
    )
    assert (tmp_path / "back" / "lights.csv").read_bytes() == (original / "lights.csv").read_bytes()
    assert 'drive = { file = "table.csv", initial_state = 2' in done.stderr
    assert "seeking = [1, 2, 11]" in done.stderr
    (tmp_path / "back" / "robot.toml").write_bytes((original / "robot.toml").read_bytes())
    tables, again = Loaded.open(original).tables, Loaded.open(tmp_path / "back").tables
    assert tables is not None and again is not None
    inputs = random_ticks(random.Random(3), tables, 200)
    assert list(replay_several(again, inputs)) == list(replay_several(tables, inputs))


@pytest.mark.parametrize(("first", "second"), [("ra", "rb"), ("zz", "aa")])
def test_python_statemachine_runs_an_scxml_documents_regions_in_document_order(first: str, second: str) -> None:
    from statemachine.io import load

    regions = "".join(
        f'<state id="{r}" initial="{r}1"><state id="{r}1"><transition event="go" target="{r}2">'
        f'<assign location="x" expr="x * 10 + {k}"/></transition></state><state id="{r}2"/></state>'
        for k, r in ((1, first), (2, second))
    )
    machine = load(
        f'<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="p"><datamodel>'
        f'<data id="x" expr="0"/></datamodel><parallel id="p">{regions}</parallel></scxml>',
        format="scxml",
    )()
    machine.send("go")
    assert machine.model.x == 12  # the first region's action, then the second's


def test_an_import_that_would_replace_a_table_of_yours_writes_none(tmp_path: Path) -> None:
    """Without --force a table of yours is never replaced, and then no other table is written either (before, the
    main table was written and the second refused, a half-imported robot)."""
    tables = Loaded.open(Path("examples/bumberbot-lights")).tables
    assert tables is not None
    source = tmp_path / "machine.scxml"
    source.write_text(export_scxml(tables.tables), encoding="utf-8")
    folder = tmp_path / "robot"
    folder.mkdir()
    (folder / "lights.csv").write_text("state,next\n1,1\n", encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "import", str(source), "--from", "scxml", "--out", str(folder)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 2 and "lights.csv exists and is a table file" in done.stderr
    assert sorted(p.name for p in folder.iterdir()) == ["lights.csv"]
    assert (folder / "lights.csv").read_text(encoding="utf-8") == "state,next\n1,1\n"
