"""`make demo`'s set-up, scripts/bootstrap.sh user (issue 34 §1): on a Python with no pip and no ensurepip (as
Debian's and Ubuntu's python3 is without the python3-pip and python3-venv packages) and no uv on PATH, it still
makes .venv with tablebot and its packages from PyPI, and never calls sudo or apt-get (stand-ins on PATH that
record a call and fail). pip's own wheel, fetched from PyPI (scripts/fetch_pip.py, its SHA-256 checked), brings uv."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
REFUSE = '#!/bin/sh\necho "$0 $*" >>"{log}"\nexit 1\n'
NO_ENSUREPIP = "raise SystemExit('ensurepip is not available (as on Debian without python3-venv)')\n"


def checkout(target: Path) -> None:
    """What the set-up reads: its scripts, pyproject.toml, the locks, and tablebot's sources (installed editable)."""
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for name in ("scripts", "requirements", "src", "examples"):
        shutil.copytree(ROOT / name, target / name, ignore=ignore)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, target / name)


def test_the_user_set_up_needs_no_pip_no_uv_and_no_system_package(tmp_path: Path) -> None:
    work, bare, tools = tmp_path / "tablebot", tmp_path / "bare-python", tmp_path / "bin"
    checkout(work)
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(bare)], check=True)  # a Python with no pip
    blocked = tmp_path / "blocked" / "ensurepip"
    blocked.mkdir(parents=True)
    (blocked / "__init__.py").write_text(NO_ENSUREPIP, encoding="utf-8")
    (blocked / "__main__.py").write_text(NO_ENSUREPIP, encoding="utf-8")
    tools.mkdir()
    calls = tmp_path / "calls.log"
    for name in ("sudo", "apt-get", "dpkg", "brew"):
        (tools / name).write_text(REFUSE.format(log=calls), encoding="utf-8")
        (tools / name).chmod(0o755)
    # a script, not a link: through a link elsewhere the venv's python would not find its pyvenv.cfg (and pip)
    (tools / "python3").write_text(f"#!/bin/sh\nexec '{bare / 'bin' / 'python'}' \"$@\"\n", encoding="utf-8")
    (tools / "python3").chmod(0o755)
    path = [str(tools), *(p for p in os.environ["PATH"].split(os.pathsep) if not (Path(p) / "uv").exists())]
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONDONTWRITEBYTECODE", "PYTHON")}
    env |= {"PATH": os.pathsep.join(path), "PYTHONPATH": str(blocked.parent)}
    for check in (["-m", "pip", "--version"], ["-m", "ensurepip"]):
        assert subprocess.run([str(tools / "python3"), *check], env=env, capture_output=True).returncode != 0
    done = subprocess.run(
        ["bash", "scripts/bootstrap.sh", "user"], cwd=work, env=env, capture_output=True, text=True, timeout=600
    )
    said = done.stdout + done.stderr
    assert done.returncode == 0, said
    assert "this Python has no pip: fetching pip's wheel from PyPI" in said
    assert not calls.exists(), calls.read_text()  # no sudo, no apt-get, no dpkg, no brew
    venv = work / ".venv" / "bin"
    assert (venv / "uv").exists() and (work / ".venv" / ".installed-user").exists()
    version = subprocess.run([str(venv / "tablebot"), "--version"], env=env, capture_output=True, text=True)
    assert version.returncode == 0 and version.stdout.startswith("tablebot "), version.stderr
    again = subprocess.run(
        ["bash", "scripts/bootstrap.sh", "user"], cwd=work, env=env, capture_output=True, text=True, timeout=60
    )
    assert again.returncode == 0 and again.stdout == "", again.stdout  # set up: nothing to do, nothing said
