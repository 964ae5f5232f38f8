"""The simulation loop: the core engine ticks, the physics core moves and senses, and the run is logged.
Tick t: the engine reads the inputs sensed at the start of the tick, fires its row, and the motors
then run for one tick.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import IO, Any

import numpy as np

from tablebot import trace
from tablebot.diagnostics import fail
from tablebot.engine import Engine
from tablebot.sim import layout as L
from tablebot.sim.params import terminal_volts
from tablebot.sim.physics import step_one
from tablebot.sim.scene import Scene
from tablebot.trace import TickInput, replay

MAX_TICKS = 360_000  # an hour at the BumberBot's 10 ms: the whole history is kept in memory
NOISE_BLOCK = 4096  # ticks of noise drawn at once: one Generator call instead of one per tick
CHUNK = 2000  # ticks between progress reports


@dataclass
class Result:
    """A finished run. ``hist[t]`` is the robot at the start of tick t (what the engine sensed then);
    ``events[t]`` is the event set the engine saw in tick t, ``states[t]``/``outputs[t]`` its state index
    and outputs after tick t."""

    scene: Scene
    seed: int
    hist: np.ndarray  # (ticks + 1, N_STATE)
    states: np.ndarray  # (ticks,) int
    events: np.ndarray  # (ticks,) int
    outputs: np.ndarray  # (ticks, n_outputs) int
    pulses: np.ndarray  # (ticks, n_counters) int
    wall_s: float  # how long the loop took; shown to people, never written into result files

    @property
    def ticks(self) -> int:
        return len(self.states)

    @property
    def tick_s(self) -> float:
        return self.scene.tick_s

    @property
    def masks(self) -> np.ndarray:
        return self.hist[:-1, L.MASK].astype(np.int64)

    def inputs(self) -> list[TickInput]:
        """The engine's inputs per tick, as recorded: replaying them gives the same run."""
        pulses = self.pulses.tolist()
        return [TickInput(int(m), tuple(p)) for m, p in zip(self.masks.tolist(), pulses, strict=True)]

    def heading_deg(self) -> np.ndarray:
        """Unwrapped heading in degrees per hist row (a turn of 270° reads 270, not -90)."""
        return np.degrees(self.hist[:, L.TH])


def initial_state(scene: Scene, rng: np.random.Generator) -> np.ndarray:
    S = np.zeros((1, L.N_STATE))
    x, y, heading = scene.world.start
    S[0, L.X], S[0, L.Y], S[0, L.TH] = x, y, math.radians(heading)
    S[0, L.SOC] = charge = scene.params["battery"]["charge"]
    S[0, L.VBAT] = terminal_volts(scene.params, charge, ())
    spread = scene.params["noise"]["motor_spread"]
    S[0, L.GAIN_R], S[0, L.GAIN_L] = 1.0 + spread * rng.standard_normal(2)
    return S


def ticks_for(scene: Scene, seconds: float) -> int:
    """The ticks in ``seconds`` of robot time (at least one); more than MAX_TICKS are refused."""
    ticks = max(1, round(seconds / scene.tick_s))
    if ticks > MAX_TICKS:
        raise fail("--seconds", f"{seconds:g} s at tick_ms = {scene.table.robot.tick_ms} is {ticks:,} ticks; "
                   f"a run holds at most {MAX_TICKS:,}", f"simulate at most {MAX_TICKS * scene.tick_s:g} s")
    return ticks


def run(scene: Scene, seconds: float, seed: int = 1, progress: Callable[[int], None] | None = None) -> Result:
    """Simulate ``seconds`` of robot time; ``progress(ticks_done)`` is called every few thousand ticks.

    Everything random comes from one numpy Generator seeded with ``seed``, and nothing depends on the
    wall clock, so a table, world and seed always give the same trace bytes.
    """
    ticks = ticks_for(scene, seconds)
    rng = np.random.default_rng(seed)
    S = initial_state(scene, rng)
    geo, P, bits = scene.geometry, scene.P, scene.bits
    args = (P, geo.verts, geo.pstart, geo.pbound, geo.edges, geo.circles, geo.lamps)
    cmd = np.zeros((1, 2), dtype=np.int64)
    hist = np.zeros((ticks + 1, L.N_STATE))
    noise = rng.standard_normal((NOISE_BLOCK, 1, L.N_NOISE))
    engine = Engine(scene.machine)
    right, left = scene.drive
    pcols = np.array(scene.pulse_columns, dtype=np.int64)
    pulse_out = np.zeros(len(pcols), dtype=np.int64)
    states = np.zeros(ticks, dtype=np.int64)
    events = np.zeros(ticks, dtype=np.int64)
    outputs: list[tuple[int, ...]] = []
    pulse_log: list[list[int]] = []
    mask = step_one(S, cmd, *args, noise, 0, bits, hist, 0, pcols, pulse_out)
    pulses: list[int] = pulse_out.tolist()  # tolist: plain ints for the engine (and its JSON)
    j, started = 1, time.perf_counter()
    for first in range(0, ticks, CHUNK):
        for t in range(first, min(ticks, first + CHUNK)):
            if j == NOISE_BLOCK:
                noise, j = rng.standard_normal((NOISE_BLOCK, 1, L.N_NOISE)), 0
            out = engine.step(mask, pulses)
            states[t], events[t] = engine.state, engine.event
            outputs.append(out)
            pulse_log.append(pulses)
            cmd[0, 0], cmd[0, 1] = out[right], out[left]
            mask = step_one(S, cmd, *args, noise, j, bits, hist, t + 1, pcols, pulse_out)
            pulses = pulse_out.tolist()
            j += 1
        if progress:
            progress(min(ticks, first + CHUNK))
    wall = time.perf_counter() - started
    return Result(scene=scene, seed=seed, hist=hist, states=states, events=events,
                  outputs=np.array(outputs, dtype=np.int64).reshape(ticks, -1),
                  pulses=np.array(pulse_log, dtype=np.int64).reshape(ticks, len(pcols)), wall_s=wall)


# --- trace ---------------------------------------------------------------------------------------


def trace_lines(result: Result) -> Iterator[dict[str, Any]]:
    """The core trace of the run (replayed from the recorded inputs) plus pose and raw sensor values.

    Added per line: ``x``, ``y`` (m), ``heading`` (degrees, -180..180) at the start of the tick, the
    light each phototransistor received (``<input>_light``, 1.0 = threshold) and the battery volts.
    """
    wiring = result.scene.params.wiring
    light_r, light_l = f"{wiring['light_right']}_light", f"{wiring['light_left']}_light"
    hist = result.hist
    for t, line in enumerate(replay(result.scene.machine, result.inputs())):
        row = hist[t]
        heading = (math.degrees(row[L.TH]) + 180.0) % 360.0 - 180.0
        line.update({"x": round(float(row[L.X]), 5), "y": round(float(row[L.Y]), 5),
                     "heading": round(heading, 3), light_r: round(float(row[L.LIGHT_R]), 4),
                     light_l: round(float(row[L.LIGHT_L]), 4), "battery_v": round(float(row[L.VBAT]), 4)})
        yield line


def write_trace(result: Result, stream: IO[str]) -> int:
    """Write the run's trace as JSON Lines (the core's writer); returns the number of ticks."""
    return trace.write_trace(trace_lines(result), stream)
