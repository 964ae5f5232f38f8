"""What a run of a candidate amounts to: the objective to make best and the behaviour descriptors that
place it in the archive, each a mean over the scenarios, each measurable only in worlds that have what
it needs (a lamp, a closed line of tape, walls). Options naming others are refused, naming the allowed.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from tablebot.diagnostics import fail
from tablebot.i18n import N_, Message, localise
from tablebot.sim.model.track import loop_of
from tablebot.sim.model.world import World

RANGE_RE = re.compile(r"^\s*([\w:.-]+?)\s*(?:=\s*(-?[\d.]+)\s*\.\.\s*(-?[\d.]+))?\s*$")
STATE_SHARE = "state_share:"


@dataclass(frozen=True)
class Measure:
    """One number per run, averaged over the scenarios; ``better``: "low" or "high" (as an objective)."""

    name: str
    text: Message  # what it is, said in the reader's language (measure_text)
    better: str
    needs: str = ""  # "lamp", "loop", "walls" or "" (measurable in any world)
    objective: bool = True  # may be the objective (a state's share of time has no better side)


MEASURES = {
    m.name: m
    for m in (
        Measure("time_to_lamp", N_("seconds until the lamp is reached (never: the whole run)"), "low", "lamp"),
        Measure(
            "time_to_light", N_("seconds until a light sensor first sees a lamp (never: the whole run)"), "low", "lamp"
        ),
        Measure("missed_lamp", N_("share of runs that never reach the lamp"), "low", "lamp"),
        Measure("lamp_distance", N_("metres from the robot to the nearest lamp when the run ends"), "low", "lamp"),
        Measure("collisions", N_("collisions per run"), "low"),
        Measure("collision_share", N_("share of the time the body touches something"), "low"),
        Measure("distance", N_("metres driven"), "high"),
        Measure(
            "area_covered",
            N_("square metres of floor the robot's centre passed over (in 10 cm squares)"),
            "high",
            "walls",
        ),
        Measure("laps", N_("net laps round the world's closed line of tape"), "high", "loop"),
    )
}


def measure_text(name: str) -> str:
    """What a measure (or a descriptor ``state_share:STATE``) is, in the reader's language."""
    if name in MEASURES:
        return str(localise(MEASURES[name].text))
    return str(localise(N_("share of the time in state {state}", state=name[len(STATE_SHARE) :])))


@dataclass(frozen=True)
class Descriptor:
    """A behaviour descriptor: a measure and the range the archive's grid spans (values beyond it go to
    the edge cells), cut into ``cells`` cells."""

    name: str
    low: float
    high: float
    cells: int


def allowed(worlds: Sequence[World], states: Sequence[object] = ()) -> list[str]:
    """The measures every world can give a meaning (a lamp measure needs a lamp in every world)."""
    has = {
        "lamp": all(w.lamps for w in worlds),
        "loop": all(loop_of(w) is not None for w in worlds),
        "walls": all(len(w.walls) >= 3 for w in worlds),
        "": True,
    }
    return [name for name, m in MEASURES.items() if has[m.needs]] + [f"{STATE_SHARE}{s}" for s in states]


def check_objective(name: str, worlds: Sequence[World]) -> Measure:
    usable = [n for n in allowed(worlds) if MEASURES[n].objective]
    if name not in usable:
        why = (
            N_("unknown objective")
            if name not in MEASURES
            else N_("the worlds cannot measure it ({need})", need=_need(name))
        )
        raise fail(
            "--objective",
            N_("--objective {name}: {why}", name=name, why=why),
            N_("use one of {choices}", choices=", ".join(usable)),
        )
    return MEASURES[name]


def _need(name: str) -> str:
    needs = MEASURES[name].needs
    return {
        "lamp": N_("it needs a [[lamp]] in every world"),
        "loop": N_("it needs a closed [[line]] in every world"),
        "walls": N_("it needs [arena] walls in every world"),
    }.get(needs, "")


def parse_descriptors(
    text: str, worlds: Sequence[World], states: Sequence[object], seconds: float, cells: int
) -> list[Descriptor]:
    """``--descriptors "collision_share,area_covered=0..0.5"``: one or two measures, each with an
    optional range (the default range fits the measure and the run's length)."""
    usable = allowed(worlds, states)
    out: list[Descriptor] = []
    for part in (p for p in text.split(",") if p.strip()):
        found = RANGE_RE.match(part)
        name = found[1] if found else part.strip()
        if not found or name not in usable:
            why = (
                N_("unknown descriptor")
                if found and name not in MEASURES and not name.startswith(STATE_SHARE)
                else N_("the worlds cannot measure it")
                if found and name in MEASURES
                else N_("not a descriptor")
            )
            raise fail(
                "--descriptors",
                N_("--descriptors {part}: {why}", part=part.strip(), why=why),
                N_(
                    "use one or two of {choices} (optionally with a range: area_covered=0..0.5)",
                    choices=", ".join(usable),
                ),
            )
        low, high = (float(found[2]), float(found[3])) if found[2] is not None else default_range(name, seconds)
        if not high > low:
            raise fail(
                "--descriptors",
                N_("--descriptors {part}: the range must be LOW..HIGH with LOW < HIGH", part=part.strip()),
                N_("write for example {name}=0..1", name=name),
            )
        if any(d.name == name for d in out):
            raise fail(
                "--descriptors", N_("--descriptors names {name} twice", name=name), N_("name each descriptor once")
            )
        out.append(Descriptor(name, low, high, cells))
    if not 1 <= len(out) <= 2:
        raise fail(
            "--descriptors",
            N_("--descriptors needs one or two descriptors, not {n}", n=len(out)),
            N_("for example --descriptors {example}", example=",".join(usable[:2])),
        )
    return out


def default_range(name: str, seconds: float) -> tuple[float, float]:
    """A range every run's mean falls in, chosen so that the grid's cells tell behaviours apart."""
    if name in ("time_to_lamp", "time_to_light"):
        return 0.0, seconds
    if name == "missed_lamp" or name.startswith(STATE_SHARE):
        return 0.0, 1.0
    if name == "area_covered":
        return 0.0, 0.01 * seconds  # a 10 cm wide strip at 0.1 m/s
    if name == "collision_share":
        return 0.0, 0.5
    if name == "collisions":
        return 0.0, max(5.0, seconds / 6)
    if name == "distance":
        return 0.0, 0.25 * seconds  # the BumberBot drives at most about 0.2 m/s
    if name == "laps":
        return 0.0, max(1.0, seconds / 30)
    return 0.0, 3.0  # lamp_distance: metres


def default_descriptors(worlds: Sequence[World]) -> str:
    """Area covered and share of time in contact where there are walls; else distance and collisions."""
    names = allowed(worlds)
    return "area_covered,collision_share" if "area_covered" in names else "distance,collision_share"


def default_objective(worlds: Sequence[World]) -> str:
    """The lamp where every world has one, else laps of a line, else as few collisions as can be."""
    names = allowed(worlds)
    return "time_to_lamp" if "time_to_lamp" in names else "laps" if "laps" in names else "collisions"


def fitness(measure: Measure, value: float) -> float:
    """The archive maximises: a measure where low is better enters negated."""
    return value if measure.better == "high" else -value
