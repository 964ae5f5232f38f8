"""The fixtures every studio test module shares, once (a plugin tests/conftest.py names): a real Chromium
for the module (one browser for the whole test process, the module's contexts closed after it), a folder for its
screenshots, and the studio served for the module's ``folder``.

A module overrides any of them by defining its own of the same name: test_studio_attacks starts its Chromium
with flags of its own, and the modules whose tests each need a fresh folder (access, saves, drafts) serve a
studio per test over a ``folder`` per test (a module-wide studio cannot stand on a per-test folder)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from studio_helpers import Browsers, screenshots, served
from tablebot.web.app import Background


@pytest.fixture(scope="session")
def browsers() -> Iterator[Browsers]:
    """This test process's Chromium, launched once for every module that needs one."""
    shared = Browsers()
    yield shared
    shared.close()


@pytest.fixture(scope="module")
def browser(browsers: Browsers) -> Iterator[Any]:
    yield from browsers.module()


@pytest.fixture(scope="module")
def shots(tmp_path_factory: pytest.TempPathFactory, request: pytest.FixtureRequest) -> Path:
    """``studio-NAME`` for tests/web/test_studio_NAME.py (each module's docstring says where its shots go)."""
    name = request.module.__name__.rpartition(".")[2].removeprefix("test_").replace("_", "-")
    return screenshots(tmp_path_factory, name)


@pytest.fixture(scope="module")
def studio(folder: Path) -> Iterator[Background]:
    yield from served(folder)
