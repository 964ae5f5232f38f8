"""Many simulated robots of one table in one world, advanced together in compiled code (fleet.kernel); how they
start is :mod:`tablebot.fleet.starts`, what their run amounts to :mod:`tablebot.fleet.results`.

Each robot is set up as :class:`~tablebot.sim.simrobot.SimRobot` sets itself up (start row, gains, first
reading, from its own ``default_rng(seed)`` stream, kept by :mod:`tablebot.fleet.streams`) and draws its noise
from that stream exactly as SimRobot does (inside the compiled loop, sim.physics.normals), so robot k of a
fleet gives the trace ``tablebot sim`` gives for the same table, world, start, battery and seed.
"""

from __future__ import annotations

import itertools
from collections import defaultdict
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from tablebot.fleet.kernel import (
    NO_TICK,
    move_fleet,
    parallel,
    run_fleet,
    run_fleet_serial,
    run_fleet_several_serial,
)
from tablebot.fleet.results import FLEET_COLLISIONS, FleetSummary, Trace
from tablebot.fleet.robots import Pose, RobotSpec, Variants
from tablebot.fleet.starts import Prepared, Starts, with_start
from tablebot.fleet.streams import Streams
from tablebot.jit import numba
from tablebot.machine import Machine
from tablebot.sim import columns as L
from tablebot.sim.model.observation import Observation
from tablebot.sim.model.scene import Scene
from tablebot.sim.model.world import World
from tablebot.sim.physics import kernel as K
from tablebot.sim.physics.several import N_K, SeveralState, several_program, table_columns
from tablebot.sim.physics.structures import FleetRecord, FleetState, ProgramVariants
from tablebot.sim.runner import SimRun
from tablebot.sim.simrobot import Joined, SimRobot, wiring_of, world_arrays
from tablebot.sim.summary import light_bits
from tablebot.table import Table
from tablebot.tables import RobotTables
from tablebot.tick import STATE, registers

__all__ = [
    "BLOCK_TICKS",
    "FLEET_COLLISIONS",
    "Fleet",
    "FleetSummary",
    "NoiseRows",
    "Prepared",
    "RobotSpec",
    "Trace",
    "Variants",
    "with_start",
]

BLOCK_TICKS = 256  # ticks per compiled call (progress is reported, and traced robots' blocks kept, per block)


