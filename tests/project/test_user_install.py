"""tablebot as a user installs it (issue 34 §1): the wheel ``uv build`` makes (pure Python, ``py3-none-any``),
installed with uv into a fresh virtual environment from PyPI's packages alone, runs every command a user runs
with a PATH that holds nothing but that environment's scripts: no dot, no gcc or cc, no node, no system
package. Only building and flashing AVR firmware needs a toolchain (docs/install.md says how to get it).

One module fixture builds and installs once; the cases share it (one xdist worker: the studio's case drives
Chromium, so the module joins the browser group). The simulator's compiled code is handed to the installed
copy from this session's numba cache (jit.cache_files, and the installed sources get the checkout's times,
which numba's cache index is stamped with): the same machine code, without a minute of compiling it again
(benchmarks/demo.py times a first run from empty caches).
"""

from __future__ import annotations

import os
import pickle
import shutil
import subprocess
import sys
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

from tablebot import jit
from test_diagram_without_graphviz import browser as chromium  # noqa: F401 (a fixture: pytest finds it here)
from test_diagram_without_graphviz import studio_diagram

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"
UV = Path(sys.executable).with_name("uv")
TOOLS = ("dot", "gcc", "cc", "node", "npm", "avr-gcc", "make")

pytestmark = pytest.mark.xdist_group("browser")


