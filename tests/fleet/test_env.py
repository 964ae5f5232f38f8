"""The Gymnasium environments: Gymnasium's checks, the table in charge runs as ``tablebot sim``, and the
native vector env (the fleet kernel) equals Gymnasium's own vectorisation of the single env."""

from __future__ import annotations

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="tablebot.fleet.env needs the research extra (gymnasium)")

from gymnasium.utils.env_checker import check_env  # noqa: E402
from gymnasium.vector import AutoresetMode  # noqa: E402
from gymnasium.wrappers.vector import NormalizeObservation  # noqa: E402

from tablebot.cli.common import load  # noqa: E402
from tablebot.fleet.env import ENV_ID, TableBotEnv, TableBotVectorEnv  # noqa: E402
from tablebot.sim.model.observation import Observation  # noqa: E402
from tablebot.sim.model.scene import scene_for  # noqa: E402
from tablebot.sim.runner import simulate  # noqa: E402
from test_sim_helpers import BUMBERBOT  # noqa: E402


def test_the_env_passes_gymnasiums_checker() -> None:
    env = gym.make(ENV_ID, seconds=2.0)
    check_env(env.unwrapped)
    env.close()


def test_with_the_table_in_charge_the_env_runs_as_tablebot_sim() -> None:
    env = TableBotEnv(seconds=10.0, battery=0.7)
    obs, info = env.reset(seed=11)
    assert info["seed"] == 11
    seen, rewards = [obs], []
    for _ in range(800):
        obs, reward, terminated, truncated, _ = env.step(None)
        seen.append(obs)
        rewards.append(reward)
        assert not truncated
        if terminated:
            break
    table, machine = load(BUMBERBOT)
    alone = simulate(scene_for(table, machine, None, {"battery": {"charge": 0.7}}), len(rewards) / 100, 11)
    np.testing.assert_array_equal(np.array(seen), Observation.of(alone.scene)(alone.kept_rows()))
    assert sum(rewards) == pytest.approx(-len(rewards) * 0.01)


def test_the_native_vector_env_matches_gymnasiums_sync_vector_env() -> None:
    """Random motor commands for 250 steps of 1 s episodes: autoresets included, every observation,
    reward, termination and truncation equal, exactly."""
    native = gym.make_vec(ENV_ID, num_envs=4, vectorization_mode="vector_entry_point", seconds=1.0)
    sync = gym.make_vec(ENV_ID, num_envs=4, vectorization_mode="sync", seconds=1.0)
    assert isinstance(native.unwrapped, TableBotVectorEnv)
    assert native.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    NormalizeObservation(native)  # a vector wrapper that refuses envs without a supported autoreset mode
    first, _ = native.reset(seed=9)
    np.testing.assert_array_equal(first, sync.reset(seed=9)[0])
    native.action_space.seed(2)
    resets = 0
    for _ in range(250):
        actions = native.action_space.sample()
        a_out, b_out = native.step(actions), sync.step(actions)
        for x, y in zip(a_out[:4], b_out[:4], strict=True):
            np.testing.assert_array_equal(x, y)
        assert native.observation_space.contains(a_out[0])
        resets += int(np.sum(a_out[2] | a_out[3]))
    assert resets >= 4  # every robot ran out of time at least once
    native.close()
    sync.close()


def test_the_vector_env_lets_the_table_drive_every_robot() -> None:
    vector = TableBotVectorEnv(num_envs=3, seconds=5.0)
    obs, _ = vector.reset(seed=20)
    singles = [TableBotEnv(seconds=5.0) for _ in range(3)]
    expected = np.array([env.reset(seed=20 + k)[0] for k, env in enumerate(singles)])
    np.testing.assert_array_equal(obs, expected)
    for _ in range(300):
        obs, rewards, terminated, truncated, _ = vector.step(None)
        steps = [env.step(None) for env in singles]
        np.testing.assert_array_equal(obs, np.array([s[0] for s in steps]))
        np.testing.assert_array_equal(rewards, [s[1] for s in steps])
        np.testing.assert_array_equal(terminated, [s[2] for s in steps])
        np.testing.assert_array_equal(truncated, [s[3] for s in steps])
        if terminated.any():
            break


def test_the_vector_env_takes_a_seed_per_robot() -> None:
    """reset(seed=[...]) as documented: robot k gets seed[k] (gymnasium seeds its own generator from an int
    only; the list once failed there)."""
    vector = TableBotVectorEnv(num_envs=3, seconds=2.0)
    obs, info = vector.reset(seed=[7, 3, 11])
    assert info["seed"].tolist() == [7, 3, 11]
    np.testing.assert_array_equal(obs, np.array([TableBotEnv(seconds=2.0).reset(seed=s)[0] for s in (7, 3, 11)]))
    np.testing.assert_array_equal(vector.reset(seed=[20, 21, 22])[0], vector.reset(seed=20)[0])


@pytest.mark.parametrize(
    ("example", "declared"), [("obstacle-avoider", ("I1_cm", "I2_cm")), ("line-follower", ("I1_line", "I2_line"))]
)
def test_the_observation_carries_each_declared_sensor_as_its_trace_writes_it(
    example: str, declared: tuple[str, ...]
) -> None:
    """A robot's declared sensors follow the BumberBot's part, named and scaled as in its trace, inside the
    space (each kind's bounds), alike in the single env and in the fleet's."""
    path = BUMBERBOT.parent / example
    env = TableBotEnv(table=path, seconds=3.0)
    assert env.setup.observation_names[-2:] == declared and len(env.setup.observation_names) == 12
    obs, _ = env.reset(seed=3)
    seen = [obs]
    for _ in range(299):
        obs, *_ = env.step(None)
        seen.append(obs)
    table, machine = load(path)
    trace = simulate(scene_for(table, machine), 3.0, 3).block().extra
    got = np.array(seen)[:, 10:]
    for k, name in enumerate(declared):
        np.testing.assert_allclose(got[:, k], trace[name], atol=0.05 if name.endswith("_cm") else 0)
    assert len({tuple(row) for row in got.tolist()}) > 1  # the readings really changed
    assert all(env.observation_space.contains(o) for o in seen)
    venv = TableBotVectorEnv(num_envs=2, table=path, seconds=3.0)
    first, _ = venv.reset(seed=3)
    np.testing.assert_array_equal(first[0], seen[0])