class Fleet:
    """N robots of one table in one world (each with its own seed, start, parameters and program variant); with
    ``tables``, of every table of a robot of several (``table`` and ``machine`` its main one's; ``variants`` then
    of every table's timers and loads, :meth:`Variants.of_tables`)."""

    def __init__(
        self,
        table: Table,
        machine: Machine,
        world: World,
        specs: Sequence[RobotSpec],
        robot_params: dict[str, Any] | None = None,
        traced: Sequence[int] = (),
        variants: Variants | None = None,
        prepared: Prepared | None = None,
        tables: RobotTables | None = None,
    ) -> None:
        if machine.arrays is None:
            raise ValueError("the compiled simulator needs a table of at most FLAT_BITS event columns")
        self.table, self.machine, self.world_model, self.robot_params = table, machine, world, robot_params
        self.tables = tables
        self.specs = list(specs)
        self.variants = variants or (Variants.of(machine) if tables is None else Variants.of_tables(tables))
        self.starts = Starts(table, machine, world, robot_params, prepared, tables)
        self.scenes = [self.starts.scene(spec) for spec in self.specs]
        self.tick_s, self.t0 = self.scenes[0].tick_s, 0
        self._tick_noise: NoiseRows | None = None
        self._observation: Observation | None = None
        self._setup(traced)

    def _setup(self, traced: Sequence[int]) -> None:
        """Every robot's rows (see :meth:`place`), and what the fleet shares."""
        machine, n = self.machine, len(self.specs)
        n_out, n_c, n_states = len(machine.output_names), len(machine.counter_bits), len(machine.states)
        # a fresh Engine's registers, outputs and counters, without making one: its step's lookups, which no
        # compiled loop reads, were a fifth of a sweep chunk's set-up
        self.initial = (
            registers(0, machine.initial_state, machine.initial_timer),
            np.zeros(n_out, dtype=np.int64),
            np.zeros(n_c, dtype=np.int64),
        )
        self.S, self.P = np.zeros((n, L.N_STATE)), np.zeros((n, self.scenes[0].P.shape[1]))
        self.acc, self.collisions = np.zeros((n, K.N_ACC)), np.zeros((n, FLEET_COLLISIONS), dtype=np.int64)
        self.regs = np.zeros((n, len(self.initial[0])), dtype=np.int64)
        self.outputs, self.counters = np.zeros((n, n_out), dtype=np.int64), np.zeros((n, n_c), dtype=np.int64)
        self.counts = np.zeros((n, n_states), dtype=np.int64)
        self.first_visit = np.full((n, n_states), NO_TICK, dtype=np.int64)
        self.first_light = np.full(n, NO_TICK, dtype=np.int64)
        self.variant = np.zeros(n, dtype=np.int64)
        self.battery_start_v = np.zeros(n)
        self.streams = Streams(n)  # each robot's noise stream: default_rng(its seed)'s
        self.bitgens = self.streams.handles  # what the compiled code draws through
        self.traces: dict[int, Trace] = {}
        self.traced = np.full(n, -1, dtype=np.int64)
        first = self.scenes[0]  # the world and wiring, shared by all robots (as SimRobot packs them)
        self.world = world_arrays(first)
        self.wiring = wiring_of(first)
        self.regs[:], self.outputs[:], self.counters[:] = self.initial
        self._setup_tables(n, n_out, n_c)
        by_params: dict[tuple, list[int]] = defaultdict(list)  # untraced robots, by parameter set
        recorded = set(traced)
        for i, spec in enumerate(self.specs):
            if i in recorded:
                self.traced[i] = len(self.traces)
                self.traces[i] = Trace(self.place(i, spec, self.scenes[i], record=True))  # type: ignore[arg-type]
            else:
                by_params[spec.params].append(i)
        for rows in by_params.values():
            self.streams.seed(rows, [self.specs[i].seed for i in rows])
            self._start(rows, self.scenes[rows[0]], [self.scenes[i].world.start for i in rows])
        self.bits = self.scenes[0].bits
        self.light_bits = light_bits(self.scenes[0])
        self.width = K.I_OUTPUTS + n_out + 2 * n_c

    def _setup_tables(self, n: int, n_out: int, n_c: int) -> None:
        """A robot of several tables: every table's rows per robot (sim.physics.several), each as a fresh Engine's."""
        if self.tables is None:
            return
        machines = self.tables.machines
        self.program = several_program(self.tables)
        self.table_initial = np.stack([registers(0, m.initial_state, m.initial_timer) for m in machines])
        count = len(machines)
        self.table_rows = SeveralState(
            np.repeat(self.table_initial[None], n, axis=0),
            np.zeros((n, count, n_out), dtype=np.int64),
            np.zeros((n, count, n_c), dtype=np.int64),
            np.zeros((n, count), dtype=np.int64),
        )

    def _reset_tables(self, i: int) -> None:
        if self.tables is not None:
            self.table_rows.regs[i], self.table_rows.outputs[i], self.table_rows.counters[i] = self.table_initial, 0, 0

    def place(self, i: int, spec: RobotSpec, scene: Scene | None = None, record: bool = False) -> SimRobot | None:
        """Put robot i at its start as SimRobot sets a robot up (its gains and first reading drawn from its
        own Generator, which then gives its noise: :class:`Starter`), with a fresh engine. With ``record``
        (a traced robot) it is a SimRobot, returned."""
        scene = scene or self.starts.scene(spec)
        self.specs[i] = spec
        self.regs[i], self.outputs[i], self.counters[i] = self.initial
        self._reset_tables(i)
        self.counts[i], self.first_visit[i], self.first_light[i] = 0, NO_TICK, NO_TICK
        if not record:
            self.streams.seed([i], [spec.seed])
            self._start([i], scene, [scene.world.start])
            return None
        robot = SimRobot(scene, spec.seed, record_history=True)
        self.S[i], self.acc[i], self.P[i] = robot.s, robot.acc, scene.P[0]
        self.collisions[i] = robot.collision_rows[:FLEET_COLLISIONS]
        self.variant[i], self.battery_start_v[i] = spec.variant, robot.s[L.VBAT]
        self.streams.use(i, robot.rng)
        return robot

    def _start(self, rows: list[int], scene: Scene, starts: list[Pose]) -> None:
        """Robots ``rows`` (of one parameter set, that of ``scene``) at their ``starts``, each drawing from its
        stream (seeded already), written straight into the fleet's rows: a SimRobot each was most of a sweep's
        set-up."""
        starter = self.starts.starter(self.specs[rows[0]], scene)
        starter.start(starts, self.bitgens[rows], rows, self.S, self.acc, self.collisions)
        self.P[rows] = scene.P[0]
        self.variant[rows] = [self.specs[i].variant for i in rows]
        self.battery_start_v[rows] = self.S[rows, L.VBAT]

    def __len__(self) -> int:
        return len(self.specs)

    def run(
        self,
        ticks: int,
        progress: Callable[[int], None] | None = None,
        block_ticks: int = BLOCK_TICKS,
        threads: bool | None = None,
    ) -> None:
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
        """The next ``ticks`` rows of every robot's noise stream (as SimRobot draws its own, robot by robot)."""
        noise = np.empty((len(self.specs), ticks, L.N_NOISE))
        for i in range(len(self.specs)):
            self.streams.generator(i).standard_normal(out=noise[i])
        return noise

    def step_block(
        self, noise: np.ndarray | None = None, ticks: int | None = None, threads: bool | None = None
    ) -> None:
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
        fleet = FleetState(self.S, self.P, self.regs, self.outputs, self.counters, self.acc, self.collisions)
        record = FleetRecord(
            self.counts, self.first_visit, self.first_light, self.traced, hist, ints, self.light_bits, self.t0
        )
        kept = None
        if self.tables is None:
            kernel = run_fleet if pool else run_fleet_serial
            kernel(
                fleet,
                self.world,
                self.machine.arrays.program,  # type: ignore[union-attr]
                ProgramVariants(v.timers, v.loads, self.variant),
                self.wiring,
                ticks,
                noise,
                self.bitgens,
                record,
            )
        else:
            kept = np.zeros((n_traced, ticks, len(self.tables.machines), N_K), dtype=np.int64)
            variants = ProgramVariants(v.timers, v.loads, self.variant)

            def robots(a: int, b: int) -> None:  # robots a..b-1: every per-robot array cut to them
                run_fleet_several_serial(
                    _rows(fleet, a, b),
                    self.world,
                    self.program,
                    variants._replace(variant=self.variant[a:b]),
                    _rows(self.table_rows, a, b),
                    self.wiring,
                    ticks,
                    noise[a:b],
                    self.bitgens[a:b],
                    record._replace(
                        counts=self.counts[a:b],
                        first_visit=self.first_visit[a:b],
                        first_light=self.first_light[a:b],
                        traced=self.traced[a:b],
                    ),
                    kept,
                )

            in_threads(numba.get_num_threads() if pool else 1, len(self.specs), robots)
            self.regs[:], self.counters[:] = self.table_rows.regs[:, 0], self.table_rows.counters[:, 0]
        n_out, n_c = self.outputs.shape[1], self.counters.shape[1]
        for i, trace in self.traces.items():
            slot = self.traced[i]
            block = trace.robot.block(self.t0, ints[slot], hist[slot], n_out, n_c)
            if kept is not None and self.tables is not None:  # the other tables' keys after the robot's fields
                block.extra = Joined(block.extra or {}, table_columns(self.tables, kept[slot]))
            trace.blocks.append(block)
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
            move_fleet(
                self.S,
                self.P,
                self.world,
                np.asarray(commands, dtype=np.int64).reshape(len(self), 2),
                noise,
                self.bits,
                self.acc,
                self.collisions,
            )

    def restart(self, i: int, spec: RobotSpec) -> None:
        """Robot i starts again as ``spec`` says (:meth:`place`), its noise stream with it."""
        self.place(i, spec)
        if self._tick_noise is not None:
            self._tick_noise.refill(i)

    def reached(self) -> np.ndarray:
        """Per robot, whether it has come within reach of a lamp."""
        return self.acc[:, K.A_REACHED] >= 0

    def observations(self) -> np.ndarray:
        """What a learning agent sees of every robot now, a row each (:class:`~.observation.Observation`
        of the fleet's scene)."""
        if self._observation is None:
            self._observation = Observation.of(self.scenes[0])
        return self._observation(self.S)

    # --- what the run amounts to (fleet.results) ------------------------------------------------------

    def summary(self) -> FleetSummary:
        return FleetSummary(
            ticks=self.t0,
            tick_s=self.tick_s,
            states=self.machine.states,
            first_light=self.first_light.copy(),
            reached=self.acc[:, K.A_REACHED].astype(np.int64),
            collisions=self.acc[:, K.A_COLLISIONS].astype(np.int64),
            distance_m=self.S[:, L.DIST].copy(),
            battery_start_v=self.battery_start_v.copy(),
            battery_end_v=self.S[:, L.VBAT].copy(),
            final_state=self.regs[:, STATE].copy(),
            counts=self.counts.copy(),
            first_visit=self.first_visit.copy(),
            collision_rows=self.collisions.copy(),
            final_pose=self.S[:, [L.X, L.Y, L.TH]].copy(),
            lamps=bool(self.world_model.lamps),
        )

    def trace_lines(self, i: int) -> list[str]:
        """Robot i's trace (it must be traced), line for line what ``tablebot sim`` writes."""
        return self.traces[i].lines(self.machine)

    def result(self, i: int) -> SimRun:
        """Robot i's whole run as the single-robot runner's :class:`SimRun` (for its pictures)."""
        return self.traces[i].result(self.S[i], self.acc[i], self.collisions[i], self.t0)


def _rows(arrays: Any, a: int, b: int) -> Any:
    """A named tuple of per-robot arrays cut to robots a..b-1 (views: what the kernel writes lands in the whole)."""
    return type(arrays)(*(array[a:b] for array in arrays))


def in_threads(threads: int, robots: int, run: Callable[[int, int], None]) -> None:
    """``run(a, b)`` on robots a..b-1 of ``robots``, cut into ``threads`` slices each on a thread of its own (the
    compiled loop holds no GIL); one slice runs on this thread."""
    cuts = [k * robots // threads for k in range(threads + 1)] if threads > 1 and robots > 1 else [0, robots]
    if len(cuts) == 2:
        run(0, robots)
        return
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(len(cuts) - 1) as pool:
        for done in [pool.submit(run, a, b) for a, b in itertools.pairwise(cuts) if b > a]:
            done.result()


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
        self.fleet.streams.generator(k).standard_normal(out=self.rows[k])
        self.at[k] = 0

    def next(self) -> np.ndarray:
        for k in np.flatnonzero(self.at >= self.BLOCK).tolist():
            self.refill(k)
        out = self.rows[np.arange(len(self.at)), self.at]
        self.at += 1
        return out
