"""The unit of work of sweeps and tuning: a chunk of robots of one table in one world, run as one fleet
in whichever thread or process gets it (one of this process's threads, a Dask worker).

Nothing compiled is imported at the top: a Dask worker that unpickles :func:`run_job` must be able to
choose its numba cache folder (:func:`ready_worker`) before the first compiled module loads.
"""

from __future__ import annotations

import os
import sys
import threading
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

from tablebot.fleet.robots import RobotSpec, Variants

if TYPE_CHECKING:
    from tablebot.fleet.results import FleetSummary
    from tablebot.fleet.starts import Prepared
    from tablebot.machine import Machine
    from tablebot.sim.model.world import World
    from tablebot.table import Table
    from tablebot.tables import RobotTables

COMPILED = ("tablebot.sim.physics.step", "tablebot.sim.physics.kernel", "tablebot.engine_batch")
CALL_ROBOT_TICKS = 256_000  # robot-ticks per compiled call of a chunk (~0.1 s of one core)
MAX_BLOCK_TICKS = 4096  # each robot records this many ticks in scratch space per call (32 B a tick and column)
_worker_threads: int | None = None  # set by ready_worker: this worker's share of its machine's cores
cache_dir_given: bool | None = None  # whether the user set NUMBA_CACHE_DIR (told by fleet.worker, a Dask preload)
SHARED_KEPT = 8  # tables × worlds × robot layers whose compiled table and scenes a process keeps
_shared: OrderedDict[tuple[int, int, int], tuple[Any, ...]] = OrderedDict()
_shared_lock = threading.Lock()


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
    tables: RobotTables | None = None  # a robot of several tables: all of them (the main one is ``table``)


@dataclass(frozen=True)
class Common:
    """What jobs of one run share -- their table, world and robot layer -- sent to each cluster worker once
    (:func:`run_common`), not pickled into every chunk."""

    table: Table
    world: World
    robot_params: dict[str, Any]
    tables: RobotTables | None = None

    @staticmethod
    def of(job: Job) -> Common:
        return Common(job.table, job.world, job.robot_params, job.tables)

    def strip(self, job: Job) -> Job:
        """The job without what it shares (None in its place: put back by :meth:`fill`)."""
        return replace(job, table=None, world=None, robot_params=None, tables=None)  # type: ignore[arg-type]

    def fill(self, job: Job) -> Job:
        return replace(job, table=self.table, world=self.world, robot_params=self.robot_params, tables=self.tables)


def run_common(fn: Callable[[Job], tuple[Job, Any]], common: Common, job: Job) -> tuple[Job, Any]:
    """On a cluster worker: ``fn`` of the job with what it shares put back -- the same objects for every chunk
    on this worker, so :func:`shared` prepares its scenes once -- and the job returned without them."""
    done, result = fn(common.fill(job))
    return common.strip(done), result


class Stopped(Exception):
    """A chunk given up between two blocks because its run was stopped (Ctrl-C)."""


def run_job(job: Job, stop: threading.Event | None = None) -> tuple[Job, FleetSummary]:
    """Run the chunk as one fleet; returns the job (without its robots) and the fleet's summary. With
    ``stop``, the chunk is given up (:class:`Stopped`) at the first block after it is set."""
    from tablebot.fleet.run import Fleet

    def check(_ticks: int) -> None:
        if stop is not None and stop.is_set():
            raise Stopped

    threads = job_threads(job)
    if threads != 1:  # one thread: the calling thread alone, without numba's pool (not even started)
        use_threads(job)
    machine, prepared = shared(job)
    fleet = Fleet(
        job.table,
        machine,
        job.world,
        job.specs,
        job.robot_params,
        variants=job.variants,
        prepared=prepared,
        tables=job.tables,
    )
    fleet.run(job.ticks, progress=check, threads=False if threads == 1 else None, block_ticks=block_ticks(job))
    return replace(job, specs=[], variants=None), fleet.summary()


def shared(job: Job) -> tuple[Machine, Prepared]:
    """The job's compiled table and prepared scenes, made once per process for each table, world and robot
    layer (the same objects: a local sweep's chunks all hold its plan's, and a cluster worker's chunks get
    them as one shared piece of data, see :mod:`tablebot.fleet.backends`). Keyed by identity: an entry holds
    its objects, so no other object can take their ids while it is kept."""
    from tablebot.fleet.starts import Prepared
    from tablebot.machine import compile_table

    key = (id(job.table), id(job.world), id(job.robot_params))
    with _shared_lock:
        found = _shared.get(key)
        if found is None:
            found = _shared[key] = (job.table, job.world, job.robot_params, compile_table(job.table), Prepared())
            while len(_shared) > SHARED_KEPT:
                _shared.popitem(last=False)
        _shared.move_to_end(key)
    return found[3], found[4]


def preload(*functions: Any) -> int:
    """Load the machine code of compiled ``functions`` from numba's cache now: every overload the cache
    holds for this machine and these sources. Meant for a thread while the caller plans -- loading is mostly
    LLVM linking the code, which leaves the GIL -- instead of in the first chunk, while the other thread waits
    for numba's compiler lock. What the cache lacks is left to compile at its first call, as ever. Returns
    how many overloads it loaded (this uses numba's cache internals: another numba loads nothing here)."""
    from tablebot.jit import cached_signatures

    loaded = 0
    for function in functions:
        for signature in cached_signatures(function):  # none: the first call loads (or compiles) as before
            function.compile(signature)
            loaded += 1
    return loaded


