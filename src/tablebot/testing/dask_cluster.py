"""A real Dask cluster on loopback for tests and benchmarks: a scheduler and its workers as processes of their
own (``python -m distributed.cli.dask_scheduler`` / ``dask_worker``), stopped workers first."""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

#: Seconds the scheduler may take to say where it listens, and the workers (twice this) to join it.
START_S = 60.0


@dataclass
class Cluster:
    """A running cluster: where its scheduler listens, and its processes (the scheduler first)."""

    address: str
    procs: list[subprocess.Popen[bytes]]


@contextlib.contextmanager
def local_cluster(
    workers: Sequence[Sequence[str]], env: Mapping[str, str], worker_env: Mapping[str, str] | None = None
) -> Iterator[Cluster]:
    """A scheduler on 127.0.0.1 (a port the system picks) and one single-threaded worker per item of
    ``workers`` (its extra options, e.g. ``["--preload", "tablebot.fleet.worker"]``), all joined when the
    block starts. ``env``: the processes' environment (``worker_env``: the workers', when it differs)."""
    from distributed import Client

    with tempfile.TemporaryDirectory(prefix="tablebot-dask-") as folder:
        file = Path(folder) / "scheduler.json"
        procs = [_start("dask_scheduler", ["--host", "127.0.0.1", "--port", "0", "--scheduler-file", str(file)], env)]
        try:
            address = _address(file, procs[0])
            procs += [
                _start("dask_worker", [address, "--nthreads", "1", *options], worker_env or env) for options in workers
            ]
            with Client(address, timeout=f"{START_S:g}s") as client:
                client.wait_for_workers(len(workers), timeout=2 * START_S)
            yield Cluster(address, procs)
        finally:
            # the workers, then the scheduler: a worker that loses its scheduler first closes 8 s later
            for group in (procs[1:], procs[:1]):
                for proc in group:
                    proc.terminate()
                for proc in group:
                    proc.wait(timeout=30)


def _start(program: str, options: Sequence[str], env: Mapping[str, str]) -> subprocess.Popen[bytes]:
    return subprocess.Popen(
        [sys.executable, "-m", f"distributed.cli.{program}", "--no-dashboard", *options],
        env=dict(env),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )


def _address(file: Path, scheduler: subprocess.Popen[bytes]) -> str:
    """The address the scheduler writes into its scheduler file once it listens."""
    deadline = time.monotonic() + START_S
    while time.monotonic() < deadline and scheduler.poll() is None:
        with contextlib.suppress(FileNotFoundError, ValueError):  # not written yet, or not whole yet
            return str(json.loads(file.read_text())["address"])
        time.sleep(0.1)
    raise RuntimeError(f"the Dask scheduler did not start (exit code {scheduler.poll()})")
