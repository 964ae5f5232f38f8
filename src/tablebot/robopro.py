"""The document's ROBO Pro list encoding, both ways: three 16-bit lists (event, action, timer).

event  = state*64 + the event bits (up to six columns, first column highest: T=32 … I8=1)
action = next*256 + M1dir*128 + M1speed*16 + M2dir*8 + M2speed   (speed 7 = keep)
timer  = ticks
Named states are numbered (integer states keep their numbers) and the numbering is written to
``states.csv`` beside the lists, which import reads back.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

from tablebot.diagnostics import Collector, Diagnostic, TableBotError, fail
from tablebot.robot import Robot, StateId
from tablebot.table import DOC_KEEP_SPEED, Row, Table

STATE_WEIGHT = 64
NEXT_WEIGHT = 256
MAX_EVENTS = 6
MAX_MOTORS = 2
MAX_STATE = 127
MAX_TIMER = 32767
LIST_FILES = ("event.csv", "action.csv", "timer.csv")
STATES_FILE = "states.csv"


@dataclass(frozen=True)
class Lists:
    """The three lists, one value per table row, plus the state numbering used."""

    event: tuple[int, ...]
    action: tuple[int, ...]
    timer: tuple[int, ...]
    numbers: dict[StateId, int]


def number_states(table: Table) -> dict[StateId, int]:
    """Integer states keep their number; each named state gets the lowest free number from 1."""
    numbers = {s: s for s in table.states if isinstance(s, int)}
    free = (n for n in range(1, 1 << 16) if n not in numbers.values())
    for state in table.states:
        if not isinstance(state, int):
            numbers[state] = next(free)
    return numbers


def _motor_fields(speed: int | None) -> tuple[int, int]:
    """(direction, speed) of a signed speed; keep is the document's speed 7."""
    if speed is None:
        return 0, DOC_KEEP_SPEED
    return (1 if speed < 0 else 0), abs(speed)


def encode_row(table: Table, row: Row, numbers: dict[StateId, int]) -> tuple[int, int, int]:
    events = sum(1 << (len(table.events) - 1 - table.events.index(e)) for e in row.events)
    motors = [_motor_fields(s) for s in row.motors] + [(0, 0)] * (MAX_MOTORS - len(row.motors))
    (d1, s1), (d2, s2) = motors
    action = numbers[row.next] * NEXT_WEIGHT + d1 * 128 + s1 * 16 + d2 * 8 + s2
    return numbers[row.state] * STATE_WEIGHT + events, action, row.timer


def fit_problems(table: Table) -> list[Diagnostic]:
    """Everything in a table that the document's list layout cannot hold, row by row."""
    out = Collector(table.path)
    robot = table.robot
    if len(table.events) > MAX_EVENTS:
        out.error(1, None, f"{len(table.events)} event columns; the ROBO Pro layout holds at most {MAX_EVENTS}",
                  "drop event columns this table does not need")
    if len(robot.motors) > MAX_MOTORS:
        out.error(1, None, f"{len(robot.motors)} motors; the ROBO Pro layout holds at most {MAX_MOTORS}",
                  "the document's action word has room for M1 and M2 only")
    if robot.counters or robot.lamps:
        feature = "counters" if robot.counters else "lamps"
        out.error(1, None, f"the robot has {feature}; the document's three lists have no place for them",
                  "export a table without counters and lamps, or use --to c")
    numbers = number_states(table)
    for row in table.rows:
        for what, state in (("state", row.state), ("next state", row.next)):
            if numbers[state] > MAX_STATE:
                out.error(row.line, None, f"row {row.index}: {what} {state} is over {MAX_STATE}",
                          f"number states 0..{MAX_STATE} so the list values stay 16-bit")
        if row.timer > MAX_TIMER:
            out.error(row.line, None, f"row {row.index}: timer {row.timer} is over {MAX_TIMER}",
                      "ROBO Pro list values are 16-bit signed")
        for motor, speed in zip(robot.motors, row.motors, strict=True):
            if speed is not None and abs(speed) >= DOC_KEEP_SPEED:
                out.error(row.line, None, f"row {row.index}: {motor} speed {abs(speed)} does not fit",
                          "the document's speeds are 0..6 (7 means keep): use 6 or less")
    return out.items


