"""Nothing left untranslated outside the studio (issue 38 §3): in the pseudo-locale every translated text stands
between markers, so a word outside them is one nobody marked. Each case below is a bad input of its own kind (a
firmware stream, a HEX file, a share link, a challenge, a statechart, a robot file's [tables] and [board], a
property's condition, a controller's address) or a command's output (diagram, import, check of a robot of several
tables), run in-process like tests/i18n/test_i18n_catalog.py's help and command-line errors. The words allowed outside
the markers are the user's: the command line, and the names in the files the case wrote."""

from __future__ import annotations

import re
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest
import typer.main

from tablebot import i18n
from tablebot.cli.app import app
from tablebot.i18n import PSEUDO_OPEN
from test_i18n_catalog import names, outside, run_in, words

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"
SEVERAL = ROOT / "examples" / "bumberbot-lights"


def bumberbot(folder: Path, robot_extra: str = "", properties: str | None = None) -> Path:
    """The BumberBot copied into ``folder``, its robot file with ``robot_extra`` added, its properties replaced."""
    shutil.copytree(EXAMPLE, folder)
    robot = folder / "robot.toml"
    robot.write_text(robot.read_text(encoding="utf-8") + robot_extra, encoding="utf-8")
    if properties is not None:
        (folder / "properties.toml").write_text(properties, encoding="utf-8")
    return folder


def garbage(tmp: Path) -> list[str]:
    (tmp / "uart.bin").write_bytes(b"garbage\x55\x00\x01junk" * 3)
    return ["monitor", str(tmp / "uart.bin"), "--table", str(EXAMPLE)]


def not_hex(tmp: Path) -> list[str]:
    (tmp / "notes.hex").write_text("hello\n", encoding="utf-8")
    return ["flash", str(tmp / "notes.hex"), "--board", "uno", "--port", "/dev/ttyACM0", "--dry-run"]


def bad_link(tmp: Path) -> list[str]:
    (tmp / "links.txt").write_text("http://127.0.0.1:8765/#share=1.%%%\n", encoding="utf-8")
    return ["grade", "find-the-lamp", str(tmp / "links.txt"), "--out", str(tmp / "out")]


def no_challenge(tmp: Path) -> list[str]:
    return ["grade", str(tmp / "nowhere"), str(EXAMPLE)]


def doctype(tmp: Path) -> list[str]:
    (tmp / "chart.scxml").write_text('<?xml version="1.0"?><!DOCTYPE x><scxml/>', encoding="utf-8")
    return ["import", str(tmp / "chart.scxml"), "--from", "scxml"]


def wrong_root(tmp: Path) -> list[str]:
    (tmp / "chart.scxml").write_text('<?xml version="1.0"?><statechart/>', encoding="utf-8")
    return ["import", str(tmp / "chart.scxml"), "--from", "scxml"]


def not_json(tmp: Path) -> list[str]:
    (tmp / "machine.json").write_text('{"meta": {"tablebot": {"format": 99}}}', encoding="utf-8")
    return ["import", str(tmp / "machine.json"), "--from", "xstate"]


def bad_tables(tmp: Path) -> list[str]:
    folder = bumberbot(
        tmp / "robot",
        '\n[tables]\n"2nd" = { file = "table.csv", initial_timer = -1 }\n'
        'main = { file = "table.csv", match = "sometimes", colour = 1 }\n',
    )
    return ["check", str(folder)]


def bad_board(tmp: Path) -> list[str]:
    folder = bumberbot(tmp / "robot", '\n[board.uno]\nI3 = "d4"\nI4 = 4\nZ9 = "D5"\nactive_high = ["M1"]\n')
    return ["check", str(folder)]


def bad_conditions(tmp: Path) -> list[str]:
    props = (
        '[a]\nnever = "state === 3"\n[b]\nnever = "state == 99"\n[c]\nnever = "M1 > fast"\n'
        '[d]\nnever = "line == 9999"\n[e]\nnever = "(state == 1"\n[f]\nnever = "bogus"\n'
    )
    folder = bumberbot(tmp / "robot", properties=props)
    return ["check", str(folder)]


def bad_address(tmp: Path) -> list[str]:
    del tmp
    return ["run", str(EXAMPLE), "--on", "robotx://"]


def no_device(tmp: Path) -> list[str]:
    """A serial device that is not there: the link's own words (tablebot.hw.serial_port), then the hint."""
    return ["run", str(EXAMPLE), "--on", f"robotx://{tmp / 'ttyACM9'}"]


BAD: list[Callable[[Path], list[str]]] = [
    garbage,
    not_hex,
    bad_link,
    no_challenge,
    doctype,
    wrong_root,
    not_json,
    bad_tables,
    bad_board,
    bad_conditions,
    bad_address,
    no_device,
]


