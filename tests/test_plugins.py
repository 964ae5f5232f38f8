"""The back-ends register when first needed (tablebot.plugins): `import tablebot` imports none of them, and the
registry and a robot file's reader see every one, from any thread, whichever is asked first."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from tablebot.testing.processes import child_env

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
EVERY_BACKEND = [
    "robopro",
    "robopro-rpp",
    "robopro-program",
    "c",
    "scxml",
    "xstate",
    "uno",
    "ftduino",
    "txt",
    "robotx",
    "roboif",
    "txt4",
    "sim",
]


def fresh(code: str) -> list[str]:
    """The lines a fresh interpreter running ``code`` prints."""
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, env=child_env(), capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def test_import_tablebot_imports_no_back_end_and_the_registry_then_knows_them_all() -> None:
    lines = fresh("""
import sys
import tablebot
print(sorted(m for m in sys.modules if m.endswith('.backend') or m in ('tablebot.robot', 'tablebot.table')))
from tablebot import registry
print(registry.names())
print('tablebot.robopro.backend' in sys.modules)
""")
    assert lines == ["[]", str(EVERY_BACKEND), "True"]


def test_a_robot_file_read_first_is_read_with_every_back_end_s_section() -> None:
    lines = fresh(f"""
from tablebot.robot import load_robot
robot = load_robot({str(EXAMPLE / "robot.toml")!r})
print(sorted(robot.sections))
""")
    assert lines == [str(sorted(["txt", "robotx", "roboif"]))]  # none refused as an unknown section


def test_the_back_ends_keep_their_order_when_a_robot_file_registered_some_first() -> None:
    lines = fresh(f"""
from tablebot import catalog, registry
from tablebot.robot import load_robot
load_robot({str(EXAMPLE / "robot.toml")!r})  # registers txt, robotx and roboif
print(registry.names())
print(list(catalog.BACKENDS))
""")
    assert lines == [str(EVERY_BACKEND)] * 2  # txt, robotx and roboif first before put_in_order


def test_threads_asking_at_once_each_see_every_back_end() -> None:
    lines = fresh("""
import threading
import tablebot
from tablebot import registry
start = threading.Barrier(8)
seen = []
def ask():
    start.wait()
    seen.append(registry.names())
threads = [threading.Thread(target=ask) for _ in range(8)]
for t in threads: t.start()
for t in threads: t.join()
print(len(seen), all(names == seen[0] for names in seen), seen[0])
""")
    assert lines == [f"8 True {EVERY_BACKEND}"]


def test_a_robot_file_s_reader_imports_the_modules_of_its_own_sections_only() -> None:
    lines = fresh(f"""
import sys
from tablebot.robot import load_robot
load_robot({str(EXAMPLE / "robot.toml")!r})
print(sorted(m for m in sys.modules if m.endswith('.backend')))
""")
    # the BumberBot's [txt], [robotx] and [roboif]: not the ROBO Pro, C, statechart, firmware or sim back-ends
    assert lines == [str(["tablebot.hw.roboif.backend", "tablebot.hw.robotx.backend", "tablebot.hw.txt.backend"])]


def test_the_catalog_names_every_section_load_all_registers_in_its_order() -> None:
    lines = fresh("""
from tablebot import catalog
from tablebot.robot import SECTION_READERS
catalog.load_all()
print(list(SECTION_READERS))
print(list(catalog.SECTIONS))
""")
    assert lines[0] == lines[1]
    assert lines[0] == str(["tables", "groups", "robopro", "board", "txt", "robotx", "roboif", "sim", "properties"])


def test_each_section_s_module_registers_its_reader_in_a_fresh_process() -> None:
    lines = fresh("""
import subprocess, sys
from tablebot import catalog
for section, module in catalog.SECTIONS.items():
    code = (f"import importlib, tablebot; from tablebot.robot import SECTION_READERS; "
            f"importlib.import_module({module!r}); print({section!r} in SECTION_READERS)")
    print(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip())
""")
    assert lines == ["True"] * 9


def test_an_unknown_section_is_told_with_every_section_there_is(tmp_path: Path) -> None:
    robot = tmp_path / "robot.toml"
    robot.write_text((EXAMPLE / "robot.toml").read_text(encoding="utf-8") + "\n[simm]\nx = 1\n", encoding="utf-8")
    lines = fresh(f"""
from tablebot.diagnostics import TableBotError
from tablebot.robot import load_robot
try:
    load_robot({str(robot)!r})
except TableBotError as exc:
    print(exc.diagnostics[0].hint)
""")
    assert "tables, groups, robopro, board, txt, robotx, roboif, sim, properties" in lines[0], lines
