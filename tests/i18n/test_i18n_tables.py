"""Tables in German (issue 38 §2): German header names and decimal-comma times, read whatever the reader's
language; a German table and its English twin give the same trace, byte for byte."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tablebot.diagnostics import TableBotError
from tablebot.durations import DurationError, to_ticks
from tablebot.formats.table_read import load_table
from tablebot.i18n import PSEUDO_CLOSE, PSEUDO_OPEN, use
from tablebot.testing.processes import child_env

ROOT = Path(__file__).resolve().parents[2]
BUMBERBOT = ROOT / "examples" / "bumberbot"
GERMAN = {
    "description": "Beschreibung",
    "state": "ZUSTAND",
    "timer": "Timer",
    "next": "folgezustand",
    "M1_dir": "M1_Richtung",
    "M1_speed": "M1_tempo",
    "M2_dir": "M2_richtung",
    "M2_speed": "M2_Tempo",
}


def twins(folder: Path) -> tuple[Path, Path]:
    """The BumberBot's table in English (timers as times with a decimal point, comma-separated) and in German
    (German header, decimal commas, semicolon-separated as German Excel saves it), each beside the robot file."""
    lines = (BUMBERBOT / "table.csv").read_text().splitlines()
    header = lines[0].split(",")
    at = header.index("timer")
    rows = [line.split(",") for line in lines[1:]]
    english, german = folder / "en", folder / "de"
    for side in (english, german):
        side.mkdir()
        shutil.copy(BUMBERBOT / "robot.toml", side / "robot.toml")
    timed = [[*row[:at], f"{int(row[at]) / 100:g} s", *row[at + 1 :]] for row in rows]  # 50 -> "0.5 s"
    (english / "table.csv").write_text("\n".join(",".join(r) for r in [header, *timed]) + "\n")
    german_rows = [[*r[:at], r[at].replace(".", ",").replace(" s", "s"), *r[at + 1 :]] for r in timed]
    german_header = [GERMAN.get(name, name) for name in header]
    (german / "table.csv").write_text("\n".join(";".join(r) for r in [german_header, *german_rows]) + "\n")
    return english / "table.csv", german / "table.csv"


SMALL_ROBOT = 'name = "Small"\ntick_ms = 10\ninitial_state = 1\n[inputs]\nI3 = "bumper"\n[motors]\nM1 = "drive"\n'


def trace(table: Path, *lang: str) -> bytes:
    done = subprocess.run(
        [sys.executable, "-m", "tablebot", *lang, "trace", str(table), "--inputs", str(BUMBERBOT / "inputs.csv")],
        capture_output=True,
        env=child_env(),
        cwd=ROOT,
    )
    assert done.returncode == 0, done.stderr.decode()
    return done.stdout


def test_a_german_table_traces_as_its_english_twin(tmp_path: Path) -> None:
    english, german = twins(tmp_path)
    assert ",5s;" in german.read_text() and "Folgezustand".lower() in german.read_text().lower()
    same = trace(english)
    assert same and trace(german) == same  # the German table, in an English reader's process
    assert trace(german, "--lang", "de") == same  # and in a German one: a table's meaning is no reader's


def test_german_headers_read_as_english_ones(tmp_path: Path) -> None:
    english, german = twins(tmp_path)
    use("de")
    try:
        ours, theirs = load_table(german), load_table(english)
    finally:
        use("en")
    assert ours.rows == theirs.rows and ours.events == theirs.events
    assert [r.timer for r in ours.rows][:2] == [50, 50]


def test_a_decimal_comma_in_a_comma_separated_table_is_read_when_quoted(tmp_path: Path) -> None:
    (tmp_path / "robot.toml").write_text(SMALL_ROBOT)
    table = tmp_path / "table.csv"
    table.write_text('Zustand,I3,M1_Richtung,M1_Tempo,Timer,Folgezustand\n1,1,,2,"1,25 s",2\n2,,,0,"0,5s",1\n')
    rows = load_table(table).rows
    assert [r.timer for r in rows] == [125, 50]


@pytest.mark.parametrize(("text", "ticks"), [("0,5s", 50), ("1,25 s", 125), (",5 s", 50), ("2,ms", 0)])
def test_decimal_comma_durations(text: str, ticks: int) -> None:
    if ticks:
        assert to_ticks(text, 10) == ticks
    else:
        with pytest.raises(DurationError):
            to_ticks(text, 10)


def test_a_bad_time_names_the_forms_accepted_in_both_languages(tmp_path: Path) -> None:
    (tmp_path / "robot.toml").write_text(SMALL_ROBOT)
    table = tmp_path / "table.csv"
    table.write_text("Zustand;I3;Timer;Folgezustand\n1;1;0.5 Sekunden;2\n2;;0;1\n")
    with pytest.raises(TableBotError) as caught:
        load_table(table)
    (found,) = caught.value.diagnostics
    assert (found.line, found.column) == (2, 5)
    assert "500ms, 0.5s or 0,5s" in found.render()
    german = found.render("de")
    assert "keine Zeitangabe" in german and "0,5s" in german and "Tipp:" in german and "Fehler" in german


def outside(text: str) -> str:
    """What ``text`` says outside the pseudo-locale's markers (they nest)."""
    depth, kept = 0, []
    for ch in text:
        depth += (ch == PSEUDO_OPEN) - (ch == PSEUDO_CLOSE)
        if depth == 0 and ch not in (PSEUDO_OPEN, PSEUDO_CLOSE):
            kept.append(ch)
    return "".join(kept)


