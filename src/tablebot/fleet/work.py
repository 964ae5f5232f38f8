"""The unit of work of sweeps and tuning: a chunk of robots of one table in one world, run as one fleet
in whichever process gets it (this one, a local worker process, a Dask worker).

Nothing compiled is imported at the top: a Dask worker that unpickles :func:`run_job` must be able to
choose its numba cache folder (:func:`warm_worker`) before the first compiled module loads.
"""

from __future__ import annotations

import os
import socket
import sys
import threading
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

from tablebot.fleet.robots import RobotSpec, Variants

if TYPE_CHECKING:
    from tablebot.fleet.run import FleetSummary
    from tablebot.sim.world import World
    from tablebot.table import Table

COMPILED = ("tablebot.sim.physics", "tablebot.sim.kernel", "tablebot.engine_batch")
_worker_threads: int | None = None  # set by warm_worker: this worker's share of its machine's cores


@dataclass
class Job:
    """Robots ``first`` .. ``first + len(specs) - 1`` of a sweep (or one generation of a tuning run)."""

    table: Table
    world: World
    robot_params: dict[str, Any]
    specs: list[RobotSpec]
    ticks: int
    first: int = 0
    variants: Variants | None = None
    threads: int | None = None  # numba threads for this job (None: numba's default)
    info: dict[str, Any] = field(default_factory=dict)  # what the caller needs back with the result


class Stopped(Exception):
    """A chunk given up between two blocks because its run was stopped (Ctrl-C)."""


def run_job(job: Job, stop: threading.Event | None = None) -> tuple[Job, FleetSummary]:
    """Run the chunk as one fleet; returns the job (without its robots) and the fleet's summary. With
    ``stop``, the chunk is given up (:class:`Stopped`) at the first block after it is set."""
    from tablebot.fleet.run import Fleet
    from tablebot.machine import compile_table

    def check(_ticks: int) -> None:
        if stop is not None and stop.is_set():
            raise Stopped

    use_threads(job)
    fleet = Fleet(job.table, compile_table(job.table), job.world, job.specs, job.robot_params,
                  variants=job.variants)
    fleet.run(job.ticks, progress=check)
    return replace(job, specs=[], variants=None), fleet.summary()


def job_threads(job: Job) -> int | None:
    """The numba threads ``job`` runs on in this process: its own ``threads``, else this cluster worker's
    share of its machine's cores (set by :func:`warm_worker`), else None (numba's default)."""
    return job.threads or _worker_threads


def use_threads(job: Job) -> None:
    """Give the calling thread :func:`job_threads` numba threads (numba keeps the count per calling thread,
    so each job sets it again); with None, the thread keeps what it has."""
    threads = job_threads(job)
    if threads is not None:
        import numba

        numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))


def warm(job: Job, both: bool = False) -> float:
    """Compile (or load from the cache) the fleet kernel on one robot for one tick -- on this thread, and
    with ``both`` on numba's thread pool too; returns the seconds."""
    import time

    from tablebot.fleet.run import Fleet
    from tablebot.machine import compile_table

    started = time.perf_counter()
    fleet = Fleet(job.table, compile_table(job.table), job.world, job.specs[:1], job.robot_params,
                  variants=job.variants)
    for threads in (False, True) if both else (False,):
        fleet.run(1, threads=threads)
    return time.perf_counter() - started


def warm_worker(job: Job, slot: str, share: int = 1,
                files: dict[str, dict[str, bytes]] | None = None) -> dict[str, Any]:
    """On a cluster worker: choose a cache folder of its own (``worker-SLOT`` in the user's numba cache
    for tablebot), unless ``NUMBA_CACHE_DIR`` was set for the worker or compiled code already loaded
    here; put the client's compiled code there (``files``, from :func:`tablebot.jit.cache_files`: a fresh
    worker then loads it instead of compiling); then load (or compile) the kernel once, before any chunk
    runs (concurrent compiles into one cache folder race: numba issues #4807, #10128). Its chunks then
    use 1/``share`` of the machine's cores (``share``: the workers on this machine)."""
    global _worker_threads
    _worker_threads = max(1, (os.cpu_count() or 1) // max(1, share))
    given = bool(os.environ.get("NUMBA_CACHE_DIR"))
    from tablebot import jit  # numba, and the default cache folder (per user, Python and sources)

    if not given and not any(name in sys.modules for name in COMPILED):
        import numba

        folder = os.path.join(jit.cache_dir(), f"worker-{slot}")
        os.environ[jit.ENV] = folder
        numba.config.CACHE_DIR = folder  # read when each compiled function is defined (on import, below)
    installed = jit.install_cache_files(files) if files else 0
    seconds = warm(job, both=_worker_threads > 1)
    import numba

    return {"host": socket.gethostname(), "pid": os.getpid(), "cache": numba.config.CACHE_DIR, "seconds": seconds,
            "threads": _worker_threads, "installed": installed}
