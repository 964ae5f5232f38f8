"""The test session under pytest-xdist: numba's kernels compiled once while the first tests run, each worker
given a numba cache folder of its own seeded from that one, and the tests that measure the wall clock kept
out of the parallel pass.

Two processes compiling into one numba cache folder at once race (numba issues #4807 and #10128: a
half-written cache file can crash the reader), and two workers compiling the same kernels would
also spend the same minute twice. So the main pytest process starts ``tests/warm_kernels.py`` into the
shared folder and, while it compiles (about a minute and a half on two cores, one of them), the workers run
the modules that need no kernel (marked ``kernel_free``, run first); a worker's first other test waits for the warm-up
and copies the shared folder into the worker's own, where whatever a test compiles that the warm-up did not
reach stays that worker's. Without ``-n`` nothing changes: the one process compiles on demand, as before.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = "TABLEBOT_TEST_NUMBA_SHARED"  # the warmed folder, handed from the main process to its workers
WARMED = "TABLEBOT_TEST_NUMBA_WARMED"  # a file the main process writes when the warm-up has ended: "ok" or its errors

#: The folders of tests/, which mirror the packages of src/tablebot (tests/sim/ tests tablebot/sim/, and so on;
#: tests of top-level modules and the shared helpers stay in tests/). A test module may import a helper or a
#: fixture from another folder's module by its name (``from test_sim_helpers import scene_of``), as when they
#: all stood in one folder: pytest puts only a module's own folder on sys.path, so every folder goes there now.
FOLDERS = sorted({p.parent for p in (ROOT / "tests").glob("*/test_*.py")})
for _folder in FOLDERS:
    if str(_folder) not in sys.path:
        sys.path.insert(1, str(_folder))

#: The studio modules' shared fixtures (a module's Chromium, its screenshot folder, its studio), in
#: tests/web/studio_fixtures.py: a plugin rather than a tests/web/conftest.py, whose module name "conftest"
#: mypy would take for a second tests/conftest.py. A module's own fixture of the same name wins over them.
pytest_plugins = ["studio_fixtures"]

#: The markers, declared in the modules they apply to (``pytestmark = [pytest.mark.realtime]``):
MARKERS = {
    "realtime": (
        "holds a controller, a link or a page to the wall clock (10 ms ticks, replies due within 50 ms, a "
        "tick that must come late or not); `make test` runs these in a pass of their own after the parallel "
        "one, two at a time: they mostly sleep, and nothing CPU-bound runs beside them"
    ),
    "browser": "drives Chromium: one browser at a time (one xdist worker), beside the other worker's tests",
    "kernel_free": (
        "runs no simulator kernel (measured: run alone on an empty numba cache, it compiles nothing, or "
        "only a small function of its own in seconds); these run first, while the kernels compile. A "
        "module wrongly marked is not wrong, only slow (it compiles the kernels itself), and the "
        "session's summary names it"
    ),
}
#: Kernels big enough that compiling them in a kernel-free module means the module is not one (see MARKERS).
BIG_KERNELS = ("kernel.run_ticks", "kernel.move", "kernel.sense", "kernel.run_fleet")


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int | None:
    """``-n auto`` (make test): a worker more than the cores. A browser test waits on Chromium's processes and a
    command's test on its child, so two workers on two cores left them part idle: the studio's tests took 155 s
    with 2 workers and 128 s with 3 (tests/web, one run each). ``PYTEST_XDIST_AUTO_NUM_WORKERS`` still decides
    when set (xdist's own hook reads it)."""
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return cores + 1


def _parallel(config: pytest.Config) -> bool:
    return bool(getattr(config.option, "numprocesses", None)) and getattr(config.option, "dist", "no") != "no"


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session: pytest.Session) -> None:
    """In the main process of a parallel run, before xdist starts its workers: start warming the shared cache."""
    config = session.config
    if hasattr(config, "workerinput") or not _parallel(config):
        return
    from tablebot import jit  # sets NUMBA_CACHE_DIR (unless given): the folder every run of tablebot uses

    shared = jit.cache_dir()
    marker = Path(tempfile.mkdtemp(prefix="tablebot-numba-warmed-")) / "warmed"
    config.stash[_WARMUP] = _WarmUp(shared, marker)
    os.environ[SHARED], os.environ[WARMED] = shared, str(marker)  # the workers start after this hook


