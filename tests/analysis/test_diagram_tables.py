"""`tablebot diagram` of a robot of several tables (issue 36 §2): one diagram per table, side by side, the
cross-table events on their edges written as the other table's states and explained in the legend."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from tablebot.analysis.diagram_tables import render_tables
from tablebot.loading import Loaded

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bumberbot-lights"


def test_one_diagram_per_table_with_cross_table_events_labelled() -> None:
    loaded = Loaded.open(EXAMPLE)
    assert loaded.tables is not None
    source = render_tables(loaded.tables, "dot").decode()
    assert "subgraph cluster_0 {" in source and "subgraph cluster_1 {" in source
    assert "<b>main table drive</b>" in source and "<b>table lights</b>" in source
    assert "drive___start -> drive_s_2 [" in source and "lights___start -> lights_s_flash_left [" in source
    # a lights edge: the drive table's states it needs, and the lamps it sets (it drives no motor)
    assert "lights_s_burn -> lights_s_blink_on [" in source
    assert "<b>drive in 20..29</b> → L1=8 L2=8 · 100 ms" in source
    assert "<b>drive in {11,12}</b>" in source and "<b>drive in {1,2}</b>" in source
    assert "table drive was in state 11 or 12 at the start of the tick" in source
    assert "table drive was in state 20 to 29 at the start of the tick" in source
    # the group row is an edge from each state of the group
    for state in (1, 2, 11):
        assert f"drive_s_{state} -> drive_s_20 [" in source


def test_mermaid_has_a_concurrent_region_per_table(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "diagram", str(EXAMPLE), "--format", "mermaid"],
        capture_output=True,
        text=True,
        check=True,
    )
    lines = done.stdout.splitlines()
    assert lines[:3] == ["stateDiagram-v2", "    direction LR", "    [*] --> robot_BumberBot_with_lights"]
    assert lines.count("        --") == 1
    split = lines.index("        --")
    assert "        [*] --> drive_s_2" in lines[:split] and "        [*] --> lights_s_flash_left" in lines[split:]
    assert "        lights_s_flash_left --> lights_s_burn: drive in (11,12) / L1=8 L2=8" in lines  # {} is Mermaid's
    out = tmp_path / "robot.png"
    subprocess.run(
        [sys.executable, "-m", "tablebot", "diagram", str(EXAMPLE), "--out", str(out)], check=True, capture_output=True
    )
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
