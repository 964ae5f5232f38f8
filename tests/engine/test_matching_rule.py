"""The robot file's ``match``: the document's rule ("if an event is detected") or "a row that requires no event
always matches". How it is read, what ``check`` says about rows that require no event, the list export's
refusal, import's warning, the studio's explanation, and the shipped robots. (That every executor follows
the rule is proven beside each executor's own equality tests, on tables where the two rules part.)"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from core_helpers import ROOT
from tablebot.cli import app
from tablebot.cli.common import load
from tablebot.diagnostics import TableBotError
from tablebot.formats.table_read import load_table
from tablebot.machine import NO_ROW, compile_table
from tablebot.robot import BUMBERBOT, load_robot
from tablebot.sim.model.scene import scene_for
from tablebot.sim.runner import simulate
from tablebot.table import no_event_rows
from tablebot.testing.random_tables import with_match
from tablebot.web.analyse import explain
from test_sim_helpers import trace_text

runner = CliRunner()

#: State 1 cruises on a row that requires no event; the back-off row leads into it with timer 100, so for
#: 99 ticks after each back-off a tick with no event can come (no bumper pressed, T absent).
TABLE = """\
description,state,T,I3,I4,I5,I7,I8,M1,M2,timer,next
bump,1,,1,,,,,0,0,50,2
cruise,1,,,,,,,5,5,0,1
back off,2,1,,,,,,-3,-3,100,1
"""
ROBOT = """\
name = "Cruiser"
initial_state = 1
{match}
[inputs]
I3 = "front-right bumper"
I4 = "front-left bumper"
I5 = "rear bumper"
I7 = "right phototransistor"
I8 = "left phototransistor"
[motors]
M1 = "right motor"
M2 = "left motor"
"""


def folder(tmp_path: Path, match: str | None) -> Path:
    """A table with its robot file: ``match`` as given, None: the key left out, "-": no robot file at all."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "table.csv").write_text(TABLE, encoding="utf-8")
    if match != "-":
        (tmp_path / "robot.toml").write_text(
            ROBOT.format(match=f'match = "{match}"' if match else ""), encoding="utf-8"
        )
    return tmp_path / "table.csv"


# --- the robot file -----------------------------------------------------------------------------------


def test_a_robot_file_chooses_the_rule_and_says_so_or_gets_the_old_rule(tmp_path: Path) -> None:
    for match, says in (("document", True), ("always", True), (None, False)):
        robot = load_robot(folder(tmp_path, match).with_name("robot.toml"))
        assert (robot.match, robot.says_match) == (match or "always", says)
    assert BUMBERBOT.match == "document" and not BUMBERBOT.says_match  # the built-in robot: the document's


@pytest.mark.parametrize("value", ['"Document"', "1", '["always"]'])
def test_a_bad_rule_is_a_located_error_naming_both_words(tmp_path: Path, value: str) -> None:
    path = tmp_path / "robot.toml"
    path.write_text(ROBOT.replace("{match}", f"match = {value}"), encoding="utf-8")
    with pytest.raises(TableBotError) as caught:
        load_robot(path)
    (problem,) = caught.value.diagnostics
    assert (problem.path, problem.line, problem.column) == (str(path), 3, 1)
    assert problem.message.startswith('match must be "document" or "always", not ')
    assert 'match = "document"' in problem.hint and 'match = "always"' in problem.hint


def test_the_shipped_robots_say_their_rule_and_the_two_newer_ones_drive_alike_under_both() -> None:
    rules = {
        name: load_table(ROOT / "examples" / name / "table.csv").robot
        for name in ("bumberbot", "bumberbot-counters", "line-follower", "obstacle-avoider")
    }
    assert {name: (r.match, r.says_match) for name, r in rules.items()} == {
        "bumberbot": ("document", True),
        "bumberbot-counters": ("document", True),
        "line-follower": ("always", True),
        "obstacle-avoider": ("always", True),
    }
    for name, rows in (("line-follower", 3), ("obstacle-avoider", 1)):
        table, _ = load(ROOT / "examples" / name)
        found = no_event_rows(table)
        assert len(found) == rows and all(f.quiet == "" for f in found)  # T on every tick of those states
        other = with_match(table, "document")
        runs = [trace_text(simulate(scene_for(t, compile_table(t)), 20.0, 1)) for t in (table, other)]
        assert runs[0] == runs[1]


# --- check ----------------------------------------------------------------------------------------------


def findings(table: Path) -> list[dict]:
    result = runner.invoke(app, ["check", str(table), "--format", "json"])
    return [f for f in json.loads(result.stdout)["findings"] if f["code"] == "no-event-row"]


@pytest.mark.parametrize(
    ("match", "severity", "words"),
    [
        (
            "always",
            "info",
            [
                'with match = "always" (',
                "robot.toml:3)",
                "fires even on a tick with no event",
                "line 4 leads into it with timer 100",
                "the document's engine looks a row up only if",
            ],
        ),
        (
            "document",
            "info",
            ['with match = "document" (', "fires only on a tick with some event", "then nothing fires"],
        ),
        (None, "warning", ["does not say which matching rule", 'by default (match = "always"']),
        ("-", "warning", ["has no robot file", "built-in BumberBot", 'match = "document"']),
    ],
)
def test_check_says_what_the_rule_does_with_a_row_that_requires_no_event(
    tmp_path: Path, match: str | None, severity: str, words: list[str]
) -> None:
    (found,) = findings(folder(tmp_path, match))
    assert (found["severity"], found["lines"], found["state"]) == (severity, [3], 1)
    assert found["message"].startswith("row on line 3 requires no event")
    for text in words:
        assert text in found["message"], text
    assert "match" in found["hint"]