class _WarmUp:
    """The kernels compiled into ``shared`` by two processes, one per core, of about a minute each (CPU): the
    tick-by-tick robot (physics.advance_called, which every robot's first reading then loads: ~26 CPU-s), the env
    and the batch engine, the robot's loop (~39), the fleet's, which calls it (~4); beside them the loops of a robot
    of several tables (~65, the longest single part: it compiles the physics again for itself) and pyribs' archive
    (~6). The halves are balanced because the first to end leaves a core idle while every test worker waits for
    the other. A function both reach may be compiled by both: numba writes a cache file whole, by renaming it
    into place; each part skips a robot's first reading while the other compiles it. A thread writes ``marker``
    when both have ended, "ok" or their errors."""

    def __init__(self, shared: str, marker: Path) -> None:
        self.shared, self.marker, self.started = shared, marker, time.monotonic()
        self.seconds: float | None = None
        env = {**os.environ, "NUMBA_CACHE_DIR": shared}
        self.parts = [
            subprocess.Popen(
                [sys.executable, str(ROOT / "tests" / "warm_kernels.py"), *names],
                env=env,
                cwd=ROOT,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                text=True,
            )
            for names in (["tick", "loop", "fleet"], ["several", "archive"])
        ]
        self.thread = threading.Thread(target=self._wait, name="numba warm-up", daemon=True)
        self.thread.start()

    def _wait(self) -> None:
        errors = [err for proc in self.parts for err in [proc.communicate()[1]] if proc.returncode != 0]
        self.seconds = time.monotonic() - self.started
        temporary = self.marker.with_suffix(".tmp")
        temporary.write_text("\n".join(err[-3000:] for err in errors) if errors else "ok", encoding="utf-8")
        temporary.replace(self.marker)

    def said(self) -> str:
        self.thread.join()
        text = self.marker.read_text(encoding="utf-8")
        shutil.rmtree(self.marker.parent, ignore_errors=True)
        said = f"numba kernels warmed in {self.shared} in {self.seconds:.0f} s, while the kernel-free tests ran"
        # the tests that run the kernels fail with the real error; say it here too
        return said if text == "ok" else f"{said}, but the warm-up failed:\n{text}"


_WARMUP = pytest.StashKey[_WarmUp]()


def pytest_terminal_summary(terminalreporter: Any, config: pytest.Config) -> None:
    if _WARMUP in config.stash:
        terminalreporter.write_line(config.stash[_WARMUP].said())
    slow = config.stash.get(_NOT_FREE, None)
    if slow:
        terminalreporter.write_line(
            "modules marked kernel_free compiled a simulator kernel "
            f"before the warm-up ended (take them out): {', '.join(sorted(slow))}"
        )


_NOT_FREE = pytest.StashKey[set[str]]()


def pytest_testnodedown(node: Any, error: Any) -> None:
    """A worker's report of kernel-free modules that were not (see _Worker.check), gathered for the summary."""
    found = getattr(node, "workeroutput", {}).get("not_kernel_free", [])
    node.config.stash.setdefault(_NOT_FREE, set()).update(found)


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    """`-m realtime` (the serial pass) does not import the other ninety modules only to deselect them."""
    if config.option.markexpr == "realtime" and collection_path.suffix == ".py":
        # the module's text, not the module: importing it is what this saves
        return collection_path.stem.startswith("test_") and not _marked(collection_path, "realtime")
    return None


def _marked(path: Path, marker: str) -> bool:
    """Whether a test module declares ``marker`` for the whole module (its ``pytestmark``, on one line or more)."""
    found = re.search(r"^pytestmark\s*=.*?(?=^\S|\Z)", path.read_text(encoding="utf-8"), re.M | re.S)
    return found is not None and f"pytest.mark.{marker}" in found.group(0)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    items.sort(key=lambda item: item.get_closest_marker("kernel_free") is None)  # stable: each part keeps its order
    for item in items:
        if item.get_closest_marker("browser"):
            item.add_marker(pytest.mark.xdist_group("browser"))


