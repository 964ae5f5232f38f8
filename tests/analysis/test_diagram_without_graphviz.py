"""Diagrams with no system Graphviz (issue 34): `tablebot diagram` (SVG and PNG) and the studio's diagram are
drawn by graphviz-pure, a dependency from PyPI, with no `dot` on PATH. With no Graphviz at all (a Python
environment without graphviz-pure, as where it has no wheel) the command says what to install and the
studio's diagram panel says so in the page; there a system `dot` still draws.

Every case runs tablebot as a user does, as a process: on PATH an empty folder (or one holding only `dot`),
so no Graphviz of the machine's is found by accident.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import sysconfig
import time
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import pytest
from PIL import Image

from core_helpers import EXAMPLE

pytestmark = [pytest.mark.browser]

SVG = "{http://www.w3.org/2000/svg}"
STATES = {"s_1", "s_2", "s_11", "s_12", "s_20", "s_21", "s_22", "s_24", "s_26", "s_29"}  # the BumberBot's
CHROMIUM = Path("/usr/bin/chromium")
FLAGS = [
    "--headless=new",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-dev-shm-usage",
    "--no-first-run",
    "--disable-extensions",
]


@pytest.fixture(scope="module")
def bare(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """An environment whose PATH is an empty folder, and whose user scripts folder (``pip install --user``)
    is empty too."""
    root = tmp_path_factory.mktemp("bare")
    (root / "bin").mkdir()
    return {**os.environ, "PATH": str(root / "bin"), "PYTHONUSERBASE": str(root / "user")}


@pytest.fixture(scope="module")
def no_packaged(tmp_path_factory: pytest.TempPathFactory) -> str:
    """The python of a new virtual environment that sees tablebot and its packages (this one's, through a
    .pth file) but has no graphviz-pure command in its scripts folder: tablebot where graphviz-pure is
    not installed."""
    venv = tmp_path_factory.mktemp("no-graphviz-pure") / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    python = venv / ("Scripts" if os.name == "nt" else "bin") / Path(sys.executable).name
    site = subprocess.run(
        [python, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    ours = sysconfig.get_path("purelib")
    Path(site, "tablebot-packages.pth").write_text(f"import site; site.addsitedir({ours!r})\n")
    assert not list(python.parent.glob("graphviz-pure*"))
    return str(python)


def tablebot(python: str, env: dict[str, str], *args: object) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [python, "-m", "tablebot", *map(str, args)], env=env, capture_output=True, text=True, timeout=120, check=False
    )


def node_titles(svg: bytes | str) -> set[str]:
    root = ET.fromstring(svg)
    return {g.findtext(f"{SVG}title") or "" for g in root.iter(f"{SVG}g") if g.get("class") == "node"}


def test_diagram_draws_svg_and_png_with_no_dot_on_path(bare: dict[str, str], tmp_path: Path) -> None:
    assert shutil.which("dot", path=bare["PATH"]) is None
    for fmt in ("svg", "png"):
        done = tablebot(sys.executable, bare, "diagram", EXAMPLE, "--out", tmp_path / f"bb.{fmt}")
        assert done.returncode == 0, done.stderr
    svg = (tmp_path / "bb.svg").read_bytes()
    assert b"(graphviz-pure)" in svg and node_titles(svg) >= STATES
    assert "Collision entry" in " ".join(e.text or "" for e in ET.fromstring(svg).iter(f"{SVG}text"))
    with Image.open(tmp_path / "bb.png") as png:
        assert png.format == "PNG" and png.width > 1000 and png.height > 1500  # 150 dpi, as with dot


def test_with_no_graphviz_at_all_the_command_says_what_to_install(
    no_packaged: str, bare: dict[str, str], tmp_path: Path
) -> None:
    done = tablebot(no_packaged, bare, "diagram", EXAMPLE, "--out", tmp_path / "bb.svg")
    assert done.returncode == 2 and not (tmp_path / "bb.svg").exists()
    said = " ".join(done.stderr.split())
    assert "no Graphviz to draw the diagram: neither graphviz-pure nor dot was found" in said, said
    assert "pip install graphviz-pure" in said and "--format mermaid" in said and "Traceback" not in said
    mermaid = tablebot(no_packaged, bare, "diagram", EXAMPLE, "--format", "mermaid")
    assert mermaid.returncode == 0 and mermaid.stdout.startswith("stateDiagram-v2")


def test_a_system_dot_draws_where_graphviz_pure_is_missing(
    no_packaged: str, bare: dict[str, str], tmp_path: Path
) -> None:
    dot = shutil.which("dot")
    if dot is None:
        pytest.skip("no system Graphviz here (scripts/bootstrap.sh installs one)")
    (tmp_path / "bin").mkdir()
    (tmp_path / "bin" / "dot").symlink_to(dot)
    done = tablebot(no_packaged, {**bare, "PATH": str(tmp_path / "bin")}, "diagram", EXAMPLE, "--format", "svg")
    assert done.returncode == 0, done.stderr
    assert "Generated by graphviz" in done.stdout and "(graphviz-pure)" not in done.stdout
    assert node_titles(done.stdout) >= STATES


# --- the studio, in a real Chromium ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def browser() -> Iterator[object]:
    sync_api = pytest.importorskip("playwright.sync_api", reason="the browser tests need playwright (pip)")
    if not CHROMIUM.exists():
        if os.environ.get("CI"):  # CI runs scripts/bootstrap.sh, which installs it: missing there is a failure
            raise RuntimeError("/usr/bin/chromium is missing: scripts/bootstrap.sh should have installed it")
        pytest.skip("the browser tests need Debian's chromium (scripts/bootstrap.sh installs it)")
    with sync_api.sync_playwright() as p:
        chromium = p.chromium.launch(executable_path=str(CHROMIUM), args=FLAGS)
        yield chromium
        chromium.close()


def address(process: subprocess.Popen[str]) -> str:
    """The address ``tablebot studio`` printed (with its token)."""
    assert process.stderr is not None
    printed = ""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        line = process.stderr.readline()
        printed += line
        found = re.search(r"http://\S+/\?token=\S+", line)
        if found:
            return found[0]
        assert line or process.poll() is None, printed
    raise AssertionError(f"no address printed: {printed}")


def studio_diagram(browser: object, python: str, env: dict[str, str], folder: Path) -> tuple[str, str]:
    """Start ``tablebot studio`` on a copy of the BumberBot as a user does, open its page and wait for the
    diagram panel to fill: its inner HTML, and its text."""
    shutil.copytree(EXAMPLE, folder)
    process = subprocess.Popen(
        [python, "-m", "tablebot", "studio", str(folder), "--port", "0", "--no-browser"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        url = address(process)
        context = browser.new_context()  # type: ignore[attr-defined]
        page = context.new_page()
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(url)
        try:  # minutes only where numba compiles the simulator first (a cold cache)
            page.wait_for_selector("#diagram .diagram-view > *", timeout=120_000)
        except Exception as exc:
            process.kill()
            raise AssertionError(f"no diagram shown; the studio said: {process.communicate()[1][-3000:]}") from exc
        # the drawing (or the studio's words) is in the panel's view, beside its zoom buttons
        shown = page.inner_html("#diagram .diagram-view"), page.inner_text("#diagram .diagram-view")
        context.close()
        assert errors == []
        return shown
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)
            try:
                process.communicate(timeout=20)
            except subprocess.TimeoutExpired:
                process.kill()
                process.communicate()


def test_the_studio_draws_its_diagram_with_no_dot_on_path(
    browser: object, bare: dict[str, str], tmp_path: Path
) -> None:
    html, _ = studio_diagram(browser, sys.executable, bare, tmp_path / "bot")
    assert html.startswith("<svg") and set(re.findall(r"<title>(s_\d+)</title>", html)) >= STATES


def test_with_no_graphviz_at_all_the_studio_says_so_in_the_diagram_panel(
    browser: object, no_packaged: str, bare: dict[str, str], tmp_path: Path
) -> None:
    html, text = studio_diagram(browser, no_packaged, bare, tmp_path / "bot")
    assert "<svg" not in html
    said = " ".join(text.split())
    assert said.startswith("No diagram: neither graphviz-pure nor dot was found. To draw it: pip install")
    assert "pip install graphviz-pure" in said and "reopen the table" in said
