"""docs/statecharts.md's programs run as written: its Python block drives the exported SCXML in python-statemachine
and its JavaScript block the exported XState machine in Node, each printing what tablebot's engine does on those two
ticks (the BumberBot turns on the first, tick 0, and backs off from the bumper on the second)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from statechart_helpers import NODE_MODULES, node_missing
from tablebot.formats.inputs_csv import TickInput
from tablebot.formats.table_read import load_table
from tablebot.machine import compile_table
from tablebot.replay import replay

ROOT = Path(__file__).resolve().parents[2]
PAGE = (ROOT / "docs" / "statecharts.md").read_text(encoding="utf-8")


def _block(language: str) -> str:
    found = re.findall(rf"```{language}\n(.*?)```", PAGE, re.S)
    assert len(found) == 1, f"docs/statecharts.md has {len(found)} {language} blocks"
    return found[0]


def _engine() -> list[tuple[int, int, int, int | None]]:
    table = load_table(ROOT / "examples" / "bumberbot" / "table.csv")
    machine = compile_table(table)
    lines = replay(machine, [TickInput(0), TickInput(machine.input_bits["I3"])])
    return [(line["M1"], line["M2"], line["timer"], line["row"]) for line in lines]


def _export(tmp_path: Path, to: str) -> None:
    subprocess.run(
        [
            sys.executable,
            "-m",
            "tablebot",
            "export",
            str(ROOT / "examples" / "bumberbot"),
            str(tmp_path / "out" / to),
            "--to",
            to,
        ],
        check=True,
        capture_output=True,
    )


def test_the_python_block_drives_the_scxml_as_the_engine_runs_the_table(tmp_path: Path) -> None:
    _export(tmp_path, "scxml")
    (tmp_path / "drive.py").write_text(_block("python"), encoding="utf-8")
    done = subprocess.run([sys.executable, "drive.py"], cwd=tmp_path, capture_output=True, text=True, check=True)
    printed = [line.split()[-4:] for line in done.stdout.splitlines()]
    assert [tuple(int(v) if v != "-1" else None for v in p) for p in printed] == _engine()


@pytest.mark.skipif(node_missing() is not None, reason=str(node_missing()))
def test_the_javascript_block_drives_the_xstate_machine_as_the_engine_runs_the_table(tmp_path: Path) -> None:
    _export(tmp_path, "xstate")
    folder = tmp_path / "out" / "xstate"
    (folder / "drive.mjs").write_text(_block("js"), encoding="utf-8")
    (folder / "node_modules").symlink_to(NODE_MODULES)
    done = subprocess.run(["node", "drive.mjs"], cwd=folder, capture_output=True, text=True, check=True)
    printed = [line.split()[-4:] for line in done.stdout.splitlines()]
    assert [tuple(int(v) if v != "-1" else None for v in p) for p in printed] == _engine()
