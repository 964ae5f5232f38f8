"""The simulated robot behind the RobotIO seam: tick by tick for real-time runs, or many ticks at once
in compiled code (engine and physics together) for ``tablebot sim``; both give the same run.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from typing import Any

import numpy as np

from tablebot.engine import Engine
from tablebot.engine.as_one import RobotEngine
from tablebot.formats.trace_lines import exact_round_array
from tablebot.loop import Reading, TickBlock
from tablebot.sim import columns as L
from tablebot.sim.model.observation import Observation
from tablebot.sim.model.params import terminal_volts
from tablebot.sim.model.scene import Scene, sensor_columns
from tablebot.sim.physics import kernel as K
from tablebot.sim.physics import several as S
from tablebot.sim.physics.normals import bitgen_address, normal_rows
from tablebot.sim.physics.structures import RobotState, Wiring, WorldArrays, untallied
from tablebot.tick import registers

DEBOUNCE_S = 0.2  # touches closer together than this are one collision (a head-on hit closes two switches)
MAX_COLLISIONS = 4096  # collision starts remembered for the pictures (the count goes on beyond)
NO_NOISE = np.empty((0, L.N_NOISE))  # advance: the compiled loop draws each tick's noise from the robot's Generator


class SimRobot:
    """One differential-drive robot in a scene's world, seeded: the same seed gives the same run.

    Gymnasium-style ``reset(seed=...)`` puts it back at the start; the RobotIO methods drive it one
    tick at a time; :meth:`advance` runs the engine and the physics for many ticks in compiled code.
    """

    def __init__(self, scene: Scene, seed: int = 1, record_history: bool = True) -> None:
        self.scene = scene
        self.record_history = record_history  # keep each tick's robot row in blocks (``TickBlock.extra``)
        self._world = world_arrays(scene)
        self._wiring = wiring_of(scene)
        self.light_keys = light_keys(scene)
        self._layout = trace_layout(scene)  # the trace fields, worked out once instead of every tick
        self.collision_rows = np.zeros(MAX_COLLISIONS, dtype=np.int64)
        self._observation: Observation | None = None
        self.reset(seed=seed)

    # --- Gymnasium-style life cycle ---------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Reading, dict]:
        """Back to the world's start pose with a fresh battery draw and noise stream (``seed``: the
        robot's Generator, as ``tablebot sim --seed``); returns the first reading and an info dict."""
        if seed is not None:
            self.seed = seed
        self.rng = np.random.default_rng(self.seed)
        S, acc = np.zeros((1, L.N_STATE)), np.zeros((1, K.N_ACC))
        handle = np.array([bitgen_address(self.rng)], dtype=np.uint64)
        Starter(self.scene).start([self.scene.world.start], handle, [0], S, acc, self.collision_rows[None, :])
        self.s, self.acc = S[0], acc[0]
        self.stopped = False
        return self.read(), {"seed": self.seed}

    def _noise(self, ticks: int) -> np.ndarray:
        """The next ``ticks`` rows of this robot's noise stream (one stream, however it is cut)."""
        return self.rng.standard_normal((ticks, L.N_NOISE))

    # --- RobotIO: one tick at a time ----------------------------------------------------------

    def open(self) -> None:
        self.stopped = False

    def read(self) -> Reading:
        s = self.s
        pulses = tuple(0 if c < 0 else int(s[c]) for c in self.scene.pulse_columns)
        return Reading(int(s[L.MASK]), pulses, RowFields(self, s.copy()))

    def write(self, outputs: Sequence[int]) -> None:
        right, left = (0, 0) if self.stopped else (outputs[self.scene.drive[0]], outputs[self.scene.drive[1]])
        K.move(
            self.s,
            right,
            left,
            self.scene.P[0],
            self._world,
            self._noise(1)[0],
            self.scene.bits,
            self.acc,
            self.collision_rows,
        )

    def stop(self) -> None:
        """The motors get no more power (a real robot would coast to a halt the same way)."""
        self.stopped = True

    def close(self) -> None:
        pass

    # --- many ticks at once -----------------------------------------------------------------------

    def advance(self, engine: Engine | RobotEngine, ticks: int) -> TickBlock:
        """Run ``engine`` on this robot for ``ticks`` ticks in compiled code; the engine ends where
        ``ticks`` calls of ``read``/``step``/``write`` would have left it."""
        if isinstance(engine, RobotEngine):
            return self._advance_several(engine, ticks)
        machine = engine.machine
        arrays = machine.arrays
        if arrays is None:
            raise ValueError("the compiled simulator needs a table of at most FLAT_BITS event columns")
        regs = registers(engine.tick, engine.state, engine.timer, engine.event, engine.row)
        outputs = np.array(engine.outputs, dtype=np.int64)
        counters = np.array(engine.counters, dtype=np.int64)
        n_out, n_c = len(outputs), len(counters)
        ints = np.zeros((ticks, K.I_OUTPUTS + n_out + 2 * n_c), dtype=np.int64)
        hist = np.zeros((ticks if self.record_history else 0, L.N_STATE))
        start = engine.tick
        robot = RobotState(self.s, self.scene.P[0], regs, outputs, counters, self.acc, self.collision_rows)
        K.run_robot(
            robot,
            self._world,
            arrays.program,
            self._wiring,
            ticks,
            NO_NOISE,
            bitgen_address(self.rng),
            untallied(hist, ints),
        )
        engine._sync(regs, outputs, counters)
        return self.block(start, ints, hist, n_out, n_c)

    def _advance_several(self, engine: RobotEngine, ticks: int) -> TickBlock:
        """:meth:`advance` for a robot of several tables (:mod:`tablebot.sim.physics.several`); the block's extra
        fields hold the other tables' keys after the robot's."""
        program, state = S.several_program(engine.tables), S.several_state(engine)
        outputs = np.array(engine.outputs, dtype=np.int64)
        n_out, n_c, start = len(outputs), state.counters.shape[1], engine.tick
        ints = np.zeros((ticks, K.I_OUTPUTS + n_out + 2 * n_c), dtype=np.int64)
        hist = np.zeros((ticks if self.record_history else 0, L.N_STATE))
        kept = np.zeros((ticks, state.regs.shape[0], S.N_K), dtype=np.int64)
        robot = RobotState(
            self.s, self.scene.P[0], state.regs[0], outputs, state.counters[0], self.acc, self.collision_rows
        )
        S.run_several(
            robot,
            self._world,
            program,
            state,
            self._wiring,
            ticks,
            NO_NOISE,
            bitgen_address(self.rng),
            untallied(hist, ints),
            kept,
        )
        S.sync(engine, state, outputs)
        block = self.block(start, ints, hist, n_out, n_c)
        block.extra = Joined(block.extra or {}, S.table_columns(engine.tables, kept))
        return block

    def block(self, start: int, ints: np.ndarray, hist: np.ndarray, n_out: int, n_c: int) -> TickBlock:
        """The ticks from ``start`` that a compiled loop recorded (``ints``: .kernel's I_* records of ``n_out``
        outputs and ``n_c`` counters; ``hist``: the robot's rows, or none) as the run loop's TickBlock."""
        o, c = K.I_OUTPUTS, K.I_OUTPUTS + n_out  # outputs, then counters, then pulses
        block = TickBlock(
            start,
            ints[:, K.I_MASK],
            ints[:, c + n_c :],
            ints[:, K.I_EVENT],
            ints[:, K.I_ROW],
            ints[:, K.I_STATE],
            ints[:, K.I_TIMER],
            ints[:, o:c],
            ints[:, c : c + n_c],
        )
        if len(hist):
            block.extra = LazyColumns(self.scene, hist)
            block.raw = hist
        return block

    # --- what the trace adds to each tick -----------------------------------------------------------

    def trace_fields(self, s: np.ndarray) -> dict[str, float | int]:
        """Pose at the start of the tick, the light each phototransistor received (1.0 = threshold), volts,
        and each declared sensor's reading: :func:`trace_layout`, for one robot row."""
        fields: dict[str, float | int] = {}
        for key, column, scale, decimals in self._layout:
            value = float(s[column])
            if column == L.TH:
                value = (math.degrees(value) + 180.0) % 360.0 - 180.0
            fields[key] = int(value) if decimals == 0 else round(value * scale, decimals)
        return fields

    # --- what the run amounts to (see sim.summary) ------------------------------------------------------

    @property
    def collisions(self) -> list[int]:
        """Robot rows (row t: the start of tick t) where each collision began (the first MAX_COLLISIONS)."""
        return self.collision_rows[: min(int(self.acc[K.A_COLLISIONS]), MAX_COLLISIONS)].tolist()

    @property
    def collision_count(self) -> int:
        return int(self.acc[K.A_COLLISIONS])

    @property
    def reached_row(self) -> int | None:
        row = int(self.acc[K.A_REACHED])
        return None if row < 0 else row

    def observation(self) -> np.ndarray:
        """What a learning agent sees of the robot now (:class:`tablebot.sim.model.observation.Observation`)."""
        if self._observation is None:
            self._observation = Observation.of(self.scene)
        return self._observation(self.s[None, :])[0]


