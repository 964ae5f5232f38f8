"""Firmware under emulation: built with avr-gcc, run by the simavr harness, its decoded UART trace must
equal the Python engine's trace tick for tick (BumberBot's recorded run and random tables)."""

from __future__ import annotations

import random
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tablebot.cli.common import load
from tablebot.diagnostics import TableBotError
from tablebot.firmware.board_header import timer_setting, ubrr
from tablebot.firmware.boards import load_board, read_robot_boards, wire
from tablebot.firmware.build import build
from tablebot.firmware.emulate import build_harness, emulate, pins_csv
from tablebot.formats.inputs_csv import TickInput, load_inputs
from tablebot.machine import compile_table
from tablebot.replay import replay
from tablebot.robot import BUMBERBOT, Counter, Match, Robot
from tablebot.testing.random_tables import Shape, random_case, random_inputs, random_table
from tablebot.tomlfile import Source

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from typing import Any

    from tablebot.machine import Machine

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"
STEP_TARGET = 100  # cycles per engine step, worst case (issue 6)


@pytest.fixture(scope="module")
def harness(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_harness(tmp_path_factory.mktemp("harness"))


@pytest.fixture(scope="module")
def bumberbot() -> tuple[Machine, list[TickInput]]:
    _, machine = load(EXAMPLE)
    return machine, load_inputs(EXAMPLE / "inputs.csv", machine)


def test_bumberbot_on_uno_equals_python_tick_for_tick(
    bumberbot: tuple[Machine, list[TickInput]], harness: Path, tmp_path: Path
) -> None:
    machine, ticks = bumberbot
    firmware = build(machine, "uno", tmp_path / "fw")
    run = emulate(firmware, machine, ticks, tmp_path / "run", harness)
    assert run.problems == []
    assert [h.table_hash for h in run.hellos] == [firmware.layout.table_hash]
    assert run.trace == list(replay(machine, ticks))
    assert len(run.cycles) == len(ticks)
    assert max(c.step for c in run.cycles) <= STEP_TARGET
    assert firmware.flash < 4096 and firmware.ram < 256
    assert firmware.hex.read_text().startswith(":")


def test_bumberbot_on_ftduino_equals_python(
    bumberbot: tuple[Machine, list[TickInput]], harness: Path, tmp_path: Path
) -> None:
    machine, ticks = bumberbot
    firmware = build(machine, "ftduino", tmp_path / "fw")
    run = emulate(firmware, machine, ticks, tmp_path / "run", harness)
    assert run.problems == [] and run.trace == list(replay(machine, ticks))
    assert firmware.flash < 4096 and firmware.ram < 256


@pytest.mark.parametrize("board", ["uno", "ftduino"])
def test_counters_example_with_encoder_pulses(board: str, harness: Path, tmp_path: Path) -> None:
    table, machine = load(ROOT / "examples" / "bumberbot-counters")
    ticks = random_inputs(random.Random(1), table, 800, density=0.03, max_pulses=3)
    firmware = build(machine, board, tmp_path / "fw")
    run = emulate(firmware, machine, ticks, tmp_path / "run", harness)
    expected = list(replay(machine, ticks))
    assert len({line["C1"] for line in expected}) > 5  # the counters really count down
    assert run.problems == [] and run.trace == expected


def test_remapped_active_high_inputs_under_emulation(
    bumberbot: tuple[Machine, list[TickInput]], harness: Path, tmp_path: Path
) -> None:
    machine, ticks = bumberbot
    robot = _robot(sections={"board": {"uno": {"I7": "A2", "I8": "A3", "M1": "B", "active_high": ["I7", "I8"]}}})
    table = load(EXAMPLE)[0]
    moved = compile_table(type(table)(robot=robot, events=table.events, rows=table.rows, path=table.path))
    firmware = build(moved, "uno", tmp_path / "fw")
    assert "if (pc & (1u << 2)) ev |= 2u; /* I7 on A2, 1 = high */" in (tmp_path / "fw/src/tb_board.h").read_text()
    run = emulate(firmware, moved, ticks[:2000], tmp_path / "run", harness)
    assert run.trace == list(replay(machine, ticks[:2000]))


def _fits(board: str, shape: Shape) -> bool:
    if board == "uno":
        return shape.inputs + shape.lamps <= 8 and shape.motors <= 2 and shape.counters <= 2
    return shape.inputs <= 8 and 2 * shape.motors + shape.lamps <= 8 and shape.counters <= 3


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    seed=st.integers(0, 2**32 - 1),
    board=st.sampled_from(["uno", "uno", "ftduino"]),
    inputs=st.integers(0, 4),
    motors=st.integers(1, 2),
    lamps=st.integers(0, 2),
    counters=st.integers(0, 2),
    lookup=st.sampled_from(["auto", "scan"]),
)
def test_random_tables_in_firmware_equal_python(
    tmp_path_factory: pytest.TempPathFactory,
    harness: Path,
    seed: int,
    board: str,
    inputs: int,
    motors: int,
    lamps: int,
    counters: int,
    lookup: str,
) -> None:
    shape = Shape(states=5, rows=15, inputs=inputs, motors=motors, lamps=lamps, counters=counters)
    assert _fits(board, shape)
    rng = random.Random(seed)
    table = random_table(rng, shape)
    machine = compile_table(table)
    ticks = random_inputs(rng, table, 120)
    work = tmp_path_factory.mktemp("random")
    firmware = build(machine, board, work / "fw", lookup)
    run = emulate(firmware, machine, ticks, work / "run", harness)
    assert run.problems == []
    assert run.trace == list(replay(machine, ticks))


