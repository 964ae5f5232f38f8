"""Every command the README, the getting-started page and the tutorial show runs as typed: each page's ``sh``
blocks are read (tests/doc_commands.py), and their ``tablebot`` lines run in order, through the CLI, in a
folder holding a copy of the repository's examples, with the edits the page asks the reader to make done
between them. A renamed option or a changed example breaks this test, not the reader. Commands that are not
tablebot's own (installing, make) are exempt, each with its reason (doc_commands.EXEMPT)."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from collections import Counter
from itertools import pairwise
from pathlib import Path

import httpx
import pytest
from typer.testing import Result

from doc_commands import (
    FENCE_RE,
    ROOT,
    Command,
    Edit,
    block_after,
    commands,
    examples_copy,
    run,
    unaccounted,
    uncomment,
)
from tablebot import i18n

TUTORIAL = "docs/tutorial.md"
TUTORIAL_DE = "docs/tutorial.de.md"


def _tutorial_sensor(folder: Path) -> None:
    """Section 5: remove the # in front of the robot file's [sensors] lines and of the table's example row."""
    uncomment(folder / "my-robot" / "robot.toml", block_after(TUTORIAL, "## 5. Give it a sensor", "toml"))
    uncomment(folder / "my-robot" / "table.csv", block_after(TUTORIAL, "remove the `#` in front of the example", ""))


def _tutorial_de_table(folder: Path) -> None:
    """The German tutorial's section 2: its table (the file the page shows, docs/tutorial-de/table.csv) in place
    of the one `new` wrote, and the states' German names in the robot file."""
    page = (ROOT / TUTORIAL_DE).read_text(encoding="utf-8")
    assert '--8<-- "docs/tutorial-de/table.csv"' in page  # what the page shows is the file
    robot = folder / "mein-roboter"
    (robot / "table.csv").write_bytes((ROOT / "docs" / "tutorial-de" / "table.csv").read_bytes())
    text = (robot / "robot.toml").read_text(encoding="utf-8")
    for line in block_after(TUTORIAL_DE, "deutsche Namen", "toml").strip().splitlines():
        text, found = re.subn(rf'^{re.escape(line.split("=")[0])}= "[^"]*"', line, text, count=1, flags=re.M)
        assert found, line
    (robot / "robot.toml").write_text(text, encoding="utf-8")


def _tutorial_de_sensor(folder: Path) -> None:
    """The German tutorial's section 5, as the English one's."""
    uncomment(folder / "mein-roboter" / "robot.toml", block_after(TUTORIAL_DE, "## 5. Ein Sensor", "toml"))
    uncomment(folder / "mein-roboter" / "table.csv", block_after(TUTORIAL_DE, "vor der\nBeispielzeile", ""))


#: Edits a page asks for between two of its commands: before the n-th run of a command (page, text, n).
EDITS: dict[tuple[str, str, int], Edit] = {
    (TUTORIAL, "tablebot check my-robot", 2): _tutorial_sensor,
    (TUTORIAL_DE, "tablebot check mein-roboter --lang de", 1): _tutorial_de_table,
    (TUTORIAL_DE, "tablebot check mein-roboter --lang de", 2): _tutorial_de_sensor,
}
#: The German pages' output blocks (a plain block right below a block of commands) are what its last command
#: printed, "..." for lines left out: the German words there are the catalog's, not the page's own.
GERMAN = ["docs/getting-started.de.md", TUTORIAL_DE]
PAGES = ["README.md", "docs/getting-started.md", TUTORIAL, *GERMAN]


def run_page(doc: str, folder: Path) -> list[str]:
    """Run the page's tablebot commands in order in ``folder``; what went wrong, one line per command."""
    seen: Counter[str] = Counter()
    failed = []
    for command in commands(doc):
        if not command.argv:
            continue
        seen[command.text] += 1
        edit = EDITS.get((doc, command.text, seen[command.text]))
        if edit is not None:
            edit(folder)
        if command.argv[0] == "studio":
            problem = studio_serves(command, folder)
        elif command.argv == ["--install-completion"]:
            problem = completion_installs(folder)
        else:
            result = run_in_language(command)
            problem = "" if result.exit_code == 0 else f"exit {result.exit_code}: {result.output[-600:]}"
            if not problem and doc in GERMAN:
                problem = unshown(shown_output(doc).get(command.line, []), result.output)
        if problem:
            failed.append(f"{command}: {problem}")
    return failed


