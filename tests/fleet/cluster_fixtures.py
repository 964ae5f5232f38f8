"""The Dask cluster the cluster tests share (a plugin tests/conftest.py names): a real scheduler and two
single-threaded workers on this machine (separate processes), one of them started with tablebot's preload
(tablebot.fleet.worker), one plain.

One for the whole test process, not one per module: a scheduler and two workers cost ~6 CPU-s to start, and four
modules each started theirs for a test or two. tests/conftest.py puts every test that asks for it into the xdist
group "dask", so one worker runs them all on one cluster. Each such test compares what the cluster gives with
what this machine gives, byte for byte, so what an earlier test left on the workers (their compiled code
loaded) cannot make a later one pass or fail."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest

from tablebot.testing.dask_cluster import local_cluster

SRC = Path(__file__).resolve().parents[2] / "src"


def cluster_env() -> dict[str, str]:
    """This process's environment, with the checkout's sources first on the workers' path."""
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])}


@pytest.fixture(scope="session")
def dask_cluster() -> Iterator[str]:
    pytest.importorskip("distributed", reason="the Dask backend needs the cluster extra (the dev extra has it)")
    with local_cluster([[], ["--preload", "tablebot.fleet.worker"]], cluster_env()) as cluster:
        yield cluster.address
