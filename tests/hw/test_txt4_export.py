"""``tablebot export --to txt4``: the workspace it writes (files, ``.project.json`` as ROBO Pro Coding writes
it, user text only as literals) and the program's engine, equal to tablebot's tick for tick on random
tables. The program against the ``fischertechnik`` stub: test_txt4_program.py."""

from __future__ import annotations

import ast
import dataclasses
import importlib.util
import json
import random
import uuid
from pathlib import Path
from types import ModuleType

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot.cli import app
from tablebot.engine import Engine
from tablebot.escape import python_string
from tablebot.hw.txt4.export import export_txt4
from tablebot.machine import Machine, compile_table
from tablebot.robot import Match
from tablebot.table import Table
from tablebot.testing.random_tables import Shape, random_case, random_inputs, random_table

pytestmark = [pytest.mark.kernel_free]


def load_program(folder: Path) -> ModuleType:
    """The exported lib/tablebot_program.py, imported from its file (importing runs nothing)."""
    path = folder / "lib" / "tablebot_program.py"
    spec = importlib.util.spec_from_file_location(f"program_{abs(hash(folder))}", path)
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def with_txt_section(table: Table) -> Machine:
    """A random table's robot wired onto TXT terminals: inputs I1.., motors M1.., lamps on the outputs the
    motors leave free, counters C1.."""
    robot = table.robot
    wiring: dict[str, object] = {name: {"terminal": name, "mode": "switch", "pressed": 1} for name in robot.inputs}
    wiring.update({name: name for name in robot.motors})
    wiring.update({name: f"O{2 * len(robot.motors) + i + 1}" for i, name in enumerate(robot.lamps)})
    wiring.update({name: name for name in robot.counter_names})
    robot = dataclasses.replace(robot, sections={"txt": wiring})
    return compile_table(dataclasses.replace(table, robot=robot))


@pytest.mark.parametrize("seed", range(12))
def test_the_exported_engine_takes_the_python_engines_decisions_tick_for_tick(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    shape = Shape(
        states=rng.randint(1, 6),
        rows=rng.randint(4, 24),
        inputs=rng.randint(1, 5),
        motors=rng.randint(1, 2),
        lamps=rng.randint(0, 3),
        counters=rng.randint(0, 3),
    )
    machine = with_txt_section(random_table(rng, shape))
    export_txt4(machine).write(tmp_path)
    program = load_program(tmp_path)
    ours, theirs = Engine(machine), program.Engine(program.TABLE)
    for tick in random_inputs(rng, machine.table, 400, max_pulses=3):
        ours.step(tick.mask, tick.pulses)
        theirs.step(tick.mask, list(tick.pulses))
        assert (theirs.state, theirs.timer, theirs.event, theirs.row) == (ours.state, ours.timer, ours.event, ours.row)
        assert (tuple(theirs.outputs), theirs.counters) == (ours.outputs, ours.counters)


@pytest.mark.parametrize("match", ["document", "always"])
def test_the_exported_engine_follows_the_tables_matching_rule(tmp_path: Path, match: Match) -> None:
    """On a table and inputs where the two rules part, the program takes the engine's decisions."""
    table, ticks = random_case(random.Random(f"txt4-{match}"), Shape(states=3, rows=9, counters=1, match=match))
    machine = with_txt_section(table)
    export_txt4(machine).write(tmp_path)
    program = load_program(tmp_path)
    ours, theirs = Engine(machine), program.Engine(program.TABLE)
    for tick in ticks:
        ours.step(tick.mask, tick.pulses)
        theirs.step(tick.mask, list(tick.pulses))
        assert (theirs.state, theirs.timer, theirs.event, theirs.row) == (ours.state, ours.timer, ours.event, ours.row)
        assert (tuple(theirs.outputs), theirs.counters) == (ours.outputs, ours.counters)


def test_export_writes_a_workspace_and_refuses_a_table_that_does_not_fit(tmp_path: Path) -> None:
    runner = CliRunner()
    result = runner.invoke(app, ["export", str(EXAMPLE), str(tmp_path / "ok"), "--to", "txt4"])
    assert result.exit_code == 0, result.output
    assert sorted(p.relative_to(tmp_path / "ok").as_posix() for p in (tmp_path / "ok").rglob("*") if p.is_file()) == [
        ".project.json",
        "BumberBot.py",
        "lib/__init__.py",
        "lib/tablebot_program.py",
    ]
    assert "tablebot upload" in result.output
    project = (tmp_path / "ok" / ".project.json").read_text()
    assert json.loads(project) == {
        "uuid": json.loads(project)["uuid"],
        "name": "BumberBot",
        "mode": "PROFESSIONAL",
        "version": "1.0",
        "controller": "TXT4",
    }
    assert list(json.loads(project)) == ["uuid", "name", "mode", "version", "controller"]  # ROBO Pro Coding's order
    assert "\n" not in project and str(uuid.UUID(json.loads(project)["uuid"])) == json.loads(project)["uuid"]
    assert not list((tmp_path / "ok").rglob("*.blockly"))  # PROFESSIONAL: Python only, no blocks
    again = runner.invoke(app, ["export", str(EXAMPLE), str(tmp_path / "again"), "--to", "txt4"])
    assert again.exit_code == 0
    for name in ("BumberBot.py", "lib/tablebot_program.py", ".project.json"):  # the same table, the same bytes
        assert (tmp_path / "ok" / name).read_bytes() == (tmp_path / "again" / name).read_bytes()
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "table.csv").write_text((EXAMPLE / "table.csv").read_text())
    (tmp_path / "bad" / "robot.toml").write_text((EXAMPLE / "robot.toml").read_text().replace('M2 = "M2"', 'M2 = "M7"'))
    refused = runner.invoke(app, ["export", str(tmp_path / "bad"), str(tmp_path / "nothing"), "--to", "txt4"])
    assert refused.exit_code == 2 and "motor M2: the TXT has no motor terminal 'M7'" in refused.output
    assert not (tmp_path / "nothing").exists()


def test_user_text_reaches_the_program_only_as_string_literals(tmp_path: Path) -> None:
    evil = "x'); import os; os.system('touch PWNED'); ('\n\"\"\" \\ \u2028 \x00 é"
    (tmp_path / "table.csv").write_text((EXAMPLE / "table.csv").read_text())
    robot = (EXAMPLE / "robot.toml").read_text().replace('name = "BumberBot"', f"name = {json.dumps(evil)}")
    (tmp_path / "robot.toml").write_text(robot)
    result = CliRunner().invoke(app, ["export", str(tmp_path), str(tmp_path / "out"), "--to", "txt4"])
    assert result.exit_code == 0, result.output
    (program_file,) = (tmp_path / "out" / "lib").glob("tablebot_program.py")
    tree = ast.parse(program_file.read_text(encoding="utf-8"))
    (table_node,) = [n for n in tree.body if isinstance(n, ast.Assign) and n.targets[0].id == "TABLE"]  # type: ignore[attr-defined]
    assert ast.literal_eval(table_node.value)["name"] == evil  # pure data, and exactly the user's text
    assert program_file.read_text(encoding="utf-8").isascii()
    assert load_program(tmp_path / "out").TABLE["name"] == evil
    assert not (tmp_path / "out" / "PWNED").exists()


@settings(max_examples=60, deadline=None)
@given(st.text())
def test_python_string_is_a_literal_that_reads_back_exactly(text: str) -> None:
    literal = python_string(text)
    assert literal.isascii() and "\n" not in literal and "\r" not in literal
    assert ast.literal_eval(literal) == text
