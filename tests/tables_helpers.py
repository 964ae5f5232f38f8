"""A small robot of two tables (drive, lights) with a state group, as files, for the tests of issue 36."""

from __future__ import annotations

from pathlib import Path

ROBOT = """name = "Two"
match = "document"

[inputs]
I1 = "bumper"
I2 = "light"

[motors]
M1 = "right"
M2 = "left"

[lamps]
L1 = "lamp"

[tables]
drive = { file = "table.csv", initial_state = 1 }
lights = { file = "lights.csv", initial_state = 1, match = "always" }

[groups]
moving = [1, 2]
"""
DRIVE = """state,T,I1,M1,M2,timer,next
moving,,1,0,0,5,3
1,1,,5,5,10,2
2,1,,-5,5,4,1
3,1,,0,0,0,1
"""
LIGHTS = """state,T,"drive=3",I2,L1,timer,next
1,,1,,8,0,2
1,1,,,0,3,1
2,1,,1,4,0,1
2,1,,,8,0,1
"""


def robot(folder: Path, drive: str = DRIVE, lights: str = LIGHTS, robot_file: str = ROBOT) -> Path:
    folder.mkdir(exist_ok=True)
    for name, text in (("robot.toml", robot_file), ("table.csv", drive), ("lights.csv", lights)):
        (folder / name).write_text(text)
    return folder
