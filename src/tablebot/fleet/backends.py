"""Where the chunks of a sweep or a tuning run go: this machine's cores (one process per core, each
running whole chunks) or a Dask cluster (each chunk one task). Both hand every finished chunk to a
callback as it comes back, so an interrupted run keeps what finished.
"""

from __future__ import annotations

import os
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
    the local worker processes or the Dask client start, and warm up, once."""

    def __init__(self, backend: str = "local", address: str | None = None, workers: int | None = None):
        self.backend, self.address, self.workers = backend, address, workers
        self.pool: Any = None
        self.client: Any = None
        self.info: dict[str, Any] = {"workers": 0}

    def __enter__(self) -> Runner:
        return self

    def __exit__(self, kind: object, *rest: object) -> None:
        self.close(failed=kind is not None)

    def slots(self) -> int:
        """How many jobs the backend runs at once: its worker processes (or the cluster's worker threads)."""
        if self.backend == "dask":
            if self.client is None:
                return 1
            return sum(w.get("nthreads", 1) for w in self.client.scheduler_info(n_workers=-1)["workers"].values()) or 1
        return max(1, self.workers or os.cpu_count() or 1)

    def run(self, jobs: Sequence[Job], done: Done) -> None:
        if not jobs:
            return
        if self.backend == "dask":
            self._run_dask(jobs, done)
        else:
            self._run_local(jobs, done)

    def close(self, failed: bool = False) -> None:
        if self.pool is not None:
            if failed:
                self.pool.terminate()  # Ctrl-C: the workers stop at once; what finished was handed over already
            else:
                self.pool.close()
            self.pool.join()
            self.pool = None
        if self.client is not None:
            self.client.close()
            self.client = None

    # --- this machine: one process per core (``workers``), each running whole chunks single-threaded

    def _run_local(self, jobs: Sequence[Job], done: Done) -> None:
        workers = max(1, self.workers or os.cpu_count() or 1)
        if workers == 1 or (len(jobs) == 1 and self.pool is None):
            self.info = {"workers": 1, "processes": "this one"}
            for job in jobs:
                done(*run_job(job))
            return
        if self.pool is None:
            import multiprocessing

            warm(jobs[0])  # this process fills the user's numba cache first: the workers only read it
            context = multiprocessing.get_context("spawn")  # never fork a process that holds numba's threads
            self.pool = context.Pool(workers, initializer=_ignore_interrupts)
            self.info = {"workers": workers, "processes": "local"}
        for job, summary in self.pool.imap_unordered(run_job, [replace(j, threads=1) for j in jobs]):
            done(job, summary)

    # --- a Dask cluster: each chunk one task

    def _run_dask(self, jobs: Sequence[Job], done: Done) -> None:
        """Every worker first warms the kernel in a cache folder of its own, from this process's compiled
        code (a fresh worker loads it instead of compiling again); then the chunks go out."""
        if self.client is None:
            self.client = connect(self.address or "")  # first: it says what to install when Dask is missing
            self.info = warm_cluster(self.client, jobs[0])
        from distributed import as_completed

        client = self.client
        futures = [client.submit(run_job, job, pure=False) for job in jobs]
        try:
            for future in as_completed(futures, loop=client.loop):
                done(*future.result())
        except BaseException:
            client.cancel(futures)
            raise


def _ignore_interrupts() -> None:
    """Workers leave Ctrl-C to the parent, which stops them (no half-written results, no tracebacks)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


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
