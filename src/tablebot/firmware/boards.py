"""Board files (``boards/*.toml``) and the wiring of a robot onto a board: the terminal of each input,
motor, lamp and counter. A name that is a terminal takes it, ``[board.NAME]`` in the robot file maps
others, and the rest take free terminals in order."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from importlib import resources
from typing import Any

from tablebot.diagnostics import fail
from tablebot.i18n import N_, Message
from tablebot.robot import Robot
from tablebot.tomlfile import Source

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
        raise fail(name, N_("unknown board {name!r}", name=name), N_("boards: {boards}", boards=tuple(BOARDS)))
    text = resources.files("tablebot.firmware").joinpath("boards").joinpath(f"{name}.toml").read_text(encoding="utf-8")
    data = tomllib.loads(text)
    pins = data.get("pins")
    inputs = pins if pins is not None else data["inputs"]
    lamps = tuple(reversed(pins)) if pins is not None else tuple(data.get("outputs", {}))
    return Board(
        name=data["name"],
        title=data["title"],
        mcu=data["mcu"],
        f_cpu=data["f_cpu"],
        baud=data["baud"],
        usart=data["usart"],
        uart=data["uart"],
        avrdude=data["avrdude"],
        inputs=dict(inputs),
        lamps=lamps,
        motors=dict(data["motors"]),
        outputs=dict(data.get("outputs", {})),
        counters=dict(data.get("counters", {})),
    )


@dataclass(frozen=True)
class Wiring:
    """A robot on a board: robot name -> board terminal for each kind of signal."""

    board: Board
    inputs: dict[str, str]
    motors: dict[str, str]
    lamps: dict[str, str]
    counters: dict[str, str]
    active_high: frozenset[str] = frozenset()


@dataclass(frozen=True)
class BoardMap:
    """A robot file's ``[board.NAME]``: a terminal per robot name, and the inputs that are active high."""

    terminals: dict[str, str]
    active_high: frozenset[str]


def read_robot_boards(src: Source, boards: Any, robot: Robot) -> dict[str, BoardMap]:
    """``[board.NAME]`` sections of a robot file, checked (errors go to ``src``): known boards, names the
    robot has, terminals the board has, ``active_high`` a list of inputs. Conflicts between terminals
    are found when the robot is wired onto the board (``tablebot build``)."""
    if not isinstance(boards, dict):
        src.error(
            ("", None, "board"),
            N_("[board] must hold one table per board, like [board.uno]"),
            N_("boards: {boards}", boards=tuple(BOARDS)),
        )
        return {}
    maps = {}
    for name, mine in boards.items():
        where = (f"board.{name}", None, None) if src.line(f"board.{name}") else ("board", None, name)
        if name not in BOARDS:
            src.error(
                where,
                N_("[board.{name}]: unknown board {name!r}", name=name),
                N_("boards: {boards}", boards=tuple(BOARDS)),
            )
        elif not isinstance(mine, dict):
            src.error(
                where,
                N_('[board.{name}] must be a table of NAME = "TERMINAL"', name=name),
                N_('for example: I3 = "D4"'),
            )
        else:
            maps[name] = _board_map(src, load_board(name), mine, robot)
    return maps


def _board_map(src: Source, board: Board, mine: dict[str, Any], robot: Robot) -> BoardMap:
    section = f"board.{board.name}"
    active_high = mine.get("active_high", [])
    if not isinstance(active_high, list) or not all(isinstance(n, str) for n in active_high):
        src.error(
            (section, None, "active_high"),
            N_("[{section}] active_high must be a list of input names", section=section),
            N_('for example: active_high = ["I7", "I8"]'),
        )
        active_high = []
    for name in active_high:
        if name not in robot.inputs:
            src.error(
                (section, None, "active_high"),
                N_("[{section}] active_high names {name!r}, not an input", section=section, name=name),
                N_("inputs are {names}", names=tuple(robot.inputs) or NONE),
            )
    terminals = {}
    for name, terminal in mine.items():
        if name == "active_high":
            continue
        if name not in (*robot.inputs, *robot.motors, *robot.lamps, *robot.counter_names):
            src.error(
                (section, None, name),
                N_("[{section}] maps {name!r}, which the robot does not have", section=section, name=name),
                N_("map the robot's inputs, motors, lamps and counters"),
            )
        elif not isinstance(terminal, str):
            src.error(
                (section, None, name),
                N_(
                    "[{section}] {name} must be a terminal name, not {value!r}",
                    section=section,
                    name=name,
                    value=terminal,
                ),
                N_(
                    'write it in quotes, for example: {name} = "{example}"',
                    name=name,
                    example=_example(board, robot, name),
                ),
            )
        else:
            kind, choices = _kind_of(board, robot, name)
            if terminal not in choices:
                src.error(
                    (section, None, name),
                    _cannot_use(kind, name, terminal, board),
                    _unknown_terminal_hint(kind, terminal, choices),
                )
            terminals[name] = terminal
    return BoardMap(terminals, frozenset(active_high))


