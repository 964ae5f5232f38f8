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
from itertools import islice
from pathlib import Path

from tablebot.csvtext import read_records, read_text
from tablebot.diagnostics import Collector, Diagnostic, TableBotError, fail
from tablebot.durations import MAX_NUMBER_CHARS
from tablebot.files import atomic_write, write_text
from tablebot.fileset import file_set
from tablebot.i18n import N_
from tablebot.robot import MATCH_DOCUMENT, STATE_RE, Robot, StateId
from tablebot.table import (
    DOC_KEEP_SPEED,
    TIMER_EVENT,
    Row,
    Table,
    from_direction_speed,
    missing_states,
    no_event_rows,
    to_direction_speed,
)

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
    numbers: dict[StateId, int] = {s: s for s in table.states if isinstance(s, int)}
    free = (n for n in range(1, 1 << 16) if n not in numbers.values())
    for state in table.states:
        if not isinstance(state, int):
            numbers[state] = next(free)
    return numbers


def event_layout(robot: Robot) -> tuple[str, ...]:
    """The list's event bits, highest first: T, then the robot's inputs in robot-file order.

    Fixed by the robot, not by the table's column order: the ROBO Pro program's DetectEvent sets one
    bit per physical input (BumberBot: T=32, I3=16, I4=8, I5=4, I7=2, I8=1), and import decodes the
    same way, so a table that omits or reorders event columns still exports to the right bits.
    """
    return (TIMER_EVENT, *robot.inputs)


def encode_row(table: Table, row: Row, numbers: dict[StateId, int]) -> tuple[int, int, int]:
    layout = event_layout(table.robot)
    events = sum(1 << (len(layout) - 1 - layout.index(e)) for e in row.events)
    motors = [to_direction_speed(s) for s in row.motors] + [(0, 0)] * (MAX_MOTORS - len(row.motors))
    (d1, s1), (d2, s2) = motors
    action = numbers[row.next] * NEXT_WEIGHT + d1 * 128 + s1 * 16 + d2 * 8 + s2
    return numbers[row.state] * STATE_WEIGHT + events, action, row.timer


def fit_problems(table: Table) -> list[Diagnostic]:
    """Everything in a table that the document's list layout cannot hold, row by row."""
    out = Collector(table.path)
    robot = table.robot
    layout = event_layout(robot)
    if len(layout) > MAX_EVENTS:
        out.error(
            1,
            1,
            N_(
                "{n} event columns (T and the inputs {inputs}); the ROBO Pro layout holds at most {most}",
                n=len(layout),
                inputs=", ".join(robot.inputs),
                most=MAX_EVENTS,
            ),
            N_("use a robot with at most {most} inputs besides T", most=MAX_EVENTS - 1),
        )
    if len(robot.motors) > MAX_MOTORS:
        out.error(
            1,
            1,
            N_("{n} motors; the ROBO Pro layout holds at most {most}", n=len(robot.motors), most=MAX_MOTORS),
            N_("the document's action word has room for M1 and M2 only"),
        )
    if robot.counter_names:
        out.error(
            1,
            1,
            N_(
                "the robot has counters ({names}); the document's three lists have no place for them",
                names=", ".join(robot.counter_names),
            ),
            N_("export a table for a robot without counters"),
        )
    if robot.lamps:
        out.error(
            1,
            1,
            N_(
                "the robot has lamps ({names}); the document's three lists have no place for them",
                names=", ".join(robot.lamps),
            ),
            N_("export a table for a robot without lamps"),
        )
    numbers = number_states(table)
    for row in table.rows:
        for what, state in ((N_("state"), row.state), (N_("next state"), row.next)):
            if numbers[state] > MAX_STATE:
                out.error(
                    row.line,
                    None,
                    N_(
                        "row {row}: {what} {state!r} is number {number}, over {most}",
                        row=row.index,
                        what=what,
                        state=state,
                        number=numbers[state],
                        most=MAX_STATE,
                    ),
                    N_("number states 0..{most} so the list values stay 16-bit", most=MAX_STATE),
                )
        if row.timer > MAX_TIMER:
            out.error(
                row.line,
                None,
                N_("row {row}: timer {timer} is over {most}", row=row.index, timer=row.timer, most=MAX_TIMER),
                N_("ROBO Pro list values are 16-bit signed"),
            )
        for motor, speed in zip(robot.motors, row.motors, strict=True):
            if speed is not None and abs(speed) >= DOC_KEEP_SPEED:
                out.error(
                    row.line,
                    None,
                    N_("row {row}: {motor} speed {speed} does not fit", row=row.index, motor=motor, speed=abs(speed)),
                    N_("the document's speeds are 0..6 (7 means keep): use 6 or less"),
                )
    _rule_problems(table, out)
    return out.items


