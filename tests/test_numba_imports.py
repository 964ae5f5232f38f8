"""numba comes without the packages it imports for what tablebot never uses (tablebot.jit): coverage where no
coverage run measures the process, yaml where no .numba_config.yaml is there to read, scipy; each still imports,
a coverage run still gets numba's coverage, and a .numba_config.yaml is still read."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from tablebot.testing.processes import child_env

ROOT = Path(__file__).resolve().parents[1]
HELD = ("scipy", "coverage", "yaml")


def fresh(code: str, cwd: Path = ROOT) -> list[str]:
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, env=child_env(), capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def test_numba_imports_none_of_them_and_each_still_imports() -> None:
    lines = fresh(f"""
import sys
import tablebot.jit
print(sorted(m for m in {HELD!r} if m in sys.modules))
import scipy, coverage, yaml
print(scipy.__name__, coverage.__name__, yaml.__name__)
""")
    assert lines == ["[]", "scipy coverage yaml"]


def test_a_coverage_run_imported_first_still_gets_numba_s_coverage_support() -> None:
    lines = fresh("""
import coverage
import tablebot.jit
from numba.misc import coverage_support
print(coverage_support.coverage_available)
""")
    assert lines == ["True"]


def test_a_numba_config_file_in_the_working_folder_is_still_read(tmp_path: Path) -> None:
    (tmp_path / ".numba_config.yaml").write_text("boundscheck: 1\n", encoding="utf-8")
    lines = fresh(
        "import sys, tablebot.jit, numba; print('yaml' in sys.modules, numba.config.BOUNDSCHECK)", cwd=tmp_path
    )
    assert lines == ["True 1"]


TWICE = """
from tablebot.jit import njit


@njit
def twice(x):
    return 2 * x
"""


def test_a_call_the_cache_holds_loads_without_numbas_set_up_for_compiling(tmp_path: Path) -> None:
    """numba reads every installed package's entry points (its extensions) before its first compile or load of a
    process; a load from the cache needs none of it (tablebot.jit._loading_first: 18-26 ms of a sweep). A call
    whose types the cache lacks still takes numba's own path, the set-up included, and compiles."""
    (tmp_path / "twice.py").write_text(TWICE, encoding="utf-8")
    env = child_env(NUMBA_CACHE_DIR=str(tmp_path / "cache"))

    def run(value: str) -> list[str]:
        code = (
            "import numpy as np, twice, numba.core.entrypoints as e; "
            f"print(twice.twice({value})); print(e._already_initialized)"
        )
        done = subprocess.run(
            [sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120
        )
        assert done.returncode == 0, done.stderr
        return done.stdout.splitlines()

    assert run("np.arange(3.0)") == ["[0. 2. 4.]", "True"]  # compiled: numba's set-up ran
    assert run("np.arange(3.0)") == ["[0. 2. 4.]", "False"]  # loaded from the cache: no set-up
    assert run("np.arange(3)") == ["[0 2 4]", "True"]  # other types: numba's own path compiles them
    assert run("np.arange(3)") == ["[0 2 4]", "False"]


def test_the_compiled_files_are_every_file_that_says_njit_and_the_constants_it_reads() -> None:
    """jit.COMPILED_FILES, which names the cache folder, is what reading every source file finds (as the digest
    was made before the list), in the same order: the same digest, so the same cache folder for the same code."""
    import hashlib

    from tablebot import jit

    constants = ("tick.py", "columns.py", "sensors.py", "layout.py")  # compiled code reads them (no njit)
    found = [p for p in sorted(jit.ROOT.rglob("*.py")) if b"njit" in p.read_bytes() or p.name in constants]
    assert tuple(p.relative_to(jit.ROOT).as_posix() for p in found) == jit.COMPILED_FILES
    digest = hashlib.sha1()
    for path in found:
        digest.update(path.relative_to(jit.ROOT).as_posix().encode() + b"\0" + path.read_bytes())
    assert jit.sources_digest() == digest.hexdigest()[:12]
    assert [p.name for p in jit.compiled_sources()] == [p.name for p in found if b"njit" in p.read_bytes()]
