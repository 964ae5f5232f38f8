"""``tablebot sweep``'s bad options and inputs: each a clear error naming the option (or the file), no traceback,
and nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from test_sweep import sweep


@pytest.mark.parametrize(
    ("args", "option", "words"),
    [
        (["--grid", "wheels=2,3", "--robots", "2"], "--grid", "unknown key 'wheels'"),
        (["--grid", "battery=1.0,1.5", "--robots", "2"], "--grid", "battery: 1.5 is out of range"),
        (["--grid", "start=1:2", "--robots", "2"], "--grid", "start: '1:2' is not a pose"),
        (["--grid", "start=0.05:0.05:0", "--robots", "2"], "--grid", "overlaps a wall"),
        (["--grid", "start=9:9:0", "--robots", "2"], "--grid", "(9, 9, heading 0°) lies outside the arena walls"),
        (
            ["--grid", "body.half_width=0.09,0.01", "--robots", "2"],
            "--grid",
            "--grid body.half_width=0.01: bumper_overlap must not exceed half_width",
        ),
        (["--grid", "battery", "--robots", "2"], "--grid", "is not KEY=VALUES"),
        (["--seeds", "9..3"], "--seeds", "--seeds 9..3 is an empty range"),
        (["--seeds", "a..b"], "--seeds", "is not a seed or a range"),
        (["--seeds", "0..3", "--robots", "4"], "--robots", "not both"),
        ([], "--seeds", "say which runs to make"),
        (["--robots", "2", "--backend", "dask"], "--backend", "needs a scheduler"),
        (["--robots", "2", "--backend", "cloud"], "--backend", "unknown backend"),
        (["--robots", "2", "--trace", "2"], "--trace", "--trace 2: the sweep has runs 0..1"),
        # addresses Dask cannot parse: an internal error (and a traceback from the half-made client) until now
        (
            ["--robots", "2", "--scheduler", "nonsense"],
            "--scheduler",
            "--scheduler 'nonsense' is not a Dask scheduler's address: missing port number",
        ),
        (["--robots", "2", "--scheduler", "foo://h:1"], "--scheduler", "unknown address scheme 'foo'"),
        (["--robots", "2", "--scheduler", "tcp://127.0.0.1:99999"], "--scheduler", "port 99999 is not from 1 to 65535"),
    ],
)
def test_bad_specs_are_clear_errors_naming_the_option(tmp_path: Path, args: list[str], option: str, words: str) -> None:
    code, output = sweep(*args, "--out", str(tmp_path / "s"))
    assert code == 2, output
    assert output.startswith(f"{option}: error:") and words in output, output
    assert "Traceback" not in output
    assert not (tmp_path / "s").exists()  # nothing written: the mended command is no "different sweep"


def test_a_table_too_wide_for_the_compiled_fleet_is_a_clear_error(tmp_path: Path) -> None:
    inputs = [f"I{k}" for k in range(1, 11)]
    robot = (
        'name = "Wide"\ntick_ms = 10\ninitial_state = 1\n[inputs]\n'
        + "".join(f'{i} = "switch"\n' for i in inputs)
        + '[motors]\nM1 = "right motor"\nM2 = "left motor"\n'
    )
    (tmp_path / "robot.toml").write_text(robot, encoding="utf-8")
    header = ",".join(["description", "state", "T", *inputs, "M1", "M2", "timer", "next"])
    (tmp_path / "table.csv").write_text(header + "\ngo,1,1," + "," * 10 + "4,4,10,1\n", encoding="utf-8")
    result = CliRunner().invoke(
        app, ["sweep", str(tmp_path / "table.csv"), "--robots", "2", "--out", str(tmp_path / "s")]
    )
    assert result.exit_code == 2, result.output
    assert "the table has 11 event columns; the compiled fleet takes at most 10" in result.output
