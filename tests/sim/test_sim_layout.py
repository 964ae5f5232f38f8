"""The simulator split by what it owns (issue 35 §2): the model, the compiled physics, the pictures. Each package
names its modules in ``__all__``, and the parts that need neither numba nor matplotlib load neither, so that a
command reading a world or a robot's [sim] section, or a painter forked before the run, stays light.
(Which module may import which is pyproject.toml's import-linter contracts, run by ``lint-imports``.)"""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SIM = ROOT / "src" / "tablebot" / "sim"
HEAVY = ("numba", "llvmlite", "matplotlib")


@pytest.mark.parametrize(
    "package", ["tablebot.sim", "tablebot.sim.model", "tablebot.sim.physics", "tablebot.sim.pictures"]
)
def test_each_package_names_its_modules(package: str) -> None:
    folder = SIM.joinpath(*package.split(".")[2:])
    modules = sorted(
        p.stem if p.is_file() else p.name
        for p in folder.iterdir()
        if (p.suffix == ".py" and p.stem != "__init__") or (p / "__init__.py").is_file()
    )
    assert sorted(importlib.import_module(package).__all__) == modules


def heavy_after(*modules: str) -> list[str]:
    """The heavy packages a fresh process has loaded after importing ``modules``."""
    code = (
        f"import json, sys\nfor m in {list(modules)!r}: __import__(m)\n"
        f"print(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r}))))"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return list(json.loads(done.stdout))


def test_the_packages_and_the_model_s_readers_load_neither_numba_nor_matplotlib() -> None:
    # the packages themselves, a world file's and a robot's [sim] section's readers, and the painter, which is
    # forked before the simulator is imported and imports matplotlib in the fork only
    assert (
        heavy_after(
            "tablebot.sim",
            "tablebot.sim.model",
            "tablebot.sim.physics",
            "tablebot.sim.pictures",
            "tablebot.sim.model.world",
            "tablebot.sim.model.params",
            "tablebot.sim.pictures.painter",
            "tablebot.sim.pictures.view",
        )
        == []
    )


def test_the_physics_brings_numba_and_no_matplotlib_and_the_pictures_matplotlib_and_no_numba() -> None:
    assert heavy_after("tablebot.sim.physics.kernel") == ["llvmlite", "numba"]
    assert heavy_after("tablebot.sim.pictures.plots", "tablebot.sim.pictures.timeline") == ["matplotlib"]
