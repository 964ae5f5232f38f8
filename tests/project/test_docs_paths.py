"""Every file the README and the docs point at is in the repository (the README once sent readers to
shared/seed/bumberbot-table.tsv, which is not), the document's own table reads as the pages say, and the README
is a front page: short, its first screen's only commands `make demo` and `make test`, and nothing about how the
project was made. (Which commands run as typed: tests/project/test_docs_commands.py.)"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from doc_commands import FENCE_RE, commands
from tablebot.cli import app

pytestmark = [pytest.mark.kernel_free]

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
DOCS = [README, ROOT / "CHANGELOG.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK_RE = re.compile(r"\]\(([^)#\s]+)\)")
PATH_RE = re.compile(r"`((?:examples|docs|src|tests|benchmarks|scripts|shared|requirements)/[^`\s]*)`")
#: Paths in other projects' repositories that the docs cite as sources.
OTHER_PROJECTS = {"src/ftrobopy_server.cpp"}
#: How the project was made is no reader's business: an issue's number, a session, other people's test runs, a
#: folder beside the repository. (The changelog is exempt: it is where changes are told.)
NOTEBOOK_RE = re.compile(
    r"\bissue \d+|\bissues? notes\b|\bin the session\b|\bthis session\b|other engineers|"
    r"\.\./shared\b|\bshared/|this 2-core machine|these 2-core machines|measured here\b",
    re.I,
)
#: The README's first screen: what a reader sees before scrolling (the picture alone fills most of it).
FIRST_SCREEN = 30


def _target(doc: Path, link: str) -> Path:
    """Where a link leads: beside the page; a docs page's link to examples/ leads to the repository's examples,
    which the site carries (scripts/docs_hooks.py)."""
    if doc.parent.name == "docs" and link.startswith("examples/"):
        return ROOT / link
    return doc.parent / link


def test_every_path_the_docs_name_exists() -> None:
    missing = []
    for doc in DOCS:
        text = doc.read_text(encoding="utf-8")
        for target in LINK_RE.findall(text):
            if "://" not in target and not _target(doc, target).exists():
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


def test_the_readme_is_a_front_page() -> None:
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 150
    assert len(re.findall(r"!\[", text)) == 1  # one picture
    first = [c.text for c in commands("README.md") if c.line <= FIRST_SCREEN]
    assert first == ["make demo", "make test"]
    blocks_on_first_screen = [b[1] for b in FENCE_RE.finditer(text) if text.count("\n", 0, b.start()) < FIRST_SCREEN]
    assert blocks_on_first_screen == ["sh"]  # no other block of commands (powershell, ...) up there either
    for system in ("Linux", "macOS", "Windows"):
        assert f"**{system}**" in text
    for page in ("getting-started", "tutorial", "teachers", "commands", "files", "findings", "api"):
        assert f"(docs/{page}.md)" in text


def test_no_page_tells_how_the_project_was_made() -> None:
    found = [
        f"{doc.name}: {m[0]!r}"
        for doc in DOCS
        if doc.name != "CHANGELOG.md"
        for m in NOTEBOOK_RE.finditer(doc.read_text(encoding="utf-8"))
    ]
    assert not found, found


def test_the_notebook_pattern_catches_what_the_readme_used_to_say() -> None:
    for said in (
        "issue 22's targets",
        "in the session, against",
        "other engineers' test runs",
        "`../shared/rpp-corpus`",
        "4.4 s on this 2-core machine",
    ):
        assert NOTEBOOK_RE.search(said), said


def test_every_german_page_is_the_twin_of_an_english_one_in_the_navigation() -> None:
    """The site's language switch leads from PAGE.de.md to PAGE.md and back: each German page has its English
    page, which the navigation lists (mkdocs.yml), and the German home page names each German page."""
    german = sorted((ROOT / "docs").glob("*.de.md"))
    assert {p.name for p in german} >= {
        "index.de.md",
        "getting-started.de.md",
        "install.de.md",
        "tutorial.de.md",
        "teachers.de.md",
        "classroom.de.md",
    }
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    home = (ROOT / "docs" / "index.de.md").read_text(encoding="utf-8")
    for page in german:
        english = page.name.removesuffix(".de.md") + ".md"
        assert (page.parent / english).exists(), english
        assert re.search(rf":\s+{re.escape(english)}$", nav, re.M), f"{english} is not in mkdocs.yml's nav"
        assert english == "index.md" or f"]({english})" in home, f"index.de.md does not name {english}"