def world_arrays(scene: Scene) -> WorldArrays:
    """The scene's walls, obstacles, lamps and lines as the compiled code takes them."""
    g = scene.geometry
    return WorldArrays(g.verts, g.pstart, g.pbound, g.edges, g.circles, g.lamps, g.lines, g.shade)


def wiring_of(scene: Scene) -> Wiring:
    """The scene's wiring as the compiled code takes it."""
    return Wiring(scene.bits, np.array(scene.drive, dtype=np.int64), np.array(scene.pulse_columns, dtype=np.int64))


class Starter:
    """How a robot of one scene begins a run (its start row, accumulator and first sensor reading), with
    what every robot of the scene shares worked out once: a fleet starts thousands of robots with one,
    writing into its own rows, without a SimRobot each."""

    def __init__(self, scene: Scene) -> None:
        params = scene.params
        self.world, self.p, self.bits = world_arrays(scene), scene.P[0], scene.bits
        self.row = np.zeros(L.N_STATE)  # all but the pose and the motor gains
        self.row[L.SOC] = charge = params["battery"]["charge"]
        self.row[L.VBAT] = terminal_volts(params, charge, ())
        self.spread = params["noise"]["motor_spread"]
        self.acc = K.new_accumulator(scene.world.reach, max(1, round(DEBOUNCE_S / scene.tick_s)))

    def start(
        self,
        poses: Sequence[Sequence[float]],
        handles: np.ndarray,
        rows: Sequence[int],
        S: np.ndarray,
        acc: np.ndarray,
        collisions: np.ndarray,
    ) -> None:
        """Fill rows ``rows`` of ``S``, ``acc`` and ``collisions`` for robots starting at ``poses`` (x, y,
        heading in degrees) whose Generators' handles (:func:`bitgen_address`) are ``handles``: each robot's
        motor gains are its first two draws, its first reading's noise the next row (one draw of both: the
        same numbers), drawn in compiled code for all of them at once."""
        draws = np.empty((len(rows), 2 + L.N_NOISE))
        normal_rows(handles, draws)
        S[rows] = self.row
        S[rows, L.X : L.TH + 1] = [(x, y, math.radians(heading)) for x, y, heading in poses]
        S[rows, L.GAIN_R] = 1.0 + self.spread * draws[:, 0]
        S[rows, L.GAIN_L] = 1.0 + self.spread * draws[:, 1]
        acc[rows] = self.acc
        collisions[rows] = 0
        K.first_readings(S, self.p, self.world, np.asarray(rows, dtype=np.int64), draws, self.bits, acc, collisions)


