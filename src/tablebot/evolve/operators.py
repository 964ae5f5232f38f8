"""Variation operators over candidate tables: change a motor cell, a timer or a next state; add a row
(a copy of a row of any state), remove one, move one within its state; and take a whole state's rows
from a second parent. Each respects the :class:`~tablebot.evolve.space.Limits` and returns None when
it finds nothing it may change, so :func:`vary` tries another.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from tablebot.evolve.space import Candidate, Limits, valid
from tablebot.i18n import N_
from tablebot.robot import StateId
from tablebot.table import MAX_LAMP


@dataclass(frozen=True)
class Space:
    """What the operators need to know: the states (fixed), the motors (a row's motor cells, in the robot's
    order), the user's limits, and the motors the table has columns for (None: all of them; one table of a
    robot of several writes only its own outputs, so a motor it has no column for is never set)."""

    states: tuple[StateId, ...]
    motors: tuple[str, ...]
    limits: Limits
    writes: frozenset[str] | None = None
    lamps: tuple[str, ...] = ()  # one table of several: the robot's lamps, in a row's order (lamp cells may change)

    def may_set(self, motor: str) -> bool:
        return self.writes is None or motor in self.writes

    def own_lamps(self) -> list[int]:
        """The lamp cells evolution may change: those of one table of several that has columns for them (a robot
        of one table keeps its lamp levels, as it always has)."""
        return [] if self.writes is None else [k for k, name in enumerate(self.lamps) if name in self.writes]


Operator = Callable[[Candidate, Space, np.random.Generator], Candidate | None]


def _pick(rng: np.random.Generator, items: Sequence[int]) -> int | None:
    return None if not items else int(items[int(rng.integers(len(items)))])


def motor(c: Candidate, space: Space, rng: np.random.Generator) -> Candidate | None:
    """One motor cell of one row: a step of 1 or 2, reversed, stopped, kept or any speed."""
    cells = [
        (i, m)
        for i, gene in enumerate(c)
        for m, name in enumerate(space.motors)
        if space.may_set(name) and not space.limits.cell_frozen(gene, name)
    ]
    if not cells:
        return None
    i, m = cells[int(rng.integers(len(cells)))]
    old = c[i].motors[m]
    speeds = space.limits.speeds
    choice = int(rng.integers(6))
    if old is None or choice == 5:
        new: int | None = int(rng.choice(speeds))
    elif choice < 2:
        new = int(np.clip(old + (1 + choice) * (1 if rng.random() < 0.5 else -1), min(speeds), max(speeds)))
    elif choice == 2:
        new = -old
    elif choice == 3:
        new = 0
    else:
        new = None
    if new == old or (new is not None and new not in speeds):
        return None
    motors = tuple(new if k == m else v for k, v in enumerate(c[i].motors))
    return (*c[:i], replace(c[i], motors=motors), *c[i + 1 :])


def lamp(c: Candidate, space: Space, rng: np.random.Generator) -> Candidate | None:
    """One lamp cell of one row (a table of several that writes lamps): off, full, a step of 1 or 2, any level,
    or kept."""
    cells = [
        (i, k)
        for i, gene in enumerate(c)
        for k in space.own_lamps()
        if not space.limits.cell_frozen(gene, space.lamps[k])
    ]
    if not cells:
        return None
    i, k = cells[int(rng.integers(len(cells)))]
    old = c[i].lamps[k]
    choice = int(rng.integers(5))
    new: int | None = (
        0
        if choice == 0
        else MAX_LAMP
        if choice == 1
        else None
        if choice == 2
        else int(rng.integers(0, MAX_LAMP + 1))
        if choice == 3 or old is None
        else int(np.clip(old + int(rng.choice([-2, -1, 1, 2])), 0, MAX_LAMP))
    )
    if new == old:
        return None
    lamps = tuple(new if n == k else v for n, v in enumerate(c[i].lamps))
    return (*c[:i], replace(c[i], lamps=lamps), *c[i + 1 :])


def timer(c: Candidate, space: Space, rng: np.random.Generator) -> Candidate | None:
    """One row's timer: scaled by a log-normal factor (halved to doubled, mostly), or set afresh."""
    rows = [i for i, gene in enumerate(c) if not space.limits.cell_frozen(gene, "timer")]
    i = _pick(rng, rows)
    if i is None:
        return None
    old, top = c[i].timer, space.limits.timer_max
    if old == 0 or rng.random() < 0.15:
        new = int(rng.integers(0, min(top, 1000) + 1))
    else:
        new = int(np.clip(round(old * float(np.exp(rng.normal(0.0, 0.5)))), 0, top))
    if new == old:
        new = min(top, old + 1)
    return None if new == old else (*c[:i], replace(c[i], timer=new), *c[i + 1 :])