def _kind_of(board: Board, robot: Robot, name: str) -> tuple[str, tuple[str, ...]]:
    """What sort of signal ``name`` is on the robot, and the board's terminals for that sort (("", ())
    for a name the robot does not have)."""
    kinds = (
        ("input", robot.inputs, board.inputs),
        ("motor", robot.motors, board.motors),
        ("lamp", robot.lamps, board.lamps),
        ("counter", robot.counter_names, board.counters),
    )
    return next(((kind, tuple(terminals)) for kind, names, terminals in kinds if name in names), ("", ()))


def _overrides(robot: Robot, board: Board) -> tuple[dict[str, str], frozenset[str]]:
    """The robot file's ``[board.NAME]`` for this board (checked when the robot file was read)."""
    mine = robot.sections.get("board", {}).get(board.name)
    return (mine.terminals, mine.active_high) if mine is not None else ({}, frozenset())


def _example(board: Board, robot: Robot, name: str) -> str:
    """A terminal of the board for the kind of signal ``name`` is, for hints."""
    terminals = _kind_of(board, robot, name)[1]
    return terminals[0] if terminals else "?"


#: The sorts of signal, said in a message (``Eingang I3``), and their terminals (a hint's list).
KINDS = {"input": N_("input"), "motor": N_("motor"), "lamp": N_("lamp"), "counter": N_("counter")}
KIND_TERMINALS = {
    "input": N_("input terminals: {names}"),
    "motor": N_("motor terminals: {names}"),
    "lamp": N_("lamp terminals: {names}"),
    "counter": N_("counter terminals: {names}"),
}
ALL_TAKEN = {
    "input": N_("its input terminals ({names}) are all taken: use fewer inputs, or another board"),
    "motor": N_("its motor terminals ({names}) are all taken: use fewer motors, or another board"),
    "lamp": N_("its lamp terminals ({names}) are all taken: use fewer lamps, or another board"),
    "counter": N_("its counter terminals ({names}) are all taken: use fewer counters, or another board"),
}
NONE = N_("none")


def _said(table: dict[str, Message], kind: str, names: tuple[str, ...]) -> Message:
    """The message of ``table`` for this sort of signal, with its terminals."""
    return (
        Message(table[kind].msgid, {"names": names or NONE})
        if kind in table
        else N_("terminals: {names}", names=names or NONE)
    )


def _kind(kind: str) -> str:
    return KINDS.get(kind, kind)


def _cannot_use(kind: str, name: str, terminal: str, board: Board) -> Message:
    return N_(
        "{kind} {name} cannot use {terminal!r} on the {board} board",
        kind=_kind(kind),
        name=name,
        terminal=terminal,
        board=board.name,
    )


def _unknown_terminal_hint(kind: str, want: str, terminals: tuple[str, ...]) -> Message:
    same = [t for t in terminals if t.lower() == want.lower()]
    if same:
        return N_("terminal names are case-sensitive: write {name!r}", name=same[0])
    return _said(KIND_TERMINALS, kind, terminals)


def _assign(
    kind: str,
    names: tuple[str, ...],
    terminals: tuple[str, ...],
    maps: dict[str, str],
    taken: set[str],
    board: Board,
    src: Source,
) -> dict[str, str]:
    """Explicit map first, then a terminal of the same name, then the next free terminal."""
    chosen: dict[str, str] = {}
    section = f"board.{board.name}"
    for name in names:
        want = maps.get(name) or (name if name in terminals and name not in taken else None)
        if want is None:
            continue
        if want not in terminals:
            src.error(
                (section, None, name),
                _cannot_use(kind, name, want, board),
                _unknown_terminal_hint(kind, want, terminals),
            )
        elif want in taken:
            src.error(
                (section, None, name),
                N_("{kind} {name}: terminal {terminal} is already used", kind=_kind(kind), name=name, terminal=want),
                N_("give {name} another terminal in [{section}]", name=name, section=section),
            )
        else:
            chosen[name] = want
            taken.add(want)
    free = [t for t in terminals if t not in taken]
    for name in names:
        if name in chosen or name in maps:
            continue
        if not free:
            src.error(
                (f"{kind}s", None, name),
                N_(
                    "the {board} board has no free terminal for {kind} {name}",
                    board=board.name,
                    kind=_kind(kind),
                    name=name,
                ),
                _said(ALL_TAKEN, kind, terminals),
            )
            continue
        chosen[name] = free.pop(0)
        taken.add(chosen[name])
    return {name: chosen[name] for name in names if name in chosen}


def wire(robot: Robot, board: Board) -> Wiring:
    """Assign every robot signal to a terminal, reporting all conflicts at once."""
    src = robot.file_source()
    maps, active_high = _overrides(robot, board)
    taken: set[str] = set()
    inputs = _assign("input", robot.inputs, tuple(board.inputs), maps, taken, board, src)
    motors = _assign("motor", robot.motors, tuple(board.motors), maps, set(), board, src)
    taken |= {o for m in motors.values() for o in board.motors[m].split()}  # ftDuino outputs the motors drive
    lamps = _assign("lamp", robot.lamps, board.lamps, maps, taken, board, src)
    counters = _assign("counter", robot.counter_names, tuple(board.counters), maps, set(), board, src)
    src.raise_if_any()
    return Wiring(board, inputs, motors, lamps, counters, active_high)
