"""What a run amounts to: first light seen, lamp reached, laps of a track, collisions, distance, time per state.

Computed from a :class:`~tablebot.sim.runner.SimRun`, so the CLI, the plots and the tests agree on one
set of numbers; collisions and the lamp are counted by the simulated robot as it runs (sim.physics.kernel.observe).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from tablebot.i18n import _, number
from tablebot.robot import StateId
from tablebot.sim import columns as L
from tablebot.sim.model.track import laps
from tablebot.sinks.run_trace import seconds_per_state

if TYPE_CHECKING:  # only types: time per state is wanted beside a real robot's run, without the simulator
    from tablebot.sim.model.scene import Scene
    from tablebot.sim.runner import SimRun


@dataclass(frozen=True)
class Summary:
    seconds: float
    first_light_s: float | None  # a phototransistor first read 1
    reached_s: float | None  # the axle centre first came within the world's reach of a lamp
    collisions: int
    collision_ticks: tuple[int, ...]  # hist rows where each collision began
    distance_m: float
    state_seconds: dict[StateId, float]  # in order of first visit
    battery_start_v: float
    battery_end_v: float
    laps: float | None = None  # net laps round the world's closed [[line]], if it has one
    lamps: bool = True  # whether the world has lamps (else the light lines say nothing)

    def lines(self, names: dict[StateId, str] | None = None) -> list[str]:
        """Human-readable summary lines (``names``: the robot's [states], see Table.state_name), in the reader's
        language (tablebot.i18n), each label padded to the longest."""
        names = names or {}

        def when(value: float | None) -> str:
            return _("never") if value is None else f"{number(value, '.2f')} s"

        pairs: list[tuple[str, str]] = []
        if self.lamps:
            pairs += [(_("first light seen:"), when(self.first_light_s)), (_("lamp reached:"), when(self.reached_s))]
        if self.laps is not None:
            pairs.append((_("laps of the line:"), number(self.laps, ".2f")))
        volts = f"{number(self.battery_start_v, '.2f')} V -> {number(self.battery_end_v, '.2f')} V"
        pairs += [
            (_("collisions:"), str(self.collisions)),
            (_("distance driven:"), f"{number(self.distance_m, '.2f')} m"),
            (_("battery:"), volts),
        ]
        longest = (_("first light seen:"), _("laps of the line:"), *(label for label, _value in pairs))
        width = max(map(len, longest))  # every label, shown or not: the values line up as in any other run
        out = [
            _("simulated {seconds:.1f} s").format(seconds=self.seconds),
            *(f"{label:<{width}} {value}".rstrip() for label, value in pairs),
            _("time per state:"),
        ]
        for state, secs in self.state_seconds.items():
            label = f"{state} {names[state]}" if state in names else str(state)
            out.append(f"  {label:<24} {number(secs, '7.2f')} s  {number(100 * secs / self.seconds, '5.1f')} %")
        return out


def light_bits(result: SimRun | Scene) -> int:
    """The input bits of the light sensors (of a run or of its scene)."""
    bits = (result.scene if hasattr(result, "scene") else result).bits  # a SimRun has a scene; a Scene is one
    return int(bits[L.B_LIGHT_R] | bits[L.B_LIGHT_L])


def first(mask: np.ndarray) -> int | None:
    hits = np.flatnonzero(mask)
    return int(hits[0]) if len(hits) else None


def time_per_state(states: np.ndarray, names: tuple[StateId, ...], tick_s: float) -> dict[StateId, float]:
    """Seconds spent in each state (the state after each tick), in order of first visit."""
    first_seen = np.full(len(names), -1, dtype=np.int64)
    order, where = np.unique(states, return_index=True)
    first_seen[order] = where
    return seconds_per_state(np.bincount(states, minlength=len(names)), first_seen, names, tick_s)


def summarise(result: SimRun) -> Summary:
    """The run's numbers: first light from the inputs read, time per state from the states after each
    tick, and the collisions and lamp reached that the simulated robot counted as it went."""
    tick_s, at_start, at_end = result.tick_s, result.ends[0], result.ends[1]
    light = first((result.masks & light_bits(result)) != 0)
    reached = result.reached_row
    return Summary(
        seconds=result.ticks * tick_s,
        first_light_s=None if light is None else light * tick_s,
        reached_s=None if reached is None else reached * tick_s,
        collisions=result.collision_count,
        collision_ticks=tuple(result.collision_rows),
        distance_m=float(at_end[L.DIST]),
        state_seconds=time_per_state(result.states, result.scene.machine.states, tick_s),
        battery_start_v=float(at_start[L.VBAT]),
        battery_end_v=float(at_end[L.VBAT]),
        laps=laps(result.scene.world, result.path[:, 0], result.path[:, 1]),
        lamps=bool(result.scene.world.lamps),
    )
