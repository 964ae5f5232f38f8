"""The numpy trace of a robot of several tables (issue 36 §2): ``run.trace`` from the compiled simulator has the
other tables' columns (``NAME.event``, ``NAME.row``, ``NAME.state``, ``NAME.timer``) as ``trace.jsonl`` has them,
rows named as the file writes them (a group's row by its line); the trace read back from the file it wrote is
the same array, and the bytes ``run.save()`` writes are those of ``tablebot sim``."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

import tablebot
from tablebot.api import traces

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_the_trace_array_has_every_table_as_the_file_has_it(tmp_path: Path) -> None:
    run = tablebot.open(EXAMPLES / "bumberbot-lights").simulate(seconds=3, seed=4)
    trace = run.trace
    names = trace.dtype.names or ()
    assert names[-4:] == ("lights.event", "lights.row", "lights.state", "lights.timer")
    run.save(tmp_path / "api", plots=False)
    lines = (tmp_path / "api" / "trace.jsonl").read_text(encoding="utf-8").splitlines()
    records = [json.loads(line) for line in lines]
    assert len(records) == len(trace) == 300
    for key in ("row", "lights.event", "lights.row", "lights.state", "lights.timer"):
        assert trace[key].tolist() == [-1 if r[key] is None else r[key] for r in records], key
    assert len(set(trace["lights.state"].tolist())) > 1  # the lights table moved on
    read = traces.from_file(tmp_path / "api" / "trace.jsonl", run.scene.machine)
    assert read.dtype == trace.dtype and all(np.array_equal(read[n], trace[n]) for n in names)
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "tablebot",
            "sim",
            str(EXAMPLES / "bumberbot-lights"),
            "--seconds",
            "3",
            "--seed",
            "4",
            "--no-plots",
            "--out",
            str(tmp_path / "cli"),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "cli" / "trace.jsonl").read_bytes() == (tmp_path / "api" / "trace.jsonl").read_bytes()


def test_a_one_table_trace_array_is_unchanged() -> None:
    trace = tablebot.open(EXAMPLES / "bumberbot").simulate(seconds=1, seed=4).trace
    assert trace.dtype.names == (
        "tick",
        "event",
        "row",
        "state",
        "timer",
        "M1",
        "M2",
        "x",
        "y",
        "heading",
        "I7_light",
        "I8_light",
        "battery_v",
    )
