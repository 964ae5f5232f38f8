"""Every file the README and the docs point at is in the repository (issue 18: the README sent readers
to shared/seed/bumberbot-table.tsv, which is not), and the document's own table reads as the README says."""

from __future__ import annotations

import re
from pathlib import Path

from typer.testing import CliRunner

from tablebot.cli import app

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK_RE = re.compile(r"\]\(([^)#\s]+)\)")
PATH_RE = re.compile(r"`((?:examples|docs|src|tests|benchmarks|scripts|shared)/[^`\s]*)`")
#: Paths in other projects' repositories that the docs cite as sources.
OTHER_PROJECTS = {"src/ftrobopy_server.cpp"}


def test_every_path_the_docs_name_exists() -> None:
    missing = []
    for doc in DOCS:
        text = doc.read_text(encoding="utf-8")
        for target in LINK_RE.findall(text):
            if "://" not in target and not (doc.parent / target).exists():
                missing.append(f"{doc.name}: ({target})")
        for target in PATH_RE.findall(text):
            if target in OTHER_PROJECTS:
                continue
            if not (list(ROOT.glob(target)) if "*" in target else (ROOT / target).exists()):
                missing.append(f"{doc.name}: `{target}`")
    assert not missing, missing


def test_the_documents_table_reads_as_the_built_in_bumberbot() -> None:
    table = ROOT / "examples" / "document" / "bumberbot-table.tsv"
    assert not list(table.parent.glob("*.toml"))  # no robot file beside it: the built-in BumberBot
    result = CliRunner().invoke(app, ["check", str(table)])
    assert result.exit_code == 0, result.output
    assert "37 rows, 10 states, robot BumberBot" in result.output