HEAD = "description,state,I3,M1_dir,M1_speed,timer,next\n"
#: Bad tables (the hardening cases of the table reader), each with a word that must stay as the file wrote it.
BAD_TABLES = [
    "",
    HEAD,
    "state,I9,next\n1,,1\n",
    "state,state,next\n1,1,1\n",
    "description,state,I3\n1,1,1\n",
    HEAD + "a,1,x,,2,0,1\n",
    HEAD + "a,1,7,,2,0,1\n",
    HEAD + "a,1,,,2,70000,1\n",
    HEAD + "a,1,,,2,0.505s,1\n",
    HEAD + "a,1,,,2,11 minutes,1\n",
    HEAD + "a,1,,,2,0,\n",
    HEAD + "a,-3,,,2,0,1\n",
    HEAD + "a,1,,,2,0,9\n",
    HEAD + "a,1,,,2,0,'bad'\n",
    HEAD + "a,1,,,2,1000s,1\n",
    "state,M1,M1_dir,M1_speed,next\n1,1,,2,1\n",
    "state,M1_dir,next\n1,1,1\n",
    "state,next\n" + "1" * 200 + ",1\n",
]


@pytest.mark.parametrize("text", BAD_TABLES, ids=range(len(BAD_TABLES)))
def test_bad_tables_are_explained_in_the_readers_language(tmp_path: Path, text: str) -> None:
    (tmp_path / "robot.toml").write_text(SMALL_ROBOT)
    table = tmp_path / "table.csv"
    table.write_text(text)
    with pytest.raises(TableBotError) as caught:
        load_table(table)
    for found in caught.value.diagnostics:
        shown = found.render("pseudo").split(": ", 1)[1]  # after the file's place
        rest = re.sub(r"'[^']*'|\b\w*\d\w*\b|robot\.toml|BumberBot|Small", "", outside(shown))  # data and names
        assert not re.search(r"[A-Za-z]{3,}", rest.replace("table.csv", "")), shown
        german = found.render("de")
        assert ": Fehler: " in german and str(found.message) not in german, german


def test_a_table_written_in_german_reads_back_the_same() -> None:
    from tablebot.formats.table_read import parse_table
    from tablebot.formats.table_write import format_table

    table = load_table(BUMBERBOT / "table.csv")
    german = format_table(table, "de")
    assert german.startswith(
        "Beschreibung,Zustand,T,I3,I4,I5,I7,I8,M1_Richtung,M1_Tempo,M2_Richtung,M2_Tempo,Timer,Folgezustand\n"
    )
    assert parse_table(german, "de.csv", table.robot).rows == table.rows
    assert format_table(table) == format_table(table, "en") and format_table(table).startswith("description,state,")


def test_new_writes_a_german_table_when_asked(tmp_path: Path) -> None:
    def new(folder: str, *args: str, **env: str) -> str:
        done = subprocess.run(
            [sys.executable, "-m", "tablebot", "new", str(tmp_path / folder), *args],
            capture_output=True,
            text=True,
            env=child_env(**env),
            cwd=ROOT,
        )
        assert done.returncode == 0, done.stderr
        return done.stdout

    said = new("de", "--lang", "de", "--inputs", "I1", "--motors", "M1,M2")
    assert said.startswith(f"{tmp_path / 'de'} angelegt aus einem leeren Roboter:")
    text = (tmp_path / "de" / "table.csv").read_text()
    assert text.startswith("Beschreibung,Zustand,T,I1,M1,M2,Timer,Folgezustand\n") and "losfahren" in text
    assert [r.timer for r in load_table(tmp_path / "de" / "table.csv").rows] == [800, 70]
    new("system", "--inputs", "I1", LANG="de_DE.UTF-8")  # German words, but the file in English: not asked for
    assert (tmp_path / "system" / "table.csv").read_text().startswith("description,state,T,I1,")


BAD_ROBOTS = [
    "name = 1\n[motors]\nM1 = 2\n",
    "tick_ms = 0\ninitial_state = 1\n[motors]\nM1 = 'm'\n",
    "initial_state = 1\n",
    "initial_state = 1\nmatch = 'sometimes'\n[inputs]\nI1 = 'a'\n[motors]\nI1 = 'b'\n",
    "initial_state = 1\n[motors]\nM1 = 'm'\n[counters]\nC1 = 'M9'\n",
    "initial_state = 1\n[motors]\nM1 = 'm'\n[wiring]\n",
    "initial_state = 1\n[motors]\nZustand = 'm'\n",
    "initial_state = 1\n[motors\n",
    "initial_state = 1\nx = = 2\n",
    "initial_state = 1\n[motors]\nM1 = 'm'\nname = 'late'\n",
    "initial_state = [1]\n[states]\nx-y = 3\n",
]


@pytest.mark.parametrize("text", BAD_ROBOTS, ids=range(len(BAD_ROBOTS)))
def test_bad_robot_files_are_explained_in_the_readers_language(tmp_path: Path, text: str) -> None:
    from tablebot.robot import load_robot

    robot = tmp_path / "robot.toml"
    robot.write_text(text)
    with pytest.raises(TableBotError) as caught:
        load_robot(robot)
    for found in caught.value.diagnostics:
        shown = found.render("pseudo").split(": ", 1)[1]
        rest = re.sub(r"'[^']*'|\b\w*\d\w*\b|robot\.toml|\bx\b|\by\b", "", outside(shown))
        assert not re.search(r"[A-Za-z]{3,}", rest), shown
        assert ": Fehler: " in found.render("de"), found.render("de")
