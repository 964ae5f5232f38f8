"""The Python lock (requirements/dev.lock, `make lock`) and its audit (`make audit`, scripts/audit.py): the lock
pins what pyproject.toml asks for, the set-up installed exactly its pins, and the audit says what pip-audit
found, or plainly that nothing was checked when the vulnerability database cannot be reached or does not
answer, never "no known vulnerabilities" then. The database here is a real HTTP server on loopback speaking
OSV's query API (pip-audit's ``-s osv --osv-url``)."""

from __future__ import annotations

import contextlib
import http.server
import json
import os
import re
import socket
import subprocess
import sys
import threading
import tomllib
from collections.abc import Iterator
from importlib import metadata
from pathlib import Path
from typing import Any

import pytest
from packaging.markers import Marker
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[2]
LOCK = ROOT / "requirements" / "dev.lock"
AUDIT = ROOT / "scripts" / "audit.py"
PIN = re.compile(r"^([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s;\\]+)(?:\s*;\s*([^\\]+?))?\s*\\?$")


def pins() -> list[tuple[str, str, Marker | None]]:
    """The lock's pins: name, version, and the marker saying where the pin applies (None: everywhere)."""
    found: list[tuple[str, str, Marker | None]] = []
    for line in LOCK.read_text(encoding="utf-8").splitlines():
        pin = PIN.match(line)
        if pin:
            found.append((canonicalize_name(pin[1]), pin[2], Marker(pin[3]) if pin[3] else None))
    return found


def pinned_here() -> dict[str, str]:
    """The pins that apply to this Python on this machine, by name."""
    return {name: version for name, version, marker in pins() if marker is None or marker.evaluate()}


def asked() -> list[Requirement]:
    """What pyproject.toml asks for, with the dev extra (what `make setup` installs), on this machine."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    wanted = [Requirement(text) for text in [*project["dependencies"], *project["optional-dependencies"]["dev"]]]
    return [r for r in wanted if r.marker is None or r.marker.evaluate({"extra": "dev"})]


def test_the_lock_pins_every_package_pyproject_asks_for_in_a_version_it_allows() -> None:
    here = pinned_here()
    for requirement in asked():
        name = canonicalize_name(requirement.name)
        assert name in here, f"{name}: in pyproject.toml, not in {LOCK.name}: run `make lock`"
        assert requirement.specifier.contains(here[name], prereleases=True), (
            f"{name} {here[name]} is pinned, pyproject.toml asks for {requirement}: run `make lock`"
        )
    assert "distributed" in here  # dask[distributed]: an extra's packages are pinned too


def test_the_set_up_installed_exactly_the_pins() -> None:
    """`make setup` installs from the lock: every pin that applies here is the installed version."""
    wrong = {}
    for name, version in pinned_here().items():
        try:
            installed = metadata.version(name)
        except metadata.PackageNotFoundError:
            installed = "missing"
        if installed != version:
            wrong[name] = f"{installed} installed, {version} pinned"
    assert not wrong, f"run `make setup` (scripts/bootstrap.sh installs the lock): {wrong}"


# --- the audit ----------------------------------------------------------------------------------------


def small_lock(folder: Path, names: set[str]) -> Path:
    """A lock of the real lock's entries (pins, markers, hashes) for these packages only."""
    entries = re.split(r"\n(?=\S)", LOCK.read_text(encoding="utf-8"))
    kept = [e for e in entries if (pin := PIN.match(e.splitlines()[0])) and canonicalize_name(pin[1]) in names]
    path = folder / "small.lock"
    path.write_text("\n".join(kept) + "\n", encoding="utf-8")
    return path


class Osv(http.server.BaseHTTPRequestHandler):
    """OSV's query API (POST /v1/query {package, version} -> {vulns}) answering from the server's ``known``."""

    def do_POST(self) -> None:
        query = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
        name, version = query["package"]["name"], query["version"]
        vulns = self.server.known.get((name, version), [])  # type: ignore[attr-defined]
        body = json.dumps({"vulns": vulns} if vulns else {}).encode()
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args: Any) -> None:
        pass


@contextlib.contextmanager
def osv(known: dict[tuple[str, str], list[dict[str, Any]]]) -> Iterator[str]:
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Osv)
    server.known = known  # type: ignore[attr-defined]
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/v1/query"
    finally:
        server.shutdown()
        server.server_close()


def audit(lock: Path, url: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "NO_PROXY": "127.0.0.1", "no_proxy": "127.0.0.1"}  # a proxy set here must not take it
    return subprocess.run(
        [sys.executable, str(AUDIT), str(lock), "-s", "osv", "--osv-url", url],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def vulnerability(name: str, fixed: str) -> dict[str, Any]:
    return {
        "id": "GHSA-test-0001",
        "summary": "made up for the test",
        "aliases": ["CVE-0000-0001"],
        "affected": [
            {
                "package": {"name": name, "ecosystem": "PyPI"},
                "ranges": [{"type": "ECOSYSTEM", "events": [{"introduced": "0"}, {"fixed": fixed}]}],
            }
        ],
    }


@pytest.fixture(scope="module")
def lock(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """scipy twice (one pin for Python 3.11, one for 3.12 and later) and six."""
    path = small_lock(tmp_path_factory.mktemp("lock"), {"scipy", "six"})
    assert [name for name, *_ in pins_of(path)] == ["scipy", "scipy", "six"]
    return path


def pins_of(path: Path) -> list[tuple[str, str]]:
    return [(canonicalize_name(p[1]), p[2]) for line in path.read_text().splitlines() if (p := PIN.match(line))]


def test_a_clean_answer_for_every_pin_is_a_clean_audit(lock: Path) -> None:
    with osv({}) as url:
        done = audit(lock, url)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "no known vulnerabilities" in done.stdout and "all 3 checked" in done.stdout


def test_a_vulnerability_in_another_pythons_pin_is_found(lock: Path) -> None:
    """The pin for Python 3.12 and later is audited too, though this machine would never install it."""
    other = [version for name, version in pins_of(lock) if name == "scipy" and version != metadata.version("scipy")]
    with osv({("scipy", other[0]): [vulnerability("scipy", "99.0")]}) as url:
        done = audit(lock, url)
    assert done.returncode == 1, done.stdout + done.stderr
    line = next(line for line in done.stdout.splitlines() if line.startswith(f"  scipy {other[0]}: "))
    assert "GHSA-test-0001" in line and "CVE-0000-0001" in line and line.endswith("; fixed in 99.0")
    assert "1 known vulnerability in" in done.stdout
    assert "no known vulnerabilities" not in done.stdout


def test_an_unreachable_database_is_not_checked_never_clean(lock: Path) -> None:
    with socket.socket() as closed:  # a port nothing listens on
        closed.bind(("127.0.0.1", 0))
        url = f"http://127.0.0.1:{closed.getsockname()[1]}/v1/query"
    done = audit(lock, url)
    assert done.returncode == 2, done.stdout + done.stderr
    assert done.stdout.startswith("make audit: NOT CHECKED: the vulnerability database could not be reached")
    assert "Connection refused" in done.stdout and "no known vulnerabilities" not in done.stdout
    assert "Traceback" not in done.stdout + done.stderr
