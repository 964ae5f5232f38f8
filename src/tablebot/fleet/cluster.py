"""A Dask cluster as a sweep's or a tuning run's backend (:class:`tablebot.fleet.backends.Runner` drives it):
connecting to its scheduler with clear errors, readying every worker before the first chunk -- its imports
at once, then this process's compiled code to load -- and sending the chunks, what they share sent once.
"""

from __future__ import annotations

import os
import threading
from collections import defaultdict
from collections.abc import Callable, Sequence
from typing import Any

from tablebot.diagnostics import fail
from tablebot.fleet.work import Common, Job, ready_worker, run_common, warm, warm_worker
from tablebot.i18n import N_

SCHEDULER_ENV = "DASK_SCHEDULER_ADDRESS"
INSTALL_HINT = N_("install the cluster extra: pip install 'tablebot[cluster]' (Dask's distributed scheduler)")


def connect(address: str) -> Any:
    """A Dask client of the scheduler at ``address`` (a clear error when Dask is missing or unreachable)."""
    try:
        from distributed import Client
    except ImportError:
        raise fail("--backend", N_("--backend dask: Dask is not installed"), INSTALL_HINT) from None
    check_address(address)
    try:
        return Client(address, timeout="15s", set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise fail(
            "--scheduler",
            N_("cannot reach the Dask scheduler at {address}: {reason}", address=address, reason=str(exc)),
            N_("start one with `dask scheduler` and `dask worker ADDRESS`, or check the address"),
        ) from None
    except TypeError as exc:  # Dask's words for a tls:// address without its TLS settings
        raise fail(
            "--scheduler",
            N_("cannot connect to the Dask scheduler at {address}: {reason}", address=address, reason=str(exc)),
            N_(
                "give Dask's TLS settings (distributed.comm.tls.ca-file, .client.cert and .client.key in its "
                "configuration), or use a tcp:// address"
            ),
        ) from None


def check_address(address: str) -> None:
    """Refuse an address Dask cannot parse before a client is made of it: Client raised a ValueError (an
    internal error here), and the half-made client then printed a traceback of its own as the process ended."""
    from distributed.comm.addressing import get_address_host_port, parse_address
    from distributed.comm.registry import get_backend

    where = SCHEDULER_ENV if address == os.environ.get(SCHEDULER_ENV) else "--scheduler"
    try:
        scheme, _ = parse_address(address)
        get_backend(scheme)  # a scheme Dask knows
        if scheme in ("tcp", "tls", "ws", "wss"):  # the network schemes: a host and a port
            _, port = get_address_host_port(address)
            if not 0 < port < 65536:
                raise ValueError(f"port {port} is not from 1 to 65535")
    except ValueError as exc:
        raise fail(
            where,
            N_(
                "{where} {address!r} is not a Dask scheduler's address: {reason}",
                where=where,
                address=address,
                reason=str(exc),
            ),
            N_("write tcp://HOST:PORT, e.g. tcp://127.0.0.1:8786 (what `dask scheduler` prints)"),
        ) from None


def submit_all(client: Any, jobs: Sequence[Job], fn: Callable[[Any], tuple[Job, Any]]) -> dict[Any, Common | None]:
    """A task per job; jobs that share their table, world and robot layer (a sweep's chunks of one world)
    get them from one piece of data sent to every worker first (:func:`~tablebot.fleet.work.run_common`):
    each chunk is then a few kilobytes of seeds, not its table and world again, and a worker prepares their
    scenes once. Returns each task's future and what it shares (None: the job went whole)."""
    groups: dict[tuple[int, int, int], list[Job]] = defaultdict(list)
    for job in jobs:
        groups[id(job.table), id(job.world), id(job.robot_params)].append(job)
    sent: dict[Any, Common | None] = {}
    for group in groups.values():
        if len(group) == 1:
            sent[client.submit(fn, group[0], pure=False)] = None
            continue
        common = Common.of(group[0])
        data = client.scatter(common, broadcast=True, hash=False)
        for job in group:
            sent[client.submit(run_common, fn, data, common.strip(job), pure=False)] = common
    return sent


def slots(client: Any) -> list[tuple[str, str, int]]:
    """Every worker's address, its cache slot (named by its host and its rank there) and how many workers
    share its host."""
    workers = client.scheduler_info(n_workers=-1)["workers"]
    by_host: dict[str, list[str]] = defaultdict(list)
    for address, worker in sorted(workers.items()):
        by_host[worker.get("host", address)].append(address)
    return [
        (address, f"{host}-{rank}".replace(":", "_").replace("/", "_"), len(addresses))
        for host, addresses in by_host.items()
        for rank, address in enumerate(addresses)
    ]


def compiled_files() -> dict[str, dict[str, bytes]] | None:
    """This process's compiled fleet code (both kernels: a worker alone on its machine runs chunks on all
    its cores), read from the cache without loading it; None if it is not compiled yet."""
    from tablebot import jit
    from tablebot.fleet.kernel import run_fleet, run_fleet_serial

    return jit.cache_files() if jit.compiled(run_fleet, run_fleet_serial) else None


def ready_cluster(client: Any, imported: threading.Event | None = None) -> dict[str, Any]:
    """Send every worker :func:`~tablebot.fleet.work.ready_worker` (pinned to it): its imports at once, then,
    once this process has imported the fleet (``imported``), its compiled code to load, if it has any yet.
    Returns the files sent (a future held by every worker), the workers and the tasks, not waited for: the
    chunks wait for :func:`warm_cluster`."""
    places = slots(client)
    futures = send_ready(client, places, None)
    if imported is not None:
        imported.wait()
    files = compiled_files()
    scattered = client.scatter(files, broadcast=True, hash=False) if files else None
    if scattered is not None:
        futures += send_ready(client, places, scattered)
    return {"files": scattered, "ready": futures, "places": {address for address, _, _ in places}}


def send_ready(client: Any, places: Sequence[tuple[str, str, int]], files: Any) -> list[Any]:
    """:func:`~tablebot.fleet.work.ready_worker` to each worker of ``places``, pinned to it: with the compiled
    code ``files`` (scattered) to load, or, with None, its imports alone."""
    load, step = (False, "import") if files is None else (True, "ready")
    return [
        client.submit(
            ready_worker,
            slot,
            share,
            files,
            load,
            workers=[address],
            allow_other_workers=False,
            pure=False,
            key=f"tablebot-{step}-{slot}",
        )
        for address, slot, share in places
    ]


def warm_cluster(client: Any, job: Job, opened: dict[str, Any] | None = None) -> dict[str, Any]:
    """Every worker ready before the first chunk: its compiled code loaded (:func:`ready_cluster`'s tasks,
    and the same for a worker that joined since); or, if this process had no compiled code to send, compiled
    here once on ``job`` and sent with a warm-up on it (pinned to each worker)."""
    opened = opened or {}
    places = slots(client)
    if not places:
        raise fail("--scheduler", N_("the Dask scheduler has no workers"), N_("start some with `dask worker ADDRESS`"))
    files = opened.get("files")
    if files is not None:
        futures = send_ready(client, [p for p in places if p[0] not in opened.get("places", ())], files)
    else:  # nothing compiled to send early: compile here once, rather than on every worker
        from tablebot import jit

        warm(job, both=True)
        files = client.scatter(jit.cache_files(), broadcast=True, hash=False)
        futures = [
            client.submit(
                warm_worker,
                job,
                slot,
                share,
                files,
                workers=[address],
                allow_other_workers=False,
                pure=False,
                key=f"tablebot-warm-{slot}",
            )
            for address, slot, share in places
        ]
    try:
        ready = client.gather(opened.get("ready", []))
        warmed = client.gather(futures)
    except Exception as exc:  # a scheduler or worker without tablebot (or another version of it)
        raise fail(
            "--scheduler",
            N_(
                "the Dask cluster could not run tablebot's fleet: {kind}: {reason}",
                kind=type(exc).__name__,
                reason=str(exc),
            ),
            N_("install the same tablebot (and Python) on the scheduler and every worker"),
        ) from None
    return {"workers": len(places), "ready": ready, "warm": warmed}
