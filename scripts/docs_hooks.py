"""MkDocs hooks of the documentation site (mkdocs.yml names this file):

* the version every page shows in its footer is tablebot's own (``tablebot.__version__``, which the wheel and
  ``tablebot --version`` also take), never a second copy;
* the example robots (examples/) are part of the site, so a page can link to ``examples/bumberbot/robot.toml``
  and the reader gets the file;
* a page made from the code (scripts/docs_reference.py) that is out of date is a warning, so the strict build
  fails until the script has been run again;
* the docstrings' Sphinx roles (``:meth:`step```) show as the code they name, without the role's name (and
  ``~a.b.Name`` as ``Name``, as Sphinx shows it).
"""

from __future__ import annotations

import importlib.util
import logging
import re
from pathlib import Path
from types import ModuleType
from typing import Any

from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parents[1]
log = logging.getLogger("mkdocs.hooks.tablebot")
ROLE_RE = re.compile(r":(?:py:)?(?:meth|func|class|mod|attr|data|exc|obj|const):(?=<code>)")
#: A role's ``~a.b.Name``: Sphinx shows the last name only.
SHORT_RE = re.compile(r"<code>~(?:\w+\.)+(\w+)</code>")


def _reference() -> ModuleType:
    spec = importlib.util.spec_from_file_location("docs_reference", ROOT / "scripts" / "docs_reference.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def on_config(config: MkDocsConfig, **_: Any) -> MkDocsConfig:
    from tablebot import __version__

    config.copyright = f"tablebot {__version__}"
    config.extra["version"] = __version__
    return config


def on_pre_build(config: MkDocsConfig, **_: Any) -> None:
    for name in _reference().stale():
        log.warning(f"docs/{name} is out of date with the code: run .venv/bin/python scripts/docs_reference.py")


def on_files(files: Files, config: MkDocsConfig, **_: Any) -> Files:
    examples = ROOT / "examples"
    for path in sorted(p for p in examples.rglob("*") if p.is_file()):
        uri = path.relative_to(ROOT).as_posix()
        files.append(File.generated(config, uri, abs_src_path=str(path)))
    return files


def on_page_content(html: str, **_: Any) -> str:
    return SHORT_RE.sub(r"<code>\1</code>", ROLE_RE.sub("", html))
