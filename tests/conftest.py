"""The test session under pytest-xdist: numba's kernels compiled once before the workers start, each worker
given a numba cache folder of its own seeded from that one, and the tests that measure the wall clock kept
out of the parallel pass.

Two processes compiling into one numba cache folder at once race (numba issues #4807 and #10128: a
half-written cache file can crash the reader), and two workers compiling the same kernels would
also spend the same half minute twice. So the main pytest process runs ``tests/warm_kernels.py``
into the shared folder first; each worker then copies it into a folder of its own, where whatever a
test compiles that the warm-up did not reach stays that worker's. Without ``-n`` nothing changes:
the one process compiles on demand, as before.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = "TABLEBOT_TEST_NUMBA_SHARED"  # the warmed folder, handed from the main process to its workers

#: Modules whose tests hold a controller, a link or a page to the wall clock (10 ms ticks, replies due within
#: 50 ms, a tick that must come late or not): marked ``realtime``. `make test` runs them in a pass of their
#: own after the parallel one, alone on the machine as they were written for.
REALTIME = {"test_txt_robot", "test_pace", "test_roboif", "test_robotx", "test_run_serial", "test_serial_wiring",
            "test_txt_link", "test_txt_wiring", "test_loop", "test_studio_live", "test_txt4_program",
            "test_txt4_softxt", "test_txt4_upload", "test_rules"}
#: Modules that drive Chromium: one browser at a time (one xdist worker), beside the other worker's tests.
BROWSER = {"test_studio_browser", "test_studio_attacks"}
_gone = sorted(m for m in REALTIME | BROWSER if not (ROOT / "tests" / f"{m}.py").exists())
if _gone:  # a renamed module would silently join the parallel pass
    raise pytest.UsageError(f"tests/conftest.py names test modules that do not exist: {', '.join(_gone)}")


def _parallel(config: pytest.Config) -> bool:
    return bool(getattr(config.option, "numprocesses", None)) and getattr(config.option, "dist", "no") != "no"


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session: pytest.Session) -> None:
    """In the main process of a parallel run, before xdist starts its workers: warm the shared cache."""
    config = session.config
    if hasattr(config, "workerinput") or not _parallel(config):
        return
    from tablebot import jit  # sets NUMBA_CACHE_DIR (unless given): the folder every run of tablebot uses

    shared = jit.cache_dir()
    started = time.monotonic()
    env = {**os.environ, "NUMBA_CACHE_DIR": shared}
    # Two processes, one per core, that write disjoint cache files: the fleet's loop calls the simulator's
    # (so those two go one after the other), pyribs' archive shares nothing with them.
    parts = [subprocess.Popen([sys.executable, str(ROOT / "tests" / "warm_kernels.py"), *names], env=env, cwd=ROOT,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
             for names in (["sim", "fleet"], ["archive"])]
    errors = [err for proc in parts for err in [proc.communicate()[1]] if proc.returncode != 0]
    said = f"numba kernels warmed in {shared} in {time.monotonic() - started:.0f} s"
    if errors:  # the tests that run the kernels will fail with the real error; say it here too
        said += ", but the warm-up failed:\n" + "\n".join(err[-3000:] for err in errors)
    config.get_terminal_writer().line(said)  # type: ignore[attr-defined]
    os.environ[SHARED] = shared  # the workers start after this hook, with this environment


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    """`-m realtime` (the serial pass) does not import the other ninety modules only to deselect them."""
    if config.option.markexpr == "realtime" and collection_path.suffix == ".py":
        return collection_path.stem.startswith("test_") and collection_path.stem not in REALTIME
    return None


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        module = item.path.stem
        if module in REALTIME:
            item.add_marker(pytest.mark.realtime)
        if module in BROWSER:
            item.add_marker(pytest.mark.xdist_group("browser"))


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "realtime: holds something to the wall clock; `make test` runs it in a "
                                       "serial pass of its own (tests/conftest.py, REALTIME)")
    _own_numba_cache(config)


def _own_numba_cache(config: pytest.Config) -> None:
    """In an xdist worker: a numba cache folder of its own, a copy of the warmed one, set before any
    tablebot module is imported (``tablebot.jit`` reads ``NUMBA_CACHE_DIR`` once, at import)."""
    shared = os.environ.get(SHARED)
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if not (shared and worker):
        return
    own = Path(tempfile.mkdtemp(prefix=f"tablebot-numba-{worker}-"))
    if Path(shared).is_dir():
        shutil.copytree(shared, own, dirs_exist_ok=True, ignore=shutil.ignore_patterns("worker-*"))
    os.environ["NUMBA_CACHE_DIR"] = str(own)
    config.add_cleanup(lambda: shutil.rmtree(own, ignore_errors=True))
