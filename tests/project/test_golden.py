"""The golden files (tests/golden/, made by scripts/golden.py: ``make golden``): what tablebot writes for the
BumberBot, made again by the commands a user types and compared byte for byte, so that a change to the
generated C, the ROBO Pro program, the diagram, the check report or a simulated trace shows up as a readable
diff here, and as a reviewed diff of tests/golden/ in the change that meant it."""

from __future__ import annotations

import difflib
import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[2]
SHOWN = 40  # diff lines in a failure's message


def script() -> ModuleType:
    spec = importlib.util.spec_from_file_location("golden", ROOT / "scripts" / "golden.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


golden = script()


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> dict[str, bytes]:
    return golden.make(tmp_path_factory.mktemp("golden"))


def difference(name: str, want: bytes, got: bytes) -> str:
    """What changed, as a unified diff of the first lines that differ (or the sizes, for bytes that are no text)."""
    try:
        old, new = want.decode("utf-8").splitlines(), got.decode("utf-8").splitlines()
    except UnicodeDecodeError:
        return f"{name}: {len(want)} bytes recorded, {len(got)} made"
    lines = list(difflib.unified_diff(old, new, f"tests/golden/{name}", f"made now: {name}", lineterm="", n=2))
    more = f"\n... {len(lines) - SHOWN} more diff lines" if len(lines) > SHOWN else ""
    same_text = "" if lines else " (the same lines: line endings or the last newline differ)"
    return f"{name} changed{same_text}:\n" + "\n".join(lines[:SHOWN]) + more


def test_the_same_files_are_made_as_are_recorded(made: dict[str, bytes]) -> None:
    assert sorted(made) == sorted(golden.recorded()), "run `make golden` and review the new or removed files"
    assert set(golden.SIMULATED) <= set(made)


@pytest.mark.parametrize("name", sorted(golden.recorded()))
def test_each_output_is_byte_for_byte_the_recorded_one(made: dict[str, bytes], name: str) -> None:
    if name in golden.SIMULATED:
        where = (golden.GOLDEN / "PLATFORM").read_text(encoding="utf-8").strip()
        if where != golden.PLATFORM:
            pytest.skip(f"{name} was recorded on {where}, not {golden.PLATFORM} (floating point may round otherwise)")
    want, got = golden.recorded()[name], made.get(name, b"")
    assert got == want, difference(name, want, got) + "\n(if the change is meant: `make golden`, then review git diff)"


def test_a_change_shows_as_a_readable_diff() -> None:
    said = difference("check.txt", b"holds    a\nholds    b\nholds    c\n", b"holds    a\nVIOLATED b\nholds    c\n")
    assert said.splitlines() == [
        "check.txt changed:",
        "--- tests/golden/check.txt",
        "+++ made now: check.txt",
        "@@ -1,3 +1,3 @@",
        " holds    a",
        "-holds    b",
        "+VIOLATED b",
        " holds    c",
    ]
    assert difference("x.bin", b"\xff\x00", b"\xff") == "x.bin: 2 bytes recorded, 1 made"
