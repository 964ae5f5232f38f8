"""Random robots of several tables (issue 36) as the files a user writes: a robot file with ``[tables]`` and
``[groups]``, and one CSV per table, with cross-table event columns (single states, lists and ranges), a state
group, each output written by one table, a counter loaded by one table and read by others, and either matching
rule per table. Property tests read them back through :func:`tablebot.loading.Loaded.open`, so the reader, the
model and every engine are tested on what a user could have written."""

from __future__ import annotations

import random
from dataclasses import dataclass
from pathlib import Path

INPUTS = ("I1", "I2", "I3")
#: The robot's outputs (motors, lamps) and counter, dealt out to the tables: each has one writer.
MOTORS = ("M1", "M2")
LAMPS = ("L1", "L2")
COUNTER = "C1"


@dataclass(frozen=True)
class RobotShape:
    """How big a random robot is."""

    tables: int = 3
    states: int = 3
    rows: int = 6
    max_timer: int = 4


def random_robot(rng: random.Random, folder: Path, shape: RobotShape = RobotShape()) -> Path:
    """Write a random robot of ``shape.tables`` tables into ``folder`` (made if missing); returns the folder."""
    folder.mkdir(parents=True, exist_ok=True)
    names = [f"t{k}" for k in range(shape.tables)]
    states = {name: [k * 10 + i for i in range(shape.states)] for k, name in enumerate(names)}
    outputs = [*MOTORS, *LAMPS, f"{COUNTER}_load"]
    owner = {output: rng.choice(names) for output in outputs}
    group = states[names[0]][:2]
    robot = [
        f'name = "Random"\nmatch = "{rng.choice(("document", "always"))}"\n',
        "[inputs]",
        *(f'{i} = "input {i}"' for i in INPUTS),
        "",
        "[motors]",
        'M1 = "right"',
        'M2 = "left"',
        "",
        "[lamps]",
        'L1 = "front"',
        'L2 = "back"',
        "",
        "[counters]",
        f'{COUNTER} = "M1"',
        "",
        "[tables]",
    ]
    for name in names:
        match = f', match = "{rng.choice(("document", "always"))}"' if rng.random() < 0.5 else ""
        robot.append(
            f'{name} = {{ file = "{name}.csv", initial_state = {rng.choice(states[name])}, '
            f"initial_timer = {rng.randint(0, 2)}{match} }}"
        )
    robot += ["", "[groups]", f"g = [{', '.join(map(str, group))}]", ""]
    (folder / "robot.toml").write_text("\n".join(robot))
    for name in names:
        writes = [o for o in outputs if owner[o] == name]
        text = _table(rng, shape, name, names, states, writes, grouped=name == names[0])
        (folder / f"{name}.csv").write_text(text)
    return folder


def _table(
    rng: random.Random,
    shape: RobotShape,
    name: str,
    names: list[str],
    states: dict[str, list[int]],
    writes: list[str],
    grouped: bool,
) -> str:
    cross = [_cross(rng, other, states[other]) for other in rng.sample(names, rng.randint(1, len(names)))]
    events = ["T", *INPUTS, COUNTER, *cross]
    header = ["state", *(f'"{e}"' if "," in e else e for e in events), *writes, "timer", "next"]
    lines = [",".join(header)]
    own = states[name]
    for i in range(max(shape.rows, len(own))):
        state = str(own[i]) if i < len(own) else ("g" if grouped and rng.random() < 0.3 else str(rng.choice(own)))
        required = [e for e in events if rng.random() < 0.25] if rng.random() > 0.1 else []
        cells = [state, *("1" if e in required else "" for e in events)]
        cells += [_output(rng, output) for output in writes]
        cells += [str(rng.randint(0, shape.max_timer)), str(rng.choice(own))]
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


def _cross(rng: random.Random, table: str, states: list[int]) -> str:
    """A cross-table column of ``table``: one state, a list or a range."""
    pick = rng.random()
    if pick < 0.4:
        return f"{table}={rng.choice(states)}"
    if pick < 0.7:
        return f"{table}={','.join(map(str, sorted(rng.sample(states, 2))))}"
    low = rng.choice(states)
    return f"{table}={low}..{low + rng.randint(0, 12)}"


def _output(rng: random.Random, output: str) -> str:
    if rng.random() < 0.25:
        return "" if output[0] in "LC" else "="  # keep (a blank motor cell would stop it)
    if output.startswith("M"):
        return str(rng.randint(-8, 8))
    return str(rng.randint(0, 8 if output.startswith("L") else 5))
