"""``tablebot evolve`` on the fleet, on tiny budgets: the BumberBot repaired first and its tables usable
(checked by ``tablebot check``, simulated by the printed command); the same command resumes from its
records; a real Dask cluster gives the local run's bytes; SIGTERM and Ctrl-C keep what ran."""

from __future__ import annotations

import json
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from test_sweep import dask_cluster, env  # noqa: F401  (dask_cluster: a real scheduler and two workers)

ROOT = Path(__file__).resolve().parents[2]
BUMBERBOT = ROOT / "examples" / "bumberbot"
LINE = ROOT / "examples" / "line-follower"
#: The line follower's run every test of resume and backends compares with.
LINE_RUN = ["--seeds", "0..2", "--check-seeds", "50..51", "--seconds", "3", "--budget", "18", "--batch", "3"]


def evolve(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(app, ["evolve", *args])
    return result.exit_code, result.output


def same_results(a: Path, b: Path) -> None:
    """The tables evaluated, their numbers and the best table: the same bytes."""
    for name in ("evaluations.csv", "best-1.csv", "best-1.check.txt"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    fresh = [(p / "report.md").read_text().split("## Before and after")[1].split("## The tables")[0] for p in (a, b)]
    assert fresh[0] == fresh[1]


@pytest.fixture(scope="module")
def line_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("line") / "local"
    code, output = evolve(str(LINE), "--out", str(out), *LINE_RUN, "--backend", "local", "--workers", "1")
    assert code == 0, output
    return out


def test_the_bumberbot_is_repaired_first_and_every_table_written_is_usable(tmp_path: Path) -> None:
    out = tmp_path / "evo"
    args = [
        str(BUMBERBOT),
        "--out",
        str(out),
        "--seeds",
        "0..2",
        "--check-seeds",
        "50..51",
        "--seconds",
        "4",
        "--budget",
        "8",
        "--batch",
        "4",
        "--workers",
        "2",
    ]
    code, output = evolve(*args)
    assert code == 0, output
    report = (out / "report.md").read_text(encoding="utf-8")
    assert "It breaks front_bumper_stops" in report and "guard rows, " in report
    assert (out / "archive.png").read_bytes()[:4] == b"\x89PNG"
    rows = (out / "evaluations.csv").read_text().splitlines()
    assert len(rows) == 1 + 8  # the budget: the start, its repairs and the children
    tables = sorted(p for p in out.rglob("*.csv") if p.name != "evaluations.csv")
    assert {"repaired.csv", "best-1.csv"} <= {p.name for p in tables}
    for table in tables:  # check itself, on the written file, proves every property
        result = CliRunner().invoke(
            app,
            [
                "check",
                str(table),
                "--robot",
                str(BUMBERBOT / "robot.toml"),
                "--properties",
                str(BUMBERBOT / "properties.toml"),
                "--format",
                "json",
            ],
        )
        statuses = {p["name"]: p["status"] for p in json.loads(result.output)["properties"]}
        assert set(statuses.values()) == {"holds"} and len(statuses) == 6, (table, statuses)
    command = next(line for line in report.splitlines() if "best-1.csv" in line and "tablebot sim" in line)
    words = shlex.split(command.split("`")[3])
    sim = CliRunner().invoke(app, [*words[1:], "--seconds", "2", "--no-plots", "--out", str(tmp_path / "sim")])
    assert sim.exit_code == 0, sim.output
    again = {p: p.read_bytes() for p in [out / "evaluations.csv", *tables]}
    code, output = evolve(*args)  # the same command: nothing proved or run again, the same tables
    assert code == 0, output
    assert "0 run on the fleet now, 8 taken from an earlier run" in output
    assert all(p.read_bytes() == data for p, data in again.items())
    repairs = (out / "repairs.json").read_bytes()
    (out / "repairs.json").write_bytes(repairs[: len(repairs) // 2])  # cut: it ended in a JSONDecodeError
    code, output = evolve(*args)
    assert code == 0 and "repairs.json: note: not the repairs evolve writes: the repair is made again" in output
    assert (out / "repairs.json").read_bytes() == repairs  # made again, the same
    assert all(p.read_bytes() == data for p, data in again.items())


def test_a_dask_cluster_gives_the_local_run_byte_for_byte(tmp_path: Path, line_run: Path, dask_cluster: str) -> None:  # noqa: F811
    code, output = evolve(str(LINE), "--out", str(tmp_path / "dask"), *LINE_RUN, "--scheduler", dask_cluster)
    assert code == 0, output
    assert "# Evolving line-follower/table.csv: laps (high is better)" in output
    same_results(line_run, tmp_path / "dask")


def stop_when_some_ran(command: list[str], records: Path, stop: signal.Signals, at_least: int) -> list[str]:
    """Start the command, send ``stop`` once ``at_least`` tables are recorded; returns the records kept."""
    proc = subprocess.Popen(command, env=env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 180
    while not (records.exists() and len(records.read_text().splitlines()) >= at_least):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.02)
    proc.send_signal(stop)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == (143 if stop == signal.SIGTERM else 130), err
    assert "run the same command again to resume" in err and "Traceback" not in err
    return records.read_text().splitlines()


def test_sigterm_and_ctrl_c_keep_what_ran_and_the_same_command_resumes(tmp_path: Path, line_run: Path) -> None:
    """Cut by SIGTERM (two worker processes), then by Ctrl-C (this process alone), then run to the end:
    the same tables and numbers as the run never cut, whatever ran where."""
    out = tmp_path / "cut"
    command = [
        sys.executable,
        "-m",
        "tablebot",
        "evolve",
        str(LINE),
        "--out",
        str(out),
        *LINE_RUN,
        "--backend",
        "local",
    ]
    records = out / "evaluations.jsonl"
    first = stop_when_some_ran([*command, "--workers", "2"], records, signal.SIGTERM, 4)
    assert 4 <= len(first) < 18 and not (out / "report.md").exists()
    second = stop_when_some_ran([*command, "--workers", "1"], records, signal.SIGINT, len(first) + 3)
    assert second[: len(first)] == first and len(second) < 18
    done = subprocess.run([*command, "--workers", "1"], env=env(), capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert records.read_text().splitlines()[: len(second)] == second  # what ran before is kept, not run again
    same_results(line_run, out)


@pytest.mark.parametrize("cut", ["evaluations.jsonl", "proofs.jsonl"])
def test_a_record_cut_mid_line_is_done_again(tmp_path: Path, line_run: Path, cut: str) -> None:
    """A kill (or a full disk) in the middle of a record's line left proofs.jsonl unreadable: the resumed run
    ended in an internal error (JSONDecodeError). And a record appended after a cut line joined it, so it was
    lost too."""
    out = tmp_path / "resumed"
    shutil.copytree(line_run, out)
    data = (out / cut).read_bytes()
    (out / cut).write_bytes(data[: len(data) - 25])  # the last record cut
    code, output = evolve(str(LINE), "--out", str(out), *LINE_RUN, "--backend", "local", "--workers", "1")
    assert code == 0, output
    same_results(line_run, out)
    lines = (out / cut).read_text(encoding="utf-8").splitlines()  # the cut record made again, on its own line
    assert len(lines) == data.count(b"\n") + 1 and json.loads(lines[-1])


def test_the_report_gives_a_working_command_for_every_world(tmp_path: Path) -> None:
    """Evolved over two worlds, each table gets a ``tablebot sim`` per world (each into its own folder) and
    one ``tablebot sweep`` runs a table on every world and scenario of the search: each of them runs."""
    other = tmp_path / "other place"
    other.mkdir()
    (other / "arena.toml").write_text(
        (LINE / "arena.toml").read_text().replace('name = "oval track"', 'name = "second track"')
    )
    out = tmp_path / "out dir"
    code, output = evolve(
        str(LINE),
        "--world",
        str(LINE / "arena.toml"),
        "--world",
        str(other / "arena.toml"),
        "--out",
        str(out),
        "--seeds",
        "0..1",
        "--check-seeds",
        "5..5",
        "--seconds",
        "1",
        "--budget",
        "3",
        "--batch",
        "2",
        "--workers",
        "1",
        "-q",
    )
    assert code == 0, output
    report = (out / "report.md").read_text(encoding="utf-8")
    block = report.split("- `best-1.csv`")[1].split("\n- ")[0]
    commands = [shlex.split(line.split("`")[1]) for line in block.splitlines()[1:3]]
    assert [c[c.index("--world") + 1] for c in commands] == [str(LINE / "arena.toml"), str(other / "arena.toml")]
    sweep = shlex.split(report.split("any table above in its place):\n\n`")[1].split("`")[0])
    assert sweep[:3] == ["tablebot", "sweep", str(out / "best-1.csv")] and sweep.count("--world") == 2
    for words in [*commands, sweep]:
        result = CliRunner().invoke(app, [*words[1:], "--no-plots", "-q"])
        assert result.exit_code == 0, (words, result.output)
    names = {p.parent.relative_to(out).as_posix() for p in out.rglob("trace.jsonl")}
    assert names == {"sim/best-1/1-arena", "sim/best-1/2-arena"}
    results = (out / "sweep" / "best-1" / "results.csv").read_text().splitlines()
    assert len(results) == 1 + 2 * 2  # two seeds in each world
