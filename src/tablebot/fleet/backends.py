"""Where the chunks of a sweep or a tuning run go: this machine's cores (a thread per core in this process,
each running whole chunks) or a Dask cluster (each chunk one task). Both hand every finished chunk to a
callback as it comes back, so an interrupted run keeps what finished.
"""

from __future__ import annotations

import os
import threading
from collections import defaultdict
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from tablebot.diagnostics import fail
from tablebot.fleet.work import Job, run_job, warm, warm_worker

if TYPE_CHECKING:
    from tablebot.fleet.run import FleetSummary

Done = Callable[[Job, "FleetSummary"], None]
SCHEDULER_ENV = "DASK_SCHEDULER_ADDRESS"
INSTALL_HINT = "install the cluster extra: pip install 'tablebot[cluster]' (Dask's distributed scheduler)"


def choose(backend: str, scheduler: str | None) -> tuple[str, str | None]:
    """The backend and scheduler address to use: Dask when asked for, or when a scheduler is named (by
    --scheduler or DASK_SCHEDULER_ADDRESS) and --backend was left at its default."""
    address = scheduler or os.environ.get(SCHEDULER_ENV) or None
    if backend not in ("auto", "local", "dask"):
        raise fail("--backend", f"--backend {backend}: unknown backend", "use --backend local or --backend dask")
    if backend == "local" and scheduler:
        raise fail("--scheduler", "--scheduler names a Dask scheduler, but --backend is local",
                   "drop --backend local (or use --backend dask)")
    if backend == "auto":
        backend = "dask" if address else "local"
    if backend == "dask" and not address:
        raise fail("--backend", "--backend dask needs a scheduler to send the chunks to",
                   f"give --scheduler tcp://HOST:8786 or set {SCHEDULER_ENV}")
    return backend, address if backend == "dask" else None


def run_jobs(jobs: Sequence[Job], done: Done, backend: str = "local", address: str | None = None,
             workers: int | None = None) -> dict[str, Any]:
    """Run every job, calling ``done(job, summary)`` as each finishes (in the order they finish);
    returns what the backend says about itself (workers, their cache folders)."""
    with Runner(backend, address, workers) as runner:
        runner.run(jobs, done)
        return runner.info


