"""examples/bumberbot-lights (issue 36 §4): the BumberBot's table with its collision rows written once for a state
group drives exactly as the BumberBot, beside a lights table that reads its state; the example checks."""

from __future__ import annotations

import itertools
import json
import random
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

import pytest

from tablebot.formats.inputs_csv import TickInput, load_inputs
from tablebot.formats.trace_lines import dumps
from tablebot.loading import Loaded
from tablebot.replay import replay, replay_several
from tablebot.table import Table

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot-lights"
ORIGINAL = ROOT / "examples" / "bumberbot"
KEYS = ("tick", "event", "row", "state", "timer", "M1", "M2")


def as_written(table: Table, line: dict[str, Any]) -> str:
    """A trace line of the BumberBot's keys, its row given as what the row says (its events and actions) rather
    than by its number: the group's rows are written once, so the rows after them have other numbers."""
    kept = {key: line[key] for key in KEYS}
    if kept["row"] is not None:
        row = next(r for r in table.rows if r.as_written == kept["row"])
        kept["row"] = [sorted(row.events), row.motors, row.timer, row.next]
    return dumps(kept)


def bumberbot_inputs(seed: int, ticks: int) -> list[TickInput]:
    """Bumpers and light in bursts, as a robot meets them (I3 I4 I5 I7 I8, first the highest bit)."""
    rng = random.Random(seed)
    masks, mask = [], 0
    for _ in range(ticks):
        if rng.random() < 0.02:
            mask = rng.choice((0, 0, 0b10000, 0b01000, 0b11000, 0b00100, 0b00010, 0b00001, 0b00011))
        masks.append(TickInput(mask))
    return masks


def test_the_drive_table_drives_as_the_bumberbot_tick_for_tick() -> None:
    lights, original = Loaded.open(EXAMPLE), Loaded.open(ORIGINAL)
    assert lights.tables is not None and lights.tables.input_bits == original.machine.input_bits
    assert len(lights.table.rows) == len(original.table.rows)  # 31 lines written, 37 rows run
    assert max(r.as_written for r in lights.table.rows) == 30
    recorded = load_inputs(ORIGINAL / "inputs.csv", original.machine)
    states = set()
    for ticks in (recorded, *(bumberbot_inputs(seed, 3000) for seed in range(6))):
        mine = [as_written(lights.table, line) for line in replay_several(lights.tables, ticks)]
        theirs = [as_written(original.table, line) for line in replay(original.machine, ticks)]
        assert mine == theirs
        states |= {json.loads(line)["state"] for line in mine}
    assert states == set(original.machine.states)  # every state of the BumberBot was driven through


def test_the_lamps_follow_what_the_drive_table_does() -> None:
    loaded = Loaded.open(EXAMPLE)
    assert loaded.tables is not None
    lines = list(replay_several(loaded.tables, bumberbot_inputs(7, 3000)))
    seen = {(line["state"], line["lights.state"]) for line in lines}
    assert (11, "burn") in seen and (22, "blink_on") in seen and (1, "flash_left") in seen
    mode = {1: "flash", 2: "flash", 11: "burn", 12: "burn", **dict.fromkeys((20, 21, 22, 24, 26, 29), "blink")}
    for before, line in itertools.pairwise(lines):  # the lights see drive's state at the start of a tick
        assert line["lights.state"].startswith(mode[before["state"]]), (before, line)
        assert line["L1"] == line["L2"] == 8 or line["lights.state"] != "burn"


def test_the_example_checks_its_properties_across_both_tables() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "check", str(EXAMPLE), "--format", "json"], capture_output=True, text=True
    )
    report = json.loads(done.stdout)
    status = {p["name"]: p["status"] for p in report["properties"]}
    assert status.pop("front_bumper_stops") == "violated"  # the BumberBot's known bug, a warning, as there
    assert set(status.values()) == {"holds"}, status
    assert {"lamps_burn_on_the_light", "no_flashing_in_a_collision", "blinks_while_backing_off"} <= set(status)
    assert report["counts"]["error"] == 0 and done.returncode == 0


def test_a_scene_runs_every_table_unless_asked_for_the_main_table_alone() -> None:
    """``scene()`` of a robot of several tables packs every table, as every command runs it,
    without a word; ``scene(every_table=False)`` packs the main table alone and says so rather than leave the
    lamps dark without a word; a robot of one table is told nothing either way."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        whole = Loaded.open(EXAMPLE).scene()
        assert whole.tables is not None and whole.tables.names == ("drive", "lights")
        assert Loaded.open(ORIGINAL).scene().tables is None
        assert Loaded.open(ORIGINAL).scene(every_table=False).tables is None
    with pytest.warns(UserWarning, match=r"robot.toml:31:1: note: the simulator runs the main table \(drive\) only"):
        alone = Loaded.open(EXAMPLE).scene(every_table=False)
    assert alone.tables is None
