"""One version: tablebot.__version__ is the source; the wheel takes it (hatchling, as `pip install` and a
build do), `tablebot --version` prints it, and the documentation site shows it (test_docs_reference.py)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest
from hatchling.metadata.core import ProjectMetadata
from hatchling.plugin.manager import PluginManager

import tablebot

pytestmark = [pytest.mark.kernel_free]

ROOT = Path(__file__).resolve().parents[2]


def test_the_wheel_takes_its_version_from_the_package() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert "version" not in project and "version" in project["dynamic"]  # no second copy to drift
    assert ProjectMetadata(str(ROOT), PluginManager()).version == tablebot.__version__


def test_the_version_is_one_a_packager_accepts() -> None:
    assert re.fullmatch(r"\d+\.\d+\.\d+(?:(?:a|b|rc)\d+)?(?:\.dev\d+)?", tablebot.__version__)


def test_the_changelog_has_an_entry_for_the_version() -> None:
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert "## [Unreleased]" in changelog and f"## [{tablebot.__version__}]" in changelog
