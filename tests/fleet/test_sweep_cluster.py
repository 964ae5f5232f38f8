"""``tablebot sweep`` on a Dask cluster: the same rows as a local sweep from a real cluster, clear errors for
addresses and a missing Dask, workers that load the compiled kernel they are sent, and the threads a job runs on."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from test_sim_helpers import BUMBERBOT
from test_sweep import dask_cluster, env, sweep  # noqa: F401  (dask_cluster: a real scheduler and two workers)


def test_a_dask_cluster_gives_the_local_results_row_for_row(tmp_path: Path, dask_cluster: str) -> None:  # noqa: F811
    spec = ["--grid", "battery=1.0,0.7", "--grid", "start=random", "--seeds", "0..23", "--seconds", "10", "--no-plots"]
    code, output = sweep(*spec, "--out", str(tmp_path / "local"), "--backend", "local", "--workers", "2")
    assert code == 0, output
    code, output = sweep(*spec, "--out", str(tmp_path / "dask"), "--scheduler", dask_cluster)
    assert code == 0, output
    local = (tmp_path / "local" / "results.csv").read_bytes()
    assert local == (tmp_path / "dask" / "results.csv").read_bytes()
    assert local.count(b"\n") == 49


def test_a_tls_address_without_dasks_tls_settings_is_a_clear_error(tmp_path: Path) -> None:
    """Found on connecting (as an unreachable scheduler is), so the sweep's folder is made first."""
    code, output = sweep("--robots", "2", "--scheduler", "tls://127.0.0.1:9", "--out", str(tmp_path / "s"))
    assert code == 2 and output.startswith("--scheduler: error: cannot connect to the Dask scheduler at tls://"), output
    assert "distributed.comm.tls.ca-file" in output and "Traceback" not in output


