"""What a run amounts to: first light seen, lamp reached, collisions, distance, time per state.

Computed from a :class:`~tablebot.sim.runner.Result` alone, so the CLI, the plots and the tests
agree on one set of numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tablebot.robot import StateId
from tablebot.sim import layout as L
from tablebot.sim.runner import Result

DEBOUNCE_S = 0.2  # touches closer together than this are one collision (a head-on hit closes two switches)


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

    def lines(self, names: dict[StateId, str] | None = None) -> list[str]:
        """Human-readable summary lines."""
        names = names or {}
        def when(value: float | None) -> str:
            return "never" if value is None else f"{value:.2f} s"
        out = [f"simulated {self.seconds:.1f} s",
               f"first light seen: {when(self.first_light_s)}",
               f"lamp reached:     {when(self.reached_s)}",
               f"collisions:       {self.collisions}",
               f"distance driven:  {self.distance_m:.2f} m",
               f"battery:          {self.battery_start_v:.2f} V -> {self.battery_end_v:.2f} V",
               "time per state:"]
        for state, secs in self.state_seconds.items():
            label = f"{state} {names[state]}" if state in names else str(state)
            out.append(f"  {label:<24} {secs:7.2f} s  {100 * secs / self.seconds:5.1f} %")
        return out


def light_bits(result: Result) -> int:
    bits = result.scene.bits
    return int(bits[L.B_LIGHT_R] | bits[L.B_LIGHT_L])


def contact_flags(result: Result) -> np.ndarray:
    """Per hist row: any bumper closed or any body contact."""
    h = result.hist
    return (h[:, L.BUMP_FR] + h[:, L.BUMP_FL] + h[:, L.BUMP_REAR] + h[:, L.CONTACT]) > 0


def collision_starts(result: Result) -> np.ndarray:
    """Hist rows where a collision begins (rising edges of contact, touches within the debounce merged)."""
    touching = contact_flags(result)
    rises = np.flatnonzero(touching[1:] & ~touching[:-1]) + 1
    if touching[0]:
        rises = np.concatenate(([0], rises))
    gap = max(1, round(DEBOUNCE_S / result.tick_s))
    # touching ticks in the `gap` rows before each rise: none means a new collision
    before = np.concatenate(([0], np.cumsum(touching)))
    recent = before[rises] - before[np.maximum(0, rises - gap)]
    return rises[recent == 0]


def first(mask: np.ndarray) -> int | None:
    hits = np.flatnonzero(mask)
    return int(hits[0]) if len(hits) else None


def summarise(result: Result) -> Summary:
    tick_s, h = result.tick_s, result.hist
    light = first((result.masks & light_bits(result)) != 0)
    lamps = result.scene.geometry.lamps
    reached = None
    if len(lamps):
        dist = np.min(np.hypot(h[:, L.X, None] - lamps[None, :, 0], h[:, L.Y, None] - lamps[None, :, 1]), axis=1)
        reached = first(dist <= result.scene.world.reach)
    starts = collision_starts(result)
    states = result.scene.machine.states
    seconds: dict[StateId, float] = {}
    order, first_seen = np.unique(result.states, return_index=True)
    counts = np.bincount(result.states, minlength=len(states))
    for index in order[np.argsort(first_seen)].tolist():
        seconds[states[index]] = float(counts[index] * tick_s)
    return Summary(
        seconds=result.ticks * tick_s,
        first_light_s=None if light is None else light * tick_s,
        reached_s=None if reached is None else reached * tick_s,
        collisions=len(starts), collision_ticks=tuple(starts.tolist()),
        distance_m=float(h[-1, L.DIST]), state_seconds=seconds,
        battery_start_v=float(h[0, L.VBAT]), battery_end_v=float(h[-1, L.VBAT]))
