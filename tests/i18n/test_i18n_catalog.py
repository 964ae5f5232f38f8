"""Nothing left untranslated (issue 38 §3): the catalog's template is what the code marks, German translates all
of it (msgfmt's own check), and in the pseudo-locale, where every translated text stands between markers, the
help of every command and the command line's errors show no text outside them."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import typer.main
from typer.testing import CliRunner

import tablebot.cli  # noqa: F401  (registers every command)
from tablebot import i18n
from tablebot.cli.app import app
from tablebot.i18n import PSEUDO_CLOSE, PSEUDO_OPEN

ROOT = Path(__file__).resolve().parents[2]
PO = ROOT / "src" / "tablebot" / "locale" / "de" / "LC_MESSAGES" / "tablebot.po"
EXAMPLE = ROOT / "examples" / "bumberbot"


def test_the_template_and_the_compiled_catalogs_are_up_to_date() -> None:
    done = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "catalog.py"), "check"], capture_output=True, text=True, cwd=ROOT
    )
    assert done.returncode == 0, done.stderr


def test_msgfmt_finds_german_complete_and_well_formed() -> None:
    msgfmt = shutil.which("msgfmt")
    assert msgfmt, "msgfmt is missing: it is Debian's gettext package, which make setup installs"
    done = subprocess.run(
        [msgfmt, "--check", "--statistics", "-o", "/dev/null", str(PO)],
        capture_output=True,
        text=True,
        env={"LC_ALL": "C", "PATH": "/usr/bin:/bin"},
    )
    assert done.returncode == 0, done.stderr
    assert re.fullmatch(r"\d+ translated messages\.\n", done.stderr), done.stderr  # no fuzzy, no untranslated


def outside(text: str) -> str:
    """What ``text`` says outside the pseudo-locale's markers (they nest: a message's arguments are messages)."""
    depth, kept = 0, []
    for ch in text:
        if ch == PSEUDO_OPEN:
            depth += 1
        elif ch == PSEUDO_CLOSE:
            depth -= 1
        elif depth == 0:
            kept.append(ch)
    return "".join(kept)


def names(command: object) -> set[str]:
    """The words a user types, never translated: commands, options, choices, the program's name."""
    found = {"tablebot"}
    stack = [command]
    while stack:
        cmd = stack.pop()
        found.add(getattr(cmd, "name", "") or "")
        stack += list(getattr(cmd, "commands", {}).values())
        for param in getattr(cmd, "params", []):
            found.update(param.opts + param.secondary_opts)
            found.update(str(c) for c in getattr(param.type, "choices", ()) or ())
    return found


def words(text: str, allowed: set[str]) -> list[str]:
    """Words of three letters or more that are not names a user types (nor parts of them, nor numbers)."""
    parts = {p for name in allowed for p in re.split(r"[^A-Za-z]+", name) if p}
    return [w for w in re.findall(r"(?<![-\w])[A-Za-z][A-Za-z]{2,}(?![\w.])", text) if w not in parts]


def commands() -> Iterator[list[str]]:
    root = typer.main.get_command(app)
    yield []
    for name in sorted(getattr(root, "commands", {})):
        yield [name]


def run_in(language: str, args: list[str]) -> str:
    i18n.use(language)
    try:
        result = CliRunner().invoke(app, args, prog_name="tablebot")
    finally:
        i18n.use("en")
    return result.output


@pytest.mark.parametrize("args", list(commands()), ids=lambda a: " ".join(a) or "tablebot")
def test_every_help_is_marked(args: list[str]) -> None:
    allowed = names(typer.main.get_command(app))
    shown = run_in(i18n.PSEUDO, [*args, "--help"])
    assert PSEUDO_OPEN in shown
    assert words(outside(shown), allowed) == [], shown


BAD_LINES = [
    ["sim"],
    ["sim", "a", "b"],
    ["sim", str(EXAMPLE), "--seconds"],
    ["sim", str(EXAMPLE), "--seconds", "nan"],
    ["sim", str(EXAMPLE), "--seconds", "1e9"],
    ["sim", str(EXAMPLE), "--seconds", "many"],
    ["sim", str(EXAMPLE), "--sed", "3"],
    ["simm"],
    ["--bogus"],
    ["check", str(EXAMPLE), "--format", "yaml"],
]


