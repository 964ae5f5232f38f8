"""``evolve --table NAME`` on a robot of several tables (issue 36 §2): the named table changes, within its own
columns, and every candidate is proved and run with the other tables as they are; only its files are written.
Tiny budgets on examples/bumberbot-lights (the lights table evolves beside the BumberBot's drive table)."""

from __future__ import annotations

import hashlib
import subprocess
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import tablebot
from tablebot.analysis.properties import load_properties
from tablebot.analysis.prove_product import check_product_property
from tablebot.cli import app
from tablebot.diagnostics import TableBotError
from tablebot.evolve.operators import Space, vary
from tablebot.evolve.space import Limits, start, to_table
from tablebot.formats.table_read import load_table
from tablebot.table import Table
from tablebot.tables import load_tables

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot-lights"
RUN = ["--seeds", "0..1", "--check-seeds", "9..10", "--seconds", "2", "--budget", "6", "--batch", "3"]


def digests(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir()) if p.is_file()}


@pytest.fixture(scope="module")
def properties(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The example's properties without front_bumper_stops: the drive table breaks it (the document's known
    bug), and no lights table can mend that (test_a_property_only_other_tables_decide_stops_it_first)."""
    text = (EXAMPLE / "properties.toml").read_text(encoding="utf-8")
    cut = text[: text.index("# A found bug")] + text[text.index("# --- the lights") :]
    path = tmp_path_factory.mktemp("props") / "properties.toml"
    path.write_text(cut, encoding="utf-8")
    return path


def evolve(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(app, ["evolve", *args])
    return result.exit_code, result.output


@pytest.fixture(scope="module")
def lights_run(tmp_path_factory: pytest.TempPathFactory, properties: Path) -> tuple[Path, dict[str, str]]:
    before = digests(EXAMPLE)
    out = tmp_path_factory.mktemp("several") / "lights"
    code, output = evolve(
        str(EXAMPLE), "--table", "lights", "--properties", str(properties), "--out", str(out), *RUN, "--workers", "2"
    )
    assert code == 0, output
    return out, before


def test_only_the_lights_table_is_written_and_the_robot_files_are_untouched(
    lights_run: tuple[Path, dict[str, str]],
) -> None:
    out, before = lights_run
    assert digests(EXAMPLE) == before  # the drive table (and every file of the robot) as it was
    tables = sorted(p.relative_to(out).as_posix() for p in out.rglob("*.csv") if p.name != "evaluations.csv")
    assert tables and all(Path(t).name.startswith("lights.") for t in tables), tables
    assert "lights.best-1.csv" in tables
    header = (out / "lights.best-1.csv").read_text(encoding="utf-8").splitlines()[0]
    assert header == (EXAMPLE / "lights.csv").read_text(encoding="utf-8").splitlines()[0]  # its own columns only
    report = (out / "report.md").read_text(encoding="utf-8")
    assert "evolve changed table **lights** only (`--table lights`)" in report
    assert "The other tables (drive) stayed exactly as they are" in report
    assert "every property holds" in report and "A PROPERTY FAILS" not in report
    check = (out / "lights.best-1.check.txt").read_text(encoding="utf-8")
    assert "VIOLATED" not in check and "lamps_burn_on_the_light" in check  # proved over both tables
    assert check.startswith("lights.best-1.csv (table lights; unchanged beside it: drive): ")
    assert "moved from state" not in (out / "lights.best-1.csv").read_text(encoding="utf-8")  # a group's rows


def test_the_printed_command_runs_the_evolved_lights_beside_the_drive_table(
    lights_run: tuple[Path, dict[str, str]], tmp_path: Path
) -> None:
    out, _ = lights_run
    report = (out / "report.md").read_text(encoding="utf-8")
    line = next(row for row in report.splitlines() if row.startswith("- `lights.best-1.csv`"))
    command = line.split(": `", 1)[1].rstrip("`")
    tablebot_bin = str(ROOT / ".venv" / "bin" / "tablebot")
    done = subprocess.run(
        command.replace("tablebot sim", f"{tablebot_bin} sim"),
        shell=True,
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    assert done.returncode == 0, done.stderr
    placed = out / "robot" / "lights.best-1"
    assert (placed / "lights.csv").read_bytes() == (out / "lights.best-1.csv").read_bytes()
    assert (placed / "table.csv").read_bytes() == (EXAMPLE / "table.csv").read_bytes()
    assert "main table" not in done.stderr  # every table ran


def test_the_same_seed_gives_the_same_bytes(
    lights_run: tuple[Path, dict[str, str]], properties: Path, tmp_path: Path
) -> None:
    out, _ = lights_run
    again = tmp_path / "again"
    code, output = evolve(
        str(EXAMPLE), "--table", "lights", "--properties", str(properties), "--out", str(again), *RUN, "--workers", "1"
    )
    assert code == 0, output
    for name in ("evaluations.csv", "lights.best-1.csv", "lights.best-1.check.txt", "spec.json"):
        assert (out / name).read_bytes() == (again / name).read_bytes(), name
    fresh = [
        (p / "report.md").read_text().split("## Before and after")[1].split("## The tables")[0] for p in (out, again)
    ]
    assert fresh[0] == fresh[1]


def test_every_candidate_changes_lights_only_and_keeps_the_properties_over_both_tables(
    properties: Path, tmp_path: Path
) -> None:
    """Through the front door: every candidate evolve kept is a lights table of the lights table's columns,
    and, put beside the drive table as it is, satisfies every property (proved here over the product)."""
    robot = tablebot.open(EXAMPLE, properties=[properties])
    evolved = robot.evolve(
        out=tmp_path / "api", table="lights", budget=6, batch=3, seeds="0..1", check_seeds="9..10", seconds=2, workers=1
    )
    drive = load_table(EXAMPLE / "table.csv")
    lights = load_table(EXAMPLE / "lights.csv")
    outcome = evolved.outcome
    kept = list(dict.fromkeys(outcome.order))
    assert len(kept) > 1
    changed = 0
    for key in kept:
        table = to_table(outcome.candidates[key], lights, str(EXAMPLE / "lights.csv"))
        assert table.events == lights.events and set(table.states) == set(lights.states)
        assert all(all(m is None for m in row.motors) for row in table.rows)  # no motor column to write
        changed += [(r.state, r.events, r.lamps, r.timer, r.next) for r in table.rows] != [
            (r.state, r.events, r.lamps, r.timer, r.next) for r in lights.rows
        ]
        both = load_tables(drive, {"lights": table})
        assert both.tables[0].rows == drive.rows  # the drive table as it is
        props = load_properties(both.machines[0], [properties], both)
        assert props
        for prop in props:
            assert check_product_property(prop, both).status == "holds", (key, prop.name)
    assert changed >= 1  # the search did change the lights


def test_a_mutation_never_sets_a_motor_the_table_has_no_column_for_and_changes_its_lamps() -> None:
    lights = load_table(EXAMPLE / "lights.csv")
    space = Space(
        lights.states, lights.robot.motors, Limits(len(lights.rows) + 8), frozenset(lights.writes), lights.robot.lamps
    )
    rng = np.random.default_rng(0)
    child, levels = start(lights), set()
    for _ in range(300):
        child = vary(child, space, rng) or child
        assert all(all(m is None for m in gene.motors) for gene in child)
        levels |= {lamp for gene in child for lamp in gene.lamps}
    assert levels - {0, 8}  # lamp cells are the lights table's own: they change (0 and 8 are the start's)


def test_a_robot_of_one_table_keeps_its_lamp_levels() -> None:
    table = load_table(EXAMPLE / "lights.csv")
    space = Space(table.states, table.robot.motors, Limits(len(table.rows) + 8), None, table.robot.lamps)
    rng = np.random.default_rng(0)
    child = start(table)
    for _ in range(200):
        child = vary(child, space, rng) or child
    assert {lamp for gene in child for lamp in gene.lamps} <= {0, 8}


def test_unknown_table_and_table_on_a_one_table_robot_are_located_errors(tmp_path: Path) -> None:
    code, output = evolve(str(EXAMPLE), "--table", "wheels", "--out", str(tmp_path / "a"), *RUN)
    assert code == 2 and "--table: error: --table wheels: the robot has no table of that name" in output
    assert "drive, lights" in output
    code, output = evolve(str(ROOT / "examples" / "bumberbot"), "--table", "lights", "--out", str(tmp_path / "b"), *RUN)
    assert code == 2 and "--table: error: --table lights: the robot has one table" in output
    with pytest.raises(TableBotError) as caught:
        tablebot.open(EXAMPLE).evolve(out=tmp_path / "c", table="wheels", budget=2, seeds="0", seconds=1)
    german = caught.value.diagnostics[0].render("de")
    assert german.startswith("--table: Fehler: --table wheels: ") and "Tabelle" in german, german
    assert not (tmp_path / "a").exists() and not (tmp_path / "c").exists()  # refused before anything is written


def test_freeze_cell_names_the_evolved_tables_own_cells(tmp_path: Path) -> None:
    code, output = evolve(str(EXAMPLE), "--table", "lights", "--freeze-cell", "line 3 M1", "--out", str(tmp_path), *RUN)
    assert code == 2 and "--freeze-cell: 'M1' is not a cell evolution changes" in output, output


def test_a_property_only_other_tables_decide_stops_it_first(tmp_path: Path) -> None:
    """The shipped properties: front_bumper_stops fails in the drive table, which lights cannot change."""
    code, output = evolve(str(EXAMPLE), "--table", "lights", "--out", str(tmp_path / "a"), *RUN)
    assert code == 2, output
    assert "--table lights: property front_bumper_stops fails in the robot as it is" in output
    assert "only table drive decides it" in output and "--properties" in output
    with pytest.raises(TableBotError) as caught:
        tablebot.open(EXAMPLE).evolve(out=tmp_path / "b", table="lights", budget=2, seeds="0", seconds=1)
    assert "front_bumper_stops" in caught.value.diagnostics[0].render("de")
    assert "Tabelle drive" in caught.value.diagnostics[0].render("de")


def test_a_lights_table_written_back_loads_beside_the_drive_table(tmp_path: Path) -> None:
    """formats.table_write writes one table of several with its own columns (it wrote every motor of the robot,
    so the lights table came back as a second writer of M1 and M2)."""
    from tablebot.formats.table_write import format_table

    lights = load_table(EXAMPLE / "lights.csv")
    copy = tmp_path / "robot"
    copy.mkdir()
    for name in ("robot.toml", "table.csv"):
        (copy / name).write_bytes((EXAMPLE / name).read_bytes())
    (copy / "lights.csv").write_text(format_table(lights), encoding="utf-8")
    both = load_tables(load_table(copy / "table.csv"))

    def cells(table: Table) -> list[tuple]:
        return [(r.state, r.events, r.motors, r.lamps, r.timer, r.next) for r in table.rows]

    assert cells(both.tables[1]) == cells(lights) and "M1" not in both.tables[1].writes


def test_the_main_table_is_repaired_on_counterexamples_of_the_whole_robot(tmp_path: Path) -> None:
    """Without --table the drive table evolves: it breaks front_bumper_stops, and the repair, replaying check's
    counterexamples on both tables, mends it so that every property of the robot holds beside the lights."""
    out = tmp_path / "drive"
    code, output = evolve(
        str(EXAMPLE),
        "--out",
        str(out),
        "--seeds",
        "0",
        "--check-seeds",
        "9",
        "--seconds",
        "1",
        "--budget",
        "3",
        "--batch",
        "1",
        "--workers",
        "2",
    )
    assert code == 0, output
    report = (out / "report.md").read_text(encoding="utf-8")
    assert "It breaks front_bumper_stops" in report and "**drive.repaired.csv** (" in report
    assert "evolve changed table **drive** only" in report
    copy = tmp_path / "robot"
    copy.mkdir()
    for name in ("robot.toml", "lights.csv", "properties.toml"):
        (copy / name).write_bytes((EXAMPLE / name).read_bytes())
    (copy / "table.csv").write_bytes((out / "drive.repaired.csv").read_bytes())
    checked = tablebot.open(copy).check_report()
    assert {r.prop.name: r.status for r in checked.results}["front_bumper_stops"] == "holds"
    assert all(r.status == "holds" for r in checked.results), [(r.prop.name, r.status) for r in checked.results]
