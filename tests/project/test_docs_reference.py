"""The reference pages say what the code does: the pages made from the code are up to date, the findings
pages list exactly the finding codes the analysis has (each example being what `check` prints), and the file
formats page names every key the loaders accept."""

from __future__ import annotations

import ast
import importlib.util
import re
from pathlib import Path
from types import ModuleType

import pytest
from typer.testing import CliRunner

import tablebot
from tablebot import plugins, registry
from tablebot.analysis.properties import KEYS as PROPERTY_KEYS
from tablebot.cli import app
from tablebot.robot import CORE_SECTIONS, SECTION_READERS
from tablebot.robot import TOP_KEYS as ROBOT_KEYS
from tablebot.sensors import KEYS as SENSOR_KEYS
from tablebot.sim.model.world import TOP_KEYS as WORLD_KEYS

pytestmark = [pytest.mark.kernel_free]

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
ANALYSIS = ROOT / "src" / "tablebot" / "analysis"


def reference_script() -> ModuleType:
    spec = importlib.util.spec_from_file_location("docs_reference", ROOT / "scripts" / "docs_reference.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_pages_made_from_the_code_are_up_to_date() -> None:
    assert reference_script().stale() == [], "run .venv/bin/python scripts/docs_reference.py"


def test_the_pages_are_made_in_english_whatever_the_process_speaks() -> None:
    """A test before this one in the same worker that left the process speaking German made the English page
    read as out of date (the command help came out German)."""
    from tablebot import i18n

    before = i18n.current()
    i18n.use("de")
    try:
        assert reference_script().stale() == []
    finally:
        i18n.use(before)


def test_the_command_reference_has_every_command_and_option() -> None:
    page = (DOCS / "commands.md").read_text(encoding="utf-8")
    for name in ("sim", "check", "run", "evolve", "studio"):
        assert f"## `tablebot {name}` {{#{name}}}" in page
    assert "`--behind-limit <float range>`" in page and "`--seconds <float range>`" in page


def codes_in_code() -> set[str]:
    """Every code a Finding is made with in tablebot.analysis: a literal, a module constant, or
    ``f"encoding-{target}"`` for each export or controller target check knows."""
    found: set[str] = set()
    for path in sorted(ANALYSIS.glob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        constants = {
            t.id: str(node.value.value)
            for node in tree.body
            if isinstance(node, ast.Assign)
            for t in node.targets
            if isinstance(t, ast.Name) and isinstance(node.value, ast.Constant)
        }
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Call) and getattr(node.func, "id", None) == "Finding" and node.args):
                continue
            code = node.args[0]
            if isinstance(code, ast.Constant) and isinstance(code.value, str):
                found.add(code.value)
            elif isinstance(code, ast.Name) and code.id in constants:
                found.add(constants[code.id])
            elif isinstance(code, ast.JoinedStr) and ast.unparse(code) == "f'encoding-{target}'":
                found |= {f"encoding-{t}" for t in registry.check_targets()}
            else:
                pytest.fail(f"{path.name}:{node.lineno}: a finding code this test cannot read: {ast.unparse(code)}")
    return found


def targets_listed(text: str) -> set[str]:
    return {f"encoding-{t}" for t in re.findall(r"`([a-z0-9-]+)`", text)} if text else set()