def user_words(tmp: Path) -> set[str]:
    """Every word of the files a case wrote (and of the examples it copied): the user's, not tablebot's."""
    return {
        w
        for folder in (tmp, EXAMPLE, SEVERAL)
        for path in folder.rglob("*")
        if path.is_file() and path.suffix in (".toml", ".csv", ".txt", ".scxml", ".json", ".hex")
        for w in re.findall(r"[A-Za-z]+", f"{path.name} {path.read_text(encoding='utf-8')}")
    }


def without_csv(text: str) -> str:
    """``text`` without the CSV grade prints (scores.csv: a data file, its words English like a trace's keys)."""
    kept, inside = [], False
    for line in text.splitlines():
        inside = inside or line.startswith("rank,name,score")
        inside = inside and "," in line and PSEUDO_OPEN not in line
        kept += [] if inside else [line]
    return "\n".join(kept)


def says_nothing_outside(args: list[str], tmp: Path) -> str:
    shown = without_csv(run_in(i18n.PSEUDO, args))
    allowed = (
        names(typer.main.get_command(app)) | user_words(tmp) | {w for a in args for w in re.findall(r"[A-Za-z]+", a)}
    )
    assert PSEUDO_OPEN in shown and words(outside(shown), allowed) == [], shown
    return shown


@pytest.mark.parametrize("case", BAD, ids=lambda case: case.__name__)
def test_bad_inputs_are_said_in_the_readers_language(case: Callable[[Path], list[str]], tmp_path: Path) -> None:
    args = case(tmp_path)
    shown = says_nothing_outside(args, tmp_path)
    assert "⟦error⟧" in shown or case is bad_link, shown  # grade says a bad submission's error in its CSV
    german = run_in("de", args)
    assert ("Fehler" in german or case is bad_link) and "error:" not in german, german


def labels(diagram: str) -> str:
    """What a diagram shows a reader: Mermaid's state and edge labels, Graphviz's labels without their HTML tags
    (the rest is the format's own syntax: digraph, fontname, stateDiagram-v2...)."""
    if diagram.startswith("stateDiagram"):
        return "\n".join(" ".join(parts) for parts in re.findall(r'^\s*state "(.*)" as|: (.*)$', diagram, re.M))
    return "\n".join(re.sub(r"<[^>]*>", " ", label) for label in re.findall(r"label=<(.*)>[ \]]", diagram))


def diagram_says_nothing_outside(args: list[str], tmp: Path) -> str:
    shown = labels(run_in(i18n.PSEUDO, args))
    allowed = user_words(tmp) | {w for a in args for w in re.findall(r"[A-Za-z]+", a)}
    assert PSEUDO_OPEN in shown and words(outside(shown), allowed) == [], shown
    return shown


def test_a_diagram_says_its_own_words_in_the_readers_language(tmp_path: Path) -> None:
    """Edge words (always, otherwise, or, forward, curve left...) and the legend; mermaid and dot."""
    for fmt in ("mermaid", "dot"):
        shown = diagram_says_nothing_outside(["diagram", str(EXAMPLE), "--format", fmt], tmp_path)
        assert "⟦stop⟧" in shown and "⟦ or ⟧" in shown, shown
    assert "Kurve rechts L5 R3" in run_in("de", ["diagram", str(EXAMPLE), "--format", "mermaid"])


def test_the_diagram_and_check_of_several_tables(tmp_path: Path) -> None:
    diagram_says_nothing_outside(["diagram", str(SEVERAL), "--format", "dot"], tmp_path)
    says_nothing_outside(["check", str(SEVERAL)], tmp_path)


def test_import_says_what_it_wrote(tmp_path: Path) -> None:
    chart = tmp_path / "machine.scxml"
    says_nothing_outside(["export", str(EXAMPLE), "--to", "scxml", str(tmp_path / "chart")], tmp_path)
    shutil.copy(next((tmp_path / "chart").glob("*.scxml")), chart)
    shown = says_nothing_outside(["import", str(chart), "--from", "scxml", "--out", str(tmp_path / "t.csv")], tmp_path)
    assert "⟦wrote" in shown, shown


def test_no_text_is_marked_where_the_extraction_cannot_see_it() -> None:
    """A ``_("...")`` inside an f-string's braces is translated in the pseudo-locale (every text is) but never
    reaches the catalog (Babel does not look inside f-strings), so German readers would read it in English."""
    import ast

    marks = {"_", "N_", "NP_", "gettext", "ngettext"}
    hidden = []
    for path in sorted((ROOT / "src" / "tablebot").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.JoinedStr):
                hidden += [
                    f"{path.relative_to(ROOT)}:{call.lineno}"
                    for call in ast.walk(node)
                    if isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.func.id in marks
                ]
    assert hidden == [], "mark the text outside the f-string: " + ", ".join(hidden)


# --- the files a command writes for people to read: evolve's report.md and check reports, tune's report.md --------