@pytest.mark.parametrize("match", ["document", "always"])
def test_both_matching_rules_in_firmware_on_tables_where_they_part(harness: Path, tmp_path: Path, match: Match) -> None:
    """Under emulation the firmware follows the table's rule where the two part (the scan lookup carries
    the rule as code, the dense one as data)."""
    table, ticks = random_case(
        random.Random(f"fw-{match}"), Shape(states=3, rows=9, inputs=3, counters=1, match=match), ticks=120
    )
    machine = compile_table(table)
    for lookup in ("scan", "dense"):
        run = emulate(
            build(machine, "uno", tmp_path / lookup / "fw", lookup), machine, ticks, tmp_path / lookup, harness
        )
        assert run.problems == [] and run.trace == list(replay(machine, ticks))


# --- boards and wiring --------------------------------------------------------------------------


def _robot(**changes: Any) -> Robot:
    """The BumberBot with ``changes``; a ``sections`` board table is read as a robot file's would be."""
    robot = Robot(**{**BUMBERBOT.__dict__, **changes, "sections": {}})
    boards = changes.get("sections", {}).get("board")
    if boards is not None:
        src = Source("robot.toml", "", {"board": boards})
        robot.sections["board"] = read_robot_boards(src, boards, robot)
        src.raise_if_any()
    return robot


def test_bumberbot_wiring_on_both_boards() -> None:
    uno = wire(BUMBERBOT, load_board("uno"))
    assert uno.inputs == {"I3": "D2", "I4": "D4", "I5": "D5", "I7": "D6", "I8": "D7"}
    assert uno.motors == {"M1": "A", "M2": "B"}
    ftduino = wire(BUMBERBOT, load_board("ftduino"))
    assert ftduino.inputs == {n: n for n in BUMBERBOT.inputs}  # I3 on the ftDuino's I3, and so on
    assert ftduino.motors == {"M1": "M1", "M2": "M2"}


def test_robot_file_maps_terminals_and_polarity() -> None:
    robot = _robot(sections={"board": {"uno": {"I7": "A2", "M1": "B", "active_high": ["I8"]}}})
    wiring = wire(robot, load_board("uno"))
    assert wiring.inputs["I7"] == "A2" and wiring.motors == {"M1": "B", "M2": "A"}
    assert wiring.active_high == frozenset({"I8"})


def test_too_many_motors_for_the_uno_is_refused() -> None:
    robot = _robot(motors=("M1", "M2", "M3"))
    with pytest.raises(TableBotError, match="no free terminal for motor M3"):
        wire(robot, load_board("uno"))


def test_ftduino_c2_carries_the_trace_not_a_counter() -> None:
    robot = _robot(counters=(Counter("C1", "M1"), Counter("C2", "M2")))
    wiring = wire(robot, load_board("ftduino"))
    assert wiring.counters == {"C1": "C1", "C2": "C3"}  # C2 is TXD1: the counter takes the next free one
    with pytest.raises(TableBotError, match="cannot use 'C2'"):
        wire(
            _robot(counters=(Counter("C1", "M1"),), sections={"board": {"ftduino": {"C1": "C2"}}}),
            load_board("ftduino"),
        )


def test_unknown_board_terminal_is_reported() -> None:
    with pytest.raises(TableBotError, match="input I3 cannot use 'D13'"):
        wire(_robot(sections={"board": {"uno": {"I3": "D13"}}}), load_board("uno"))


def test_pins_csv_drives_active_low_inputs_and_pulses() -> None:
    _, machine = load(EXAMPLE)
    wiring = wire(BUMBERBOT, load_board("uno"))
    text = pins_csv(machine, wiring, [TickInput(0), TickInput(machine.input_bits["I3"])])
    assert text.splitlines() == ["PD2,PD4,PD5,PD6,PD7", "1,1,1,1,1", "0,1,1,1,1"]


def test_tick_timer_and_uart_settings() -> None:
    assert timer_setting(16_000_000, 10) == (19999, "(1 << CS11)")  # /8: 2 MHz, 20000 counts
    assert timer_setting(16_000_000, 1000)[0] == 62499  # /256
    with pytest.raises(TableBotError):
        timer_setting(16_000_000, 5000)
    assert ubrr(16_000_000, 115200) == 16
