"""A robot of several tables on a real Dask cluster (a scheduler and two single-threaded workers, processes of
their own on loopback): a sweep of the BumberBot with its lights gives the local sweep's results byte for byte,
and a tuning of another table's timer the local tuning's evaluations (issue 36 §2: every table runs on the
workers, the other tables shared with them as the main one is, with every table's program variants)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.testing.dask_cluster import local_cluster
from test_tune_several import robot

if TYPE_CHECKING:
    from collections.abc import Iterator

ROOT = Path(__file__).resolve().parents[2]
LIGHTS = ROOT / "examples" / "bumberbot-lights"


@pytest.fixture(scope="module")
def cluster() -> Iterator[str]:
    pytest.importorskip("distributed", reason="the Dask backend needs the cluster extra (the dev extra has it)")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    with local_cluster([[], ["--preload", "tablebot.fleet.worker"]], env) as running:
        yield running.address


def command(*args: str) -> str:
    result = CliRunner().invoke(app, list(args))
    assert result.exit_code == 0, result.output
    return result.output


def test_a_dask_sweep_of_several_tables_gives_the_local_results(tmp_path: Path, cluster: str) -> None:
    spec = ["sweep", str(LIGHTS), "--grid", "battery=1.0,0.7", "--seeds", "0..11", "--seconds", "6", "--no-plots"]
    command(*spec, "--out", str(tmp_path / "local"), "--backend", "local", "--workers", "2")
    command(*spec, "--out", str(tmp_path / "dask"), "--scheduler", cluster)
    local = (tmp_path / "local" / "results.csv").read_bytes()
    assert local == (tmp_path / "dask" / "results.csv").read_bytes()
    assert local.count(b"\n") == 25
    assert b"time_flash_left_s" not in local.splitlines()[0]  # the main table's states are the result's columns


def test_a_dask_tuning_of_another_tables_timer_gives_the_local_evaluations(tmp_path: Path, cluster: str) -> None:
    folder = robot(tmp_path)
    spec = [
        "tune",
        str(folder / "drive.csv"),
        "--robot",
        str(folder / "robot.toml"),
        "--world",
        str(folder / "hall.toml"),
        "--cells",
        "clock: line 2 timer=600..660",
        "--budget",
        "12",
        "--seeds",
        "0..3",
        "--check-seeds",
        "7..8",
        "--seconds",
        "9",
        "--objective",
        "lamp_distance",
        "--quiet",
    ]
    command(*spec, "--out", str(tmp_path / "local"), "--backend", "local", "--workers", "2")
    command(*spec, "--out", str(tmp_path / "dask"), "--scheduler", cluster)
    local = (tmp_path / "local" / "evaluations.csv").read_bytes()
    assert local == (tmp_path / "dask" / "evaluations.csv").read_bytes()
    values = [line.split(b",")[2] for line in local.splitlines()[1:]]
    assert len(values) == len(set(values)) == 13  # the table's own value and twelve candidates, none tied
    assert (tmp_path / "local" / "clock.tuned.csv").read_bytes() == (tmp_path / "dask" / "clock.tuned.csv").read_bytes()
