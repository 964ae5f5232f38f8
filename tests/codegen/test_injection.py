"""Hostile names, descriptions, state names, input labels and property texts through every exporter: each
output parses in its own language's real reader and holds no injected construct (issue 14)."""

from __future__ import annotations

import json
import re
import shlex
import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from hostile import EVIL_SYMBOL, HOSTILE, INJECTED, STATES, robot_toml, write_project
from tablebot.cli import app

pytestmark = [pytest.mark.kernel_free]

if TYPE_CHECKING:
    from typer.testing import Result

RPP = Path(__file__).resolve().parents[1] / "fixtures" / "rpp" / "engine.rpp"
SVG = "{http://www.w3.org/2000/svg}"
runner = CliRunner()
needs = {
    tool: pytest.mark.skipif(shutil.which(tool) is None, reason=f"{tool} is not installed")
    for tool in ("gcc", "avr-gcc", "dot")
}


@pytest.fixture
def project(tmp_path: Path) -> Path:
    """The hostile project in a folder whose own name ends a C comment (``a*/``)."""
    return write_project(tmp_path / "a*" / "p")


def run(*args: object, code: int = 0) -> Result:
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    assert result.exit_code == code, result.output
    return result


def code_only(path: Path, compiler: str = "gcc") -> str:
    """A C file with its comments removed by the compiler's own preprocessor: what the compiler sees."""
    done = subprocess.run(
        [compiler, "-std=c99", "-fpreprocessed", "-dD", "-E", "-P", "-x", "c", str(path)],
        capture_output=True,
        text=True,
        check=True,
    )
    return done.stdout


def assert_clean(text: str) -> None:
    found = [word for word in INJECTED if word in text]
    assert not found, f"injected {found}"


@needs["gcc"]
def test_c_export_compiles_and_holds_no_injection(project: Path, tmp_path: Path) -> None:
    from tablebot.cli.common import load
    from tablebot.codegen.host import build_host

    out = tmp_path / "c"
    run("export", project, out, "--to", "c")
    for name in ("tb_config.h", "tb_table.c"):
        assert_clean(code_only(out / name))
        assert "tb_evil_boot" in (out / name).read_text() or name == "tb_config.h"  # kept, inside a comment
    _, machine = load(project)
    build_host(machine, tmp_path / "host")  # -Wall -Wextra -pedantic -Werror


@needs["avr-gcc"]
@pytest.mark.parametrize("name", [HOSTILE[0], HOSTILE[1], HOSTILE[3], HOSTILE[4]])
def test_firmware_board_header_keeps_the_robot_name_inert(project: Path, tmp_path: Path, name: str) -> None:
    """The reproduced injection: a robot name ending the comment of tb_board.h with a constructor
    after it built and ran at boot; one with #include printed another file during the build."""
    (project.parent / "robot.toml").write_text(robot_toml(name), encoding="utf-8")
    out = tmp_path / "fw"
    result = run("build", project, "--board", "uno", "--out", out)
    assert "/etc/hostname" not in result.output
    assert_clean(code_only(out / "src" / "tb_board.h", "avr-gcc"))
    symbols = subprocess.run(["avr-nm", str(out / "tablebot.elf")], capture_output=True, text=True, check=True)
    assert EVIL_SYMBOL not in symbols.stdout


def test_robopro_lists_and_import_round_trip(project: Path, tmp_path: Path) -> None:
    out = tmp_path / "lists"
    run("export", project, out, "--to", "robopro")
    names = (out / "states.csv").read_text(encoding="utf-8")
    assert all(state in names for state in STATES if not state.isdigit())
    back = tmp_path / "back.csv"
    run("import", out, "--from", "robopro", "--robot", project.parent / "robot.toml", "--out", back)
    assert set(STATES) <= set(re.findall(r"^,([^,]+),", back.read_text(encoding="utf-8"), re.M))


def test_rpp_parses_as_xml(project: Path, tmp_path: Path) -> None:
    out = tmp_path / "rpp"
    run("export", project, out, "--to", "robopro-rpp", "--into", RPP)
    root = ET.parse(out / RPP.name).getroot()
    assert not [e for e in root.iter() if e.tag == "evil"]
    values = [init.attrib["value"] for o in root.iter("o") if o.get("name") == "Event" for init in o.iter("init")]
    assert len(values) == len(HOSTILE) and all(v.isdigit() for v in values)


