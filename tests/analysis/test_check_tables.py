"""check of a robot of several tables (issue 36 §2): each table's findings named by its table and file, properties
naming any table's state, proved over the product of the tables, counterexamples that replay on the engine."""

from __future__ import annotations

import json
import random
import subprocess
import sys
from pathlib import Path
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from tablebot.analysis.product import ProductModel
from tablebot.formats.inputs_csv import load_inputs
from tablebot.loading import Loaded
from tablebot.replay import replay_several
from tablebot.testing.random_robots import RobotShape, random_robot
from tables_helpers import robot

PROPERTIES = """[stopped_dark]
text = "the lamp is never off once drive has stopped and lights has seen it"
never = "drive == 3 and lights == 2"

[lamp_follows]
text = "within 2 ticks of drive stopping, lights is in state 2"
when = "drive == 3"
then = "lights == 2"
within = "2 ticks"

[comes_back]
text = "lights can always get back to 1"
always_reachable = "lights == 1"
"""


def check(folder: Path, *args: str) -> dict[str, Any]:
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "check", str(folder), "--format", "json", *args],
        capture_output=True,
        text=True,
    )
    assert done.stderr == "", done.stderr
    return json.loads(done.stdout)


def test_properties_across_tables_are_proved_or_broken_with_a_counterexample_that_replays(tmp_path: Path) -> None:
    folder = robot(tmp_path / "robot")
    (folder / "properties.toml").write_text(PROPERTIES)
    report = check(folder, "--counterexamples", str(tmp_path / "cex"))
    status = {p["name"]: p["status"] for p in report["properties"]}
    assert status == {"stopped_dark": "violated", "lamp_follows": "holds", "comes_back": "holds"}
    assert [(t["name"], Path(t["table"]).name, t["rows"], t["states"]) for t in report["tables"]] == [
        ("drive", "table.csv", 5, 3),
        ("lights", "lights.csv", 4, 2),
    ]
    broken = next(p for p in report["properties"] if p["name"] == "stopped_dark")
    assert broken["shortest"] and broken["ticks"] == 2  # I1 at once: drive in 3 on tick 0, lights sees it on 1
    loaded = Loaded.open(folder)
    assert loaded.tables is not None
    lines = list(replay_several(loaded.tables, load_inputs(broken["inputs_csv"], loaded.tables)))
    assert (lines[-1]["state"], lines[-1]["lights.state"]) == (3, 2)
    assert all((line["state"], line["lights.state"]) != (3, 2) for line in lines[:-1])


def test_each_tables_findings_name_its_table_and_file(tmp_path: Path) -> None:
    folder = robot(tmp_path)
    lights = (folder / "lights.csv").read_text() + "1,1,,,8,0,2\n"  # T in state 1 again: line 3 takes it
    (folder / "lights.csv").write_text(lights)
    findings = check(folder)["findings"]
    late = [f for f in findings if f.get("table") == "lights" and f["lines"][:1] == [6]]
    assert late and all(f["file"] == str(folder / "lights.csv") for f in late)
    assert all(f["message"].startswith("table lights: ") for f in late)
    assert all("table" not in f for f in findings if f["lines"] and f["lines"][0] <= 5 and "file" not in f)
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "check", str(folder), "-v"], capture_output=True, text=True
    )
    assert f"{folder / 'lights.csv'}:6: warning: table lights: row on line 6 can never fire" in done.stdout


def test_a_condition_naming_a_state_a_table_lacks_is_a_located_error(tmp_path: Path) -> None:
    folder = robot(tmp_path)
    (folder / "properties.toml").write_text('[p]\nnever = "lights == 9"\n')
    done = subprocess.run([sys.executable, "-m", "tablebot", "check", str(folder)], capture_output=True, text=True)
    assert done.returncode == 2
    assert "properties.toml:1: error: property p: never: there is no state 9 in table lights" in done.stderr


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**32))
def test_every_run_of_the_engine_is_a_run_of_the_product(tmp_path_factory: Any, seed: int) -> None:
    """Soundness: what the robot's engine does on random inputs, the exact product model has among its nodes."""
    rng = random.Random(seed)
    folder = random_robot(rng, tmp_path_factory.mktemp("robot"), RobotShape(tables=rng.randint(2, 3), states=3))
    tables = Loaded.open(folder / "t0.csv").tables
    assert tables is not None
    model = ProductModel.exact(tables)
    nodes = {(node[0], node[1], node[3]) for node in model.explore().nodes}
    from tablebot.engine.several import Several

    engine = Several(tables)
    for _ in range(80):
        engine.step(rng.randrange(1 << len(tables.input_bits)) if rng.random() < 0.4 else 0, (rng.choice((0, 5)),))
        seen = (tuple(e.state for e in engine.engines), tuple(e.timer for e in engine.engines), engine.outputs)
        assert seen in nodes


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**32))
def test_leaving_out_tables_that_cannot_influence_changes_nothing_a_property_sees(
    tmp_path_factory: Any, seed: int
) -> None:
    rng = random.Random(seed)
    folder = random_robot(rng, tmp_path_factory.mktemp("robot"), RobotShape(tables=3, states=3))
    tables = Loaded.open(folder / "t0.csv").tables
    assert tables is not None
    for read in ({0}, {1}, {2}, {0, 2}):
        relevant = tables.influence(frozenset(read))
        whole = ProductModel(tables, 2).explore().nodes
        part = ProductModel(tables, 2, relevant=relevant).explore().nodes
        outputs = [i for i, name in enumerate(tables.output_names) if tables.writer(name) in relevant]

        def seen(nodes: list[Any], relevant: frozenset[int] = relevant, outputs: list[int] = outputs) -> set[Any]:
            return {
                (
                    tuple(n[0][k] for k in sorted(relevant)),
                    tuple(n[1][k] for k in sorted(relevant)),
                    tuple(n[3][i] for i in outputs),
                )
                for n in nodes
            }

        assert seen(part) == seen(whole)