@dataclass(frozen=True)
class Installed:
    python: Path
    env: dict[str, str]
    work: Path  # a folder outside the checkout, holding a copy of the BumberBot as bumberbot/

    def tablebot(self, *args: str | Path, ok: tuple[int, ...] = (0,)) -> subprocess.CompletedProcess[str]:
        done = subprocess.run(
            [str(self.python.with_name("tablebot")), *map(str, args)],
            cwd=self.work,
            env=self.env,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode in ok, f"tablebot {' '.join(map(str, args))}: {done.returncode}\n{done.stderr[-3000:]}"
        assert "Traceback" not in done.stderr and "internal error" not in done.stderr, done.stderr[-3000:]
        return done


def run(*argv: str | Path, **kwargs: object) -> subprocess.CompletedProcess[str]:
    done = subprocess.run([str(a) for a in argv], capture_output=True, text=True, timeout=600, **kwargs)  # type: ignore[call-overload]
    assert done.returncode == 0, f"{' '.join(map(str, argv))}:\n{done.stdout[-2000:]}{done.stderr[-3000:]}"
    return done


def hand_over_compiled_code(python: Path, env: dict[str, str], scratch: Path) -> None:
    """This session's compiled kernels into the installed copy's cache (see the module's docstring)."""
    where = run(python, "-c", "import tablebot, os; print(os.path.dirname(tablebot.__file__))", env=env).stdout
    site = Path(where.strip())
    for installed in site.rglob("*.py"):
        ours = ROOT / "src" / "tablebot" / installed.relative_to(site)
        if ours.exists() and ours.read_bytes() == installed.read_bytes():
            stat = ours.stat()
            os.utime(installed, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    files = scratch / "compiled.pickle"
    files.write_bytes(pickle.dumps(jit.cache_files()))
    run(
        python,
        "-c",
        "import pickle, sys; from tablebot import jit; "
        "jit.install_cache_files(pickle.loads(open(sys.argv[1], 'rb').read()))",
        files,
        env=env,
    )


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Installed]:
    base = tmp_path_factory.mktemp("user install")
    dist = base / "dist"
    run(UV, "build", "--wheel", "--quiet", "--out-dir", dist, ROOT)
    wheels = list(dist.glob("*.whl"))
    assert len(wheels) == 1 and wheels[0].name.endswith("-py3-none-any.whl"), wheels
    venv = base / "venv"
    run(UV, "venv", "--quiet", "--python", sys.executable, venv)
    python = venv / "bin" / "python"
    # PyPI's packages as the user lock pins them (uv's cache holds them after the set-up: no download)
    run(
        UV,
        "pip",
        "install",
        "--quiet",
        "--python",
        python,
        "--constraint",
        ROOT / "requirements" / "user.lock",
        wheels[0],
    )
    env = {
        key: value
        for key, value in os.environ.items()
        if key not in ("PYTHONPATH", "PYTHONDONTWRITEBYTECODE", "VIRTUAL_ENV")
    }
    env |= {
        "PATH": str(venv / "bin"),
        "NUMBA_CACHE_DIR": str(base / "numba"),
        "HOME": str(base / "home"),
        "XDG_CACHE_HOME": str(base / "cache"),
        "MPLCONFIGDIR": str(base / "mpl"),
        "COLUMNS": "200",
    }
    assert not [tool for tool in TOOLS if shutil.which(tool, path=env["PATH"])]
    hand_over_compiled_code(python, env, base)
    work = base / "work"
    shutil.copytree(EXAMPLE, work / "bumberbot")
    yield Installed(python, env, work)


def test_the_wheel_holds_tablebot_alone_and_runs_outside_the_checkout(installed: Installed) -> None:
    where = run(
        installed.python, "-c", "import tablebot; print(tablebot.__file__)", env=installed.env, cwd=installed.work
    ).stdout
    assert "site-packages" in where and str(ROOT) not in where
    assert installed.tablebot("--version").stdout.startswith("tablebot ")


def test_sim_check_export_new_demo(installed: Installed) -> None:
    t, work = installed.tablebot, installed.work
    t("sim", "bumberbot", "--seconds", "20", "--out", "sim")
    assert {"trace.jsonl", "trajectory.png", "timeline.png"} <= {p.name for p in (work / "sim").iterdir()}
    assert "0 errors" in t("check", "bumberbot", ok=(0, 1)).stdout
    t("export", "bumberbot", "robopro", "--to", "robopro")
    t("export", "bumberbot", "c", "--to", "c")
    assert list((work / "c").glob("*.c")) and list((work / "robopro").iterdir())
    t("new", "mine")
    t("check", "mine", ok=(0, 1))
    t("sim", "mine", "--seconds", "5", "--out", "mine-sim")
    t("demo")
    assert (work / "out" / "replay" / "trace.jsonl").exists()


def test_diagram_to_svg_and_png_with_no_dot(installed: Installed) -> None:
    for suffix, magic in (("svg", b"<?xml"), ("png", b"\x89PNG")):
        installed.tablebot("diagram", "bumberbot", "--out", f"bumberbot.{suffix}")
        assert (installed.work / f"bumberbot.{suffix}").read_bytes().startswith(magic)


def test_run_on_sim_sweep_tune_evolve(installed: Installed) -> None:
    t, work = installed.tablebot, installed.work
    ran = t("run", "bumberbot", "--on", "sim", "--seconds", "0.3")
    assert "ran 30 ticks" in ran.stdout + ran.stderr
    t("sweep", "bumberbot", "--robots", "20", "--seconds", "5", "--out", "sweep")
    assert (work / "sweep" / "results.csv").exists()
    t(
        "tune",
        "bumberbot",
        "--cells",
        "line 5 timer=800..900",
        "--budget",
        "3",
        "--seeds",
        "0..1",
        "--check-seeds",
        "5..5",
        "--seconds",
        "2",
        "--workers",
        "1",
        "-q",
        "--out",
        "tuned",
    )
    assert (work / "tuned" / "report.md").exists()
    t(
        "evolve",
        "bumberbot",
        "--out",
        "evolved",
        "--budget",
        "3",
        "--batch",
        "2",
        "--seeds",
        "0..1",
        "--check-seeds",
        "10..11",
        "--seconds",
        "2",
        "--workers",
        "1",
        "-q",
    )
    assert (work / "evolved").is_dir()


def test_the_controllers_run_and_upload(installed: Installed, tmp_path: Path) -> None:
    from txt4_fake_rest import FakeTxt4
    from txt_fake import FakeTxt

    with FakeTxt(period_s=0.0) as fake:  # a TXT 4.0's ftrobopy_server answers at once
        installed.tablebot("run", "bumberbot", "--on", f"txt://127.0.0.1:{fake.port}", "--seconds", "0.3")
    assert fake.exchanges >= 30
    installed.tablebot("export", "bumberbot", "program", "--to", "txt4")
    with FakeTxt4(tmp_path / "controller") as controller:
        env = {**installed.env, "TABLEBOT_TXT4_KEY": "SECRET"}
        done = subprocess.run(
            [
                str(installed.python.with_name("tablebot")),
                "upload",
                "program",
                "--to",
                f"txt4://127.0.0.1:{controller.port}",
            ],
            cwd=installed.work,
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert done.returncode == 0, done.stderr
    assert controller.started == ["BumberBot"]


def test_the_studio_draws_its_diagram(installed: Installed, chromium: object, tmp_path: Path) -> None:  # noqa: F811
    html, _ = studio_diagram(chromium, str(installed.python), installed.env, tmp_path / "bot")
    assert "<svg" in html


def test_the_user_lock_pins_what_pyproject_asks_for_at_the_dev_locks_versions() -> None:
    def pins(lock: str) -> dict[tuple[str, str], str]:
        found: dict[tuple[str, str], str] = {}
        for line in (ROOT / "requirements" / lock).read_text(encoding="utf-8").splitlines():
            if line[:1].isalnum() and "==" in line:
                requirement = Requirement(line.rstrip(" \\"))
                found[canonicalize_name(requirement.name), str(requirement.marker or "")] = str(
                    requirement.specifier
                ).removeprefix("==")
        return found

    user, dev = pins("user.lock"), pins("dev.lock")
    # a package may be pinned for fewer platforms in the user lock (colorama: Windows only), never to another version
    differ = [
        (name, version)
        for (name, _), version in user.items()
        if version not in {v for (n, _), v in dev.items() if n == name}
    ]
    assert user and not differ, f"requirements/user.lock differs from dev.lock ({differ}): run make lock"
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    names = {name for name, _ in user}
    assert {canonicalize_name(Requirement(r).name) for r in project["dependencies"]} <= names
    assert not {"dask", "gymnasium", "pytest", "mypy", "playwright"} & names  # extras and dev tools stay out


def test_only_firmware_needs_a_toolchain_and_it_says_how_to_get_it_on_each_system(installed: Installed) -> None:
    done = installed.tablebot("build", "bumberbot", "--board", "uno", "--out", "firmware", ok=(2,))
    said = " ".join(done.stderr.split())
    assert "avr-gcc not found (only firmware needs it)" in said
    for system in (
        "Debian or Ubuntu sudo apt-get install gcc-avr avr-libc",
        "macOS brew tap osx-cross/avr",
        "Windows unpack Microchip's AVR 8-bit Toolchain",
    ):
        assert system in said, said
    assert not list(installed.work.glob("firmware/**/*.hex"))


def test_uv_tool_install_from_the_checkout_puts_a_working_tablebot_on_path(tmp_path: Path) -> None:
    tools, bin_dir = tmp_path / "tools", tmp_path / "bin"
    env = {key: value for key, value in os.environ.items() if key not in ("VIRTUAL_ENV", "PYTHONPATH")}
    env |= {"UV_TOOL_DIR": str(tools), "UV_TOOL_BIN_DIR": str(bin_dir)}
    run(
        UV,
        "tool",
        "install",
        "--quiet",
        "--python",
        sys.executable,
        "--constraints",
        ROOT / "requirements" / "user.lock",
        ROOT,
        env=env,
    )
    user = {**env, "PATH": str(bin_dir), "HOME": str(tmp_path), "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    work = tmp_path / "work"
    shutil.copytree(EXAMPLE, work / "bumberbot")
    checked = subprocess.run(
        ["tablebot", "check", "bumberbot"], cwd=work, env=user, capture_output=True, text=True, timeout=120
    )
    assert checked.returncode in (0, 1) and "0 errors" in checked.stdout, checked.stderr