def run_in_language(command: Command) -> Result:
    """The command in the language it asks for (--lang, TABLEBOT_LANG), as `tablebot` chooses it before its
    app runs (the CLI's main, which the runner does not call); the process's own language again after."""
    argv = i18n.set_from(command.argv, {**os.environ, **command.env})
    try:
        return run(argv, env=command.env or None)
    finally:
        i18n.set_from([], os.environ)


def shown_output(doc: str) -> dict[int, list[str]]:
    """The output a page shows below a block of commands, by the line of the block's last command."""
    text = (ROOT / doc).read_text(encoding="utf-8")
    blocks = list(FENCE_RE.finditer(text))
    shown = {}
    for above, below in pairwise(blocks):
        if above[1] == "sh" and below[1] == "" and not text[above.end() : below.start()].strip():
            last = text.count("\n", 0, above.start(2)) + len(above[2].rstrip("\n").splitlines())
            shown[last] = [line for line in below[2].splitlines() if line.strip() not in ("", "...")]
    return shown


def unshown(lines: list[str], output: str) -> str:
    """The shown lines the command did not print (spacing aside: the runner's console may wrap)."""
    said = " ".join(output.split())
    missing = [line for line in lines if " ".join(line.split()) not in said]
    return f"printed no {missing}, but: {output[-600:]}" if missing else ""


