"""Where the chunks of a sweep or a tuning run go: this machine's cores (a thread per core in this process,
each running whole chunks) or a Dask cluster (each chunk one task). Both hand every finished chunk to a
callback as it comes back, so an interrupted run keeps what finished.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from tablebot.diagnostics import fail
from tablebot.fleet.cluster import SCHEDULER_ENV, check_address, connect, ready_cluster, submit_all, warm_cluster
from tablebot.fleet.work import Job, chunk_functions, preload, run_job
from tablebot.i18n import N_

__all__ = ["Done", "Runner", "choose"]

#: Called with each job and what the run's ``fn`` gave for it (by default run_job's FleetSummary).
Done = Callable[[Job, Any], None]


def choose(backend: str, scheduler: str | None) -> tuple[str, str | None]:
    """The backend and scheduler address to use: Dask when asked for, or when a scheduler is named (by
    --scheduler or DASK_SCHEDULER_ADDRESS) and --backend was left at its default."""
    address = scheduler or os.environ.get(SCHEDULER_ENV) or None
    if backend not in ("auto", "local", "dask"):
        raise fail(
            "--backend",
            N_("--backend {backend}: unknown backend", backend=backend),
            N_("use --backend local or --backend dask"),
        )
    if backend == "local" and scheduler:
        raise fail(
            "--scheduler",
            N_("--scheduler names a Dask scheduler, but --backend is local"),
            N_("drop --backend local (or use --backend dask)"),
        )
    if backend == "auto":
        backend = "dask" if address else "local"
    if backend == "dask" and not address:
        raise fail(
            "--backend",
            N_("--backend dask needs a scheduler to send the chunks to"),
            N_("give --scheduler tcp://HOST:8786 or set {env}", env=SCHEDULER_ENV),
        )
    return backend, address if backend == "dask" else None


class Runner:
    """A backend kept open over many batches of jobs (a tuning run sends one batch per generation):
    the local worker threads or the Dask client start, and warm up, once."""

    def __init__(self, backend: str = "local", address: str | None = None, workers: int | None = None) -> None:
        self.backend, self.address, self.workers = backend, address, workers
        self.pool: Any = None
        self.client: Any = None
        self.stop = threading.Event()  # set on Ctrl-C: local chunks end at their next block, unfinished
        self.info: dict[str, Any] = {"workers": 0}
        self._opening: threading.Thread | None = None  # connecting to the cluster (see start)
        self._lock, self._closed = threading.Lock(), False
        self._opened: dict[str, Any] = {}  # what the opening thread sent the workers, or the error it met
        self._imported = threading.Event()  # the caller's fleet modules are imported (see start)
        self._imported.set()
        self._dask_imported = threading.Event()  # the opening thread has imported Dask (or failed to)
        self._loading: threading.Thread | None = None  # loading this process's compiled code (see imported)

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
        return self._local_workers

    @property
    def _local_workers(self) -> int:
        """The threads a local run has: ``--workers``, else one per core."""
        return max(1, self.workers or os.cpu_count() or 1)

    def start(self, imported: bool = True) -> None:
        """Begin opening the backend while the caller still plans: for Dask, connect on a thread and send
        every worker the start-up that needs no job (:func:`~tablebot.fleet.work.ready_worker`: imports, then
        this process's compiled code, loaded there); :meth:`run` waits for it. A caller that has not imported
        the fleet's modules yet says so (``imported=False``) and calls :meth:`imported` when it has: the
        workers start importing meanwhile, and this process's compiled code is read only then (two threads
        importing the same modules at once could meet half-made ones)."""
        if not imported:
            self._imported.clear()
        if self.backend != "dask" or self.client is not None or self._opening is not None:
            return
        self._opening = threading.Thread(target=self._open, name="tablebot-dask-connect", daemon=True)
        self._opening.start()
        # Dask's own import (~0.5 s of Python) first, alone: the workers get their start-up that much sooner
        # than if it shared the GIL with the caller's imports; the connection itself then waits on the network.
        self._dask_imported.wait()
        if sys.modules.get("distributed") is not None:  # (without Dask, connecting says what to install)
            check_address(self.address or "")  # a mistyped address stops the command before it writes

    def load_compiled(self) -> None:
        """Locally, start loading this process's compiled code on a thread (:func:`~tablebot.fleet.work.preload`:
        mostly LLVM, which leaves the GIL) while the caller goes on importing and planning, instead of in the
        first chunks, the second thread waiting for numba's lock. The compiled modules are imported here, in the
        calling thread, so that thread never imports what the caller imports meanwhile. Called as early as
        the caller can (the sooner the thread starts, the more of its LLVM work runs beside the caller's Python);
        :meth:`imported` calls it when the caller has not. A cluster loads its workers' code instead."""
        if self.backend == "local" and self._loading is None:
            functions = chunk_functions(1 if self._local_workers > 1 else None)  # as _run_local runs them
            self._loading = threading.Thread(target=preload_quietly, args=functions, name="tablebot-load", daemon=True)
            self._loading.start()

    def imported(self) -> None:
        """The caller has imported the fleet (see :meth:`start`): a cluster's workers are sent this process's
        compiled code; locally, :meth:`load_compiled` if the caller has not called it yet."""
        self._imported.set()
        self.load_compiled()

    def _open(self) -> None:
        try:
            with contextlib.suppress(ImportError):  # connect says what to install
                import distributed  # noqa: F401
            self._dask_imported.set()
            client = connect(self.address or "")  # first: it says what to install when Dask is missing
            with self._lock:
                if self._closed:  # the caller gave up meanwhile (a mistake in its options, Ctrl-C)
                    client.close()
                    return
                self.client = client
            self._opened = ready_cluster(client, self._imported)
        except BaseException as exc:  # raised again in the caller's thread, by _connected
            self._opened = {"failed": exc}
        finally:
            self._dask_imported.set()

    def _connected(self) -> Any:
        """The Dask client, once :meth:`start`'s thread is through (its error raised here)."""
        self.start()
        assert self._opening is not None
        self._opening.join()
        if "failed" in self._opened:
            raise self._opened["failed"]
        return self.client

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
        """Stop the local threads or close the Dask client. A connection still being made is not waited
        for: its thread closes the client it gets (an unreachable scheduler takes its whole timeout)."""
        if self._loading is not None:  # a fraction of a second: not left loading while the process ends
            self._loading.join()
        self._imported.set()  # a connecting thread still waiting for the caller's imports goes on, and ends
        if self.pool is not None:
            if failed:
                self.stop.set()  # Ctrl-C: running chunks end within a block; what finished was handed over already
            self.pool.shutdown(wait=True, cancel_futures=True)
            self.pool = None
        with self._lock:
            self._closed = True
            client, self.client = self.client, None
        if client is not None:
            client.close()

    def _call(self, fn: Callable[..., tuple[Job, Any]], job: Job) -> tuple[Job, Any]:
        """``fn(job)``; the fleet's own run_job also stops at its next block when the run is stopped."""
        return fn(job, self.stop) if fn is run_job else fn(job)

    # --- this machine: a thread per core (``workers``), each running whole chunks single-threaded
    #
    # Threads, not processes: the compiled fleet loop releases the GIL, so two threads run two chunks on two
    # cores, and this process's compiled code serves both -- no worker processes to start, no Python, numpy and
    # numba to import again in each, no jobs and summaries to pickle across (seconds of a short sweep's time).

    def _run_local(self, jobs: Sequence[Job], done: Done, fn: Callable[[Any], tuple[Job, Any]]) -> None:
        workers = self._local_workers
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
        if not self.info.get("warm"):
            self.info = warm_cluster(self._connected(), jobs[0], self._opened)
        from distributed import as_completed

        client = self.client
        sent = submit_all(client, jobs, fn)
        try:
            for future in as_completed(list(sent), loop=client.loop):
                job, result = future.result()
                common = sent[future]
                done(common.fill(job) if common is not None else job, result)
        except BaseException:
            client.cancel(list(sent))
            raise


def preload_quietly(*functions: Any) -> None:
    """:func:`~tablebot.fleet.work.preload` compiled ``functions`` (any error left for the first call to meet and
    report, as it would have without this)."""
    with contextlib.suppress(Exception):
        preload(*functions)