def encode(table: Table) -> Lists:
    """The three lists of a table; raises with every row that does not fit the layout."""
    problems = fit_problems(table)
    if problems:
        raise TableBotError(problems)
    numbers = number_states(table)
    values = [encode_row(table, row, numbers) for row in table.rows]
    return Lists(*(tuple(column) for column in zip(*values, strict=True)), numbers=numbers)  # type: ignore[arg-type]


def write_lists(lists: Lists, outdir: Path) -> list[Path]:
    """Write event.csv, action.csv, timer.csv (one value per line) and states.csv for names."""
    outdir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, values in zip(LIST_FILES, (lists.event, lists.action, lists.timer), strict=True):
        path = outdir / name
        path.write_text("".join(f"{v}\n" for v in values), encoding="utf-8")
        written.append(path)
    if any(not isinstance(s, int) for s in lists.numbers):
        path = outdir / STATES_FILE
        with path.open("w", encoding="utf-8", newline="") as f:
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow(["number", "name"])
            writer.writerows((n, s) for s, n in sorted(lists.numbers.items(), key=lambda kv: kv[1]))
        written.append(path)
    return written


# --- import -------------------------------------------------------------------------------------

def _read_list(path: Path) -> list[int]:
    if not path.is_file():
        raise fail(path, "list file not found", f"a ROBO Pro export has {', '.join(LIST_FILES)}")
    values = []
    for number, line in enumerate(path.read_text(encoding="utf-8-sig").splitlines(), start=1):
        text = line.split(",")[0].split(";")[0].strip()
        if not text:
            continue
        try:
            value = int(text)
        except ValueError:
            raise fail(path, f"{text!r} is not an integer", "one integer per line", number, 1) from None
        if not -32768 <= value <= 32767:
            raise fail(path, f"{value} is not a 16-bit list value", "values are -32768..32767", number, 1)
        values.append(value)
    return values


def _read_names(directory: Path) -> dict[int, StateId]:
    path = directory / STATES_FILE
    if not path.is_file():
        return {}
    with path.open(encoding="utf-8-sig", newline="") as f:
        return {int(row["number"]): row["name"] for row in csv.DictReader(f)}


def decode(lists: Lists, robot: Robot, events: tuple[str, ...], path: str = "<lists>") -> Table:
    """Rebuild a table (descriptions are lost: the lists never held them)."""
    names = {n: s for s, n in lists.numbers.items()}
    rows = []
    for index, (event, action, timer) in enumerate(zip(lists.event, lists.action, lists.timer, strict=True)):
        state, bits = divmod(event, STATE_WEIGHT)
        nxt, low = divmod(action, NEXT_WEIGHT)
        fields = [(low >> 7) & 1, (low >> 4) & 7, (low >> 3) & 1, low & 7]
        motors = tuple(None if speed == DOC_KEEP_SPEED else (-speed if direction else speed)
                       for direction, speed in ((fields[0], fields[1]), (fields[2], fields[3])))
        required = frozenset(e for i, e in enumerate(events) if bits & (1 << (len(events) - 1 - i)))
        rows.append(Row(index=index, line=index + 1, description="", state=names.get(state, state),
                        events=required, motors=motors[: len(robot.motors)], timer=timer,
                        next=names.get(nxt, nxt)))
    return Table(robot=robot, events=events, rows=tuple(rows), path=path)


def read_lists(directory: Path) -> Lists:
    event, action, timer = (_read_list(directory / name) for name in LIST_FILES)
    if not len(event) == len(action) == len(timer):
        raise fail(directory, f"the lists differ in length: event {len(event)}, action {len(action)}, "
                   f"timer {len(timer)}", "each row of the table is one entry in every list")
    for i, value in enumerate(event):
        if value < 0 or action[i] < 0:
            raise fail(directory / (LIST_FILES[0] if value < 0 else LIST_FILES[1]),
                       "negative value: not written by the document's encoding", "check the list", i + 1, 1)
    numbers = {state: number for number, state in _read_names(directory).items()}
    return Lists(tuple(event), tuple(action), tuple(timer), numbers)
