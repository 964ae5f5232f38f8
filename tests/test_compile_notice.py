"""A first run compiles tablebot's kernels for tens of seconds: tablebot.jit.Compiling talks all that while
(what, how long it usually takes, the seconds so far) instead of a progress bar standing at 0 %, and says
nothing at all once the code is in numba's cache. tablebot.talk.Talking, which it uses, also covers a first
start's imports, and says nothing for a step that ends within its delay."""

from __future__ import annotations

import importlib.util
import io
import sys
import time
from pathlib import Path
from types import ModuleType

from tablebot.jit import USUALLY, Compiling
from tablebot.loop import TickBlock
from tablebot.talk import SPINNER, Talking

KERNEL = """
from tablebot.jit import njit


@njit
def twice(x):
    return 2 * x
"""


def fresh_kernel(folder: Path, name: str) -> ModuleType:
    """A module with one compiled function that no cache has seen (a file of its own: numba caches by file)."""
    path = folder / f"{name}.py"
    path.write_text(KERNEL, encoding="utf-8")
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def test_a_compile_is_announced_then_talked_through_then_timed_in_a_log(tmp_path: Path) -> None:
    kernel = fresh_kernel(tmp_path, f"notice_kernel_{time.monotonic_ns()}")
    log = io.StringIO()
    notice = Compiling("the doubler", kernel.twice, every_s=0.05, stream=log)
    assert notice.active
    time.sleep(0.3)
    assert kernel.twice(21) == 42  # compiled (and cached) here
    notice.done()
    notice.done()  # only the first says anything
    lines = log.getvalue().splitlines()
    assert lines[0] == f"compiling the doubler for this machine (first run only, {USUALLY}; later runs start at once)"
    still = "  still compiling the doubler for this machine: "
    assert len(lines) >= 4 and all(line.startswith(still) for line in lines[1:-1])
    assert lines[-1].startswith("compiled the doubler in ") and "later runs start at once" in lines[-1]
    # the function is in the cache now: a later run is told nothing
    quiet = io.StringIO()
    later = Compiling("the doubler", kernel.twice, every_s=0.01, stream=quiet)
    time.sleep(0.05)
    later.done()
    assert not later.active and quiet.getvalue() == ""


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_on_a_terminal_one_line_is_redrawn_with_a_spinner_and_the_seconds(tmp_path: Path) -> None:
    kernel = fresh_kernel(tmp_path, f"notice_kernel_{time.monotonic_ns()}")
    screen = Terminal()
    notice = Compiling("the doubler", kernel.twice, stream=screen)
    time.sleep(0.35)
    notice.done(finished=False)  # cut short (an error, Ctrl-C): the line is cleared, nothing claimed
    shown = screen.getvalue()
    frames = [frame for frame in shown.split("\r") if frame]
    assert "\n" not in shown and len(frames) >= 3
    assert frames[0].startswith(f"{SPINNER[0]} compiling the doubler for this machine: 0 s (first run only")
    assert frames[-1] == "\x1b[K"


def test_a_step_that_ends_within_the_delay_says_nothing_and_a_longer_one_is_talked_through() -> None:
    quick = io.StringIO()
    Talking("loading", "why", "loaded in {s} s", every_s=0.05, delay_s=0.5, stream=quick).done()
    assert quick.getvalue() == ""
    slow = io.StringIO()
    talking = Talking("loading", "why", "loaded in {s} s", every_s=0.05, delay_s=0.1, stream=slow)
    time.sleep(0.4)
    talking.done()
    lines = slow.getvalue().splitlines()
    assert lines[0] == "loading (why)" and lines[1].startswith("  still loading: ") and lines[-1] == "loaded in 0 s"


def test_a_sim_refused_before_its_run_leaves_no_notice_talking(tmp_path: Path) -> None:
    import threading

    from typer.testing import CliRunner

    from tablebot.cli import app

    blocker = tmp_path / "a file"
    blocker.write_text("not a folder", encoding="utf-8")
    example = Path(__file__).resolve().parents[1] / "examples" / "bumberbot"
    result = CliRunner().invoke(app, ["sim", str(example), "--out", str(blocker), "--seconds", "1"])
    assert result.exit_code == 2, result.output
    assert not [t for t in threading.enumerate() if t.name == "talking"]


FIRST_SHORT_RUN = """
import pickle, sys
from pathlib import Path
from tablebot import jit
jit.install_cache_files(pickle.loads(Path(sys.argv[1]).read_bytes()))
sys.argv = ["tablebot", "sim", sys.argv[2], "--seconds", "120", "--no-plots", "-q", "--out", sys.argv[3]]
from tablebot.cli import main
main()
"""


def test_a_first_short_run_writes_its_trace_in_python_rather_than_compile_the_trace_writer(tmp_path: Path) -> None:
    """make demo's run (120 s, 12,000 ticks) on a cache holding the simulator but not the trace writer's
    compiled lines: the trace is written by Python (0.04 s) instead of compiling them (4-7 s), byte for byte
    what the compiled lines write."""
    import os
    import pickle
    import subprocess

    import tablebot
    from tablebot import jit
    from tablebot.sim.runner import simulate
    from tablebot.sinks.trace_file import block_views_of
    from tablebot.testing.processes import child_env

    example = Path(__file__).resolve().parents[1] / "examples" / "bumberbot"
    files = {source: found for source, found in jit.cache_files().items() if source != "sinks/trace_text.py"}
    (tmp_path / "compiled.pickle").write_bytes(pickle.dumps(files))
    cache = tmp_path / "numba"
    env = child_env(NUMBA_CACHE_DIR=str(cache))
    done = subprocess.run(
        [sys.executable, "-c", FIRST_SHORT_RUN, str(tmp_path / "compiled.pickle"), str(example), str(tmp_path / "out")],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert not list(cache.rglob("trace_text._lines-*.nbi")), "the trace writer's lines were compiled"
    written = (tmp_path / "out" / "trace.jsonl").read_bytes()

    blocks: list[TickBlock] = []

    class Keep:
        def start(self, info: object) -> None:
            pass

        def block(self, block: TickBlock) -> None:
            blocks.append(block)

        def end(self, end: object) -> None:
            pass

    scene = tablebot.open(example).scene(None, {})
    simulate(scene, 120, 1, sinks=[Keep()])
    compiled = b""
    for block in blocks:
        views = block_views_of(block, scene.machine, {}, compiled=True)
        assert isinstance(views, list)  # the compiled lines made these
        compiled += b"".join(views)
    assert written == compiled
    assert os.path.getsize(tmp_path / "out" / "trace.jsonl") > 1_000_000