def completion_installs(folder: Path) -> str:
    """`tablebot --install-completion` writes into the user's shell start-up files: here into a home folder of
    the test's own, from a bash (the shell is found among the process's parents: under make it is sh, which
    typer does not complete for; a second command keeps bash from replacing itself with the one)."""
    home = folder / "home"
    home.mkdir(exist_ok=True)
    env = {**os.environ, "HOME": str(home), "PYTHONPATH": str(ROOT / "src")}
    tablebot = Path(sys.executable).parent / "tablebot"  # the command as installed: its name is what completes
    done = subprocess.run(
        ["bash", "-c", f"'{tablebot}' --install-completion; exit $?"],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    if done.returncode != 0:
        return f"exit {done.returncode}: {(done.stdout + done.stderr)[-600:]}"
    script = home / ".bash_completions" / "tablebot.sh"
    sourced = (home / ".bashrc").read_text(encoding="utf-8") if (home / ".bashrc").exists() else ""
    return "" if script.exists() and str(script) in sourced else f"no completion installed: {done.stdout}"


def studio_serves(command: Command, folder: Path) -> str:
    """`tablebot studio` serves until Ctrl-C and opens a browser: here it runs as a process with
    --no-browser on a free port; the page it prints must load, then Ctrl-C must end it."""
    argv = [sys.executable, "-m", "tablebot", *command.argv, "--no-browser", "--port", "0"]
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    with subprocess.Popen(
        argv, cwd=folder, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    ) as studio:
        assert studio.stdout is not None
        said, deadline = "", time.monotonic() + 60
        while "http://" not in said and time.monotonic() < deadline and studio.poll() is None:
            said += studio.stdout.readline()
        address = re.search(r"http://\S+", said)
        page = httpx.get(address[0], timeout=10) if address else None
        studio.send_signal(signal.SIGINT)
        rest, _ = studio.communicate(timeout=30)
    if page is None or page.status_code != 200:
        return f"no page served: {said + rest}"
    return "" if studio.returncode in (0, 130) else f"exit {studio.returncode}: {rest[-600:]}"


@pytest.mark.parametrize("doc", PAGES)
def test_every_command_a_page_shows_runs_as_typed(doc: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert not unaccounted(commands(doc)), "run these commands in the test, or exempt them with the reason"
    assert any(c.argv for c in commands(doc))
    monkeypatch.chdir(examples_copy(tmp_path))
    assert run_page(doc, tmp_path) == []


def test_the_tutorials_edits_lead_to_what_it_shows(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """After section 5's edits the robot turns away from the walls: check proves its properties, and the
    trace has the distance sensor's field, as the tutorial says."""
    monkeypatch.chdir(examples_copy(tmp_path))
    assert run(["new", "my-robot"]).exit_code == 0
    _tutorial_sensor(tmp_path)
    checked = run(["check", "my-robot"])
    assert checked.exit_code == 0 and "0 errors" in checked.output, checked.output
    simulated = run(["sim", "my-robot", "--seconds", "20", "--no-plots"])
    assert simulated.exit_code == 0, simulated.output
    first = (tmp_path / "out" / "sim" / "trace.jsonl").read_text().splitlines()[0]
    assert '"I1_cm"' in first


def demo_commands() -> list[list[str]]:
    """The tablebot commands `make demo` runs: its recipe's, and those of a script of scripts/ it calls."""
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    recipe = re.search(r"^demo:.*\n((?:\t.*\n)+)", makefile, re.M)
    assert recipe is not None
    lines = recipe[1].splitlines()
    for script in re.findall(r"\./(scripts/[\w.-]+\.sh)", recipe[1]):
        lines += (ROOT / script).read_text(encoding="utf-8").splitlines()
    return [
        line.split()[1:]
        for line in (raw.strip().lstrip("@") for raw in lines)
        if line.startswith(".venv/bin/tablebot ")
    ]


def test_the_makefiles_demo_command_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """`make demo` sets up, then runs tablebot: its commands must run as it has them."""
    found = demo_commands()
    assert found
    monkeypatch.chdir(examples_copy(tmp_path))
    for argv in found:
        result = run(argv)
        assert result.exit_code == 0, result.output
    assert {"trace.jsonl", "trajectory.png", "timeline.png"} <= {p.name for p in (tmp_path / "out" / "demo").iterdir()}


def test_a_page_with_an_unknown_command_is_caught(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("```sh\ntablebot sim x\nrm -rf out   # not tablebot's\n```\n")
    found = commands(str(page))  # a path outside the repository is taken as it is
    assert [c.text for c in found] == ["tablebot sim x", "rm -rf out"]
    assert unaccounted(found) == [f"{page}:3: rm -rf out"]


@pytest.mark.parametrize("doc", ["docs/engine.md", "docs/api.md"])
def test_the_python_examples_run(doc: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The Python a page shows runs as it stands, in a folder holding a copy of the examples (its paths are
    examples/...; what it writes, out/..., lands there)."""
    text = (ROOT / doc).read_text(encoding="utf-8")
    blocks = [b[2] for b in FENCE_RE.finditer(text) if b[1] == "python"]
    assert blocks
    monkeypatch.chdir(examples_copy(tmp_path))
    for block in blocks:
        exec(compile(block, doc, "exec"), {"__name__": "__docs__"})


def test_the_german_tutorials_table_drives_as_the_english_one(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The German tutorial's table (Richtung and Tempo, semicolons, 0,7s) is the English template's in other
    words: with their sensor rows in use, the same trace byte for byte."""
    monkeypatch.chdir(tmp_path)
    for name in ("english", "german"):
        assert run(["new", name]).exit_code == 0
        if name == "german":
            (tmp_path / name / "table.csv").write_bytes((ROOT / "docs" / "tutorial-de" / "table.csv").read_bytes())
        table, robot = tmp_path / name / "table.csv", tmp_path / name / "robot.toml"
        table.write_text(
            re.sub(r"^# (I1 \w+ 1)", r"\1", table.read_text(encoding="utf-8"), flags=re.M), encoding="utf-8"
        )
        uncomment(robot, block_after(TUTORIAL, "## 5. Give it a sensor", "toml"))
        assert run(["sim", name, "--seconds", "20", "--no-plots", "--out", f"out-{name}"]).exit_code == 0
    english, german = ((tmp_path / f"out-{name}" / "trace.jsonl").read_bytes() for name in ("english", "german"))
    assert b'"I1_cm"' in german and german == english
