"""The ROBO Pro program of a robot of several tables (issue 36 §2): one process per table and a clock process,
run by the element interpreter with its processes switched at random after any element, takes the engine's
decisions tick for tick (random robots of 2–3 tables with cross-table events, counters and lamps; the BumberBot
with its lights on its recorded inputs); the barrier is what makes it so; it keeps to real programs' vocabulary;
``export --to robopro-program`` writes it."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

import tablebot.testing.executors  # noqa: F401  (registers the executors)
from core_helpers import ROOT
from tablebot.diagnostics import TableBotError
from tablebot.formats.inputs_csv import load_inputs
from tablebot.formats.table_read import load_table
from tablebot.robopro.executor import run_several
from tablebot.robopro.processes import generate_several
from tablebot.tables import RobotTables, load_tables
from tablebot.testing.harness import Run
from tablebot.testing.robopro_several import robopro_several_case
from tablebot.testing.rpp_vocabulary import problems as vocabulary_problems
from tablebot.testing.several_cases import check_several, several_differences
from test_robopro_program import crossing, wire_segments
from test_run_cli import invoke

LIGHTS = ROOT / "examples" / "bumberbot-lights"


@pytest.fixture(scope="module")
def lights() -> RobotTables:
    return load_tables(load_table(LIGHTS / "table.csv"))


def functions(text: str) -> dict[str, ET.Element]:
    root = ET.fromstring(text.encode("utf-8"))
    return {f.get("name", ""): f for f in root.iter("o") if f.get("classname") == "ftProSubroutineFunction"}


@pytest.mark.parametrize("seed", range(4))
def test_random_robots_of_several_tables_tick_for_tick(seed: int, tmp_path: Path) -> None:
    """2 and 3 tables with cross-table columns, a counter one table loads and others read, lamps, either rule;
    the interpreter switches processes at random (the case's seed) after any element."""
    case = robopro_several_case(seed, tmp_path / "robot")
    assert len(case.tables.tables) == 2 + seed % 2 and any(t.cross for t in case.tables.tables)
    report = check_several(case, tmp_path / "work", ["ROBO Pro program"])
    assert report.agreed == ["ROBO Pro program"], (report.skipped, report.differ)


def test_the_bumberbot_with_its_lights_on_its_recorded_inputs(lights: RobotTables) -> None:
    inputs = load_inputs(ROOT / "examples" / "bumberbot" / "inputs.csv", lights)[:500]
    assert several_differences(lights, Run(list(inputs), run_several(lights, inputs))) is None
    some = inputs[:200]
    for seed in (1, 2):
        assert several_differences(lights, Run(list(some), run_several(lights, some, seed=seed))) is None


def test_without_the_start_of_tick_image_the_lights_see_the_drive_table_move(
    lights: RobotTables, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The barrier matters: reading the drive table's state as it is (``drive ST``) instead of its image at the
    start of the tick (``drive S0``), the lights process sees this tick's move of the drive table, and the trace
    differs from the engine's."""
    import tablebot.robopro.processes as processes

    text = generate_several(lights)
    sabotaged = text.replace('name="drive S0"', 'name="drive ST"').replace('value="drive S0"', 'value="drive ST"')
    assert sabotaged != text
    monkeypatch.setattr(processes, "generate_several", lambda tables: sabotaged)
    inputs = load_inputs(ROOT / "examples" / "bumberbot" / "inputs.csv", lights)[:800]
    difference = several_differences(lights, Run(list(inputs), run_several(lights, inputs)))
    assert difference is not None and "lights." in difference


def test_one_process_per_table_and_names_that_do_not_collide(lights: RobotTables) -> None:
    text = generate_several(lights)
    subs = functions(text)
    starts = [e for e in subs["Main program"].findall("o") if e.get("classname") == "ftProProcessStart"]
    assert len(starts) == 3  # the clock, then a process per table, each a Start of the main program
    assert set(subs) == {
        "Main program",
        *(
            f"{table} {sub}"
            for table in ("drive", "lights")
            for sub in ("DetectEvent", "DetermineAction", "ExecuteAction", "CountDown", "WaitTick")
        ),
    }
    calls = [e.get("name") for e in subs["Main program"].findall("o") if e.get("classname") == "ftProSubroutineRef"]
    assert calls == [
        f"{table} {sub}"
        for table in ("drive", "lights")
        for sub in ("WaitTick", "DetectEvent", "DetermineAction", "ExecuteAction", "WaitTick", "CountDown")
    ]
    for name, sub in subs.items():  # as every real subprogram: an entry and an exit (the processes never return)
        kinds = {e.get("classname") for e in sub.findall("o")}
        assert name == "Main program" or {"ftProSubroutineFlowIn", "ftProSubroutineFlowOut"} <= kinds, name
    root = ET.fromstring(text.encode("utf-8"))
    lists = {o.get("name", "") for o in root.iter("o") if o.get("classname") == "ftProDataArray1D"}
    assert lists == {
        "drive Event",
        "drive Action",
        "drive Timer",
        "lights Event",
        "lights Action",
        "lights Timer",
        "lights L1",
        "lights L2",
        "lights from drive",
    }
    lamps = {
        (o.get("output"), f)
        for f, sub in subs.items()
        for o in sub.iter("o")
        if o.get("classname") == "ftProDataOutSngl"
    }
    assert {output for output, _ in lamps} == {"4", "5"}  # O5 and O6, as the robot file wires them on the TXT
    assert {f for _, f in lamps} == {"Main program", "lights ExecuteAction"}  # off at the start, then by its rows
    motors = {f for f, sub in subs.items() for o in sub.iter("o") if o.get("classname") == "ftProDataOutDual"}
    assert motors == {"Main program", "drive ExecuteAction"}
    assert vocabulary_problems(text) == []


def test_export_writes_every_table_and_check_says_what_does_not_fit(tmp_path: Path) -> None:
    result = invoke("export", LIGHTS, "--to", "robopro-program", tmp_path / "out")
    assert result.exit_code == 0, result.output
    assert "main table" not in result.output and "process per table (drive, lights)" in result.output
    written = (tmp_path / "out" / "BumberBot_with_lights.rpp").read_text(encoding="utf-8")
    assert written == generate_several(load_tables(load_table(LIGHTS / "table.csv")))
    robot = tmp_path / "fast"
    robot.mkdir()
    for name in ("table.csv", "lights.csv"):
        (robot / name).write_text((LIGHTS / name).read_text(encoding="utf-8"), encoding="utf-8")
    text = (LIGHTS / "robot.toml").read_text(encoding="utf-8").replace("tick_ms = 10 ", "tick_ms = 5 ")
    (robot / "robot.toml").write_text(text, encoding="utf-8")
    line = text.splitlines().index(next(s for s in text.splitlines() if s.startswith("tick_ms"))) + 1
    with pytest.raises(TableBotError):
        generate_several(load_tables(load_table(robot / "table.csv")))
    checked = invoke("check", robot, "--target", "robopro-program")
    said = " ".join(checked.output.split())
    assert "error: robopro-program: tick_ms = 5: the processes of the tables look for the next tick" in said
    assert f"robot.toml:{line}:1)" in said and "1 error," in said, said


def test_wires_do_not_cross_and_everything_sits_on_the_grid(lights: RobotTables, tmp_path: Path) -> None:
    from tablebot.testing.robopro_several import wired_txt

    three = load_tables(wired_txt(robopro_several_case(1, tmp_path / "robot").tables.table))
    for text in (generate_several(lights), generate_several(three)):
        for name, segments in wire_segments(text).items():
            crossed = [
                (a[0], b[0])
                for n, a in enumerate(segments)
                for b in segments[n + 1 :]
                if a[0] != b[0] and crossing(a, b)
            ]
            assert crossed == [], f"{name}: wires cross"
            assert all(x % 4 == 0 and y % 4 == 0 for _, p, q in segments for x, y in (p, q)), name


def test_a_row_of_another_table_that_does_not_fit_is_named_once_where_it_is_written(tmp_path: Path) -> None:
    """The lights table's third row as written (the table's fifth once its groups are rows) with a timer over
    ROBO Pro's 16 bits: check names its line and its row as written, once, whichever table check is given."""
    for name in ("robot.toml", "table.csv", "lights.csv", "properties.toml"):
        (tmp_path / name).write_text((LIGHTS / name).read_text(encoding="utf-8"), encoding="utf-8")
    lights = (tmp_path / "lights.csv").read_text(encoding="utf-8")
    (tmp_path / "lights.csv").write_text(
        lights.replace("flash_left,1,,,,0,8,50,", "flash_left,1,,,,0,8,40000,"), encoding="utf-8"
    )
    for given in (tmp_path, tmp_path / "lights.csv"):
        said = " ".join(invoke("check", given, "--target", "robopro-program").output.split())
        assert said.count("error:") == 1, said
        assert f"{tmp_path / 'lights.csv'}:4: error: table lights: robopro-program: row 2: timer 40000 is over" in said