LINE = ROOT / "examples" / "line-follower"
#: The measures' names: option values a user types (--objective laps), never translated.
MEASURE_NAMES = {
    "time_to_lamp",
    "time_to_light",
    "missed_lamp",
    "lamp_distance",
    "collisions",
    "collision_share",
    "distance",
    "area_covered",
    "laps",
}


def evolve_args(folder: Path, out: Path) -> list[str]:
    """The tiniest evolve that writes every file: 2 tables, 2 seeds of 1 s, 2 fresh ones, proved in this process."""
    return [
        "evolve",
        str(folder),
        "--budget",
        "2",
        "--batch",
        "2",
        "--seeds",
        "0..1",
        "--check-seeds",
        "1000..1001",
        "--seconds",
        "1",
        "--workers",
        "1",
        "--out",
        str(out),
        "-q",
    ]


def tune_args(out: Path) -> list[str]:
    return [
        "tune",
        str(EXAMPLE),
        "--cells",
        "line 5 timer",
        "--budget",
        "3",
        "--seeds",
        "0..1",
        "--check-seeds",
        "1000..1003",
        "--seconds",
        "2",
        "--out",
        str(out),
        "-q",
    ]


def written_words(out: Path) -> set[str]:
    """The names of the files a run wrote (best-1.csv, elites/cell-07-00.csv, archive.png): the command's own."""
    return {w for path in out.rglob("*") for w in re.findall(r"[A-Za-z]+", str(path.relative_to(out)))}


def file_says_nothing_outside(path: Path, args: list[str], tmp: Path) -> None:
    shown = path.read_text(encoding="utf-8")
    allowed = (
        names(typer.main.get_command(app))
        | user_words(tmp)
        | written_words(path.parent)
        | MEASURE_NAMES
        | {w for a in args for w in re.findall(r"[A-Za-z]+", a)}
    )
    assert PSEUDO_OPEN in shown and words(outside(shown), allowed) == [], f"{path.name}:\n{shown}"


def test_evolves_report_and_check_reports_are_marked(tmp_path: Path) -> None:
    folder = tmp_path / "robot"
    shutil.copytree(LINE, folder)  # its words (state names, properties) are the user's
    args = evolve_args(folder, tmp_path / "out")
    run_in(i18n.PSEUDO, args)
    for path in [tmp_path / "out" / "report.md", *sorted((tmp_path / "out").rglob("*.check.txt"))]:
        file_says_nothing_outside(path, args, tmp_path)


def test_tunes_report_is_marked(tmp_path: Path) -> None:
    args = tune_args(tmp_path / "out")
    run_in(i18n.PSEUDO, args)
    file_says_nothing_outside(tmp_path / "out" / "report.md", args, tmp_path)


def csv_numbers_keep_the_point(path: Path) -> None:
    """Every number of a CSV file reads as Python's float: a German run's data has no decimal comma."""
    import csv

    rows = list(csv.DictReader(path.open(encoding="utf-8")))
    numbers = [value for row in rows for key, value in row.items() if key != "key"]
    assert numbers and all(re.fullmatch(r"-?\d+(\.\d+)?(e-?\d+)?", v) for v in numbers), path.read_text("utf-8")


def test_german_reports_write_decimal_commas_and_their_data_the_point(tmp_path: Path) -> None:
    """A German reader reads 0,125 in report.md; evaluations.csv and the JSON records stay Python's (0.125)."""
    import json

    run_in("de", evolve_args(LINE, tmp_path / "ev"))
    report = (tmp_path / "ev" / "report.md").read_text(encoding="utf-8")
    assert "## Vorher und nachher" in report and re.search(r"\| -?\d+,\d{3} \|", report), report
    assert not re.search(r"\| -?\d+\.\d{3} \|", report), report
    csv_numbers_keep_the_point(tmp_path / "ev" / "evaluations.csv")
    for line in (tmp_path / "ev" / "evaluations.jsonl").read_text(encoding="utf-8").splitlines():
        assert all(isinstance(v, float | int) for v in json.loads(line)["means"].values())
    run_in("de", tune_args(tmp_path / "tune"))
    report = (tmp_path / "tune" / "report.md").read_text(encoding="utf-8")
    assert "| time_to_lamp (Ziel) | " in report and re.search(r"\| \d+,\d{3} \| \d+,\d{3} \|", report), report
    csv_numbers_keep_the_point(tmp_path / "tune" / "evaluations.csv")


def test_the_leaderboards_counterexample_is_in_the_readers_language(tmp_path: Path) -> None:
    """grade's leaderboard.html told a broken rule's story in English (its steps are messages, joined as text)."""
    run_in("de", ["grade", "find-the-lamp", str(EXAMPLE), "--out", str(tmp_path / "de")])
    page = (tmp_path / "de" / "leaderboard.html").read_text(encoding="utf-8")
    assert "Zeile 19 (Collision Rear) schaltet" in page and "fires:" not in page, page
