"""`tablebot check`: exit codes, text and JSON output, targets, counterexample files that replay."""

from __future__ import annotations

import json
import shlex
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from tablebot.analysis.properties import load_properties
from tablebot.analysis.prove import first_violation
from tablebot.cli import app
from tablebot.formats.inputs_csv import load_inputs
from tablebot.formats.table_read import load_table
from tablebot.formats.trace_lines import read_trace
from tablebot.machine import compile_table
from tablebot.replay import replay

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from typer.testing import Result

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "analysis"
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bumberbot"
runner = CliRunner()


def check(*args: object, out: Path) -> Result:
    result = runner.invoke(app, ["check", *map(str, args), "--counterexamples", str(out)])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    return result


@pytest.mark.parametrize(
    ("name", "strict", "code"),
    [
        ("counters.csv", False, 0),
        ("counters.csv", True, 0),
        ("shadowed.csv", False, 0),
        ("shadowed.csv", True, 1),
        ("stuckloop.csv", False, 2),
        ("stuckloop.csv", True, 2),
        ("bump.csv", False, 2),  # an error-level property is violated
    ],
)
def test_exit_codes(tmp_path: Path, name: str, strict: bool, code: int) -> None:
    result = check(FIX / name, *(["--strict"] if strict else []), out=tmp_path)
    assert result.exit_code == code, result.output


def test_text_output_names_lines_and_hides_notes(tmp_path: Path) -> None:
    result = check(FIX / "shadowed.csv", out=tmp_path)
    assert f"{FIX / 'shadowed.csv'}:4: warning: row on line 4 can never fire" in result.stdout
    assert "overlap" in result.stdout and "--verbose lists them" in result.stdout
    verbose = check(FIX / "shadowed.csv", "--verbose", out=tmp_path)
    assert "both match" in verbose.stdout and "does not react to" in verbose.stdout


def test_json_output(tmp_path: Path) -> None:
    result = check(FIX / "bump.csv", "--format", "json", out=tmp_path)
    data = json.loads(result.stdout)
    assert data["exit_code"] == 2 == result.exit_code
    props = {p["name"]: p for p in data["properties"]}
    assert props["bump_stops"]["status"] == "violated" and props["bump_stops"]["ticks"] == 52
    assert props["returns"]["status"] == "holds" and props["backs_off"]["status"] == "holds"
    assert Path(props["bump_stops"]["inputs_csv"]).is_file()
    assert data["counts"]["error"] == 2  # bump_stops and no_spin_in_1


def test_counterexample_replays_with_tablebot_trace(tmp_path: Path) -> None:
    """The CSV check writes is read by `tablebot trace` and shows the violation at the last tick."""
    check(FIX / "bump.csv", out=tmp_path)
    csv_path = tmp_path / "bump_stops.csv"
    trace_path = tmp_path / "trace.jsonl"
    traced = runner.invoke(app, ["trace", str(FIX / "bump.csv"), "--inputs", str(csv_path), "--out", str(trace_path)])
    assert traced.exit_code == 0, traced.output
    lines = read_trace(trace_path)
    machine = compile_table(load_table(FIX / "bump.csv"))
    (prop,) = [p for p in load_properties(machine, [FIX / "bump.properties.toml"]) if p.name == "bump_stops"]
    assert first_violation(prop, machine, lines) == len(lines) - 1 == 51
    assert first_violation(prop, machine, replay(machine, load_inputs(csv_path, machine))) == 51


def test_target_robopro(tmp_path: Path) -> None:
    (tmp_path / "robot.toml").write_text((FIX / "robot.toml").read_text())
    table = tmp_path / "t.csv"
    table.write_text((FIX / "shadowed.csv").read_text().replace(",3,3,100,2", ",8,3,100,2", 1))
    assert check(table, out=tmp_path).exit_code == 0
    result = check(table, "--target", "robopro", out=tmp_path)
    assert result.exit_code == 2 and f"{table}:2: error: robopro: " in result.stdout
    assert check(table, "--target", "nonsense", out=tmp_path).exit_code == 2


def test_bad_property_file_is_a_located_error(tmp_path: Path) -> None:
    props = tmp_path / "p.toml"
    props.write_text('[ok]\nnever = "state == 2"\n\n[bad]\nnever = "M7 > 0"\n')
    result = check(FIX / "bump.csv", "--properties", props, out=tmp_path)
    assert result.exit_code == 2
    assert f"{props}:4: error: property bad: never: unknown name 'M7'" in result.stderr
    assert "Traceback" not in result.output


def test_bumberbot_shipped_properties(tmp_path: Path) -> None:
    result = check(EXAMPLE, "--format", "json", out=tmp_path)
    data = json.loads(result.stdout)
    status = {p["name"]: p["status"] for p in data["properties"]}
    assert status == {
        "collision_stops": "holds",
        "collision_pause": "holds",
        "never_stands_still": "holds",
        "back_to_seeking": "holds",
        "can_follow_light": "holds",
        "front_bumper_stops": "violated",
    }
    assert result.exit_code == 0  # the found bug is shipped as a warning ...
    assert check(EXAMPLE, "--strict", out=tmp_path).exit_code == 1  # ... which --strict turns into 1


def test_the_replay_line_can_be_pasted_into_a_shell(tmp_path: Path) -> None:
    """A folder with a space in its name: the printed command must still name it as one word."""
    out = tmp_path / "my counterexamples"
    line = next(
        text
        for text in check(EXAMPLE, out=out).stdout.splitlines()
        if "replay:" in text and "front_bumper_stops" in text
    )
    assert shlex.split(line.split("replay:", 1)[1]) == [
        "tablebot",
        "trace",
        str(EXAMPLE),
        "--inputs",
        str(out / "front_bumper_stops.csv"),
    ]


def test_bumberbot_text_tells_the_story(tmp_path: Path) -> None:
    result = check(EXAMPLE, out=tmp_path)
    out = result.stdout
    assert "VIOLATED front_bumper_stops" in out and "shortest counterexample: 54 ticks" in out
    assert f"replay: tablebot trace {EXAMPLE} --inputs {tmp_path / 'front_bumper_stops.csv'}" in out
    assert "<- it shows here" in out and "known bug" in out