def _rule_problems(table: Table, out: Collector) -> None:
    """The lists are run by the document's engine, which looks a row up only if an event is detected: a row
    that requires no event, in a table that fires it on a tick with no event (``match = "always"``) where such
    a tick can come, would drive another robot there."""
    robot = table.robot
    if robot.match == MATCH_DOCUMENT:
        return
    said = (
        N_('match = "always" in {source}', source=robot.source)
        if robot.says_match
        else N_('{source} does not say match, so "always"', source=robot.source)
    )
    for found in no_event_rows(table):
        if found.quiet:
            out.error(
                found.row.line,
                None,
                N_(
                    "row {row} requires no event and the table fires it even on a tick with no event at all "
                    "({said}), which can come in state {state!r}: {why}; the document's engine, which runs "
                    "these lists, looks a row up only if an event is detected, so there it would do nothing",
                    row=found.row.index,
                    said=said,
                    state=found.row.state,
                    why=found.quiet,
                ),
                N_(
                    'write match = "document" in {source} if the robot should do nothing on such a tick '
                    "(tablebot then runs it so too), or give the row an event to wait for",
                    source=robot.source,
                ),
            )


def encode(table: Table) -> Lists:
    """The three lists of a table; raises with every row that does not fit the layout."""
    problems = fit_problems(table)
    if problems:
        raise TableBotError(problems)
    numbers = number_states(table)
    values = [encode_row(table, row, numbers) for row in table.rows]
    event, action, timer = (tuple(column) for column in zip(*values, strict=True))
    return Lists(event, action, timer, numbers=numbers)


def write_lists(lists: Lists, outdir: Path) -> list[Path]:
    """Write event.csv, action.csv, timer.csv (one value per line) and states.csv for names, replacing the
    previous lists at once (an earlier states.csv goes when these states have no names: import would
    read it back onto the wrong table)."""
    written = []
    with file_set(outdir, remove=[STATES_FILE]):
        for name, values in zip(LIST_FILES, (lists.event, lists.action, lists.timer), strict=True):
            written.append(write_text(outdir / name, "".join(f"{v}\n" for v in values)))
        if any(not isinstance(s, int) for s in lists.numbers):
            path = outdir / STATES_FILE
            with atomic_write(path, newline="") as f:
                writer = csv.writer(f, lineterminator="\n")
                writer.writerow(["number", "name"])
                named = [(n, s) for s, n in lists.numbers.items() if not isinstance(s, int)]  # ints are their number
                writer.writerows(sorted(named))
            written.append(path)
    return written


# --- import -------------------------------------------------------------------------------------


def _read_list(path: Path) -> list[int]:
    """One list: an integer per line (ROBO Pro may add columns after a separator; they are ignored)."""
    if not path.is_file():
        raise fail(path, N_("list file not found"), N_("a ROBO Pro export has {files}", files=", ".join(LIST_FILES)))
    values = []
    for number, line in enumerate(read_text(path).splitlines(), start=1):
        text = line.split(",")[0].split(";")[0].strip()
        if not text:
            continue
        try:
            value = int(text)
        except ValueError:
            raise fail(
                path, N_("{text!r} is not an integer", text=text), N_("one integer per line"), number, 1
            ) from None
        if not 0 <= value <= 32767:
            raise fail(
                path,
                N_("{value} is not a value of the document's encoding", value=value),
                N_("list values are 16-bit signed, and the encoding never writes negative ones"),
                number,
                1,
            )
        values.append(value)
    return values


def _digits(text: str) -> bool:
    """ASCII digits only (str.isdigit() also takes '²', which int() refuses), and not so many that int() fails."""
    return text.isascii() and text.isdigit() and len(text) <= MAX_NUMBER_CHARS


def _read_names(directory: Path) -> dict[int, StateId]:
    """states.csv as export writes it: a header, then ``number,name`` per named state."""
    path = directory / STATES_FILE
    if not path.is_file():
        return {}
    names: dict[int, StateId] = {}
    for record in islice(read_records(read_text(path), str(path)), 1, None):
        cells = [cell.text.strip() for cell in record.cells]
        if record.is_blank():
            continue
        if len(cells) < 2 or not _digits(cells[0]) or not (_digits(cells[1]) or STATE_RE.match(cells[1])):
            raise fail(
                path,
                N_("expected number,name, not {cells!r}", cells=",".join(cells)),
                N_("export writes one named state per line, like: 1,seek"),
                record.line,
                1,
            )
        number, name = int(cells[0]), int(cells[1]) if _digits(cells[1]) else cells[1]  # as tables read it
        if number in names or name in names.values():
            raise fail(
                path,
                N_("state number {number} or name {name!r} is given twice", number=number, name=name),
                N_("each number names one state and each name one number"),
                record.line,
                1,
            )
        names[number] = name
    return names


