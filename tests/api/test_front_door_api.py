"""The front door's surface: ``import tablebot`` and ``tablebot.open`` stay light, the public names are exactly
the ones docs/api.md documents, and ``open`` finds a robot's files as the commands do."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import tablebot
import tablebot.api
from doc_commands import ROOT, examples_copy
from tablebot.diagnostics import TableBotError

pytestmark = [pytest.mark.kernel_free]

API_PAGE = ROOT / "docs" / "api.md"
#: What importing tablebot and opening a robot must not import: the simulator's compiler, the pictures, the cluster.
HEAVY = ("numba", "llvmlite", "matplotlib", "dask", "distributed")


def test_import_tablebot_and_open_load_no_compiler_pictures_or_cluster() -> None:
    code = (
        "import sys, tablebot\n"
        "robot = tablebot.open('examples/bumberbot')\n"
        "assert robot.table.rows and robot.property_files\n"
        f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r})))\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def _section(text: str, heading: str) -> str:
    """A page's text from ``heading`` to the next heading of its level."""
    start = text.index(f"\n{heading}\n")
    end = text.find("\n## ", start + len(heading) + 2)
    return text[start : end if end >= 0 else len(text)]


def test_the_public_names_are_exactly_the_documented_ones() -> None:
    text = API_PAGE.read_text(encoding="utf-8")
    front = _section(text, "## The front door")
    said = re.search(r"\(`tablebot\.__all__`\): (.*?)\. ", front, re.S)
    assert said is not None, "docs/api.md must list tablebot's names"
    assert sorted(re.findall(r"`(\w+)`", said[1])) == sorted(tablebot.__all__)
    for name in tablebot.__all__:
        assert getattr(tablebot, name) is not None  # each one resolves (they are imported on first use)
    assert tablebot.open is tablebot.api.open and tablebot.Project is tablebot.api.Project
    star: dict[str, object] = {}
    exec("from tablebot import *", star)
    assert sorted(k for k in star if not k.startswith("__")) == sorted(tablebot.__all__)
    # tablebot.api's names are the objects the front door section documents, each one where it lives
    documented = set(re.findall(r"^::: (tablebot\.api\.\S+)$", front, re.M))
    public = {f"{getattr(tablebot.api, name).__module__}.{name}" for name in tablebot.api.__all__}
    assert documented == public
    with pytest.raises(AttributeError):
        tablebot.api.Nothing  # noqa: B018


def test_open_takes_a_folder_a_table_or_a_robot_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(examples_copy(tmp_path))
    folder = Path("examples/bumberbot")
    opened = [tablebot.open(folder), tablebot.open(folder / "table.csv"), tablebot.open(folder / "robot.toml")]
    for robot in opened:
        assert robot.path == folder / "table.csv" and robot.robot.name == "BumberBot"
        assert robot.property_files == (folder / "properties.toml",) and robot.world_files == ()
    assert opened[2].robot_file == folder / "robot.toml"
    given = tablebot.open(folder, worlds=[folder / "arena.toml"], properties=[])
    assert given.property_files == () and [w.name for w in given.worlds] == ["BumberBot arena"]
    with pytest.raises(TableBotError, match="No such file"):
        tablebot.open(folder / "nothing.toml")
    (tmp_path / "alone").mkdir()
    (tmp_path / "alone" / "robot.toml").write_text((folder / "robot.toml").read_text())
    with pytest.raises(TableBotError, match="no table beside this robot file"):
        tablebot.open(tmp_path / "alone" / "robot.toml")


@pytest.mark.parametrize(
    ("method", "home"),
    [
        ("simulate", "simulation"),
        ("check", "checking"),
        ("sweep", "sweeping"),
        ("tune", "tuning"),
        ("evolve", "evolution"),
        ("export", "exporting"),
        ("connect", "running"),
    ],
)
def test_each_call_takes_what_its_function_takes(method: str, home: str) -> None:
    """Project's methods spell out the options of the functions they call (typed, for an editor to offer): the
    same names, kinds and defaults, so that neither can change without the other."""
    import importlib
    import inspect

    function = inspect.signature(getattr(importlib.import_module(f"tablebot.api.{home}"), method))
    bound = inspect.signature(getattr(tablebot.Project, method))
    assert list(bound.parameters.values())[1:] == list(function.parameters.values())[1:]
    assert bound.return_annotation == function.return_annotation
