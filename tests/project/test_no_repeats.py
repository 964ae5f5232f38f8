"""Code written once, in modules of one concern (issue 35): the places a review found repeating each other share no
run of six lines, and the modules it found too long stay under 400 lines.
A run is six lines alike once indentation, blank lines and imports are set aside; the firmware's C mains share theirs
through tb_tick_frames.h, the Python helpers through the one module each was moved to."""

from __future__ import annotations

from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src" / "tablebot"
RUN = 6


def runs(path: Path) -> set[tuple[str, ...]]:
    """Every run of RUN consecutive lines of a file, stripped, blank lines and imports set aside."""
    lines = [
        line.strip()
        for line in path.read_text(encoding="utf-8").splitlines()
        if line.strip() and not line.startswith(("from ", "import ", "#include"))
    ]
    return {tuple(lines[i : i + RUN]) for i in range(len(lines) - RUN + 1)}


@pytest.mark.parametrize(
    ("one", "other"),
    [
        ("firmware/c/tb_firmware.c", "firmware/c/tb_firmware_several.c"),
        ("firmware/c/tb_bench.c", "firmware/c/tb_firmware_several.c"),
        # cross-table events per state: tablebot.engine.several.cross_bits
        ("codegen/several.py", "engine/several.py"),
        ("codegen/several.py", "hw/txt4/export.py"),
        ("engine/several.py", "hw/txt4/export.py"),
        # the models' exploration and successor cache (analysis.model), the harness's comparison and report
        ("analysis/product.py", "analysis/model.py"),
        ("testing/several_cases.py", "testing/harness.py"),
        # a UART stream's frames: tablebot.firmware.framing.take_frames
        ("firmware/several.py", "firmware/framing.py"),
    ],
)
def test_no_run_of_six_lines_stands_in_both(one: str, other: str) -> None:
    shared = runs(SRC / one) & runs(SRC / other)
    assert not shared, "\n".join(sorted("\n".join(run) for run in shared)[:1])


@pytest.mark.parametrize("name", ["firmware/monitor.py"])
def test_no_run_of_six_lines_stands_twice_in_one_module(name: str) -> None:
    lines = [line.strip() for line in (SRC / name).read_text(encoding="utf-8").splitlines() if line.strip()]
    seen: dict[tuple[str, ...], int] = {}
    for i in range(len(lines) - RUN + 1):
        run = tuple(lines[i : i + RUN])
        assert seen.setdefault(run, i) == i or seen[run] + RUN > i, "\n".join(run)


@pytest.mark.parametrize(
    "name",
    ["formats/table_read.py", "formats/table_cells.py", "hw/wiring.py", "hw/terminals.py", "loop.py", "pacing.py"],
)
def test_a_module_split_by_concern_stays_under_400_lines(name: str) -> None:
    lines = (SRC / name).read_text(encoding="utf-8").count("\n")
    assert lines <= 400, f"{name} has {lines} lines: split it by what its parts own"
