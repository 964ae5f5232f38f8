"""Gymnasium environments of a simulated tablebot robot: :class:`TableBotEnv` (one robot, built on
:class:`~tablebot.sim.simrobot.SimRobot`) and :class:`TableBotVectorEnv` (many robots in the compiled fleet),
registered as ``tablebot/TableBot-v0``.

Observation: pose and sensor readings (see :data:`OBSERVATION`). Action: the two drive motors' signed
speed levels (-8..8: right, left), or ``None`` to let the table drive (its engine ticks as in ``tablebot
sim``, so a learned controller and the hand-written table can be compared in the same arena). Reward:
minus the tick's seconds, so an episode's return is minus the time it took; it terminates when the lamp
is reached and is truncated after ``seconds``. Needs ``pip install 'tablebot[research]'`` (gymnasium).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

import numpy as np

try:
    import gymnasium as gym
    from gymnasium import spaces
    from gymnasium.vector import AutoresetMode, VectorEnv
    from gymnasium.vector.utils import batch_space
except ImportError as exc:  # pragma: no cover - gymnasium is an extra
    raise ImportError("tablebot.fleet.env needs Gymnasium: pip install 'tablebot[research]'") from exc

from tablebot.loop import exchange
from tablebot.sim.model.observation import BUILT_IN

ENV_ID = "tablebot/TableBot-v0"
#: The observation vector's first part, in order; every declared sensor's reading follows (the names of a
#: robot's whole vector: ``env.observation_names``; see :class:`tablebot.sim.model.observation.Observation`).
OBSERVATION = tuple(name for name, _ in BUILT_IN)


class Setup:
    """The table, world and parameters an environment runs, loaded once (errors as in ``tablebot sim``)."""

    def __init__(
        self,
        table: str | Path | None,
        world: str | Path | None,
        robot: str | Path | None,
        seconds: float,
        battery: float | None,
    ) -> None:
        from tablebot.examples import example_path
        from tablebot.formats.table_read import load_table, resolve_table_path
        from tablebot.machine import compile_table
        from tablebot.robot import load_robot
        from tablebot.sim.model.observation import Observation
        from tablebot.sim.model.scene import find_world, prepare, robot_layer
        from tablebot.sim.runner import ticks_for

        path = resolve_table_path(Path(table) if table else example_path("bumberbot"))
        self.table = load_table(path, load_robot(robot) if robot else None)
        self.machine = compile_table(self.table)
        self.robot_params, robot_world = robot_layer(self.table.robot)
        self.world = find_world(self.table, Path(world) if world else None, robot_world)
        self.params = (("battery", "charge", float(battery)),) if battery is not None else ()
        self.scene = prepare(self.table, self.machine, self.world, self.robot_params, self.spec(0).overrides())
        self.ticks = ticks_for(self.scene, seconds)
        levels = int(self.scene.params["motor"]["levels"])
        self.action_space = spaces.MultiDiscrete(
            [2 * levels + 1, 2 * levels + 1], start=[-levels, -levels], dtype=np.int64
        )
        observation = Observation.of(self.scene)
        self.observation_names = observation.names
        self.observation_space = spaces.Box(observation.low, observation.high, dtype=np.float64)

    def spec(self, seed: int) -> Any:
        from tablebot.fleet.robots import RobotSpec

        return RobotSpec(seed=seed, params=self.params)


class TableBotEnv(gym.Env):
    """One simulated robot (a :class:`~tablebot.sim.simrobot.SimRobot`): ``reset(seed=s)`` then ``step(None)``
    ticks give exactly the run of ``tablebot sim --seed s``."""

    # gymnasium declares metadata as an instance variable, but it is (and is documented as) a class attribute
    metadata: ClassVar[dict[str, Any]] = {"render_modes": []}  # type: ignore[misc]

    def __init__(
        self,
        table: str | Path | None = None,
        world: str | Path | None = None,
        seconds: float = 60.0,
        battery: float | None = None,
        robot: str | Path | None = None,
        render_mode: str | None = None,
    ) -> None:
        from tablebot.engine import Engine
        from tablebot.sim.simrobot import SimRobot

        self.setup = Setup(table, world, robot, seconds, battery)
        self.action_space, self.observation_space = self.setup.action_space, self.setup.observation_space
        self.render_mode = render_mode
        self.engine = Engine(self.setup.machine)
        self.robot = SimRobot(self.setup.scene, 0, record_history=False)
        self.drive = self.setup.scene.drive
        self.ticks = 0

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        robot_seed = seed if seed is not None else int(self.np_random.integers(2**31))
        self.robot.reset(seed=robot_seed)
        self.engine.reset()
        self.ticks = 0
        return self._observation(), {"seed": robot_seed}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict]:
        if action is None:  # the table drives: the engine ticks on what the robot reads, as in the run loop
            exchange(self.engine, self.robot)
        else:
            levels = np.asarray(action, dtype=np.int64).reshape(2)
            outputs = [0] * len(self.engine.outputs)
            outputs[self.drive[0]], outputs[self.drive[1]] = int(levels[0]), int(levels[1])
            self.robot.write(outputs)
        self.ticks += 1
        reached = self.robot.reached_row is not None
        info = {"state": self.setup.machine.states[self.engine.state], "collisions": self.robot.collision_count}
        return (
            self._observation(),
            -self.setup.scene.tick_s,
            reached,
            self.ticks >= self.setup.ticks and not reached,
            info,
        )

    def _observation(self) -> np.ndarray:
        return self.robot.observation()


class TableBotVectorEnv(VectorEnv):
    """``num_envs`` robots in one compiled fleet, stepped together (``prange``). Sub-environment i reset
    with seed s + i is the robot :class:`TableBotEnv` gives for seed s + i. Autoreset: next step (a
    sub-environment that terminated or truncated is reset by the following ``step``, which returns its
    first observation with reward 0)."""

    # gymnasium declares metadata as an instance variable, but it is (and is documented as) a class attribute
    metadata: ClassVar[dict[str, Any]] = {  # type: ignore[misc]
        "autoreset_mode": AutoresetMode.NEXT_STEP,
        "render_modes": [],
    }

    def __init__(
        self,
        num_envs: int = 8,
        table: str | Path | None = None,
        world: str | Path | None = None,
        seconds: float = 60.0,
        battery: float | None = None,
        robot: str | Path | None = None,
        render_mode: str | None = None,
    ) -> None:
        from tablebot.fleet.run import Fleet

        self.setup = Setup(table, world, robot, seconds, battery)
        self.num_envs, self.render_mode = num_envs, render_mode
        self.single_action_space, self.single_observation_space = self.setup.action_space, self.setup.observation_space
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        s = self.setup
        self.fleet = Fleet(s.table, s.machine, s.world, [s.spec(k) for k in range(num_envs)], s.robot_params)
        self.ticks = np.zeros(num_envs, dtype=np.int64)
        self.done = np.zeros(num_envs, dtype=bool)
        self.generators: list[np.random.Generator] = []

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict]:
        """Sub-environment k gets seed ``seed + k`` (or ``seed[k]``): its robot's seed, and the seed of the
        generator its later autoresets draw robot seeds from, as TableBotEnv.reset(seed=...) does."""
        from gymnasium.utils import seeding

        super().reset(seed=seed if isinstance(seed, int) else None)  # gymnasium seeds np_random from an int only
        if seed is None:
            seeds = [int(v) for v in self.np_random.integers(2**31, size=self.num_envs)]
        elif isinstance(seed, int):
            seeds = [seed + k for k in range(self.num_envs)]
        else:
            seeds = [int(v) for v in seed]
        self.generators = [seeding.np_random(s)[0] for s in seeds]
        for k, robot_seed in enumerate(seeds):
            self._reset_one(k, robot_seed)
        return self.fleet.observations(), {"seed": np.array(seeds)}

    def _reset_one(self, k: int, seed: int) -> None:
        self.fleet.restart(k, self.setup.spec(seed))
        self.ticks[k], self.done[k] = 0, False

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict]:
        fleet, again = self.fleet, self.done.copy()
        fleet.tick(None if actions is None else np.asarray(actions, dtype=np.int64).reshape(self.num_envs, 2))
        self.ticks += 1
        reached = fleet.reached()
        terminated = reached & ~again
        truncated = (self.ticks >= self.setup.ticks) & ~reached & ~again
        rewards = np.where(again, 0.0, -self.setup.scene.tick_s)
        for k in np.flatnonzero(again).tolist():  # next-step autoreset: whatever it did this step is dropped
            self._reset_one(k, int(self.generators[k].integers(2**31)))
        self.done = terminated | truncated
        return fleet.observations(), rewards, terminated, truncated, {}


if ENV_ID not in gym.registry:
    gym.register(
        ENV_ID, entry_point="tablebot.fleet.env:TableBotEnv", vector_entry_point="tablebot.fleet.env:TableBotVectorEnv"
    )