def next_state(c: Candidate, space: Space, rng: np.random.Generator) -> Candidate | None:
    """One row's next state: any other state of the table."""
    rows = [i for i, gene in enumerate(c) if not space.limits.cell_frozen(gene, "next")]
    i = _pick(rng, rows)
    if i is None or len(space.states) < 2:
        return None
    choices = [s for s in space.states if s != c[i].next]
    return (*c[:i], replace(c[i], next=choices[int(rng.integers(len(choices)))]), *c[i + 1 :])


def add_row(c: Candidate, space: Space, rng: np.random.Generator) -> Candidate | None:
    """A copy of any row, put into a state that may change (its own, half the time), at a random place
    among that state's rows."""
    if len(c) >= space.limits.max_rows:
        return None
    source = c[int(rng.integers(len(c)))]
    open_states = [s for s in space.states if not space.limits.state_frozen(s)]
    if not open_states:
        return None
    state = (
        source.state
        if rng.random() < 0.5 and source.state in open_states
        else open_states[int(rng.integers(len(open_states)))]
    )
    where = [i for i, gene in enumerate(c) if gene.state == state]
    slots = [*where, where[-1] + 1] if where else [len(c)]
    at = slots[int(rng.integers(len(slots)))]
    note = N_("a copy of an added row") if source.origin is None else N_("a copy of line {line}", line=source.origin)
    gene = replace(source, state=state, origin=None, note=note)
    return (*c[:at], gene, *c[at:])


def remove_row(c: Candidate, space: Space, rng: np.random.Generator) -> Candidate | None:
    """Remove a row that may be removed, when its state keeps another."""
    rows = [
        i for i, gene in enumerate(c) if not space.limits.row_fixed(gene) and sum(g.state == gene.state for g in c) > 1
    ]
    i = _pick(rng, rows)
    return None if i is None else (*c[:i], *c[i + 1 :])


def move_row(c: Candidate, space: Space, rng: np.random.Generator) -> Candidate | None:
    """Move a row to another place among its state's rows (which row of the state is tried first)."""
    rows = [
        i for i, gene in enumerate(c) if not space.limits.row_fixed(gene) and sum(g.state == gene.state for g in c) > 1
    ]
    i = _pick(rng, rows)
    if i is None:
        return None
    gene = c[i]
    rest = (*c[:i], *c[i + 1 :])
    places = [k for k, g in enumerate(rest) if g.state == gene.state]
    places.append(places[-1] + 1)
    at = places[int(rng.integers(len(places)))]
    moved = (*rest[:at], gene, *rest[at:])
    return None if moved == c else moved


def take_state(c: Candidate, other: Candidate, space: Space, rng: np.random.Generator) -> Candidate | None:
    """Crossover: the rows of one state (that may change) taken from a second parent, where this
    parent's rows of that state first were."""
    differ = [
        s
        for s in space.states
        if not space.limits.state_frozen(s)
        and [g.effect() for g in c if g.state == s] != [g.effect() for g in other if g.state == s]
    ]
    if not differ:
        return None
    state = differ[int(rng.integers(len(differ)))]
    mine = [i for i, gene in enumerate(c) if gene.state == state]
    if any(space.limits.row_fixed(c[i]) for i in mine):
        return None
    theirs = tuple(g for g in other if g.state == state)
    rest = [g for g in c if g.state != state]
    out = (*rest[: mine[0]], *theirs, *rest[mine[0] :])
    return out if len(out) <= space.limits.max_rows else None


OPERATORS: dict[str, tuple[Operator, float]] = {
    "motor": (motor, 3.0),
    "timer": (timer, 3.0),
    "next": (next_state, 1.0),
    "add": (add_row, 1.0),
    "remove": (remove_row, 1.0),
    "move": (move_row, 1.0),
    "lamp": (lamp, 3.0),  # last, and weighed 0 where no lamp may change: a robot of one table draws as it did
}
CROSSOVER_RATE = 0.2


def vary(
    parent: Candidate, space: Space, rng: np.random.Generator, other: Candidate | None = None, tries: int = 50
) -> Candidate | None:
    """A child of ``parent``: a crossover with ``other`` now and then, then one or more mutations (one
    most often, a few at times); None when nothing could change."""
    names = list(OPERATORS)
    lamps = bool(space.own_lamps())
    weights = np.array([OPERATORS[n][1] if n != "lamp" or lamps else 0.0 for n in names])
    weights /= weights.sum()
    for _ in range(tries):
        child: Candidate | None = parent
        if other is not None and rng.random() < CROSSOVER_RATE:
            child = take_state(parent, other, space, rng) or parent
        for _ in range(int(rng.geometric(0.6))):
            changed = OPERATORS[names[int(rng.choice(len(names), p=weights))]][0](child, space, rng)  # type: ignore[arg-type]
            child = changed if changed is not None else child
        if child is not None and child != parent and valid(child, space.states, space.limits):
            return child
    return None
