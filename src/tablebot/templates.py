"""Starting points for ``tablebot new``: a shipped example copied under the names of your inputs and motors,
or an empty robot made from them. Every template is a table, a robot file, a world and properties.

Templates come from the shipped examples (:mod:`tablebot.examples`), so an installed wheel has them too.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.diagnostics import fail
from tablebot.examples import example_path
from tablebot.i18n import N_, Message, asked, localise
from tablebot.robot import NAME_RE, RESERVED_LOWER, RESERVED_NAMES

if TYPE_CHECKING:
    from collections.abc import Callable

EXAMPLES = ("bumberbot", "line-follower", "obstacle-avoider")
TEMPLATES = (*EXAMPLES, "empty")
FILES = ("table.csv", "robot.toml", "arena.toml", "properties.toml")
#: What each file is for, shown after ``tablebot new``.
PURPOSE = {
    "table.csv": N_("the behaviour: one row per transition (open it in a spreadsheet)"),
    "robot.toml": N_("its inputs, motors, sensors and state names"),
    "arena.toml": N_("the world `tablebot sim` drives it in"),
    "properties.toml": N_("claims about every run that `tablebot check` proves or refutes"),
}
#: The simulator's default parts (tablebot.sim.model.params.WIRING): a renamed BumberBot keeps them wired.
BUMBERBOT_ROLES = {
    "right_motor": "M1",
    "left_motor": "M2",
    "front_right": "I3",
    "front_left": "I4",
    "rear": "I5",
    "light_right": "I7",
    "light_left": "I8",
}
Named = tuple[str, str]  # (name, label; "" keeps the template's label)
HARDWARE_SECTIONS = ("txt", "robotx", "roboif", "board")  # robot-file sections that wire the table's names to terminals


@dataclass(frozen=True)
class Template:
    """The four files of a new robot folder, as text."""

    files: dict[str, str]
    notes: tuple[str, ...] = ()


def parse_names(values: list[str], option: str) -> list[Named]:
    """``--inputs I1,I2`` or ``--inputs "I1=left bumper" --inputs I2``: names with optional labels."""
    names: list[Named] = []
    for value in values:
        for part in (p.strip() for p in value.split(",")):
            if not part:
                continue
            name, _, label = (s.strip() for s in part.partition("="))
            if not NAME_RE.match(name) or name in RESERVED_NAMES or name.lower() in RESERVED_LOWER:
                raise fail(
                    option,
                    N_("{name!r} cannot name a column", name=name),
                    N_(
                        "use a letter then letters or digits, like I1 or M2 (not T, state, timer or next); add "
                        "a label with NAME=label"
                    ),
                )
            if '"' in label or "\\" in label:
                raise fail(
                    option,
                    N_("the label of {name} may not hold quotes or backslashes", name=name),
                    N_("write it without them"),
                )
            names.append((name, label))
    seen = [n for n, _ in names]
    twice = sorted({n for n in seen if seen.count(n) > 1})
    if twice:
        raise fail(option, N_("{names} given twice", names=", ".join(twice)), N_("give each name once"))
    return names


def make(template: str, name: str, inputs: list[Named], motors: list[Named]) -> Template:
    """The files of a new robot called ``name`` from ``template`` (see TEMPLATES)."""
    if template == "empty":
        return empty(
            name,
            inputs or [("I1", "input 1"), ("I2", "input 2")],
            motors or [("M1", "right motor"), ("M2", "left motor")],
        )
    folder = example_path(template)
    files = {f: (folder / f).read_text(encoding="utf-8") for f in FILES}
    return renamed(template, files, inputs, motors)


def renamed(template: str, files: dict[str, str], inputs: list[Named], motors: list[Named]) -> Template:
    """An example's files with its inputs and motors renamed, in order, to the ones given (and relabelled)."""
    import tomllib

    robot = tomllib.loads(files["robot.toml"])
    mapping: dict[str, str] = {}
    labels: dict[str, str] = {}
    for section, given, option in (("inputs", inputs, "--inputs"), ("motors", motors, "--motors")):
        old = list(robot.get(section, {}))
        if not given:
            continue
        if len(given) != len(old):
            raise fail(
                option,
                N_(
                    "the {template} template has {n} {section} ({names}); {option} gives {given}",
                    template=template,
                    n=len(old),
                    section=section,
                    names=", ".join(old),
                    option=option,
                    given=len(given),
                ),
                N_("give {n} names, in that order, or leave {option} out", n=len(old), option=option),
            )
        mapping.update({o: n for o, (n, _) in zip(old, given, strict=True)})
        labels.update({n: label for n, label in given if label})
    if not mapping and not labels:
        return Template(files)
    out = {
        "robot.toml": _rename_robot(files["robot.toml"], mapping),
        "properties.toml": _rename_words(files["properties.toml"], mapping),
        "table.csv": _rename_header(files["table.csv"], mapping),
        "arena.toml": files["arena.toml"],
    }
    out["robot.toml"] = _relabel(out["robot.toml"], labels)
    wiring = {
        role: mapping[name]
        for role, name in BUMBERBOT_ROLES.items()
        if name in mapping and mapping[name] != name and name not in _declared(robot)
    }
    if wiring:
        out["robot.toml"] += (
            "\n# The simulator's bumpers, phototransistors and drive motors, under their new names.\n"
            "[sim.wiring]\n" + "".join(f'{role} = "{new}"\n' for role, new in wiring.items())
        )
    return Template(out)


