"""What makes a sweep quicker without changing a byte: its robots worked out per grid combination, chunks
of a process sharing their scenes, and cluster chunks their table and world."""

from __future__ import annotations

import json
import time
from dataclasses import asdict, replace
from typing import Any

import numpy as np
import pytest

from tablebot.fleet.plan import make_plan
from tablebot.fleet.spec import chunks, runs
from tablebot.fleet.work import run_job, shared
from test_sim_helpers import BUMBERBOT


def test_each_chunks_robots_are_those_of_its_runs_one_by_one() -> None:
    """Grid combinations spanning chunks, a fixed and a random start, two worlds: the robots a job gets are
    :meth:`Plan.robot` of each of its runs."""
    worlds = [BUMBERBOT / "arena.toml", BUMBERBOT.parent / "obstacle-avoider" / "arena.toml"]
    plan = make_plan(BUMBERBOT, None, worlds, ["battery=1.0,0.6", "start=random,0.4:0.4:30"], "0..6,9,12", None, 1.0)
    jobs = plan.jobs()
    assert [(job.first, job.info["stop"]) for job in jobs] == chunks(plan.spec) and len(jobs) > 4
    for job in jobs:
        chosen = runs(plan.spec, job.first, job.info["stop"])
        assert job.specs == [plan.robot(run) for run in chosen]
        assert job.world is plan.worlds[chosen[0].world]
        assert job.info["starts"] == [spec.start for spec in job.specs]
    skipped = plan.jobs(skip={chunks(plan.spec)[1]})
    assert [job.first for job in skipped] == [job.first for job in jobs if job.first != jobs[1].first]


def test_chunks_of_one_plan_share_their_scenes_and_run_as_they_would_alone() -> None:
    """Two chunks of a plan get one compiled table and one set of prepared scenes; a copy of the job (as a
    cluster worker unpickles it) gets its own; each runs to the numbers it gives with nothing shared."""
    import pickle

    from tablebot.fleet.run import Fleet

    plan = make_plan(BUMBERBOT, None, [], ["battery=1.0,0.6"], "0..40", None, 1.0)
    jobs = plan.jobs()
    first, second = jobs[0], jobs[-1]  # battery 1.0, then 0.6
    assert shared(first)[1] is shared(second)[1] and shared(first)[0] is shared(second)[0]
    copy = pickle.loads(pickle.dumps(second))
    assert shared(copy)[1] is not shared(second)[1]
    for job in (first, second, copy):
        _, summary = run_job(replace(job, threads=1))
        alone = Fleet(plan.table, plan.machine, job.world, job.specs, plan.robot_params)
        alone.run(job.ticks)
        expected = alone.summary()
        for name in ("distance_m", "battery_end_v", "counts", "first_visit", "collision_rows", "final_pose"):
            assert np.array_equal(getattr(summary, name), getattr(expected, name)), name
    assert len(shared(first)[1].scenes) == 2  # one per battery


def test_spec_json_is_the_spec_as_a_resumed_sweep_compares_it() -> None:
    """spec.json, written without asdict's deep copy of every seed, holds what asdict gives (a sweep made by an
    earlier tablebot resumes): every field, each axis with its key and values, a start pose as a list."""
    plan = make_plan(
        BUMBERBOT / "table.csv", None, [], ["battery=1.0,0.6", "start=random,0.5:0.4:90"], "0..2,7", None, 0.5
    )
    spec = plan.spec
    assert spec.to_json() == json.dumps(asdict(spec), indent=1, sort_keys=True) + "\n"
    data = json.loads(spec.to_json())
    assert data["seeds"] == [0, 1, 2, 7] and data["ticks"] == 50 and data["code"] == spec.code
    assert data["axes"] == [
        {"key": "battery", "values": [1.0, 0.6]},
        {"key": "start", "values": ["random", [0.5, 0.4, 90.0]]},
    ]


def test_threads_starting_chunks_at_once_prepare_each_scene_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """A sweep's two worker threads start their first chunks together: one prepares the scene their chunks
    share while the other waits for it, and nothing reads the scenes while they change (two threads both
    prepared it, and one read the scenes as the other added one: "dictionary changed size during iteration")."""
    import threading

    import tablebot.fleet.starts as starts
    from tablebot.fleet.run import Fleet

    plan = make_plan(BUMBERBOT, None, [], [], "0..3", None, 0.1)
    job = plan.jobs()[0]
    machine, prepared = shared(job)
    inside, calls = threading.Event(), []

    def slow_prepare(*args: Any, **kwargs: Any) -> Any:
        calls.append(threading.current_thread().name)
        inside.set()
        time.sleep(0.3)  # the other thread asks meanwhile
        return prepare(*args, **kwargs)

    prepare = starts.prepare
    monkeypatch.setattr(starts, "prepare", slow_prepare)
    failed: list[BaseException] = []

    def chunk() -> None:
        try:
            Fleet(job.table, machine, job.world, job.specs, job.robot_params, prepared=prepared)
        except BaseException as exc:
            failed.append(exc)

    first = threading.Thread(target=chunk, name="first")
    first.start()
    inside.wait(10)
    second = threading.Thread(target=chunk, name="second")
    second.start()
    first.join(30)
    second.join(30)
    assert failed == [] and calls == ["first"] and len(prepared.scenes) == 1
