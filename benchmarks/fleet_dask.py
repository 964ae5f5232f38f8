"""The Dask figures of benchmarks/fleet.py: the 10,000-robot sweep through ``--scheduler`` to a cluster of 2
single-threaded worker processes started for it with an empty cache (*fresh*: they are sent this machine's compiled
code), then again (*warm*), as speed ratios to the local sweep of the same repeat (target: fresh >= 0.8x); then
the same with workers started with tablebot's preload (``--preload tablebot.fleet.worker``)."""

from __future__ import annotations

import contextlib
import statistics
import tempfile

from fleet_sweep import CPU_S, sweep_process, verdict
from tablebot.testing.dask_cluster import local_cluster
from tablebot.testing.processes import child_env

TARGET_FRESH = 0.8  # a fresh Dask cluster's speed as a share of the local run's


# --------------------------------------------------------------


class FreshCluster:
    """A Dask scheduler and 2 single-threaded workers on loopback, the workers with an empty cache folder
    (as on machines that never ran tablebot); with ``preload``, started with tablebot's preload
    (``--preload tablebot.fleet.worker``: numba imported as the worker starts, no compiled code)."""

    def __init__(self, preload: bool = False) -> None:
        self.preload = preload

    def __enter__(self) -> str:
        self.stack = contextlib.ExitStack()
        home = self.stack.enter_context(tempfile.TemporaryDirectory())
        options = ["--preload", "tablebot.fleet.worker"] if self.preload else []
        cluster = self.stack.enter_context(
            local_cluster([options, options], child_env(), child_env(NUMBA_CACHE_DIR=None, XDG_CACHE_HOME=home))
        )
        self.procs = cluster.procs
        return cluster.address

    def cpu(self) -> float:
        """CPU seconds (user + system) so far of the scheduler and the workers (their nannies' children too)."""
        import psutil

        total = 0.0
        for proc in self.procs:
            with contextlib.suppress(psutil.Error):
                parent = psutil.Process(proc.pid)
                total += sum(sum(p.cpu_times()[:2]) for p in [parent, *parent.children(recursive=True)])
        return total

    def __exit__(self, *exc: object) -> None:
        self.stack.close()


def dask_ratios(
    robots: int, seconds: float, repeat: int, preload: bool = False
) -> tuple[list[float], list[float], list[float], dict[str, list[float]]]:
    """Per repeat: local sweep seconds, then fresh and warm Dask sweep seconds (a new cluster per repeat, its
    workers started with tablebot's preload or not); and the CPU seconds of each (for Dask: the client's and
    the cluster's processes' together)."""
    local: list[float] = []
    fresh: list[float] = []
    warm: list[float] = []
    cpu: dict[str, list[float]] = {"local": [], "fresh": [], "warm": []}
    for _ in range(repeat):
        local.append(sweep_process(robots, seconds))
        cpu["local"].append(CPU_S[-1])
        cluster = FreshCluster(preload)
        with cluster as address:
            for walls, name in ((fresh, "fresh"), (warm, "warm")):
                before = cluster.cpu()
                walls.append(sweep_process(robots, seconds, "--scheduler", address))
                cpu[name].append(CPU_S[-1] + cluster.cpu() - before)
    return local, fresh, warm, cpu


def dask_figures(robots: int, seconds: float, repeat: int) -> int:
    """Print the Dask figures; returns the targets missed."""
    med = statistics.median
    missed = 0
    local, fresh, warm, cpus = dask_ratios(robots, seconds, repeat)
    f_ratio = med(a / b for a, b in zip(local, fresh, strict=True))
    w_ratio = med(a / b for a, b in zip(local, warm, strict=True))
    ok = f_ratio >= TARGET_FRESH
    missed += not ok
    print(
        f"Dask, 2 single-threaded workers: local {med(local):.2f} s, fresh cluster {med(fresh):.2f} s, "
        f"warm {med(warm):.2f} s (whole sweep processes; CPU s: local {med(cpus['local']):.2f}, fresh "
        f"{med(cpus['fresh']):.2f}, warm {med(cpus['warm']):.2f}, the cluster's processes included)"
    )
    print(
        f"  fresh/local speed {f_ratio:.2f}x   target >= {TARGET_FRESH}x  {verdict(ok)};  warm/local speed "
        f"{w_ratio:.2f}x"
    )
    local, fresh, warm, cpus = dask_ratios(robots, seconds, repeat, preload=True)
    print(
        f"  workers started with --preload tablebot.fleet.worker: local {med(local):.2f} s, fresh "
        f"{med(fresh):.2f} s ({med(a / b for a, b in zip(local, fresh, strict=True)):.2f}x), warm "
        f"{med(warm):.2f} s ({med(a / b for a, b in zip(local, warm, strict=True)):.2f}x); CPU s: local "
        f"{med(cpus['local']):.2f}, fresh {med(cpus['fresh']):.2f}, warm {med(cpus['warm']):.2f}"
    )
    return missed
