"""The colour of each state, the same in every picture of a table (trajectory, timeline, gif, sweep and
tune pictures, state diagrams): chosen from the state itself, not from its place in the table, so a row
added above it or a state added beside it leaves it as it was.
"""

from __future__ import annotations

import zlib
from collections.abc import Sequence

from tablebot.robot import StateId

# tab10 without its red (red marks collisions) and with darker extras after it
PALETTE = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#9467bd",
    "#17becf",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#393b79",
    "#637939",
    "#8c6d31",
    "#843c39",
    "#7b4173",
    "#3182bd",
    "#31a354",
)


def _wish(state: StateId) -> int:
    """The palette slot a state asks for: state 1 the first colour, 2 the second, ...; a name by a hash of
    its text that is the same on every machine and every run (not Python's ``hash``)."""
    if isinstance(state, int):
        return (state - 1) % len(PALETTE)
    return zlib.crc32(str(state).encode("utf-8")) % len(PALETTE)  # str(): a joint table's (k, state) too


def _order(state: StateId) -> tuple[int, int, str]:
    return (0, state, "") if isinstance(state, int) else (1, 0, str(state))


def state_colours(states: Sequence[StateId]) -> list[str]:
    """The colour of each of ``states`` (a table's states, in any order), in the same order.

    Each state gets the slot it asks for; two states asking for one slot are told apart (numbers first,
    then names, the later one taking the next free slot), so within a table no two share a colour while
    the palette lasts.
    """
    taken: dict[int, StateId] = {}
    slot: dict[StateId, int] = {}
    for state in sorted(set(states), key=_order):
        wish = _wish(state)
        for step in range(len(PALETTE)):
            if (wish + step) % len(PALETTE) not in taken:
                wish = (wish + step) % len(PALETTE)
                break
        taken[wish] = state
        slot[state] = wish
    return [PALETTE[slot[state]] for state in states]


def state_colour(state: StateId, states: Sequence[StateId]) -> str:
    """The colour of ``state`` among a table's ``states``."""
    return state_colours(states)[list(states).index(state)]