class Runner:
    """A backend kept open over many batches of jobs (a tuning run sends one batch per generation):
    the local worker threads or the Dask client start, and warm up, once."""

    def __init__(self, backend: str = "local", address: str | None = None, workers: int | None = None):
        self.backend, self.address, self.workers = backend, address, workers
        self.pool: Any = None
        self.client: Any = None
        self.stop = threading.Event()  # set on Ctrl-C: local chunks end at their next block, unfinished
        self.info: dict[str, Any] = {"workers": 0}

    def __enter__(self) -> Runner:
        return self

    def __exit__(self, kind: object, *rest: object) -> None:
        self.close(failed=kind is not None)

    def slots(self) -> int:
        """How many jobs the backend runs at once: its worker threads (or the cluster's)."""
        if self.backend == "dask":
            if self.client is None:
                return 1
            return sum(w.get("nthreads", 1) for w in self.client.scheduler_info(n_workers=-1)["workers"].values()) or 1
        return max(1, self.workers or os.cpu_count() or 1)

    def run(self, jobs: Sequence[Job], done: Done, fn: Callable[[Any], tuple[Job, Any]] = run_job) -> None:
        """Run every job with ``fn`` (default: the fleet's :func:`run_job`; evolve measures more per robot),
        handing each result to ``done`` as it comes back."""
        if not jobs:
            return
        if self.backend == "dask":
            self._run_dask(jobs, done, fn)
        else:
            self._run_local(jobs, done, fn)

    def close(self, failed: bool = False) -> None:
        if self.pool is not None:
            if failed:
                self.stop.set()  # Ctrl-C: running chunks end within a block; what finished was handed over already
            self.pool.shutdown(wait=True, cancel_futures=True)
            self.pool = None
        if self.client is not None:
            self.client.close()
            self.client = None

    def _call(self, fn: Callable[..., tuple[Job, Any]], job: Job) -> tuple[Job, Any]:
        """``fn(job)``; the fleet's own run_job also stops at its next block when the run is stopped."""
        return fn(job, self.stop) if fn is run_job else fn(job)

    # --- this machine: a thread per core (``workers``), each running whole chunks single-threaded
    #
    # Threads, not processes: the compiled fleet loop releases the GIL, so two threads run two chunks on two
    # cores, and this process's compiled code serves both -- no worker processes to start, no Python, numpy and
    # numba to import again in each, no jobs and summaries to pickle across (seconds of a short sweep's time).

    def _run_local(self, jobs: Sequence[Job], done: Done, fn: Callable[[Any], tuple[Job, Any]]) -> None:
        workers = max(1, self.workers or os.cpu_count() or 1)
        if workers == 1 or len(jobs) == 1:  # numba's own threads share each chunk's robots out
            self.info = {"workers": 1, "threads": "numba's"}
            for job in jobs:
                done(*self._call(fn, job))
            return
        if self.pool is None:
            from concurrent.futures import ThreadPoolExecutor

            self.pool = ThreadPoolExecutor(workers, thread_name_prefix="tablebot-fleet")
            self.info = {"workers": workers, "threads": "local"}
        from concurrent.futures import as_completed

        futures = [self.pool.submit(self._call, fn, replace(job, threads=1)) for job in jobs]
        try:
            for future in as_completed(futures):
                done(*future.result())
        except BaseException:
            for future in futures:
                future.cancel()
            raise

    # --- a Dask cluster: each chunk one task

    def _run_dask(self, jobs: Sequence[Job], done: Done, fn: Callable[[Any], tuple[Job, Any]]) -> None:
        """Every worker first warms the kernel in a cache folder of its own, from this process's compiled
        code (a fresh worker loads it instead of compiling again); then the chunks go out."""
        if self.client is None:
            self.client = connect(self.address or "")  # first: it says what to install when Dask is missing
            self.info = warm_cluster(self.client, jobs[0])
        from distributed import as_completed

        client = self.client
        futures = [client.submit(fn, job, pure=False) for job in jobs]
        try:
            for future in as_completed(futures, loop=client.loop):
                done(*future.result())
        except BaseException:
            client.cancel(futures)
            raise


# --- a Dask cluster ---------------------------------------------------------------------------------


def connect(address: str) -> Any:
    """A Dask client of the scheduler at ``address`` (a clear error when Dask is missing or unreachable)."""
    try:
        from distributed import Client
    except ImportError:
        raise fail("--backend", "--backend dask: Dask is not installed", INSTALL_HINT) from None
    try:
        return Client(address, timeout="15s", set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise fail("--scheduler", f"cannot reach the Dask scheduler at {address}: {exc}",
                   "start one with `dask scheduler` and `dask worker ADDRESS`, or check the address") from None


def warm_cluster(client: Any, job: Job) -> dict[str, Any]:
    """Warm every worker (pinned to it), with a cache slot named by its host and its rank there, from this
    process's compiled code: compiled (or loaded) here once, sent to every worker once."""
    workers = client.scheduler_info(n_workers=-1)["workers"]
    if not workers:
        raise fail("--scheduler", "the Dask scheduler has no workers", "start some with `dask worker ADDRESS`")
    from tablebot import jit

    warm(job, both=True)  # both kernels: a worker alone on its machine runs chunks on all its cores
    files = client.scatter(jit.cache_files(), broadcast=True, hash=False)
    by_host: dict[str, list[str]] = defaultdict(list)
    for address, worker in sorted(workers.items()):
        by_host[worker.get("host", address)].append(address)
    futures = []
    for host, addresses in by_host.items():
        for rank, address in enumerate(addresses):
            slot = f"{host}-{rank}".replace(":", "_").replace("/", "_")
            futures.append(client.submit(warm_worker, job, slot, len(addresses), files, workers=[address],
                                         allow_other_workers=False, pure=False, key=f"tablebot-warm-{slot}"))
    try:
        warmed = client.gather(futures)
    except Exception as exc:  # a scheduler or worker without tablebot (or another version of it)
        raise fail("--scheduler", f"the Dask cluster could not run tablebot's fleet: {type(exc).__name__}: {exc}",
                   "install the same tablebot (and Python) on the scheduler and every worker") from None
    return {"workers": len(workers), "warm": warmed}