def light_keys(scene: Scene) -> tuple[str, str]:
    """The trace's names for the light each phototransistor received: ``I7_light`` and ``I8_light``."""
    wiring = scene.params.wiring
    return f"{wiring['light_right']}_light", f"{wiring['light_left']}_light"


def wired_lights(scene: Scene) -> list[tuple[str, int]]:
    """(trace key, state column) of the phototransistors wired to inputs: a robot without them gets no
    light fields (not two fields both called ``_light``)."""
    wiring = scene.params.wiring
    return [
        (f"{wiring[role]}_light", column)
        for role, column in (("light_right", L.LIGHT_R), ("light_left", L.LIGHT_L))
        if wiring[role]
    ]


def trace_layout(scene: Scene) -> tuple[tuple[str, int, float, int], ...]:
    """What the simulator adds to each trace line, and from where: (key, state column, scale, decimals;
    0 decimals = a whole number). The heading is the column's radians as degrees in -180..180."""
    return (
        ("x", L.X, 1.0, 5),
        ("y", L.Y, 1.0, 5),
        ("heading", L.TH, 1.0, 3),
        *((key, column, 1.0, 4) for key, column in wired_lights(scene)),
        ("battery_v", L.VBAT, 1.0, 4),
        *sensor_columns(scene),
    )


