"""The command index (tablebot.cli.index): `tablebot --help` lists every command from it, in either language,
without importing the commands' modules, and every command registered on the app is in it."""

from __future__ import annotations

import importlib
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

import tablebot.cli
from tablebot.cli.app import app
from tablebot.cli.index import BY_NAME, COMMANDS
from tablebot.i18n import translation
from tablebot.testing.processes import child_env

ROOT = Path(__file__).resolve().parents[2]

# A child runs the command line and prints, at exit, the tablebot modules it imported.
MODULES = """
import atexit, sys
atexit.register(lambda: print('MODULES', *sorted(m for m in sys.modules if m.startswith('tablebot.cli.'))))
sys.argv = ['tablebot', *sys.argv[1:]]
from tablebot.cli import main
main()
"""


def run(*args: str) -> tuple[str, set[str]]:
    """What ``tablebot ARGS`` printed (its last line, the modules, taken off) and the cli modules it imported."""
    done = subprocess.run(
        [sys.executable, "-c", MODULES, *args], cwd=ROOT, env=child_env(), capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[-1].startswith("MODULES")
    return "\n".join(lines[:-1]), set(lines[-1].split()[1:])


def flat(text: str) -> str:
    """Help text with its wrapping undone (a summary may wrap onto the next line, after a space or a hyphen)."""
    return " ".join(re.sub(r"-\n\s+", "-", text).split())


def test_every_registered_command_is_in_the_index_and_each_entry_registers_its_command() -> None:
    for module in pkgutil.iter_modules(tablebot.cli.__path__):
        if module.name != "__main__":
            importlib.import_module(f"tablebot.cli.{module.name}")
    registered = {info.name: info.callback.__module__ for info in app.registered_commands if info.callback}
    assert set(registered) == set(BY_NAME)
    assert all(registered[e.name] == f"tablebot.cli.{e.module}" for e in COMMANDS)
    assert len(BY_NAME) == len(COMMANDS)


@pytest.mark.parametrize("language", ["en", "de"])
def test_help_lists_every_command_with_its_summary_and_imports_no_command_module(language: str) -> None:
    text, modules = run("--lang", language, "--help")
    catalog = translation(language)
    for entry in COMMANDS:
        summary = catalog.gettext(entry.summary)
        assert language == "en" or summary != str(entry.summary), f"{entry.name}: no German summary"
        assert f"{entry.name} {summary}" in flat(text)
    assert modules == {"tablebot.cli.app", "tablebot.cli.index", "tablebot.cli.usage", "tablebot.cli.words"}


def test_a_command_imports_its_own_module_alone_and_shows_its_whole_help() -> None:
    text, modules = run("--lang", "de", "sweep", "--help")
    assert "tablebot.cli.sweep" in modules
    assert not modules & {f"tablebot.cli.{e.module}" for e in COMMANDS if e.module != "sweep"}
    assert "Strg-C (oder SIGTERM) behält jeden fertigen Abschnitt" in flat(text)  # its docstring, in German
    assert "--robots" in text


def test_a_mistyped_command_is_answered_from_the_index() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", "sweeep"],
        cwd=ROOT,
        env=child_env(),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2
    assert "'sweeep' is not a tablebot command" in done.stderr and "did you mean sweep" in done.stderr
