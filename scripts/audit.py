"""`make audit`: every pin of the Python lock checked against the vulnerability database by pip-audit, and the
outcome said as it is.

    python scripts/audit.py requirements/dev.lock [pip-audit options, e.g. -s osv]

Exit 0: the database answered for every pin and knows no vulnerability. Exit 1: it knows some (listed, with
the versions that fix them). Exit 2: NOT CHECKED, the database could not be reached or had no answer for a
pin; never reported as "no known vulnerabilities" (pip-audit itself says that when it skipped every package,
and stops with a traceback, exit 1 as for a finding, when the network is down).

The lock is universal: a package may be pinned twice (one version for Python 3.11, another for 3.12 and
later). pip-audit refuses a file naming a package twice, and would skip the pins whose markers do not match
this machine, so the pins are audited without their markers, in rounds that name each package once.
"""

from __future__ import annotations

import importlib.util
import json
import re
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

CLEAN, FOUND, NOT_CHECKED = 0, 1, 2
PIN = re.compile(r"^([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s;\\]+)")
HASH = re.compile(r"--hash=\S+")


@dataclass
class Pin:
    name: str
    version: str
    hashes: list[str] = field(default_factory=list)

    def line(self) -> str:
        return " ".join([f"{self.name}=={self.version}", *self.hashes])


@dataclass
class Outcome:
    """What the rounds found: each vulnerability as a line to print, and why any pin went unchecked."""

    audited: int = 0
    found: list[str] = field(default_factory=list)
    unchecked: list[str] = field(default_factory=list)


def read_pins(lock: Path) -> list[Pin]:
    """The lock's pins, each with its hashes (uv's requirements format: a pin, then its indented options)."""
    pins: list[Pin] = []
    for line in lock.read_text(encoding="utf-8").splitlines():
        pin = PIN.match(line)
        if pin:
            pins.append(Pin(pin[1], pin[2]))
        elif line[:1].isspace() and pins:
            pins[-1].hashes += HASH.findall(line)
    return pins


def rounds(pins: list[Pin]) -> list[list[Pin]]:
    """The pins in groups naming each package at most once (the first pin of each, then the second...)."""
    groups: list[list[Pin]] = []
    seen: dict[str, int] = {}
    for pin in pins:
        key = re.sub(r"[-_.]+", "-", pin.name).lower()
        at = seen[key] = seen.get(key, -1) + 1
        if at == len(groups):
            groups.append([])
        groups[at].append(pin)
    return groups


def run_round(index: int, pins: list[Pin], folder: Path, options: list[str], outcome: Outcome) -> None:
    """pip-audit on these pins (--strict: a pin the database has no answer for stops it, rather than being
    skipped and left out of a clean result), its findings or its failure added to ``outcome``."""
    requirements, report = folder / f"round-{index}.txt", folder / "report.json"
    requirements.write_text("".join(pin.line() + "\n" for pin in pins), encoding="utf-8")
    report.unlink(missing_ok=True)
    command = [
        sys.executable,
        "-m",
        "pip_audit",
        "-r",
        str(requirements),
        "--disable-pip",
        "--strict",
        "--format",
        "json",
        "--output",
        str(report),
        "--progress-spinner",
        "off",
        "--cache-dir",
        str(folder / "cache"),
        *options,
    ]  # an empty cache: the database's answer of now
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    answer = _json(report) if report.exists() else None
    if answer is None:
        reason = _last_line(done.stderr) or f"pip-audit exit {done.returncode}"
        outcome.unchecked.append(f"{len(pins)} pins unchecked, pip-audit stopped at the first failure: {reason}")
        return
    for dependency in answer.get("dependencies", []):
        if "skip_reason" in dependency:
            outcome.unchecked.append(f"{dependency['name']}: {dependency['skip_reason']}")
            continue
        outcome.audited += 1
        for vuln in dependency.get("vulns", []):
            fixes = ", ".join(vuln.get("fix_versions", [])) or "no fixed version yet"
            aliases = f" ({', '.join(vuln['aliases'])})" if vuln.get("aliases") else ""
            outcome.found.append(
                f"  {dependency['name']} {dependency['version']}: {vuln['id']}{aliases}; fixed in {fixes}"
            )


def _json(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def _last_line(text: str) -> str:
    """pip-audit's own reason: the last line of its error output (its log prefix dropped)."""
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    return re.sub(r"^[A-Z]+:pip_audit[\w.]*:", "", lines[-1]) if lines else ""


def service(options: list[str]) -> str:
    for i, option in enumerate(options[:-1]):
        if option in ("-s", "--vulnerability-service"):
            return options[i + 1]
    return next((o.split("=", 1)[1] for o in options if o.startswith("--vulnerability-service=")), "pypi")


def say(lock: Path, pins: list[Pin], options: list[str], outcome: Outcome) -> int:
    """Print the outcome; return the exit code."""
    where = f"{lock} ({len(pins)} pins, every platform's and Python's; database: {service(options)})"
    for line in outcome.found:
        print(line)
    if outcome.found:
        count = f"{len(outcome.found)} known vulnerabilit{'y' if len(outcome.found) == 1 else 'ies'}"
        print(
            f"make audit: {count} in {where}: move the packages named to a "
            "fixed version (`make lock UPGRADE=1`, or a bound in pyproject.toml and `make lock`), then "
            "`make audit` again"
        )
    if outcome.unchecked:
        print(
            f"make audit: NOT CHECKED: the vulnerability database could not be reached or had no answer for "
            f"{lock}; this is not a clean result, nothing is known of the unchecked pins. pip-audit said:"
        )
        for reason in outcome.unchecked:
            print(f"  {reason}")
        print(
            "Run `make audit` again where the database answers (PyPI's JSON API at pypi.org/pypi/NAME/VERSION"
            '/json; or `make audit AUDIT_ARGS="-s osv"` for api.osv.dev).'
        )
    if outcome.found:
        return FOUND
    if outcome.unchecked:
        return NOT_CHECKED
    print(f"make audit: no known vulnerabilities in {where}; all {outcome.audited} checked just now")
    return CLEAN


def main(argv: list[str]) -> int:
    if not argv:
        print("usage: python scripts/audit.py LOCK [pip-audit options]", file=sys.stderr)
        return NOT_CHECKED
    lock, options = Path(argv[0]), argv[1:]
    if not lock.is_file():
        print(f"make audit: NOT CHECKED: {lock}: no such file (`make lock` writes it)")
        return NOT_CHECKED
    if importlib.util.find_spec("pip_audit") is None:
        print(
            f"make audit: NOT CHECKED: pip-audit is not installed for {sys.executable} (`make setup` installs "
            "it from the lock)"
        )
        return NOT_CHECKED
    pins = read_pins(lock)
    if not pins:
        print(f"make audit: NOT CHECKED: {lock} pins no package (`make lock` writes it)")
        return NOT_CHECKED
    outcome = Outcome()
    with tempfile.TemporaryDirectory(prefix="tablebot-audit-") as folder:
        for index, group in enumerate(rounds(pins)):
            run_round(index, group, Path(folder), options, outcome)
    if not outcome.unchecked and outcome.audited < len(pins):
        outcome.unchecked.append(f"pip-audit answered for {outcome.audited} of the {len(pins)} pins")
    return say(lock, pins, options, outcome)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
