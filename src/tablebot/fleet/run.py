"""Many simulated robots of one table in one world, advanced together in compiled code (sim.fleet_kernel).

Each robot is set up by :class:`~tablebot.sim.simrobot.SimRobot` itself (start row, gains, first reading,
its own numpy Generator) and draws its noise from that Generator exactly as SimRobot does (inside the
compiled loop, sim.normals), so robot k of a fleet gives the trace ``tablebot sim`` gives for the same
table, world, start, battery and seed.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from tablebot.diagnostics import fail
from tablebot.engine import Engine
from tablebot.fleet.generators import generators
from tablebot.fleet.kernel import NO_TICK, move_fleet, parallel, run_fleet, run_fleet_serial
from tablebot.fleet.robots import Pose, RobotSpec, Variants
from tablebot.loop import RunEnd, TickBlock
from tablebot.machine import Machine
from tablebot.sim import columns as L
from tablebot.sim import kernel as K
from tablebot.sim.normals import bitgen_address
from tablebot.sim.observation import Observation
from tablebot.sim.runner import PATH_STRIDE, SimRun
from tablebot.sim.scene import Scene, _check_start, prepare
from tablebot.sim.simrobot import SimRobot, Starter, wiring_of, world_arrays
from tablebot.sim.structures import FleetRecord, FleetState, ProgramVariants
from tablebot.sim.summary import Summary, light_bits
from tablebot.sim.world import World, inside
from tablebot.sinks.run_trace import seconds_per_state
from tablebot.sinks.trace_file import block_lines
from tablebot.table import Table
from tablebot.tick import STATE, registers

BLOCK_TICKS = 256  # ticks per compiled call (progress is reported, and traced robots' blocks kept, per block)
FLEET_COLLISIONS = 16  # collision starts remembered per robot (the count goes on beyond)


@dataclass
class FleetSummary:
    """Per robot, what a sweep needs: arrays indexed by robot (``NO_TICK``/-1: never)."""

    ticks: int
    tick_s: float
    states: tuple[Any, ...]  # the machine's states (indices in final_state and counts)
    first_light: np.ndarray  # tick whose reading first held a light bit
    reached: np.ndarray  # robot row that first came within reach of a lamp
    collisions: np.ndarray
    distance_m: np.ndarray
    battery_start_v: np.ndarray
    battery_end_v: np.ndarray
    final_state: np.ndarray  # state index after the last tick
    counts: np.ndarray  # (N, states): ticks spent in each state (the state after each tick)
    first_visit: np.ndarray  # (N, states): first tick after which the robot was in that state
    collision_rows: np.ndarray  # (N, FLEET_COLLISIONS): the first collision starts
    final_pose: np.ndarray  # (N, 3): x, y (m) and heading (radians, unwrapped) after the last tick
    lamps: bool = True  # whether the world has lamps (as in sim.summary.Summary)

    def __len__(self) -> int:
        return len(self.first_light)

    def summary(self, i: int) -> Summary:
        """Robot i's numbers as :func:`tablebot.sim.summary.summarise` gives them for a single run, but for
        laps round a track (they need the whole path, which a fleet does not keep: None)."""
        def seconds(tick: int) -> float | None:
            return None if tick < 0 else tick * self.tick_s
        count = int(self.collisions[i])
        return Summary(seconds=self.ticks * self.tick_s, first_light_s=seconds(int(self.first_light[i])),
                       reached_s=seconds(int(self.reached[i])), collisions=count,
                       collision_ticks=tuple(self.collision_rows[i, : min(count, FLEET_COLLISIONS)].tolist()),
                       distance_m=float(self.distance_m[i]),
                       state_seconds=seconds_per_state(self.counts[i], self.first_visit[i], self.states, self.tick_s),
                       battery_start_v=float(self.battery_start_v[i]), battery_end_v=float(self.battery_end_v[i]),
                       lamps=self.lamps)


@dataclass
class Prepared:
    """What fleets of one table in one world with one robot layer share, by parameter set: the scene
    (:func:`~tablebot.sim.scene.prepare`: the world's pieces and shadow grid, milliseconds each) and how its
    robots start. A sweep's chunks in one process share one instead of preparing them again per chunk
    (:func:`tablebot.fleet.work.shared`); scenes and starters are only read once made."""

    scenes: dict[tuple, Scene] = field(default_factory=dict)
    starters: dict[tuple, Starter] = field(default_factory=dict)


@dataclass
class Trace:
    """A traced robot's run, kept block by block (its SimRobot makes the blocks, as in ``tablebot sim``)."""

    robot: SimRobot
    blocks: list[TickBlock] = field(default_factory=list)
    rows: list[np.ndarray] = field(default_factory=list)  # robot rows at the start of each tick


class Fleet:
    """N robots of one table in one world (each with its own seed, start, parameters and program variant)."""

    def __init__(self, table: Table, machine: Machine, world: World, specs: Sequence[RobotSpec],
                 robot_params: dict[str, Any] | None = None, traced: Sequence[int] = (),
                 variants: Variants | None = None, prepared: Prepared | None = None) -> None:
        if machine.arrays is None:
            raise ValueError("the compiled simulator needs a table of at most FLAT_BITS event columns")
        self.table, self.machine, self.world_model, self.robot_params = table, machine, world, robot_params
        self.specs = list(specs)
        self.variants = variants or Variants.of(machine)
        self._prepared = prepared or Prepared()
        self.scenes = [self.scene_of(spec) for spec in self.specs]
        self.tick_s, self.t0 = self.scenes[0].tick_s, 0
        self._tick_noise: NoiseRows | None = None
        self._observation: Observation | None = None
        self._setup(traced)

    def scene_of(self, spec: RobotSpec) -> Scene:
        """The robot's scene: the table in the world with its parameters (made once per parameter set)
        and its start; every robot of a fleet must be wired alike."""
        scenes = self._prepared.scenes
        if spec.params not in scenes:
            scene = prepare(self.table, self.machine, self.world_model, self.robot_params, spec.overrides())
            first = next(iter(scenes.values()), scene)
            if (scene.bits.tolist(), scene.drive, scene.pulse_columns) != (first.bits.tolist(), first.drive,
                                                                           first.pulse_columns):
                raise ValueError("robots of one fleet must share their wiring")
            scenes[spec.params] = scene
        return with_start(scenes[spec.params], spec.start)

    def _setup(self, traced: Sequence[int]) -> None:
        """Every robot's rows (see :meth:`place`), and what the fleet shares."""
        n, engine = len(self.specs), Engine(self.machine)
        n_out, n_c, n_states = len(engine.outputs), len(engine.counters), len(self.machine.states)
        self.initial = (registers(engine.tick, engine.state, engine.timer, engine.event, engine.row),
                        np.array(engine.outputs, dtype=np.int64), np.array(engine.counters, dtype=np.int64))
        self.S, self.P = np.zeros((n, L.N_STATE)), np.zeros((n, self.scenes[0].P.shape[1]))
        self.acc, self.collisions = np.zeros((n, K.N_ACC)), np.zeros((n, FLEET_COLLISIONS), dtype=np.int64)
        self.regs = np.zeros((n, len(self.initial[0])), dtype=np.int64)
        self.outputs, self.counters = np.zeros((n, n_out), dtype=np.int64), np.zeros((n, n_c), dtype=np.int64)
        self.counts = np.zeros((n, n_states), dtype=np.int64)
        self.first_visit = np.full((n, n_states), NO_TICK, dtype=np.int64)
        self.first_light = np.full(n, NO_TICK, dtype=np.int64)
        self.variant = np.zeros(n, dtype=np.int64)
        self.battery_start_v = np.zeros(n)
        self.rngs: list[np.random.Generator] = [np.random.default_rng(0)] * n
        self.bitgens = np.zeros(n, dtype=np.uint64)  # each robot's Generator's handle (sim.normals.bitgen_address)
        self.traces: dict[int, Trace] = {}
        self.traced = np.full(n, -1, dtype=np.int64)
        first = self.scenes[0]  # the world and wiring, shared by all robots (as SimRobot packs them)
        self.world = world_arrays(first)
        self.wiring = wiring_of(first)
        self.regs[:], self.outputs[:], self.counters[:] = self.initial
        rngs = generators([spec.seed for spec in self.specs])  # default_rng(seed) each, made at once
        by_params: dict[tuple, list[int]] = defaultdict(list)  # untraced robots, by parameter set
        recorded = set(traced)
        for i, spec in enumerate(self.specs):
            if i in recorded:
                self.traced[i] = len(self.traces)
                self.traces[i] = Trace(self.place(i, spec, self.scenes[i], record=True))  # type: ignore[arg-type]
            else:
                by_params[spec.params].append(i)
        for rows in by_params.values():
            self._start(rows, [rngs[i] for i in rows], self.scenes[rows[0]], [self.scenes[i].world.start for i in rows])
        self.bits = self.scenes[0].bits
        self.light_bits = light_bits(self.scenes[0])
        self.width = K.I_OUTPUTS + n_out + 2 * n_c

    def place(self, i: int, spec: RobotSpec, scene: Scene | None = None, record: bool = False) -> SimRobot | None:
        """Put robot i at its start as SimRobot sets a robot up (its gains and first reading drawn from its
        own Generator, which then gives its noise: :class:`Starter`), with a fresh engine. With ``record``
        (a traced robot) it is a SimRobot, returned."""
        scene = scene or self.scene_of(spec)
        self.specs[i] = spec
        self.regs[i], self.outputs[i], self.counters[i] = self.initial
        self.counts[i], self.first_visit[i], self.first_light[i] = 0, NO_TICK, NO_TICK
        if not record:
            self._start([i], [np.random.default_rng(spec.seed)], scene, [scene.world.start])
            return None
        robot = SimRobot(scene, spec.seed, record_history=True)
        self.S[i], self.acc[i], self.P[i] = robot.s, robot.acc, scene.P[0]
        self.collisions[i] = robot.collision_rows[:FLEET_COLLISIONS]
        self.variant[i], self.battery_start_v[i] = spec.variant, robot.s[L.VBAT]
        self.rngs[i], self.bitgens[i] = robot.rng, bitgen_address(robot.rng)
        return robot

    def _start(self, rows: list[int], rngs: list[np.random.Generator], scene: Scene, starts: list[Pose]) -> None:
        """Robots ``rows`` (of one parameter set, that of ``scene``) at their ``starts``, each with its
        Generator (``default_rng(seed)``), written straight into the fleet's rows: a SimRobot each was
        most of a sweep's set-up."""
        self.starter(self.specs[rows[0]], scene).start(starts, rngs, rows, self.S, self.acc, self.collisions)
        self.P[rows] = scene.P[0]
        self.variant[rows] = [self.specs[i].variant for i in rows]
        self.battery_start_v[rows] = self.S[rows, L.VBAT]
        for i, rng in zip(rows, rngs, strict=True):
            self.rngs[i], self.bitgens[i] = rng, bitgen_address(rng)

    def starter(self, spec: RobotSpec, scene: Scene) -> Starter:
        """How robots with ``spec``'s parameters start (one per parameter set, as their scenes)."""
        starters = self._prepared.starters
        if spec.params not in starters:
            starters[spec.params] = Starter(scene)
        return starters[spec.params]

    def __len__(self) -> int:
        return len(self.specs)

    def run(self, ticks: int, progress: Callable[[int], None] | None = None, block_ticks: int = BLOCK_TICKS,
            threads: bool | None = None) -> None:
        """Advance every robot ``ticks`` ticks; ``progress(ticks_done)`` after each block. ``threads``: run on
        numba's thread pool (True) or on this thread (False); None: the pool when the work is worth it."""
        done = 0
        while done < ticks:
            b = min(block_ticks, ticks - done)
            self.step_block(ticks=b, threads=threads)
            done += b
            if progress:
                progress(done)

    def draw_noise(self, ticks: int) -> np.ndarray:
        """The next ``ticks`` rows of every robot's noise stream (SimRobot._noise, robot by robot)."""
        noise = np.empty((len(self.specs), ticks, L.N_NOISE))
        for i, rng in enumerate(self.rngs):
            rng.standard_normal(out=noise[i])
        return noise

    def step_block(self, noise: np.ndarray | None = None, ticks: int | None = None,
                   threads: bool | None = None) -> None:
        """Advance every robot ``noise.shape[1]`` ticks with the given noise rows, or ``ticks`` ticks with
        noise each robot draws from its own Generator as it goes (the same numbers :meth:`draw_noise` gives);
        ``threads`` as in :meth:`run`."""
        if noise is None:
            assert ticks is not None, "give the noise rows or the ticks"
            noise = np.empty((len(self.specs), 0, L.N_NOISE))
        else:
            ticks = noise.shape[1]
        n_traced = len(self.traces)
        hist = np.zeros((n_traced, ticks, self.S.shape[1]))
        ints = np.zeros((n_traced, ticks, self.width), dtype=np.int64)
        v = self.variants
        pool = parallel(len(self.specs), ticks) if threads is None else threads
        kernel = run_fleet if pool else run_fleet_serial
        fleet = FleetState(self.S, self.P, self.regs, self.outputs, self.counters, self.acc, self.collisions)
        record = FleetRecord(self.counts, self.first_visit, self.first_light, self.traced, hist, ints, self.light_bits,
                             self.t0)
        kernel(fleet, self.world, self.machine.arrays.program, ProgramVariants(v.timers, v.loads, self.variant),  # type: ignore[union-attr]
               self.wiring, ticks, noise, self.bitgens, record)
        n_out, n_c = self.outputs.shape[1], self.counters.shape[1]
        for i, trace in self.traces.items():
            slot = self.traced[i]
            trace.blocks.append(trace.robot._block(self.t0, ints[slot], hist[slot], n_out, n_c))
            trace.rows.append(hist[slot])
        self.t0 += ticks

    # --- tick by tick (the Gymnasium vector environment) -------------------------------------------

    def tick(self, commands: np.ndarray | None = None) -> None:
        """Advance every robot one tick: its table drives it, or, given ``commands`` (N, 2: signed motor levels
        right, left), they drive its motors and its engine does not tick (a learned controller).

        The noise comes a row at a time from each robot's stream, as :meth:`run` draws it a block at a time;
        a fleet is driven by one of the two, never both."""
        if self._tick_noise is None:
            self._tick_noise = NoiseRows(self)
        noise = self._tick_noise.next()
        if commands is None:
            self.step_block(noise[:, None, :])
        else:
            move_fleet(self.S, self.P, self.world, np.asarray(commands, dtype=np.int64).reshape(len(self), 2), noise,
                       self.bits, self.acc, self.collisions)

    def restart(self, i: int, spec: RobotSpec) -> None:
        """Robot i starts again as ``spec`` says (:meth:`place`), its noise stream with it."""
        self.place(i, spec)
        if self._tick_noise is not None:
            self._tick_noise.refill(i)

    def reached(self) -> np.ndarray:
        """Per robot, whether it has come within reach of a lamp."""
        return self.acc[:, K.A_REACHED] >= 0

    def observations(self) -> np.ndarray:
        """What a learning agent sees of every robot now, a row each (:class:`~tablebot.sim.observation.Observation`
        of the fleet's scene)."""
        if self._observation is None:
            self._observation = Observation.of(self.scenes[0])
        return self._observation(self.S)

    # --- what the run amounts to --------------------------------------------------------------------

    def summary(self) -> FleetSummary:
        return FleetSummary(
            ticks=self.t0, tick_s=self.tick_s, states=self.machine.states, first_light=self.first_light.copy(),
            reached=self.acc[:, K.A_REACHED].astype(np.int64), collisions=self.acc[:, K.A_COLLISIONS].astype(np.int64),
            distance_m=self.S[:, L.DIST].copy(), battery_start_v=self.battery_start_v.copy(),
            battery_end_v=self.S[:, L.VBAT].copy(), final_state=self.regs[:, STATE].copy(), counts=self.counts.copy(),
            first_visit=self.first_visit.copy(), collision_rows=self.collisions.copy(),
            final_pose=self.S[:, [L.X, L.Y, L.TH]].copy(), lamps=bool(self.world_model.lamps))

    def trace_lines(self, i: int) -> list[str]:
        """Robot i's trace (it must be traced), line for line what ``tablebot sim`` writes."""
        return [line for block in self.traces[i].blocks for line in block_lines(block, self.machine)]

    def result(self, i: int) -> SimRun:
        """Robot i's whole run as the single-robot runner's :class:`SimRun` (for its pictures)."""
        trace = self.traces[i]
        blocks, robot = trace.blocks, trace.robot
        def column(name: str) -> np.ndarray:
            return np.concatenate([np.asarray(getattr(b, name)) for b in blocks])
        hist = np.concatenate([*trace.rows, self.S[i][None, :]])
        count = int(self.acc[i, K.A_COLLISIONS])
        reached = int(self.acc[i, K.A_REACHED])
        return SimRun(scene=robot.scene, seed=robot.seed, hist=hist, ends=hist[[0, -1]],
                      path=hist[::PATH_STRIDE, [L.X, L.Y]], masks=column("masks"), events=column("events"),
                      rows=column("rows"), states=column("states"), timers=column("timers"),
                      outputs=column("outputs"), counters=column("counters"), pulses=column("pulses"),
                      collision_rows=self.collisions[i, : min(count, FLEET_COLLISIONS)].tolist(),
                      collision_count=count, reached_row=None if reached < 0 else reached,
                      end=RunEnd("done", self.t0), wall_s=0.0)


class NoiseRows:
    """Each robot's noise stream, drawn ahead in blocks from its own Generator (as SimRobot draws it, one
    row a tick) and handed out a row per tick."""

    BLOCK = 256

    def __init__(self, fleet: Fleet) -> None:
        self.fleet = fleet
        n = len(fleet)
        self.rows = np.empty((n, self.BLOCK, L.N_NOISE))
        self.at = np.zeros(n, dtype=np.int64)
        for k in range(n):
            self.refill(k)

    def refill(self, k: int) -> None:
        self.fleet.rngs[k].standard_normal(out=self.rows[k])
        self.at[k] = 0

    def next(self) -> np.ndarray:
        for k in np.flatnonzero(self.at >= self.BLOCK).tolist():
            self.refill(k)
        out = self.rows[np.arange(len(self.at)), self.at]
        self.at += 1
        return out


def with_start(scene: Scene, start: Pose | None) -> Scene:
    """The scene with the robot starting at ``start`` (checked inside the walls, as a world file's [start]
    is, and free of walls and obstacles)."""
    if start is None:
        return scene
    sx, sy, sh = start
    world = replace(scene.world, start=(float(sx), float(sy), float(sh)))
    x, y, heading = world.start
    if world.walls and not inside(world.walls, (x, y)):
        raise fail(world.path, f"the robot's start pose ({x:g}, {y:g}, heading {heading:g}°) lies outside the "
                   "arena walls", "choose a start inside the [arena] walls")
    _check_start(world, scene.geometry, scene.P)
    return replace(scene, world=world)
