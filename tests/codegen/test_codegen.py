"""Generated C: the host-compiled engine equals the Python engine tick for tick (BumberBot and random
tables), compiles warning-free with gcc and avr-gcc, and holds no heap and no floating point."""

from __future__ import annotations

import random
import re
import shutil
import subprocess
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tablebot.cli.common import load
from tablebot.codegen.host import build_host, run_host
from tablebot.codegen.packing import DENSE_LIMIT_BYTES, plan, reachable, unsigned_for
from tablebot.codegen.source import ENGINE_FILES, generate, template
from tablebot.formats.inputs_csv import load_inputs
from tablebot.machine import compile_table
from tablebot.replay import replay
from tablebot.robot import Match
from tablebot.testing.random_tables import Shape, random_case, random_inputs, random_table

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from tablebot.formats.inputs_csv import TickInput
    from tablebot.machine import Machine

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"


@pytest.fixture(scope="module")
def bumberbot() -> tuple[Machine, list[TickInput]]:
    _, machine = load(EXAMPLE)
    return machine, load_inputs(EXAMPLE / "inputs.csv", machine)


@pytest.mark.parametrize("lookup", ["dense", "scan"])
def test_bumberbot_host_c_equals_python(
    bumberbot: tuple[Machine, list[TickInput]], lookup: str, tmp_path: Path
) -> None:
    machine, ticks = bumberbot
    exe = build_host(machine, tmp_path, lookup)
    assert run_host(exe, machine, ticks) == list(replay(machine, ticks))


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    seed=st.integers(0, 2**32 - 1),
    lookup=st.sampled_from(["dense", "scan"]),
    lamps=st.integers(0, 2),
    counters=st.integers(0, 3),
    states=st.integers(1, 7),
)
def test_random_tables_host_c_equals_python(
    tmp_path_factory: pytest.TempPathFactory, seed: int, lookup: str, lamps: int, counters: int, states: int
) -> None:
    rng = random.Random(seed)
    table = random_table(rng, Shape(states=states, rows=states * 3, lamps=lamps, counters=counters))
    machine = compile_table(table)
    ticks = random_inputs(rng, table, 150)
    exe = build_host(machine, tmp_path_factory.mktemp("host"), lookup)
    assert run_host(exe, machine, ticks) == list(replay(machine, ticks))


@pytest.mark.parametrize("match", ["document", "always"])
@pytest.mark.parametrize("lookup", ["dense", "scan"])
def test_both_matching_rules_in_c_on_tables_where_they_part(tmp_path: Path, match: Match, lookup: str) -> None:
    """Tables and inputs on which the two rules take different decisions: C follows the table's own."""
    table, ticks = random_case(random.Random(f"c-{match}"), Shape(states=3, rows=9, counters=1, match=match))
    machine = compile_table(table)
    assert run_host(build_host(machine, tmp_path, lookup), machine, ticks) == list(replay(machine, ticks))


def test_wide_table_uses_16_bit_rows_and_scan(tmp_path: Path) -> None:
    rng = random.Random(7)
    table = random_table(rng, Shape(states=60, rows=300, inputs=9, counters=1))
    machine = compile_table(table)
    layout = plan(machine)
    assert layout.row.size == 2 and layout.event.size == 2  # 300 rows, 11 event bits
    assert not layout.dense  # 60 states * 2^11 * 2 bytes is far over the limit
    ticks = random_inputs(rng, table, 300)
    assert run_host(build_host(machine, tmp_path), machine, ticks) == list(replay(machine, ticks))


def _avr_gcc_compiles(folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            "avr-gcc",
            "-mmcu=atmega328p",
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-Os",
            "-c",
            "tb_engine.c",
            "tb_table.c",
        ],
        cwd=folder,
        capture_output=True,
        text=True,
    )


@pytest.mark.parametrize("shape", [Shape(), Shape(lamps=2, counters=2, states=9), Shape(states=1, rows=1)])
@pytest.mark.parametrize("lookup", ["dense", "scan"])
def test_generated_c_is_warning_free_for_avr_gcc(tmp_path: Path, shape: Shape, lookup: str) -> None:
    assert shutil.which("avr-gcc"), "avr-gcc is needed (scripts/bootstrap.sh installs gcc-avr)"
    machine = compile_table(random_table(random.Random(3), shape))
    generate(machine, lookup).write(tmp_path)
    done = _avr_gcc_compiles(tmp_path)
    assert done.returncode == 0, done.stderr


def test_export_c_cli_writes_engine_and_table(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from tablebot.cli import app

    result = CliRunner().invoke(app, ["export", str(EXAMPLE), str(tmp_path), "--to", "c"])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tb_config.h", "tb_engine.c", "tb_engine.h", "tb_table.c"]
    assert "lookup: dense" in result.output
    config = (tmp_path / "tb_config.h").read_text()
    assert "#define TB_TIMER_BIT 32u" in config and "#define TB_INPUT_MASK 31u" in config
    assert _avr_gcc_compiles(tmp_path).returncode == 0


def test_export_c_cli_reports_a_bad_table(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from tablebot.cli import app

    bad = tmp_path / "table.csv"
    bad.write_text("description,state,T,I3,M1_dir,M1_speed,timer,next\nx,1,1,,0,3,abc,1\n")
    result = CliRunner().invoke(app, ["export", str(bad), str(tmp_path / "out"), "--to", "c"])
    assert result.exit_code == 2
    assert re.search(r"table\.csv:2:\d+: error: timer", result.output)


def test_engine_sources_have_no_heap_and_no_float() -> None:
    for name in (*ENGINE_FILES, "host_run.c"):
        code = re.sub(r"/\*.*?\*/", "", template(name), flags=re.S)
        assert not re.search(r"\b(malloc|calloc|realloc|free|float|double)\b", code), name


def test_table_data_is_const_and_progmem_on_avr(tmp_path: Path) -> None:
    _, machine = load(EXAMPLE)
    source = generate(machine)
    assert "TB_ROM const uint8_t tb_actions" in source.files["tb_table.c"]
    assert "#define TB_ROM PROGMEM" in source.files["tb_engine.h"]


def test_unreachable_rows_are_dropped_from_the_scan() -> None:
    # row 1 needs a superset of row 0's events: it can never fire; row 2 needs other events
    assert reachable([(0b01, 0), (0b11, 1), (0b10, 2), (0, 3), (0b100, 4)]) == [(0b01, 0), (0b10, 2), (0, 3)]


def test_integer_widths() -> None:
    assert unsigned_for(255).size == 1 and unsigned_for(256).size == 2 and unsigned_for(70000).size == 4


def test_auto_lookup_is_dense_for_the_bumberbot() -> None:
    _, machine = load(EXAMPLE)
    layout = plan(machine)
    assert layout.dense and layout.lookup_bytes == 10 * 64 <= DENSE_LIMIT_BYTES
    # state 1 with both front bumpers and the timer: row 0 (collision) comes first in the table
    state1 = machine.states.index(1)
    assert layout.lookup[(state1 << 6) | 0b111000] == 0
