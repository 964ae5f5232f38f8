"""Board files (``boards/*.toml``) and the wiring of a robot onto a board: the terminal of each input,
motor, lamp and counter. A name that is a terminal takes it, ``[board.NAME]`` in the robot file maps
others, and the rest take free terminals in order."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from importlib import resources
from typing import Any

from tablebot.diagnostics import Collector, fail
from tablebot.robot import Robot

BOARDS = ("uno", "ftduino")


@dataclass(frozen=True)
class Board:
    """One board file: the MCU, its UART, and the terminals a robot can be wired to."""

    name: str
    title: str
    mcu: str
    f_cpu: int
    baud: int
    usart: int  # which USART carries the trace
    uart: str
    avrdude: dict[str, Any]
    inputs: dict[str, str]  # terminal -> pin (PD2) or ADC channel (ADC6)
    lamps: tuple[str, ...]  # terminals lamps may take, in order
    motors: dict[str, str]  # terminal -> channel (C function, or "O1 O2")
    outputs: dict[str, int] = field(default_factory=dict)  # ftDuino O1..O8 -> driver output index
    counters: dict[str, str] = field(default_factory=dict)  # terminal -> pin


def load_board(name: str) -> Board:
    if name not in BOARDS:
        raise fail(name, f"unknown board {name!r}", f"boards: {', '.join(BOARDS)}")
    text = resources.files("tablebot.firmware").joinpath("boards").joinpath(f"{name}.toml").read_text(encoding="utf-8")
    data = tomllib.loads(text)
    pins = data.get("pins")
    inputs = pins if pins is not None else data["inputs"]
    lamps = tuple(reversed(pins)) if pins is not None else tuple(data.get("outputs", {}))
    return Board(name=data["name"], title=data["title"], mcu=data["mcu"], f_cpu=data["f_cpu"],
                 baud=data["baud"], usart=data["usart"], uart=data["uart"], avrdude=data["avrdude"],
                 inputs=dict(inputs), lamps=lamps, motors=dict(data["motors"]), outputs=dict(data.get("outputs", {})),
                 counters=dict(data.get("counters", {})))


@dataclass(frozen=True)
class Wiring:
    """A robot on a board: robot name -> board terminal for each kind of signal."""

    board: Board
    inputs: dict[str, str]
    motors: dict[str, str]
    lamps: dict[str, str]
    counters: dict[str, str]
    active_high: frozenset[str] = frozenset()

    def used_outputs(self) -> set[str]:
        """ftDuino O terminals taken by motors and lamps."""
        taken = {o for m in self.motors.values() for o in self.board.motors[m].split()}
        return taken | set(self.lamps.values())


def _overrides(robot: Robot, board: Board, out: Collector) -> tuple[dict[str, str], frozenset[str]]:
    section = robot.sections.get("board", {})
    mine = section.get(board.name, {}) if isinstance(section, dict) else {}
    if not isinstance(mine, dict):
        out.error(None, None, f"[board.{board.name}] must be a table of NAME = \"TERMINAL\"",
                  'for example: I3 = "D4"')
        return {}, frozenset()
    active_high = mine.get("active_high", [])
    if not isinstance(active_high, list) or not all(isinstance(n, str) for n in active_high):
        out.error(None, None, f"[board.{board.name}] active_high must be a list of input names",
                  'for example: active_high = ["I7", "I8"]')
        active_high = []
    for name in active_high:
        if name not in robot.inputs:
            out.error(None, None, f"[board.{board.name}] active_high names {name!r}, not an input",
                      f"inputs are {', '.join(robot.inputs)}")
    maps = {k: str(v) for k, v in mine.items() if k != "active_high"}
    return maps, frozenset(active_high)


def _assign(kind: str, names: tuple[str, ...], terminals: tuple[str, ...], maps: dict[str, str],
            taken: set[str], board: Board, out: Collector) -> dict[str, str]:
    """Explicit map first, then a terminal of the same name, then the next free terminal."""
    chosen: dict[str, str] = {}
    for name in names:
        want = maps.get(name) or (name if name in terminals and name not in taken else None)
        if want is None:
            continue
        if want not in terminals:
            out.error(None, None, f"{kind} {name} cannot use {want!r} on the {board.name} board",
                      f"{kind} terminals: {', '.join(terminals) or 'none'}")
        elif want in taken:
            out.error(None, None, f"{kind} {name}: terminal {want} is already used",
                      f"give {name} another terminal in [board.{board.name}]")
        else:
            chosen[name] = want
            taken.add(want)
    free = [t for t in terminals if t not in taken]
    for name in names:
        if name in chosen or name in maps:
            continue
        if not free:
            out.error(None, None, f"the {board.name} board has no free terminal for {kind} {name}",
                      f"{kind} terminals: {', '.join(terminals) or 'none'}")
            continue
        chosen[name] = free.pop(0)
        taken.add(chosen[name])
    return {name: chosen[name] for name in names if name in chosen}


def wire(robot: Robot, board: Board) -> Wiring:
    """Assign every robot signal to a terminal, reporting all conflicts at once."""
    out = Collector(robot.source)
    maps, active_high = _overrides(robot, board, out)
    for name in maps:
        if name not in (*robot.inputs, *robot.motors, *robot.lamps, *robot.counter_names):
            out.error(None, None, f"[board.{board.name}] maps {name!r}, which the robot does not have",
                      "map the robot's inputs, motors, lamps and counters")
    taken: set[str] = set()
    inputs = _assign("input", robot.inputs, tuple(board.inputs), maps, taken, board, out)
    motors = _assign("motor", robot.motors, tuple(board.motors), maps, set(), board, out)
    motor_outputs = {o for m in motors.values() for o in board.motors[m].split()}
    lamp_terminals = tuple(t for t in board.lamps if t not in motor_outputs)
    lamps = _assign("lamp", robot.lamps, lamp_terminals, maps, taken, board, out)
    counters = _assign("counter", robot.counter_names, tuple(board.counters), maps, set(), board, out)
    out.raise_if_any()
    return Wiring(board, inputs, motors, lamps, counters, active_high)