@needs["dot"]
def test_diagram_dot_and_svg(project: Path, tmp_path: Path) -> None:
    dot_file = tmp_path / "d.dot"
    run("diagram", project, "--out", dot_file)
    svg = subprocess.run(["dot", "-Tsvg", str(dot_file)], capture_output=True, check=True).stdout
    run("diagram", project, "--out", tmp_path / "d.svg")
    for data in (svg, (tmp_path / "d.svg").read_bytes()):
        root = ET.fromstring(data)
        assert not [e for e in root.iter() if e.tag.removeprefix(SVG) in ("evil", "b", "script")]
        texts = " ".join(e.text or "" for e in root.iter(f"{SVG}text"))
        assert "</init><evil/><![CDATA[x]]> & <b>bold</b>" in texts  # the input label, as text
        assert "*/ __attribute__((constructor))" in texts  # the robot name in the title


MERMAID_LINE = re.compile(r'^    (state "[^"\n]*" as \w+|\[\*\] --> \w+|\w+ --> \w+: [^:;\n]+|direction LR)$')


def test_mermaid_has_only_its_own_statements(project: Path) -> None:
    text = run("diagram", project, "--format", "mermaid").stdout
    lines = text.splitlines()
    assert lines[0] == "stateDiagram-v2" and lines[1] == "    direction LR"
    bad = [line for line in lines[1:] if not MERMAID_LINE.match(line)]
    assert not bad
    assert len([line for line in lines if " state " in f" {line.strip()}"]) == len(STATES)
    assert not [line for line in lines[2:] if re.search(r"(?i)direction\s+(tb|bt|rl|lr)", line)]
    assert not re.search(r"#\w+;|%%|<|>", text.replace("-->", ""))


def test_check_prints_user_text_literally(project: Path, tmp_path: Path) -> None:
    result = run("check", project, "--verbose", "--counterexamples", tmp_path / "cex")
    out = result.stdout
    assert "[bold]markup[/bold] :x: [/]" in out and "\u274c" not in out  # no markup, no emoji
    assert "\x1b" not in out and "\x07" not in out and "\x00" not in out
    assert "\\x1b[31mred\\x07\\x00nul" in out  # controls shown, not sent
    report = json.loads(run("check", project, "--format", "json").stdout)
    assert report["robot"] == HOSTILE[0]
    assert {p["text"] for p in report["properties"]} == set(HOSTILE)


def test_bad_input_diagnostics_print_literally(tmp_path: Path) -> None:
    (tmp_path / "robot.toml").write_text(robot_toml(), encoding="utf-8")
    (tmp_path / "t.csv").write_text("state,[bold]x[/bold] :x:,next\n1,,1\n", encoding="utf-8")
    result = run("check", tmp_path / "t.csv", code=2)
    assert "unknown column '[bold]x[/bold] :x:'" in result.stderr


def test_golden_tests_and_trace_are_data(project: Path, tmp_path: Path) -> None:
    run("tests", project, "--out", tmp_path / "golden")
    json.loads((tmp_path / "golden" / "coverage.json").read_text(encoding="utf-8"))
    inputs = next((tmp_path / "golden").glob("*.csv"))
    trace = run("trace", project, "--inputs", inputs).stdout
    states = {json.loads(line)["state"] for line in trace.splitlines()}
    assert states <= set(STATES)


def test_flash_dry_run_prints_a_command_a_shell_reads_back(tmp_path: Path) -> None:
    port = "$(touch pwned) `id`; rm -rf ~ \x1b[31m"
    hexfile = tmp_path / "a b;$(x).hex"
    hexfile.write_text(":00000001FF\n")
    result = run("flash", hexfile, "--board", "uno", "--port", port, "--dry-run")
    printed = result.stdout.strip()
    assert "\x1b" not in printed
    argv = subprocess.run(
        ["bash", "-c", f'for a in {printed}; do printf "%s\\0" "$a"; done'],
        capture_output=True,
        check=True,
        cwd=tmp_path,
    ).stdout.split(b"\0")[:-1]
    assert argv[argv.index(b"-P") + 1] == port.encode()
    assert argv[-1] == f"flash:w:{hexfile}:i".encode()
    assert not (tmp_path / "pwned").exists()
    assert shlex.split(printed)[0] == "avrdude"
