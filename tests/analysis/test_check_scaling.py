"""The linear-time shadowed-row and overlap searches find exactly what the plain pairwise ones did (issue 14).
Speed itself is measured by benchmarks/check.py, not here."""

from __future__ import annotations

import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tablebot.analysis.lints import overlaps, shadowed_rows
from tablebot.analysis.names import events_text, state_text
from tablebot.robot import BUMBERBOT
from tablebot.table import Row, Table

pytestmark = [pytest.mark.kernel_free]

EVENTS = ("T", *BUMBERBOT.inputs)


def reference_shadowed(table: Table) -> list[tuple[int, int]]:
    """(row line, shadowing line): the first earlier row of the state whose events are a subset."""
    found = []
    for state in table.states:
        rows = [r for r in table.rows if r.state == state]
        for i, row in enumerate(rows):
            earlier = next((q for q in rows[:i] if q.events <= row.events), None)
            if earlier is not None:
                found.append((row.line, earlier.line))
    return found


def reference_overlaps(table: Table) -> list[tuple[int, int, str]]:
    found = []
    for state in table.states:
        rows = [r for r in table.rows if r.state == state]
        masks = [table.mask(r.events) for r in rows]
        for j, later in enumerate(rows):
            for i, first in enumerate(rows[:j]):
                same = (first.next, first.motors, first.timer) == (later.next, later.motors, later.timer)
                if first.events <= later.events or same:
                    continue
                both = first.events | later.events
                winner = next(k for k in range(j + 1) if masks[k] & table.mask(both) == masks[k])
                if winner == i:
                    found.append((first.line, later.line, f"{state_text(table, state)} {events_text(table, both)}"))
    return found


def random_table(seed: int, states: int, per_state: int) -> Table:
    rng = random.Random(seed)
    rows: list[Row] = []
    for state in range(1, states + 1):
        for _ in range(per_state):
            events = frozenset(rng.sample(EVENTS, rng.choice((0, 1, 1, 2, 3))))
            motors = (rng.choice((0, 3, None)), rng.choice((0, 3)))
            rows.append(
                Row(len(rows), len(rows) + 2, "", state, events, motors, rng.choice((0, 10)), rng.randint(1, states))
            )
    return Table(BUMBERBOT, EVENTS, tuple(rows), "<random>")


@settings(max_examples=40, derandomize=True, deadline=None)
@given(st.integers(0, 10**6), st.integers(1, 4), st.integers(1, 30))
def test_same_findings_as_the_pairwise_search(seed: int, states: int, per_state: int) -> None:
    table = random_table(seed, states, per_state)
    assert [(f.lines[0], f.lines[1]) for f in shadowed_rows(table)] == reference_shadowed(table)
    got = [(f.lines[0], f.lines[1], f.message) for f in overlaps(table)]
    expected = reference_overlaps(table)
    assert [g[:2] for g in got] == [e[:2] for e in expected]
    assert all(e[2].split(" ")[1] in g[2] for g, e in zip(got, expected, strict=True))
