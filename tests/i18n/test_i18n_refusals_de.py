"""The refusals a German user meets first, said in German (issue 38): each once gave its words in English inside a
German line ("OUTDIR: Fehler: --to c needs a folder to write into"); the live view's are in test_i18n_live_view.py."""

from __future__ import annotations

import shutil
from pathlib import Path

from test_i18n_catalog import run_in

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "bumberbot"


def test_export_without_a_folder_says_so_in_german() -> None:
    shown = run_in("de", ["export", str(EXAMPLE), "--to", "c"])
    assert "OUTDIR: Fehler: --to c braucht einen Ordner, in den geschrieben wird" in shown, shown
    assert "Tipp: tablebot export TABELLE AUSGABEORDNER --to c" in shown


def test_writing_over_a_link_is_refused_in_german(tmp_path: Path) -> None:
    victim, out = tmp_path / "victim.txt", tmp_path / "out"
    victim.write_text("mine\n")
    out.mkdir()
    (out / "trace.jsonl").symlink_to(victim)
    shown = run_in("de", ["sim", str(EXAMPLE), "--out", str(out), "--seconds", "1", "--no-plots"])
    assert f"Fehler: trace.jsonl ist ein symbolischer Link (auf {victim}): tablebot schreibt nie durch" in shown, shown
    assert "Tipp: den Link entfernen" in shown and victim.read_text() == "mine\n"


def test_a_start_in_a_box_is_refused_in_german_with_german_numbers(tmp_path: Path) -> None:
    robot = tmp_path / "bot"
    shutil.copytree(EXAMPLE, robot)
    arena = robot / "arena.toml"
    arena.write_text(arena.read_text(encoding="utf-8").replace("at = [0.35, 0.35]", "at = [1.25, 0.95]", 1))
    shown = " ".join(run_in("de", ["sim", str(robot), "--seconds", "1", "--no-plots"]).split())
    assert "Fehler: der Roboter in seiner Startpose (1,25, 0,95, Richtung 20°) überlappt eine Wand oder ein" in shown
    assert "Tipp: [start] at verschieben oder mit heading drehen" in shown, shown


def test_a_robot_files_sim_and_robopro_sections_are_refused_in_german(tmp_path: Path) -> None:
    robot = tmp_path / "bot"
    shutil.copytree(EXAMPLE, robot)
    with (robot / "robot.toml").open("a", encoding="utf-8") as extra:
        extra.write('\n[sim]\nworld = 3\n\n[robopro]\ncontroller = "c64"\nM1 = "X9"\n')
    shown = run_in("de", ["check", str(robot)])
    assert "Fehler: [robopro] controller = 'c64' ist keiner, den ROBO Pro hier ansteuert" in shown, shown
    assert "Fehler: [robopro] M1: 'X9' ist kein Anschluss (Motor) des Controllers" in shown
    assert 'Tipp: output = "M1" … "M4" schreiben' in shown
    assert "Fehler: sim.world muss ein Dateiname sein" in shown


def test_the_robo_pro_program_export_says_what_it_wrote_in_german(tmp_path: Path) -> None:
    shown = run_in("de", ["export", str(EXAMPLE), str(tmp_path / "out"), "--to", "robopro-program"])
    assert "geschrieben: in ROBO Pro 4.x öffnen" in shown and "open it" not in shown, shown


def test_a_motor_too_weak_for_its_calibration_spin_is_refused_in_german(tmp_path: Path) -> None:
    robot = tmp_path / "bot"
    shutil.copytree(EXAMPLE, robot)
    with (robot / "arena.toml").open("a", encoding="utf-8") as extra:
        extra.write("\n[motor]\nfriction_volts = 5\n")
    shown = run_in("de", ["sim", str(robot), "--seconds", "1", "--no-plots"])
    assert "Fehler: die Tempostufe der Kalibrierdrehung überwindet friction_volts nicht" in shown, shown
    assert "Tipp: den Wert in der Welt- oder Roboterdatei korrigieren" in shown