def block_ticks(job: Job) -> int:
    """Ticks per compiled call of a chunk: about a tenth of a second of one core's work (BLOCK_TICKS at
    least), so a chunk on a thread comes back for the GIL (and to see a Ctrl-C) a few times, not every 256
    ticks; the whole chunk at once when that is little more."""
    from tablebot.fleet.run import BLOCK_TICKS

    ticks = max(BLOCK_TICKS, min(CALL_ROBOT_TICKS // max(1, len(job.specs)), MAX_BLOCK_TICKS))
    return job.ticks if job.ticks <= ticks * 5 // 4 else ticks


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

        # numba.config sets its settings at import time, unseen by mypy
        numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))  # type: ignore[attr-defined]


def warm(job: Job, both: bool = False) -> float:
    """Compile (or load from the cache) the fleet kernel on one robot for one tick -- on this thread, and
    with ``both`` on numba's thread pool too; returns the seconds."""
    import time

    from tablebot.fleet.run import Fleet

    started = time.perf_counter()
    machine, prepared = shared(job)
    fleet = Fleet(
        job.table,
        machine,
        job.world,
        job.specs[:1],
        job.robot_params,
        variants=job.variants,
        prepared=prepared,
        tables=job.tables,
    )
    for threads in (False, True) if both else (False,):
        fleet.run(1, threads=threads)
    return time.perf_counter() - started


def ready_worker(
    slot: str, share: int = 1, files: dict[str, dict[str, bytes]] | None = None, load: bool = True
) -> dict[str, Any]:
    """On a cluster worker, before it sees a job: choose a cache folder of its own (``worker-SLOT`` in the
    user's numba cache for tablebot) unless ``NUMBA_CACHE_DIR`` was set for the worker or compiled code is
    already loaded here, and import the compiled modules; put the client's compiled code in their folder
    (``files``, from :func:`tablebot.jit.cache_files`: a fresh worker then loads it instead of compiling);
    with ``load``, load the machine code a chunk runs (:func:`preload`). Needs no job, so the client sends it
    as soon as it is connected: first without files or loading (the imports, while the client itself still
    imports and plans), then with them. Its chunks use 1/``share`` of the machine's cores (``share``: the
    workers on this machine). Idempotent.

    numba's compiler is not readied: cached code loads without it (tablebot.jit), and readying it cost a
    fresh worker ~0.5 s of CPU (its typing and lowering rules, and scipy.linalg), taken from the chunks on a
    machine whose cores the workers share."""
    import socket
    import time

    global _worker_threads
    started = time.perf_counter()
    _worker_threads = max(1, (os.cpu_count() or 1) // max(1, share))
    given = bool(os.environ.get("NUMBA_CACHE_DIR")) if cache_dir_given is None else cache_dir_given
    from tablebot import jit  # numba, and the default cache folder (per user, Python and sources)

    if not given and not any(name in sys.modules for name in COMPILED):
        import numba

        folder = os.path.join(jit.cache_dir(), f"worker-{slot}")
        os.environ[jit.ENV] = folder
        # read when each compiled function is defined (on import, below); set at run time, unseen by mypy
        numba.config.CACHE_DIR = folder  # type: ignore[attr-defined]
    import numba

    import tablebot.fleet.run  # noqa: F401  (the fleet and every compiled module it calls: their cache folder is set)

    installed = jit.install_cache_files(files) if files else 0  # read by each function at its first load
    loaded = preload(*chunk_functions(_worker_threads)) if load else 0
    return {
        "host": socket.gethostname(),
        "pid": os.getpid(),
        "cache": numba.config.CACHE_DIR,  # type: ignore[attr-defined]  # a run-time numba setting
        "threads": _worker_threads,
        "installed": installed,
        "loaded": loaded,
        "ready_s": time.perf_counter() - started,
    }


def chunk_functions(threads: int | None) -> tuple[Any, ...]:
    """The compiled functions a chunk calls: the start check of a scene, its robots' streams seeded and first
    numbers drawn, their first readings, and the fleet loop on this thread alone or, with more ``threads``, on
    numba's pool too (small fleets still run on the calling thread)."""
    from tablebot.fleet.kernel import run_fleet, run_fleet_serial
    from tablebot.sim.physics import contacts, kernel, normals

    loops = (run_fleet_serial,) if threads == 1 else (run_fleet_serial, run_fleet)
    starting = (normals.seed_pcg64, normals.normal_rows, kernel.first_readings)
    return (contacts.body_corners, contacts.deepest_contact, *starting, *loops)


def warm_worker(
    job: Job, slot: str, share: int = 1, files: dict[str, dict[str, bytes]] | None = None
) -> dict[str, Any]:
    """On a cluster worker: :func:`ready_worker` (if it has not run), then load (or compile) the kernel
    once, before any chunk runs (concurrent compiles into one cache folder race: numba issues #4807,
    #10128)."""
    info = ready_worker(slot, share, files)
    return {**info, "seconds": warm(job, both=(_worker_threads or 1) > 1)}
