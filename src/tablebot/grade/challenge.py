"""A challenge: a folder with ``challenge.toml`` naming the robot every submission runs on, its worlds, the
scenarios (the same for everyone), the measure that scores a run and the rules a table must keep (proved by
``check``). Read with every mistake located in the file, before any submission is graded."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tablebot.diagnostics import TableBotError, fail
from tablebot.i18n import N_
from tablebot.tomlfile import Source, known_keys, label, number

KEYS = ("title", "robot", "worlds", "seconds", "seeds", "score", "properties", "max_rows", "grid")
FILE_NAME = "challenge.toml"
HINT = N_("see examples/challenges/find-the-lamp/challenge.toml")


@dataclass(frozen=True)
class Challenge:
    """What ``challenge.toml`` says, its files resolved: ``robot``, ``worlds`` and ``properties`` are paths;
    ``better`` is the score's direction (``low`` or ``high``, as evolve's measure has it)."""

    folder: Path
    title: str
    robot: Path
    worlds: tuple[Path, ...]
    seconds: float
    seeds: str
    score: str
    better: str
    properties: Path | None
    max_rows: int | None
    grid: tuple[str, ...]


#: The challenges tablebot ships (examples/challenges/NAME): a name alone finds them, in a wheel as in a checkout.
SHIPPED = ("find-the-lamp", "line-laps")


def load_challenge(path: str | Path) -> Challenge:
    """The challenge in ``path`` (its folder, or its ``challenge.toml``), or a shipped one by its name."""
    path = Path(path)
    if not path.exists() and str(path) in SHIPPED:
        from tablebot.examples import example_path

        path = example_path(f"challenges/{path}")
    file = path / FILE_NAME if path.is_dir() else path
    if not file.is_file():
        raise fail(
            path,
            N_("no {file} here", file=FILE_NAME),
            N_(
                "give a challenge folder holding {file}, or the name of a shipped challenge: {names}",
                file=FILE_NAME,
                names=tuple(SHIPPED),
            ),
        )
    src = Source.read(file, HINT)
    data = src.data
    known_keys(src, ("", None), data, KEYS)
    for key in ("title", "robot", "worlds", "seconds", "seeds", "score"):
        if key not in data:
            src.error(
                ("", None, None),
                N_("{file} has no {key}", file=FILE_NAME, key=key),
                N_("add {key} = ... ({hint})", key=key, hint=HINT),
            )
    folder = file.parent
    title = _text(src, "title", data.get("title", ""))
    robot = _file(src, folder, "robot", data.get("robot"))
    worlds = tuple(w for w in (_world(src, folder, k, v) for k, v in enumerate(_list(src, "worlds", data))) if w)
    seconds = number(src, ("", None, "seconds"), data.get("seconds", 60), 0.01, 3600)
    seeds = _seeds(src, data.get("seeds", "0..0"))
    properties = _file(src, folder, "properties", data["properties"]) if "properties" in data else None
    max_rows = (
        number(src, ("", None, "max_rows"), data["max_rows"], 1, 10_000, integer=True) if "max_rows" in data else None
    )
    grid = tuple(_text(src, "grid", g) for g in _list(src, "grid", data))
    src.raise_if_any()
    score, better = _score(src, data["score"], worlds)
    return Challenge(
        folder,
        title,
        robot,
        worlds,
        float(seconds or 60),
        seeds,
        score,
        better,
        properties,
        int(max_rows) if max_rows is not None else None,
        grid,
    )


def _text(src: Source, key: str, value: Any) -> str:
    if not isinstance(value, str):
        src.key_error(
            ("", None, key),
            N_("{key} must be text in quotes, not {value!r}", key=key, value=value),
            N_("for example: {example}", example=key + ' = "..."'),
        )
        return ""
    return value


def _list(src: Source, key: str, data: dict[str, Any]) -> list[Any]:
    value = data.get(key, [])
    if not isinstance(value, list):
        src.key_error(
            ("", None, key),
            N_("{key} must be a list", key=key),
            N_("for example: {example}", example=key + ' = ["arena.toml"]'),
        )
        return []
    return value


def _file(src: Source, folder: Path, key: str, value: Any) -> Path:
    """A file the challenge names, relative to its folder."""
    name = _text(src, key, value)
    path = folder / name
    if name and not path.is_file():
        src.key_error(
            ("", None, key),
            N_("{key}: {name} is not a file beside challenge.toml", key=label(("", None, key)), name=name),
            N_("name a file in the challenge's folder"),
        )
    return path


def _world(src: Source, folder: Path, index: int, value: Any) -> Path | None:
    """A world file relative to the challenge's folder, or the name of a shipped example (its arena.toml)."""
    from tablebot.examples import example_path

    name = _text(src, "worlds", value)
    if not name:
        return None
    if (folder / name).is_file():
        return folder / name
    try:
        shipped = example_path(name) / "arena.toml"
    except TableBotError:
        shipped = None
    if shipped is not None and shipped.is_file():
        return shipped
    src.key_error(
        ("", None, "worlds"),
        N_(
            "worlds[{index}]: {name} is neither a file beside challenge.toml nor a shipped example's world",
            index=index,
            name=name,
        ),
        N_("name a world file, or one of bumberbot, line-follower, obstacle-avoider"),
    )
    return None


def _seeds(src: Source, value: Any) -> str:
    from tablebot.fleet.spec import parse_seeds

    text = _text(src, "seeds", value)
    try:
        parse_seeds(text, None, "seeds")
    except TableBotError as exc:
        src.key_error(
            ("", None, "seeds"), exc.diagnostics[0].message, N_("for example: {example}", example='seeds = "0..31"')
        )
    return text


def _score(src: Source, name: Any, worlds: tuple[Path, ...]) -> tuple[str, str]:
    """The measure that scores a run (evolve's list), measurable in every world of the challenge."""
    from tablebot.evolve.measures import MEASURES, allowed
    from tablebot.sim.model.world import load_world

    usable = [n for n in allowed([load_world(w) for w in worlds]) if MEASURES[n].objective]
    if name not in usable:
        why = N_("not a measure tablebot has") if name not in MEASURES else N_("the worlds cannot measure it")
        src.key_error(
            ("", None, "score"),
            N_("score = {name!r}: {why}", name=name, why=why),
            N_("use one of {names}", names=tuple(usable)),
        )
        src.raise_if_any()
    return name, MEASURES[name].better
