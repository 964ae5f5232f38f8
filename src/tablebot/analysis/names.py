"""How the analysis names things for people: states with their labels, rows by file line, event sets."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from tablebot.i18n import N_, Message
from tablebot.robot import StateId
from tablebot.table import TIMER_EVENT, Row, Table


def state_text(table: Table, state: StateId) -> Message:
    """``state 20 (Collision Entry)``."""
    label = table.state_name(state)
    return N_("state {state} ({label})", state=state, label=label) if label else N_("state {state}", state=state)


def event_name(table: Table, name: str) -> str:
    """``I3 (front-right bumper)``, ``T (timer ran out)``."""
    names = table.memo.setdefault("event_names", {})
    if name not in names:
        names[name] = _event_name(table, name)
    return names[name]


def _event_name(table: Table, name: str) -> str:
    if name == TIMER_EVENT:
        return N_("T (timer ran out)")
    label = table.robot.labels.get(name)
    if name in table.robot.counter_names:  # (each name is worked out once per table: see event_name)
        return N_("{name} (counter at 0)", name=name)
    return f"{name} ({label})" if label else name


def events_text(table: Table, events: Iterable[str], short: bool = False) -> str:
    """Events in column order joined with "and"; ``nothing`` for none."""
    texts = table.memo.setdefault("events_text", {})
    key = (frozenset(events), short)
    if key not in texts:
        ordered = [e for e in table.events if e in key[0]]
        texts[key] = and_list(ordered if short else [event_name(table, e) for e in ordered]) or N_("nothing")
    return texts[key]


def and_list(items: Sequence[str]) -> str:
    """``a and b and c`` in the reader's language (each item may be a Message); "" for none."""
    if len(items) < 2:
        return items[0] if items else ""
    return N_("{first} and {rest}", first=items[0], rest=and_list(items[1:]))


def mask_events(table: Table, mask: int) -> list[str]:
    return [e for e in table.events if mask & table.bit(e)]


def lines_text(rows: Iterable[Row]) -> str:
    """``line 4`` or ``lines 4, 7 and 9``."""
    numbers = sorted({r.line for r in rows})
    if len(numbers) == 1:
        return N_("line {n}", n=numbers[0])
    return N_("lines {some} and {last}", some=", ".join(map(str, numbers[:-1])), last=numbers[-1])


def rows_phrase(rows: Iterable[Row]) -> str:
    """``the row on line 4`` or ``the rows on lines 4 and 7`` (pair with :func:`verb`)."""
    rows = list(rows)
    if len({r.line for r in rows}) > 1:
        return N_("the rows on {lines}", lines=lines_text(rows))
    return N_("the row on {lines}", lines=lines_text(rows))


def verb(rows: Iterable[Row], singular: str, plural: str) -> str:
    return plural if len({r.line for r in rows}) > 1 else singular


def plural(count: int, noun: str) -> str:
    """``3 rows``: English only (a noun passed in cannot be translated; translated texts use NP_)."""
    return f"{count} {noun}{'' if count == 1 else 's'}"
