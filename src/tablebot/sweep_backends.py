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
from tablebot.sim.fleet_work import Job, run_job, warm, warm_worker

if TYPE_CHECKING:
    from tablebot.sim.fleet import FleetSummary

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
    if not jobs:
        return {"workers": 0}
    if backend == "dask":
        return run_dask(jobs, done, address or "")
    return run_local(jobs, done, workers)


# --- this machine -----------------------------------------------------------------------------------


def run_local(jobs: Sequence[Job], done: Done, workers: int | None = None) -> dict[str, Any]:
    """One process per core (``workers``: how many), each running whole chunks single-threaded. This
    process compiles the kernel into the user's numba cache first, so the workers only read it."""
    workers = max(1, min(workers or os.cpu_count() or 1, len(jobs)))
    if workers == 1:
        for job in jobs:
            done(*run_job(job))
        return {"workers": 1, "processes": "this one"}
    import multiprocessing

    warm(jobs[0])
    context = multiprocessing.get_context("spawn")  # never fork a process that holds numba's threads
    pool = context.Pool(workers, initializer=_ignore_interrupts)
    try:
        for job, summary in pool.imap_unordered(run_job, [replace(j, threads=1) for j in jobs]):
            done(job, summary)
        pool.close()
    except BaseException:
        pool.terminate()  # Ctrl-C: the workers stop at once; what finished was handed over already
        raise
    finally:
        pool.join()
    return {"workers": workers, "processes": "local"}


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


def run_dask(jobs: Sequence[Job], done: Done, address: str) -> dict[str, Any]:
    """Each chunk one task. Every worker first warms the kernel in a cache folder of its own (one
    compile per worker, never two processes writing one folder); then the chunks go out."""
    from distributed import as_completed

    client = connect(address)
    try:
        info = warm_cluster(client, jobs[0])
        futures = [client.submit(run_job, job, pure=False, key=f"tablebot-chunk-{job.first}-{k}")
                   for k, job in enumerate(jobs)]
        try:
            for future in as_completed(futures, loop=client.loop):
                done(*future.result())
        except BaseException:
            client.cancel(futures)
            raise
        return info
    finally:
        client.close()


def warm_cluster(client: Any, job: Job) -> dict[str, Any]:
    """Warm every worker (pinned to it), with a cache slot named by its host and its rank there."""
    workers = client.scheduler_info(n_workers=-1)["workers"]
    if not workers:
        raise fail("--scheduler", "the Dask scheduler has no workers", "start some with `dask worker ADDRESS`")
    by_host: dict[str, list[str]] = defaultdict(list)
    for address, worker in sorted(workers.items()):
        by_host[worker.get("host", address)].append(address)
    futures = []
    for host, addresses in by_host.items():
        for rank, address in enumerate(addresses):
            slot = f"{host}-{rank}".replace(":", "_").replace("/", "_")
            futures.append(client.submit(warm_worker, job, slot, len(addresses), workers=[address],
                                         allow_other_workers=False, pure=False, key=f"tablebot-warm-{slot}"))
    try:
        warmed = client.gather(futures)
    except Exception as exc:  # a scheduler or worker without tablebot (or another version of it)
        raise fail("--scheduler", f"the Dask cluster could not run tablebot's fleet: {type(exc).__name__}: {exc}",
                   "install the same tablebot (and Python) on the scheduler and every worker") from None
    return {"workers": len(workers), "warm": warmed}