def test_a_scheduler_address_from_the_environment_is_named_as_such(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", "junk")
    code, output = sweep("--robots", "2", "--out", str(tmp_path / "s"))
    assert code == 2, output
    assert output.startswith("DASK_SCHEDULER_ADDRESS: error: DASK_SCHEDULER_ADDRESS 'junk' is not"), output
    assert "tcp://127.0.0.1:8786" in output and not (tmp_path / "s").exists()


def test_without_dask_the_dask_backend_says_what_to_install(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if Dask were not installed: importing fails
    code, output = sweep("--robots", "2", "--scheduler", "tcp://127.0.0.1:9", "--out", str(tmp_path / "s"))
    assert code == 2, output
    assert output.startswith("--backend: error: --backend dask: Dask is not installed")
    assert "pip install 'tablebot[cluster]'" in output


def test_a_fresh_cluster_worker_loads_the_compiled_kernel_it_is_sent(tmp_path: Path) -> None:
    """A worker started without NUMBA_CACHE_DIR keeps its compiled kernels in worker-SLOT of the user's
    tablebot cache. A fresh one (an empty cache) is sent this process's compiled code with the warm-up
    task and loads it: every file it was sent lands there, and nothing else (it compiled nothing)."""
    import pickle

    from tablebot import jit
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.work import warm

    plan = make_plan(BUMBERBOT, None, [], [], "0", None, 1.0)
    job = plan.jobs()[0]
    warm(job)  # this process's cache holds the kernel a worker of one thread runs
    files = jit.cache_files()
    home = tmp_path / "cache"
    version = f"py{sys.version_info.major}{sys.version_info.minor}"
    mine = home / "tablebot" / f"numba-{version}-{jit.sources_digest()}" / "worker-testhost-0"
    (tmp_path / "job.pickle").write_bytes(pickle.dumps((job, files)))
    code = (
        "import json, os, pickle, sys; from tablebot.fleet.work import job_threads, warm_worker; "
        "job, files = pickle.load(open(sys.argv[1], 'rb')); "
        "info = warm_worker(job, 'testhost-0', os.cpu_count(), files); "
        "print(json.dumps({**info, 'job_threads': job_threads(job)}))"
    )
    worker_env = {k: v for k, v in env().items() if k != "NUMBA_CACHE_DIR"}
    worker_env["XDG_CACHE_HOME"] = str(home)
    info = worker_says(code, tmp_path / "job.pickle", worker_env)
    assert info["cache"] == str(mine) and info["threads"] == 1
    assert info["job_threads"] == 1  # a job without threads of its own takes the worker's share of the cores
    sent = sorted(name for named in files.values() for name in named)
    assert info["installed"] == len(sent) > 0
    landed = sorted(p.name for p in mine.rglob("*") if p.is_file())
    assert landed == sent  # loaded, not compiled: a compile would have added or rewritten files
    for relative, named in files.items():
        folder = next(p for p in mine.iterdir() if p.name.startswith((Path(relative).parent.name or "tablebot") + "_"))
        assert all((folder / name).read_bytes() == data for name, data in named.items())
    # as a sweep readies a worker: its imports first, without code; then the code, which it loads, before any job
    code = (
        "import json, pickle, sys; from tablebot.fleet.work import chunk_functions, ready_worker; "
        "job, files = pickle.load(open(sys.argv[1], 'rb')); first = ready_worker('testhost-1', 2, None, False); "
        "functions = chunk_functions(1); before = [len(f.overloads) for f in functions]; "
        "second = ready_worker('testhost-1', 2, files); "
        "print(json.dumps([first, second, before, [len(f.overloads) for f in functions]]))"
    )
    first, second, before, after = worker_says(code, tmp_path / "job.pickle", worker_env)
    assert first["cache"] == second["cache"] == str(mine.parent / "worker-testhost-1")
    assert (first["installed"], first["loaded"]) == (0, 0) and before == [0] * len(before)
    assert second["installed"] == len(sent) and second["loaded"] == len(after) and after == [1] * len(after)
    landed = sorted(p.name for p in (mine.parent / "worker-testhost-1").rglob("*") if p.is_file())
    assert landed == sent  # loaded, not compiled
    # a worker started with tablebot's preload has numba before the client comes, and still gets its own folder
    code = (
        "import json, pickle, sys; from tablebot.fleet.worker import dask_setup; dask_setup(); "
        "early = 'numba' in sys.modules; from tablebot.fleet.work import ready_worker; "
        "job, files = pickle.load(open(sys.argv[1], 'rb')); ready_worker('testhost-2', 2, None, False); "
        "print(json.dumps([early, ready_worker('testhost-2', 2, files)]))"
    )
    early, info = worker_says(code, tmp_path / "job.pickle", worker_env)
    assert early and info["cache"] == str(mine.parent / "worker-testhost-2") and info["loaded"] == len(after)
    assert sorted(p.name for p in (mine.parent / "worker-testhost-2").rglob("*") if p.is_file()) == sent


def worker_says(code: str, job: Path, env: dict[str, str]) -> Any:
    """What a fresh process, as a worker, prints last (JSON) after running ``code`` on the pickled job."""
    done = subprocess.run([sys.executable, "-c", code, str(job)], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_job_with_threads_of_its_own_runs_on_them() -> None:
    """What a job runs on is the fleet's to say and set (evolve's jobs ask it too); numba keeps the count per
    calling thread, and this process is no cluster worker, so a job without threads leaves it alone."""
    from dataclasses import replace

    import numba

    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.work import job_threads, use_threads

    job = make_plan(BUMBERBOT, None, [], [], "0", None, 1.0).jobs()[0]
    before = numba.get_num_threads()
    try:
        assert job_threads(job) is None and job_threads(replace(job, threads=1)) == 1
        use_threads(replace(job, threads=1))
        assert numba.get_num_threads() == 1
        use_threads(job)
        assert numba.get_num_threads() == 1
    finally:
        numba.set_num_threads(before)