def _hear_ctrl_c() -> None:
    """Python's own Ctrl-C handler where pytest was started with SIGINT ignored (a background job of a
    non-interactive shell, ``make test &`` or ``nohup make test &``, as a CI runner may start it): every process
    the tests start would inherit the ignore, and the tests that interrupt a command with SIGINT would see it
    run on to the end (16 of them failed so). A handler set here is reset to the default by exec: the workers
    and the commands they start get Python's handler, as from a terminal."""
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_configure(config: pytest.Config) -> None:
    _hear_ctrl_c()
    for name, meaning in MARKERS.items():
        config.addinivalue_line("markers", f"{name}: {meaning}")
    _own_numba_cache(config)


def _own_numba_cache(config: pytest.Config) -> None:
    """In an xdist worker: a numba cache folder of its own, set before any tablebot module is imported
    (``tablebot.jit`` reads ``NUMBA_CACHE_DIR`` once, at import), filled from the warmed one before the worker's
    first test that is not kernel-free (:class:`_Worker`)."""
    shared, marker = os.environ.get(SHARED), os.environ.get(WARMED)
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if not (shared and marker and worker):
        return
    own = Path(tempfile.mkdtemp(prefix=f"tablebot-numba-{worker}-"))
    os.environ["NUMBA_CACHE_DIR"] = str(own)
    config.pluginmanager.register(_Worker(config, Path(shared), Path(marker), own), "tablebot-numba-worker")
    config.add_cleanup(lambda: shutil.rmtree(own, ignore_errors=True))


class _Worker:
    """A worker's side of the warm-up: before its first test not marked kernel_free, wait for the warm-up to end
    and copy the warmed cache into the worker's own folder; until then, note a kernel-free module that compiled
    a simulator kernel itself (it is not kernel-free: the main process's summary names it)."""

    WAIT_S = 1800  # a warm-up that never ends: the tests go on and compile what they need themselves

    def __init__(self, config: pytest.Config, shared: Path, marker: Path, own: Path) -> None:
        self.config, self.shared, self.marker, self.own = config, shared, marker, own
        self.ready = False
        self.not_free: set[str] = set()

    @pytest.hookimpl(tryfirst=True)
    def pytest_runtest_setup(self, item: pytest.Item) -> None:
        if self.ready or item.get_closest_marker("kernel_free"):
            return
        deadline = time.monotonic() + self.WAIT_S
        while not self.marker.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        self.ready = True
        _copy_new_files(self.shared, self.own)

    def pytest_runtest_teardown(self, item: pytest.Item) -> None:
        if not self.ready and any(next(self.own.rglob(f"{name}-*.nbi"), None) for name in BIG_KERNELS):
            self.not_free.add(item.path.stem)

    def pytest_sessionfinish(self) -> None:
        self.config.workeroutput["not_kernel_free"] = sorted(self.not_free)  # type: ignore[attr-defined]


def _copy_new_files(source: Path, target: Path) -> None:
    """Each file of ``source`` that ``target`` lacks, under a temporary name renamed into place (an index after the
    data files it names), so a test's process loading meanwhile sees a whole function or none; a function this
    worker compiled itself keeps its own files."""
    if not source.is_dir():
        return
    files = sorted(
        (
            p
            for p in source.rglob("*")
            if p.is_file() and not any(part.startswith("worker-") for part in p.relative_to(source).parts)
        ),
        key=lambda p: p.suffix == ".nbi",
    )
    for path in files:
        destination = target / path.relative_to(source)
        if destination.exists() or (path.suffix == ".nbc" and _indexed(destination)):
            continue
        destination.parent.mkdir(parents=True, exist_ok=True)
        temporary = destination.with_name(destination.name + ".copying")
        shutil.copyfile(path, temporary)
        temporary.replace(destination)


def _indexed(data_file: Path) -> bool:
    """Whether this worker has its own index for the function a data file (NAME-LINE.pyXY.N.nbc) belongs to."""
    return data_file.with_name(data_file.name.rsplit(".", 2)[0] + ".nbi").exists()