def test_the_findings_page_lists_exactly_the_codes_the_analysis_has() -> None:
    page = (DOCS / "findings.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"^## `([a-z-]+)` \{#", page, re.M))
    assert "encoding-TARGET" not in listed
    section = page[page.index("## `encoding-TARGET`") :]
    targets = targets_listed(section[section.index("The targets:") : section.index("```")])
    code = codes_in_code()
    assert "no-event-row" in code and "encoding-robopro" in code
    assert listed | targets == code


def test_checkings_table_lists_every_code_too() -> None:
    page = (DOCS / "checking.md").read_text(encoding="utf-8")
    table = page[page.index("| finding | level |") :]
    rows = set(re.findall(r"^\| `([a-zA-Z-]+)` \|", table[: table.index("\n\n")], re.M))
    assert "encoding-TARGET" in rows
    assert (rows - {"encoding-TARGET"}) | {c for c in codes_in_code() if c.startswith("encoding-")} == codes_in_code()


def test_each_findings_example_is_what_check_prints(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    page = (DOCS / "findings.md").read_text(encoding="utf-8")
    examples = re.findall(r"^```text\n\$ tablebot (check [^\n]+)\n(.*?)^```", page, re.M | re.S)
    assert len(examples) >= 11
    for argv, shown in examples:
        said = CliRunner().invoke(app, argv.split()).output.splitlines()
        for line in shown.splitlines():
            assert line in said, f"`tablebot {argv}` no longer prints: {line}"


def world_section_keys() -> dict[str, set[str]]:
    source = (ROOT / "src" / "tablebot" / "sim" / "model" / "world.py").read_text(encoding="utf-8")
    found = re.findall(r'known_keys\(src, \("(\w+)", \w+\), \w+, \(([^)]*)\)\)', source)
    return {section: set(re.findall(r'"(\w+)"', keys)) for section, keys in found}


def test_the_file_formats_page_names_every_key() -> None:
    page = (DOCS / "files.md").read_text(encoding="utf-8")
    named = set(re.findall(r"`\[*([\w.]+)\]*`", page))
    sections = world_section_keys()
    assert {"box", "line", "arena"} <= set(sections)
    plugins.load()  # every back-end's robot-file section registered
    keys = {
        *ROBOT_KEYS,
        *CORE_SECTIONS,
        *SECTION_READERS,
        *SENSOR_KEYS,
        *PROPERTY_KEYS,
        *WORLD_KEYS,
        *(k for ks in sections.values() for k in ks),
    }
    assert sorted(keys - named) == []


def test_the_version_is_the_packages_everywhere() -> None:
    """`--version` prints tablebot.__version__ (the wheel's version is read from it, test_version.py), and the
    site's footer shows it (scripts/docs_hooks.py)."""
    spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / "scripts" / "docs_hooks.py")
    assert spec is not None and spec.loader is not None
    hooks = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hooks)
    from mkdocs.config.defaults import MkDocsConfig

    config = MkDocsConfig()
    config.load_dict({"site_name": "tablebot"})
    assert hooks.on_config(config).copyright == f"tablebot {tablebot.__version__}"
    assert CliRunner().invoke(app, ["--version"]).output.strip() == f"tablebot {tablebot.__version__}"


TABLEBOT_LINE = re.compile(r"^\s*(?:\$ )?(?:\w+=\S+ )*tablebot (.*)$")


def mentioned_commands(text: str) -> list[str]:
    """Every `tablebot COMMAND ...` a page shows: a line of a code block (a synopsis's indented continuation
    lines joined to it) or an inline code span; the words after `tablebot`, comments dropped."""
    found = []
    for block in re.finditer(r"^```\w*\n(.*?)^```", text, re.M | re.S):
        body = re.sub(r"\n\s+(?=\[|--|\()", " ", block[1].replace("\\\n", " "))
        found += [m[1] for m in map(TABLEBOT_LINE.match, body.splitlines()) if m]
    found += re.findall(r"`tablebot ([^`]+)`", text.replace("\n", " "))
    return [line.split(" #")[0] for line in found]


def unknown_options(text: str) -> list[str]:
    """Options a page gives a command that the command does not have (a rename the page missed)."""
    import typer.main

    group = typer.main.get_command(app)
    commands = group.commands  # type: ignore[attr-defined]
    bad = []
    for line in mentioned_commands(text):
        words = line.split()
        if not words or words[0] not in commands:
            continue
        known = {"-h", "--help"}
        for param in commands[words[0]].params:
            known |= {*getattr(param, "opts", ()), *getattr(param, "secondary_opts", ())}
        bad += [
            f"tablebot {words[0]} {option}"
            for word in words[1:]
            for option in re.findall(r"(?<![\w-])(--?[a-z][\w-]*)", word)
            if option not in known
        ]
    return bad


def test_every_option_a_page_gives_a_command_exists() -> None:
    """Pages not run by the tests (synopses such as `tablebot sweep TABLE [--grid ...]`) still name only
    options their command has."""
    pages = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]
    checked = sum(len(mentioned_commands(p.read_text(encoding="utf-8"))) for p in pages)
    assert checked > 150
    bad = [f"{p.name}: {o}" for p in pages for o in unknown_options(p.read_text(encoding="utf-8"))]
    assert bad == []


def test_a_renamed_option_is_caught() -> None:
    page = (
        "```sh\ntablebot sweep TABLE [--world W ...] (--robots N | --seeds 0..9)\n"
        "               [--grid start=random] [--bogus 3]\n```\nthen `tablebot sim x --no-plots --colour`.\n"
    )
    assert unknown_options(page) == ["tablebot sweep --bogus", "tablebot sim --colour"]
