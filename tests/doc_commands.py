"""The commands a page tells its reader to type: every line of its fenced ``sh`` blocks, each either a
``tablebot`` command (which the tests run) or one this module exempts, with the reason. A plain module shared
by tests/project/test_docs_commands.py and tests/project/test_docs_controllers.py."""

from __future__ import annotations

import re
import shlex
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from typer.testing import CliRunner, Result

from tablebot.cli import app

ROOT = Path(__file__).resolve().parents[1]
FENCE_RE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.M | re.S)

#: Lines that are not tablebot commands, or tablebot commands the tests cannot run as typed, and why.
EXEMPT = {
    "make demo": "the Makefile's demo target: make setup, then its tablebot command, which "
    "test_the_makefiles_demo_command_runs runs",
    "make test": "the test suite itself (it runs this test)",
    "PYTHON=python3.12 make demo": "make demo on macOS, with Homebrew's Python (see make demo)",
    "brew install python@3.12 node": "installs system packages (macOS)",
    "cd tablebot": "the reader's checkout; the tests run in a copy of its examples",
    "python3 -m venv .venv && .venv/bin/pip install .": "installs tablebot: the tests run the installed CLI",
    "source .venv/bin/activate": "puts the installed CLI on the reader's path: the tests call it directly",
    "tablebot --install-completion": "writes into the reader's shell start-up file",
}


@dataclass(frozen=True)
class Command:
    """One line a page shows (continuations joined, the comment dropped), and where it is."""

    doc: str
    line: int
    text: str

    @property
    def words(self) -> list[str]:
        return shlex.split(self.text)

    @property
    def env(self) -> dict[str, str]:
        """Variables set in front of the command (``NAME=value tablebot ...``)."""
        out = {}
        for word in self.words:
            if "=" not in word or word.startswith("-"):
                break
            name, value = word.split("=", 1)
            out[name] = value
        return out

    @property
    def argv(self) -> list[str]:
        """The words after ``tablebot`` (empty when this is not a tablebot command)."""
        words = self.words[len(self.env) :]
        return words[1:] if words[:1] == ["tablebot"] else []

    def __str__(self) -> str:
        return f"{self.doc}:{self.line}: {self.text}"


def commands(doc: str) -> list[Command]:
    """Every command of the page's ``sh`` blocks, in order."""
    text = (ROOT / doc).read_text(encoding="utf-8")
    found = []
    for block in FENCE_RE.finditer(text):
        if block[1] not in ("sh", "bash", "shell"):
            continue
        first = text.count("\n", 0, block.start(2)) + 1
        joined = block[2].replace("\\\n", " \n")  # a continued line keeps its place in the count
        for offset, raw in enumerate(joined.splitlines()):
            words = shlex.split(raw, comments=True)
            if words:
                found.append(Command(doc, first + offset, " ".join(shlex.quote(w) if " " in w else w for w in words)))
    return found


def unaccounted(cmds: list[Command]) -> list[str]:
    """Commands that are neither tablebot commands nor exempt: a page gained a command nobody runs."""
    return [str(c) for c in cmds if not c.argv and c.text not in EXEMPT]


def examples_copy(tmp: Path) -> Path:
    """A folder holding a copy of the repository's examples, as a checkout would: the commands run there."""
    shutil.copytree(ROOT / "examples", tmp / "examples")
    return tmp


def run(argv: list[str], env: dict[str, str] | None = None) -> Result:
    """One command through the CLI, in this process (the working folder is the caller's)."""
    return CliRunner().invoke(app, argv, env=env, catch_exceptions=True)


def uncomment(path: Path, shown: str) -> None:
    """Remove the ``#`` in front of each line ``shown`` (as a page shows it) in ``path``, as the page asks
    the reader to: every shown line must be there, commented out."""
    text = path.read_text(encoding="utf-8")
    for line in shown.strip().splitlines():
        commented = re.compile(r"^#\s?" + re.escape(line) + "$", re.M)
        assert commented.search(text), f"{path.name} has no commented-out line {line!r}"
        text = commented.sub(line.replace("\\", "\\\\"), text, count=1)
    path.write_text(text, encoding="utf-8")


def block_after(doc: str, marker: str, lang: str) -> str:
    """The first ``lang`` block after ``marker`` in the page: what it shows the reader."""
    text = (ROOT / doc).read_text(encoding="utf-8")
    start = text.index(marker)
    block = next(b for b in FENCE_RE.finditer(text, start) if b[1] == lang)
    return block[2]


Edit = Callable[[Path], None]