def _declared(robot: dict) -> set[str]:
    sensors = robot.get("sensors", {})
    return set(sensors) if isinstance(sensors, dict) else set()


def _word_re(mapping: dict[str, str]) -> re.Pattern[str]:
    # a name stands alone or before a column suffix (M1_dir): never inside a longer name (I13, XM1)
    return re.compile(
        r"(?<![A-Za-z0-9_])(" + "|".join(map(re.escape, sorted(mapping, key=len, reverse=True))) + r")(?![A-Za-z0-9])"
    )


def _rename_words(text: str, mapping: dict[str, str]) -> str:
    """Every whole-word use of an old name, in one pass (I3→I1 and I1→I2 do not chain)."""
    if not mapping:
        return text
    return _word_re(mapping).sub(lambda m: mapping[m[1]], text)


def _rename_robot(text: str, mapping: dict[str, str]) -> str:
    """The robot file renamed; in a controller's wiring section ([txt], [board], ...) only the names the table
    uses (the keys), never the terminals they are wired to: your names on the template's terminals."""
    if not mapping:
        return text
    words, section, out = _word_re(mapping), "", []
    for line in text.splitlines(keepends=True):
        header = re.match(r"^\s*\[+\s*([^\]]+?)\s*\]", line)
        if header:
            section = header[1].split(".")[0]
        if section in HARDWARE_SECTIONS and not header:
            key = re.match(r"^(\s*)([A-Za-z][A-Za-z0-9]*)(\s*=)", line)
            if key and key[2] in mapping:
                line = f"{key[1]}{mapping[key[2]]}{key[3]}{line[key.end() :]}"
            out.append(line)
        else:
            out.append(words.sub(lambda m: mapping[m[1]], line))
    return "".join(out)


def _rename_header(table: str, mapping: dict[str, str]) -> str:
    """Only the header line: descriptions are the user's words."""
    head, _, rest = table.partition("\n")
    return _rename_words(head, mapping) + "\n" + rest


def _labelled(label: str) -> Callable[[re.Match[str]], str]:
    """The replacement of a ``NAME = "..."`` line's label by ``label`` (taken as it is: no escapes)."""
    return lambda m: f'{m[1]}"{label}"'


def _relabel(robot_toml: str, labels: dict[str, str]) -> str:
    """``NAME = "label"`` lines of [inputs] and [motors] get the labels given."""
    for name, label in labels.items():
        robot_toml = re.sub(rf'(?m)^(\s*{re.escape(name)}\s*=\s*)"[^"\n]*"', _labelled(label), robot_toml, count=1)
    return robot_toml


def empty(name: str, inputs: list[Named], motors: list[Named]) -> Template:
    """A robot of the given inputs and motors, a table that drives it straight on and turns now and then
    (into the walls, until its first input is made a sensor), an empty room."""
    notes = (
        ()
        if len(motors) >= 2
        else (
            "the simulator drives two wheels: `tablebot sim` needs two motors in [motors] (check and tests work now)",
        )
    )
    inputs_toml = "".join(f'{n} = "{label or "input " + str(k + 1)}"\n' for k, (n, label) in enumerate(inputs))
    sides = ("right motor", "left motor")  # the simulator drives the first two as right and left wheel
    motors_toml = "".join(f'{n} = "{label or (sides[k] if k < 2 else n)}"\n' for k, (n, label) in enumerate(motors))
    files = {
        "robot.toml": ROBOT.format(
            name=name.replace('"', "'"),
            inputs=inputs_toml,
            motors=motors_toml,
            sensors=_sensor_examples([n for n, _ in inputs] or ["I1"]),
        ),
        "table.csv": _empty_table(inputs, motors),
        "arena.toml": ARENA,
        "properties.toml": _empty_properties([n for n, _ in motors]),
    }
    return Template(files, notes)