@pytest.mark.parametrize("args", BAD_LINES, ids=" ".join)
def test_command_line_errors_are_marked(args: list[str]) -> None:
    allowed = names(typer.main.get_command(app)) | set(args)  # what the user wrote comes back as written
    shown = run_in(i18n.PSEUDO, args)
    assert PSEUDO_OPEN in shown and words(outside(shown), allowed) == [], shown
    german = run_in("de", args)
    assert "Fehler" in german and "error" not in german, german


def test_the_language_is_chosen_before_the_help_is_built() -> None:
    """--lang anywhere, else TABLEBOT_LANG, else the system's locale; a language tablebot does not speak is refused
    by name when asked for, and English when it is merely the system's."""
    env = {"PATH": "/usr/bin:/bin", "LANG": "de_DE.UTF-8"}
    cases = [
        (["--help"], {}, "Aufruf:"),
        (["--help", "--lang", "en"], {}, "Usage:"),
        (["sim", "--lang=de", "-h"], {"LANG": "C"}, "Aufruf:"),
        (["-h"], {"TABLEBOT_LANG": "en"}, "Usage:"),
        (["-h"], {"LANG": "fr_FR.UTF-8"}, "Usage:"),
        (["-h"], {"LC_ALL": "de_AT", "LANG": "en_GB"}, "Aufruf:"),
    ]
    for args, extra, expected in cases:
        done = subprocess.run(
            [sys.executable, "-m", "tablebot", *args], capture_output=True, text=True, env={**env, **extra}, cwd=ROOT
        )
        assert done.returncode == 0 and done.stdout.startswith(expected), (args, extra, done.stdout[:80])
    refused = subprocess.run(
        [sys.executable, "-m", "tablebot", "-h"],
        capture_output=True,
        text=True,
        env={**env, "TABLEBOT_LANG": "fr"},
        cwd=ROOT,
    )
    assert refused.returncode == 2, refused.stderr
    assert refused.stderr == (
        "TABLEBOT_LANG: error: 'fr' is not a language tablebot speaks\n    hint: use one of: en, de\n"
    )


def test_the_windows_user_interface_language() -> None:
    assert i18n.system_language({}, "win32", lambda: 0x0407) == "de"  # German (Germany)
    assert i18n.system_language({}, "win32", lambda: 0x0C07) == "de"  # German (Austria)
    assert i18n.system_language({}, "win32", lambda: 0x0409) == "en"
    assert i18n.system_language({"LANG": "C.UTF-8"}, "linux") is None


def example_words(folder: Path) -> set[str]:
    """Every word of an example's own files and their names (its states' names, inputs' labels, properties'
    texts, table.csv): the user's."""
    return {
        w
        for path in folder.iterdir()
        if path.is_file()
        for w in re.findall(r"[A-Za-z]+", f"{path.name} {path.read_text()}")
    }


@pytest.mark.parametrize(
    "args",
    [["check", str(EXAMPLE), "-v"], ["sim", str(EXAMPLE), "--seconds", "2", "--no-plots", "--out", "OUT"]],
    ids=lambda a: a[0],
)
def test_check_and_sim_say_nothing_outside_the_markers(args: list[str], tmp_path: Path) -> None:
    args = [a.replace("OUT", str(tmp_path / "out")) for a in args]
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", *args],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={
            "PATH": "/usr/bin:/bin",
            "TABLEBOT_LANG": i18n.PSEUDO,
            "HOME": str(Path.home()),
            # the test session's compiled kernels (else sim compiles them all: a minute)
            **{k: v for k, v in os.environ.items() if k == "NUMBA_CACHE_DIR"},
        },
    )
    assert done.returncode in (0, 1), done.stderr
    allowed = names(typer.main.get_command(app)) | set(args) | example_words(EXAMPLE) | {"jsonl"}
    shown = done.stdout + done.stderr
    assert PSEUDO_OPEN in shown and words(outside(shown), allowed) == [], shown[-3000:]