def test_check_says_both_rules_agree_where_t_is_always_there() -> None:
    (found,) = findings(ROOT / "examples" / "obstacle-avoider" / "table.csv")
    assert found["severity"] == "info" and "both matching rules fire it" in found["message"]
    assert findings(ROOT / "examples" / "bumberbot" / "table.csv") == []


def test_check_names_every_row_that_requires_no_event_a_later_one_of_its_state_too(tmp_path: Path) -> None:
    """Issue 36 §2: the second of two rows that need no event in state 2 was left out."""
    table = tmp_path / "table.csv"
    table.write_text("state,T,I3,M1,M2,timer,next\n2,,,0,0,5,2\n2,,,1,1,0,2\n")
    found = findings(table)
    assert [f["lines"] for f in found] == [[2], [3]]
    assert "the row on line 2 above it requires no event either, so this one never fires" in found[1]["message"]
    assert "line 2" not in found[0]["message"].split(";")[-1]


# --- the lists: run by the document's engine ----------------------------------------------------------------


@pytest.mark.parametrize("match", ["always", None])
def test_the_list_export_refuses_a_row_the_document_would_not_fire(tmp_path: Path, match: str | None) -> None:
    table = folder(tmp_path / "t", match)
    program = tmp_path / "engine.rpp"
    program.write_bytes((ROOT / "tests" / "fixtures" / "rpp" / "engine.rpp").read_bytes())
    for target in (["robopro"], ["robopro-rpp", "--into", str(program)]):
        result = runner.invoke(app, ["export", str(table), "--to", *target, str(tmp_path / "out")])
        assert result.exit_code == 2, result.output
        assert f"{table}:3: error: row 1 requires no event" in result.output
        assert 'write match = "document" in' in result.output
    assert not (tmp_path / "out").exists()
    assert program.read_bytes() == (ROOT / "tests" / "fixtures" / "rpp" / "engine.rpp").read_bytes()
    checked = runner.invoke(app, ["check", str(table), "--target", "robopro"])
    assert checked.exit_code == 2 and "robopro: row 1 requires no event" in checked.output


def test_the_lists_of_the_document_rule_and_of_tables_where_the_rules_agree_are_written(tmp_path: Path) -> None:
    for table in (folder(tmp_path / "doc", "document"), ROOT / "examples" / "line-follower" / "table.csv"):
        out = tmp_path / "out" / table.parent.name
        result = runner.invoke(app, ["export", str(table), "--to", "robopro", str(out)])
        assert result.exit_code == 0, result.output
        assert (out / "event.csv").is_file()


def test_import_warns_when_the_robot_would_fire_what_the_lists_did_not(tmp_path: Path) -> None:
    lists = tmp_path / "lists"
    runner.invoke(app, ["export", str(folder(tmp_path / "doc", "document")), "--to", "robopro", str(lists)])
    for match, warned in (("document", False), ("always", True)):
        robot = folder(tmp_path / match, match).with_name("robot.toml")
        result = runner.invoke(app, ["import", "--from", "robopro", str(lists), "--robot", str(robot)])
        assert result.exit_code == 0
        assert ("warning: line 2 of the lists requires no event" in " ".join(result.output.split())) == warned


# --- the studio's explanation -------------------------------------------------------------------------------


def test_the_studio_says_why_a_row_that_requires_no_event_did_not_fire(tmp_path: Path) -> None:
    for match in ("document", "always"):
        table, machine = load(folder(tmp_path / match, match))
        why = explain(table, machine, machine.state_index(1), 0)
        cruise = next(w for w in why if w["line"] == 3)
        if match == "document":
            assert machine.lookup(machine.state_index(1), 0) == NO_ROW
            assert cruise["status"] == "missing" and "no event this tick" in cruise["why"]
        else:
            assert cruise["status"] == "fired"


@pytest.mark.parametrize(
    ("template", "match"),
    [("empty", "document"), ("bumberbot", "document"), ("line-follower", "always"), ("obstacle-avoider", "always")],
)
def test_new_robots_write_the_rule_down(tmp_path: Path, template: str, match: str) -> None:
    result = runner.invoke(app, ["new", str(tmp_path / "bot"), "--from", template])
    assert result.exit_code == 0, result.output
    robot = load_robot(tmp_path / "bot" / "robot.toml")
    assert robot.says_match and robot.match == match


def test_the_robopro_program_is_generated_for_the_robot_files_rule(tmp_path: Path) -> None:
    """export --to robopro-program takes the rule from the robot file: the document's test of EV, or none."""
    for match in ("document", "always"):
        out = tmp_path / "out" / match
        result = runner.invoke(
            app, ["export", str(folder(tmp_path / match, match)), "--to", "robopro-program", str(out)]
        )
        assert result.exit_code == 0, result.output
        text = (out / "Cruiser.rpp").read_text(encoding="utf-8")
        assert ("if an event is detected (EV &gt; 0)" in text) == (match == "document")