def _sensor_examples(inputs: list[str]) -> str:
    """The commented [sensors] lines: a kind of sensor per input, never two for one input, so that uncommenting
    every line gives a file that loads (a second kind for the same input is offered in words, not as a line)."""
    distance = '{ sensor = "distance", below = "20 cm", at = [0.12, 0] }   # ultrasonic: 1 nearer than 20 cm'
    line = '{ sensor = "line", at = [0.1, 0.01] }                       # track sensor: 1 over tape'
    if len(inputs) >= 2:
        return f"# {inputs[0]} = {distance}\n# {inputs[1]} = {line}\n"
    return (
        f'# {inputs[0]} = {distance}\n#   (or a track sensor, 1 over tape: {{ sensor = "line", at = [0.1, 0.01] }})\n'
    )


def _empty_table(inputs: list[Named], motors: list[Named]) -> str:
    names = [n for n, _ in inputs]
    drives = [n for n, _ in motors]
    header = ",".join(["description", "state", "T", *names, *drives, "timer", "next"])

    def row(text: str, state: int, t: str, events: dict[str, str], speeds: list[int], timer: str, nxt: int) -> str:
        cells = [text, str(state), t, *(events.get(n, "") for n in names)]
        cells += [str(speeds[k]) if k < len(speeds) else "0" for k in range(len(drives))]
        return ",".join([*cells, timer, str(nxt)])

    said = asked()  # the table's words in the language asked for (--lang); its header: cli/new.py

    def words(text: Message) -> str:
        return str(localise(text, said))

    example = (
        row(
            words(N_("# {name} reads 1 while driving: turn away for 1 s", name=names[0])),
            2,
            "",
            {names[0]: "1"},
            [5, -5],
            "1s",
            1,
        )
        if names
        else words(N_("# description,state,T,inputs...,motors...,timer,next"))
    )
    return (
        "\n".join(
            [
                header,
                words(
                    N_(
                        "# A row fires in its state when its marked events are present: it sets the motors and loads "
                        "the timer and the robot goes to the next state (the first such row of a state wins)"
                    )
                ),
                words(N_("# Remove the # of the next line to use it (it must come before the other state 2 row):")),
                example,
                row(words(N_("start driving")), 1, "1", {}, [6, 6], "8s", 2),
                row(words(N_("time to turn")), 2, "1", {}, [5, -5], "0.7s", 1),
            ]
        )
        + "\n"
    )


ROBOT = """\
# {name}: a robot of your own, made by `tablebot new`. The table's columns come from these names.
name = "{name}"
tick_ms = 10          # one engine tick; the table's timer counts these (or write 500ms, 0.5s)
initial_state = 1
initial_timer = 0
match = "document"    # a row that requires no event fires only on a tick with some event, as in the
                      # document's engine; "always": on every tick, even one with no event at all

[inputs]              # each input is an event column of the table: 1 = it reads 1
{inputs}
[motors]              # each motor is a column: -8..8, 0 stops, = keeps
{motors}
[states]              # names for people: what the robot does while in each state
1 = "turning"         # (the start: the timer is 0, so "start driving" fires at once)
2 = "driving"

# What drives an input in the simulator (uncomment and adapt; docs/tutorial.md explains):
# [sensors]
{sensors}"""

ARENA = """\
# The world `tablebot sim` drives the robot in (format: examples/bumberbot/arena.toml).
# Lengths in metres, angles in degrees (0 = +x, counter-clockwise).
name = "empty room"

[arena]
walls = [[0, 0], [2.5, 0], [2.5, 2.0], [0, 2.0]]

[start]
at = [0.6, 0.6]       # the axle centre
heading = 30

# [[box]]             # an obstacle: at = centre, size = [width, depth], angle
# at = [1.6, 1.2]
# size = [0.4, 0.3]
"""


def _empty_properties(motors: list[str]) -> str:
    text = (
        "# Claims about every run of the table, proved or refuted by `tablebot check` (docs/checking.md).\n\n"
        "[back_to_the_start]\n"
        'text = "from every situation the robot can get back to state 1"\n'
        'always_reachable = "state == 1"\n'
    )
    if motors:
        still, moving = " and ".join(f"{m} == 0" for m in motors), " or ".join(f"{m} != 0" for m in motors)
        text += (
            "\n[keeps_moving]\n"
            'text = "the robot never stands still for more than 1 s"\n'
            f'when = "{still}"\nthen = "{moving}"\nwithin = "1 s"\n'
        )
    return text


def write_folder(folder: Path, template: Template) -> list[Path]:
    """Write the template's files into ``folder`` (it must not exist, or be empty): the folder appears
    with all of them at once, or not at all."""
    from tablebot.files import write_text
    from tablebot.fileset import new_folder

    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        what = N_("this is a file, not a folder") if not folder.is_dir() else N_("this folder is not empty")
        raise fail(folder, what, N_("give the name of a new folder (tablebot new never writes over files)"))
    with new_folder(folder) as stage:
        for name in FILES:
            write_text(stage / name, template.files[name])
    return [folder / name for name in FILES]