def decode(lists: Lists, robot: Robot, events: tuple[str, ...] | None = None, path: str = "<lists>") -> Table:
    """Rebuild a table (descriptions are lost: the lists never held them); ``events`` defaults to
    :func:`event_layout`, the layout :func:`encode` writes."""
    events = event_layout(robot) if events is None else events
    names = {n: s for s, n in lists.numbers.items()}
    rows = []
    for index, (event, action, timer) in enumerate(zip(lists.event, lists.action, lists.timer, strict=True)):
        state, bits = divmod(event, STATE_WEIGHT)
        if bits >> len(events):
            raise fail(
                Path(path) / LIST_FILES[0],
                N_(
                    "event {event} has bits beyond the {n} events {events}",
                    event=event,
                    n=len(events),
                    events=" ".join(events),
                ),
                N_("the lists were written for another robot: pass its --robot"),
                index + 1,
                1,
            )
        nxt, low = divmod(action, NEXT_WEIGHT)
        fields = [(low >> 7) & 1, (low >> 4) & 7, (low >> 3) & 1, low & 7]
        motors = tuple(
            from_direction_speed(direction, speed)
            for direction, speed in ((fields[0], fields[1]), (fields[2], fields[3]))
        )
        required = frozenset(e for i, e in enumerate(events) if bits & (1 << (len(events) - 1 - i)))
        rows.append(
            Row(
                index=index,
                line=index + 1,
                description="",
                state=names.get(state, state),
                events=required,
                motors=motors[: len(robot.motors)],
                timer=timer,
                next=names.get(nxt, nxt),
                counters=(None,) * len(robot.counters),
                lamps=(None,) * len(robot.lamps),
            )
        )
    return Table(robot=robot, events=events, rows=tuple(rows), path=path)


def read_lists(directory: Path) -> Lists:
    if not directory.is_dir():
        raise fail(
            directory,
            N_("not a folder") if directory.exists() else N_("folder not found"),
            N_("give the folder that holds {files}", files=", ".join(LIST_FILES)),
        )
    event, action, timer = (_read_list(directory / name) for name in LIST_FILES)
    if not len(event) == len(action) == len(timer):
        raise fail(
            directory,
            N_(
                "the lists differ in length: event {event}, action {action}, timer {timer}",
                event=len(event),
                action=len(action),
                timer=len(timer),
            ),
            N_("each row of the table is one entry in every list"),
        )
    if not event:
        raise fail(directory, N_("the lists are empty"), N_("export a table with at least one row"))
    numbers = {state: number for number, state in _read_names(directory).items()}
    return Lists(tuple(event), tuple(action), tuple(timer), numbers)


def read_table(directory: Path, robot: Robot) -> Table:
    """The table that the lists in ``directory`` hold for ``robot``; problems are located in the lists."""
    layout = event_layout(robot)
    if len(layout) > MAX_EVENTS or len(robot.motors) > MAX_MOTORS:
        raise fail(
            robot.source,
            N_(
                "{inputs} inputs and {motors} motors do not fit the ROBO Pro layout",
                inputs=len(layout) - 1,
                motors=len(robot.motors),
            ),
            N_(
                "import needs a robot with at most {inputs} inputs and {motors} motors",
                inputs=MAX_EVENTS - 1,
                motors=MAX_MOTORS,
            ),
        )
    table = decode(read_lists(directory), robot, layout, str(directory))
    problems = []
    for row, where, message, hint in missing_states(table.rows, robot):
        if row is not None:  # the row's line is its line in every list; its next state is in action.csv
            problems.append(Diagnostic(str(directory / LIST_FILES[1]), row.line, 1, message, hint))
        else:
            line = robot.line(*where)
            at: tuple[str, int | None, int | None] = (
                (robot.source, line, 1) if line is not None else (str(directory / LIST_FILES[0]), None, None)
            )
            problems.append(Diagnostic(*at, message, "the lists may be for another robot: pass its --robot"))
    if problems:
        raise TableBotError(problems)
    return table