def field_columns(scene: Scene, hist: np.ndarray) -> dict[str, list]:
    """:meth:`SimRobot.trace_fields` for every row of ``hist``, as columns, rounded exactly as Python's
    ``round`` does (so the bytes are those of the one-tick path)."""
    return {key: values.tolist() for key, (values, _) in number_columns(scene, hist).items()}


def number_columns(scene: Scene, hist: np.ndarray) -> dict[str, tuple[np.ndarray, int]]:
    """:func:`field_columns` as arrays, with their decimals (0: whole numbers, an int64 array)."""
    columns: dict[str, tuple[np.ndarray, int]] = {}
    for key, column, scale, decimals in trace_layout(scene):
        values = hist[:, column].astype(np.float64)
        if column == L.TH:
            values = (np.degrees(values) + 180.0) % 360.0 - 180.0  # as math.degrees and float % do
        columns[key] = (
            (values.astype(np.int64), 0) if decimals == 0 else (exact_round_array(values * scale, decimals), decimals)
        )
    return columns


class RowFields(Mapping[str, Any]):
    """The trace fields of one robot row (:meth:`SimRobot.trace_fields`), worked out only when asked for:
    a Gymnasium step or a fleet's set-up reads the mask and the pulses alone."""

    def __init__(self, robot: SimRobot, s: np.ndarray) -> None:
        self.robot, self.s = robot, s
        self._fields: dict[str, float | int] | None = None

    def _all(self) -> dict[str, float | int]:
        if self._fields is None:
            self._fields = self.robot.trace_fields(self.s)
        return self._fields

    def __getitem__(self, key: str) -> float | int:
        return self._all()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._all())

    def __len__(self) -> int:
        return len(self._all())


class LazyColumns(Mapping[str, Sequence[float]]):
    """The trace fields of a block, made only when a sink asks for them (most runs keep no trace)."""

    def __init__(self, scene: Scene, hist: np.ndarray) -> None:
        self.scene, self.hist = scene, hist
        self.keys_ = tuple(key for key, *_ in trace_layout(scene))
        self._columns: dict[str, list[float]] | None = None

    def __getitem__(self, key: str) -> Sequence[float]:
        if self._columns is None:
            self._columns = field_columns(self.scene, self.hist)
        return self._columns[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.keys_)

    def __len__(self) -> int:
        return len(self.keys_)

    def number_columns(self) -> list[tuple[str, np.ndarray, int]]:
        """(key, values, decimals) of every field in order, the values as arrays: what the compiled trace
        writer (tablebot.sinks.trace_text) takes."""
        columns = number_columns(self.scene, self.hist)
        return [(key, *columns[key]) for key in self.keys_]


class Joined(Mapping[str, Sequence[Any]]):
    """A block's robot fields (made when asked for) followed by the other tables' columns: what a trace writer
    reads of a block of a robot of several tables."""

    def __init__(self, first: Mapping[str, Sequence[Any]], then: Mapping[str, Sequence[Any]]) -> None:
        self.first, self.then = first, then

    def __getitem__(self, key: str) -> Sequence[Any]:
        return self.then[key] if key in self.then else self.first[key]

    def __iter__(self) -> Iterator[str]:
        yield from self.first
        yield from self.then

    def __len__(self) -> int:
        return len(self.first) + len(self.then)
