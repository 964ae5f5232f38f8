"""What a fresh tablebot process loads before it works: compiled code straight from numba's cache (not numba's
whole compiler), numba without scipy, and commands that need neither numba nor pictures import neither.
Timings live in benchmarks/startup.py; these tests pin down what is imported, which a change can break."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"

# Runs the command line in this process, then prints the top-level packages it imported (on exit, also after
# SystemExit).
CLI_MODULES = """
import atexit, json, sys
atexit.register(lambda: print(json.dumps(sorted({m.split('.')[0] for m in sys.modules}))))
sys.argv = ['tablebot', *sys.argv[1:]]
from tablebot.cli import main
main()
"""


def python(code: str, *args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", code, *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env={**os.environ, **(env or {})},
        timeout=300,
    )


def packages_of(*args: str) -> set[str]:
    """The top-level packages ``tablebot ARGS`` imports."""
    done = python(CLI_MODULES, *args)
    assert done.returncode in (0, 1), done.stderr
    return set(json.loads(done.stdout.strip().splitlines()[-1]))


def test_a_cached_function_loads_without_numba_s_compiler_and_scipy(tmp_path: Path) -> None:
    cache = {"NUMBA_CACHE_DIR": str(tmp_path)}
    compile_it = "from tablebot.sim.physics.step import duty; print(duty(3, 8))"
    first = python(compile_it, env=cache)
    assert first.returncode == 0, first.stderr
    load_it = """
import sys
from tablebot.sim.physics.step import duty
print(duty(3, 8), sum(duty.stats.cache_hits.values()), sum(duty.stats.cache_misses.values()))
print(sorted(m for m in ('numba.np.arraymath', 'numba.np.linalg', 'scipy', 'scipy.linalg') if m in sys.modules))
"""
    second = python(load_it, env=cache)
    assert second.returncode == 0, second.stderr
    result, hits, misses, *_ = second.stdout.split()
    assert result == first.stdout.strip() == "0.375"
    assert (hits, misses) == ("1", "0"), second.stdout  # loaded from the cache, not compiled
    assert second.stdout.splitlines()[1] == "[]"  # numba's rules and scipy were never imported


def test_numba_comes_without_scipy_and_scipy_still_imports() -> None:
    done = python(
        "import sys, tablebot.jit; print('scipy' in sys.modules); import scipy.linalg; print(scipy.linalg.__name__)"
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False", "scipy.linalg"]


def test_check_imports_neither_numba_nor_pictures() -> None:
    assert not packages_of("check", str(EXAMPLE)) & {"numba", "llvmlite", "matplotlib", "scipy", "dask"}


def test_parsing_a_command_s_options_imports_no_pydantic(tmp_path: Path) -> None:
    # typer 0.29 coerces every option through pydantic (+0.1-0.2 s a process): pyproject.toml keeps typer below it
    found = packages_of(
        "sim", str(EXAMPLE), "--seconds", "0.05", "--seed", "3", "--no-plots", "--quiet", "--out", str(tmp_path / "sim")
    )
    assert "typer" in found and "numba" in found  # it parsed options and ran the robot
    assert "pydantic" not in found


def test_a_sweep_without_pictures_imports_neither_matplotlib_nor_scipy(tmp_path: Path) -> None:
    def sweep(out: str) -> set[str]:
        return packages_of(
            "sweep",
            str(EXAMPLE),
            "--robots",
            "4",
            "--seconds",
            "0.1",
            "--no-plots",
            "--quiet",
            "--out",
            str(tmp_path / out),
        )

    sweep("first")  # on a cold cache this one compiles (numba's whole compiler, scipy included)
    found = sweep("second")
    assert "numba" in found  # it did run the fleet
    assert not found & {"matplotlib", "scipy"}


def test_preload_loads_what_the_cache_holds_before_the_first_call_and_compiles_nothing(tmp_path: Path) -> None:
    """fleet.work.preload (a sweep loads its compiled code on a thread while it plans): a function the cache
    holds is loaded without a call, from the cache; one it does not hold is left alone, not compiled."""
    cache = {"NUMBA_CACHE_DIR": str(tmp_path)}
    first = python("from tablebot.sim.physics.step import duty; print(duty(3, 8))", env=cache)
    assert first.returncode == 0, first.stderr
    load_it = """
from tablebot.fleet.work import preload
from tablebot.sim.physics.contacts import body_corners
from tablebot.sim.physics.step import duty
print(preload(duty), len(duty.overloads), preload(body_corners), len(body_corners.overloads))
print(duty(3, 8), sum(duty.stats.cache_hits.values()), sum(duty.stats.cache_misses.values()))
"""
    second = python(load_it, env=cache)
    assert second.returncode == 0, second.stderr
    assert second.stdout.splitlines()[0] == "1 1 0 0"  # duty loaded before any call; body_corners not compiled
    assert second.stdout.splitlines()[1] == "0.375 1 0"  # from the cache


def test_a_sweep_loads_its_kernel_on_a_thread_once_its_modules_are_imported_in_the_callers_thread() -> None:
    """Runner.load_compiled (a sweep calls it before importing the rest of the fleet and planning): the kernel's
    modules are imported in the calling thread, so the loading thread never imports beside it, and the thread
    loads every function a local chunk calls from the cache (warmed by the test session), none compiled."""
    load_it = """
import sys, threading
from tablebot.fleet.backends import Runner
from tablebot.fleet.work import chunk_functions
runner = Runner(workers=2)
runner.load_compiled()
print("tablebot.fleet.kernel" in sys.modules, "tablebot.fleet.plan" in sys.modules, runner._loading.name)
runner._loading.join()
functions = chunk_functions(1)
print(all(len(f.overloads) > 0 for f in functions), sum(sum(f.stats.cache_misses.values()) for f in functions))
runner.close()
"""
    done = python(load_it)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["True False tablebot-load", "True 0"]
