"""The robot file's ``[sensors]``: what kind of sensor drives each input and when it reads 1.

A table stays binary: an analog sensor becomes an event through a threshold declared here (with
units and an optional hysteresis), so the simulator and a controller that reads analog values turn
the same declaration into the same events. Reading this section never imports the simulator.

    [sensors]   # input = { sensor = KIND, at = [forward, left] metres from the axle centre, ... }
    I1 = { sensor = "line", at = [0.1, 0.008] }                      # 1 over the tape
    I3 = { sensor = "distance", below = "20 cm", hysteresis = "5 cm", at = [0.12, 0], angle = 0 }
    I7 = { sensor = "phototransistor", above = 1.5, at = [0.11, -0.03], angle = -10 }
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

from tablebot.i18n import N_, NP_
from tablebot.tomlfile import Source, is_number

KEYS = ("sensor", "at", "angle", "below", "above", "hysteresis")
#: Lengths accept these units (the value is kept in metres); light levels are plain numbers.
LENGTH_UNITS = {"mm": 0.001, "cm": 0.01, "m": 1.0}
LENGTH_RE = re.compile(r"^\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+))\s*(mm|cm|m)\s*$")
MAX_OFFSET = 2.0  # metres: a sensor further than this from the axle centre is a typo, not a robot


# --- sensor kinds -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Panel:
    """A kind's panel in the timeline picture: its axis label, the scale of the reading on it, a log axis (else
    the axis reaches three times the thresholds), and its place among the panels."""

    label: str
    scale: float
    log: bool
    position: int


class Sections(Protocol):
    """The simulator's parameters as a sensor kind reads them: ``params[section][key]`` (sim.model.params.Params)."""

    def __getitem__(self, section: str) -> Mapping[str, Any]: ...


@dataclass(frozen=True)
class SensorKind:
    """One kind of sensor the simulator models, and everything that follows from it: the words that declare
    it, how its thresholds are written, its code in the simulator (whose physics, ``sim/physics/sensing.py``, has a
    branch per code), its trace field, how pictures draw it, its reading panel, the controller input modes
    that read it with its declared threshold, and its place in a learning agent's observation.

    Adding a kind: register one here, its physics in ``sim/physics/sensing.py`` (and its parameters, if it has any, in
    ``sim/model/params.py``); every other stage reads this object.
    """

    name: str  # what the simulator models
    words: tuple[str, ...]  # the ``sensor =`` words that declare it
    code: int  # its code in the simulator's parameter row (sim.columns.F_KIND); 0 is "no sensor"
    units: str  # "length" (written with mm, cm or m, kept in metres), "level" (a plain number), "" (no threshold)
    example: str  # a threshold as a robot file writes it ("" when it has none)
    reads: str  # what it reads, in words: "1 over a line"; for a thresholded kind, what its level means
    trace: tuple[str, float, int]  # trace key suffix, scale of the reading, decimals (0: a whole number)
    draw: str  # "spot" (a floor spot, dark while it reads 1), "beam" (out to its echo), "cone" (its field of view)
    spread: tuple[str, str] | None = None  # the [sim] parameter of its drawn half angle (degrees)
    panel: Panel | None = None  # its reading panel in the timeline (None: the event panel shows it)
    modes: Mapping[str, float] = field(default_factory=dict)  # controller input mode -> scale from its units
    high: Callable[[Sections, float], float] = lambda params, light: 1.0  # its observation's upper bound
    # (params: the simulator's parameters, light: the most light a sensor can get in the world)


#: Every sensor kind, by name, in the order their words are listed to people.
SENSOR_KINDS: dict[str, SensorKind] = {}


def register_kind(kind: SensorKind) -> SensorKind:
    if kind.code <= 0 or any(k.code == kind.code for k in SENSOR_KINDS.values() if k.name != kind.name):
        raise ValueError(f"sensor kind {kind.name}: code {kind.code} is taken or not above 0")
    SENSOR_KINDS[kind.name] = kind
    return kind


register_kind(SensorKind("line", ("line",), 1, "", "", N_("1 over a line"), ("line", 1.0, 0), "spot"))
register_kind(
    SensorKind(
        "distance",
        ("distance", "ultrasonic"),
        2,
        "length",
        '"20 cm"',
        "",
        ("cm", 100.0, 1),
        "beam",
        spread=("distance", "beam"),
        panel=Panel("distance (cm)\n-- on, ·· off", 100.0, False, 1),
        modes={"ultrasonic": 100.0},
        high=lambda params, light: params["distance"]["range"],
    )
)
register_kind(
    SensorKind(
        "light",
        ("phototransistor", "photoresistor", "light"),
        3,
        "level",
        "1.5",
        N_("1 is the level at which a phototransistor switches"),
        ("light", 1.0, 4),
        "cone",
        spread=("light", "half_response"),
        panel=Panel("light\n(× threshold)", 1.0, True, 0),
        high=lambda params, light: light,
    )
)


def word_kinds() -> dict[str, str]:
    """Each ``sensor =`` word and the kind it declares, in the order they are listed to people."""
    return {word: kind.name for kind in SENSOR_KINDS.values() for word in kind.words}


@dataclass(frozen=True)
class Sensor:
    """One declared sensor: the input it drives and how its reading becomes that input's event.

    ``threshold`` and ``hysteresis`` are in metres for distances and in light units for light (1 =
    the level at which the BumberBot's phototransistor switches); ``unit`` is the unit the file used,
    so a controller's mapping can give the threshold back in the same words. The event is on while
    the reading is ``below`` (or ``above``) the threshold and, once on, stays on until the reading has
    gone back past the threshold by the hysteresis. A line sensor reads 1 over a line, 0 elsewhere.
    """

    name: str
    model: str  # the word written: line, distance, ultrasonic, phototransistor, photoresistor, light
    at: tuple[float, float]  # forward, left of the axle centre, metres
    angle: float = 0.0  # degrees, 0 = straight ahead, positive = to the left
    direction: str = ""  # "below" or "above" ("" for a line sensor)
    threshold: float = 0.0
    hysteresis: float = 0.0
    unit: str = ""  # "cm", "mm", "m" for distances; "" for light levels and line sensors

    @property
    def kind(self) -> str:
        """What the simulator models: ``line``, ``distance`` or ``light`` (:attr:`sensor_kind`'s name)."""
        return word_kinds()[self.model]

    @property
    def sensor_kind(self) -> SensorKind:
        return SENSOR_KINDS[self.kind]

    def switch_points(self) -> tuple[float, float]:
        """The reading at which the event turns on, and the one at which it turns off again."""
        back = self.hysteresis if self.direction == "below" else -self.hysteresis
        return self.threshold, self.threshold + back

    def event(self, reading: float, was_on: bool) -> bool:
        """Whether the input reads 1 for ``reading`` (``was_on``: whether it read 1 last tick)."""
        return threshold_event(reading, self.direction == "above", *self.switch_points(), was_on)

    def describe(self) -> str:
        """``distance below 20 cm (hysteresis 5 cm)`` — the declaration in words, for reports."""
        if not self.sensor_kind.units:
            return f"{self.model} sensor: {self.sensor_kind.reads}"
        text = f"{self.model} {self.direction} {self._show(self.threshold)}"
        return text + (f" (hysteresis {self._show(self.hysteresis)})" if self.hysteresis else "")

    def _show(self, value: float) -> str:
        if not self.unit:
            return f"{value:g}"
        return f"{value / LENGTH_UNITS[self.unit]:g} {self.unit}"


def threshold_event(reading: float, above: bool, on_at: float, off_at: float, was_on: bool) -> bool:
    """THE threshold rule, with its hysteresis: the event is on while the reading is past ``on_at`` (above it,
    or below it) and, once on, stays on until the reading is back past ``off_at`` (``on_at`` moved back by the
    hysteresis; ``was_on``: the event last tick).

    The one rule for every analog input: the simulator compiles this function into its sensing
    (``sim.physics.sensing``), every controller's wiring calls it (``hw.wiring``), and the TXT 4.0 program, a standalone
    file, carries a copy that ``tests/hw/test_rules.py`` proves equal to it.
    """
    level = off_at if was_on else on_at
    return reading > level if above else reading < level


def parse_sensors(src: Source, inputs: dict[str, str]) -> tuple[Sensor, ...]:
    """Every ``[sensors]`` entry, checked; problems go to ``src``'s collector with their line."""
    section = src.data.get("sensors")
    if section is None:
        return ()
    if not isinstance(section, dict):
        src.key_error(
            ("", None, "sensors"),
            N_("[sensors] must be a table of INPUT = { sensor = ... }"),
            N_('for example: I1 = { sensor = "line", at = [0.1, 0.01] }'),
        )
        return ()
    found = [_sensor(src, name, value, inputs) for name, value in section.items()]
    return tuple(s for s in found if s is not None)


def _sensor(src: Source, name: str, value: Any, inputs: dict[str, str]) -> Sensor | None:
    where = ("sensors", None, name)
    if name not in inputs:
        src.key_error(
            where,
            N_("[sensors] {name} is not an input of the robot", name=name),
            N_("add {name} to [inputs] first (its column in the table is the sensor's event)", name=name),
        )
        return None
    if not isinstance(value, dict):
        src.key_error(
            where,
            N_(
                '[sensors] {name} must be a table like {{ sensor = "distance", ... }}, not {value!r}',
                name=name,
                value=value,
            ),
            N_('for example: {name} = {{ sensor = "distance", below = "20 cm", at = [0.12, 0] }}', name=name),
        )
        return None
    unknown = sorted(set(value) - set(KEYS))
    if unknown:
        src.key_error(
            where,
            NP_(
                "[sensors] {name}: unknown key {keys}",
                "[sensors] {name}: unknown keys {keys}",
                len(unknown),
                name=name,
                keys=", ".join(unknown),
            ),
            N_("known keys: {known}", known=", ".join(KEYS)),
        )
    model = value.get("sensor")
    words = word_kinds()
    if model not in words:
        src.key_error(
            where,
            N_("[sensors] {name}: sensor = {model!r} is not a sensor kind tablebot knows", name=name, model=model),
            N_("write sensor = one of {kinds}", kinds=", ".join(repr(k) for k in words)),
        )
        return None
    kind = SENSOR_KINDS[words[model]]
    at = _at(src, name, value.get("at"))
    angle = _angle(src, name, value)
    if not kind.units:
        return _unthresholded(src, name, model, kind, value, at, angle)
    threshold = _threshold(src, name, model, kind, value)
    if at is None or angle is None or threshold is None:
        return None
    direction, level, unit = threshold
    hysteresis = _amount(src, name, "hysteresis", value.get("hysteresis", 0), kind)
    if hysteresis is None:
        return None
    return Sensor(name, model, at, angle, direction, level, hysteresis[0], unit)


def _unthresholded(
    src: Source,
    name: str,
    model: str,
    kind: SensorKind,
    value: dict[str, Any],
    at: tuple[float, float] | None,
    angle: float | None,
) -> Sensor | None:
    """A kind without a threshold (a floor sensor reads the floor straight below it): no direction, no angle."""
    extra = [k for k in ("below", "above", "hysteresis", "angle") if k in value]
    if extra:
        src.key_error(
            ("sensors", None, name),
            N_("[sensors] {name}: a {kind} sensor has no {keys}", name=name, kind=kind.name, keys=", ".join(extra)),
            N_("it reads {reads} and 0 elsewhere; give only sensor and at", reads=kind.reads),
        )
    return None if at is None or angle is None or extra else Sensor(name, model, at)


def _at(src: Source, name: str, value: Any) -> tuple[float, float] | None:
    ok = isinstance(value, list) and len(value) == 2 and all(is_number(v) and abs(v) <= MAX_OFFSET for v in value)
    if not ok:
        src.key_error(
            ("sensors", None, name),
            N_(
                "[sensors] {name}: at must be [forward, left] in metres from the axle centre, not {value!r}",
                name=name,
                value=value,
            ),
            N_("for example: at = [0.12, 0] (each within ±{most} m)", most=str(MAX_OFFSET)),
        )
        return None
    return float(value[0]), float(value[1])


def _angle(src: Source, name: str, value: dict[str, Any]) -> float | None:
    angle = value.get("angle", 0.0)
    if not is_number(angle) or not -180 <= angle <= 180:
        src.key_error(
            ("sensors", None, name),
            N_("[sensors] {name}: angle must be degrees from -180 to 180, not {angle!r}", name=name, angle=angle),
            N_("0 points straight ahead, positive to the left"),
        )
        return None
    return float(angle)


def _threshold(
    src: Source, name: str, model: str, kind: SensorKind, value: dict[str, Any]
) -> tuple[str, float, str] | None:
    """(below|above, threshold in metres or light units, unit written)."""
    given = [k for k in ("below", "above") if k in value]
    if len(given) != 1:
        example = kind.example
        src.key_error(
            ("sensors", None, name),
            N_("[sensors] {name}: a {model} sensor needs one of below or above, not both", name=name, model=model)
            if given
            else N_("[sensors] {name}: a {model} sensor needs a threshold", name=name, model=model),
            N_(
                "write below = {example} (the event is 1 while the reading is below it) or above = {example}",
                example=example,
            ),
        )
        return None
    direction = given[0]
    amount = _amount(src, name, direction, value[direction], kind)
    return None if amount is None else (direction, *amount)


def _amount(src: Source, name: str, key: str, raw: Any, kind: SensorKind) -> tuple[float, str] | None:
    """A threshold or hysteresis and the unit written: a length with its unit (the value in metres; a bare 0
    counts as cm), or a plain level (unit "")."""
    where = ("sensors", None, name)
    unit = ""
    if kind.units == "length":
        if raw == 0:
            return 0.0, "cm"
        match = LENGTH_RE.match(raw) if isinstance(raw, str) else None
        if match is None:
            src.key_error(
                where,
                N_("[sensors] {name}: {key} must be a length with its unit, not {raw!r}", name=name, key=key, raw=raw),
                N_('write it in quotes with mm, cm or m: {key} = "20 cm"', key=key),
            )
            return None
        metres, unit = float(match[1]) * LENGTH_UNITS[match[2]], match[2]
    else:
        if not is_number(raw):
            src.key_error(
                where,
                N_(
                    "[sensors] {name}: {key} must be a {kind} level (a number), not {raw!r}",
                    name=name,
                    key=key,
                    kind=kind.name,
                    raw=raw,
                ),
                N_("{reads}: {key} = {example}", reads=kind.reads, key=key, example=kind.example),
            )
            return None
        metres = float(raw)
    if metres < 0 or not math.isfinite(metres):
        src.key_error(
            where,
            N_("[sensors] {name}: {key} must not be negative", name=name, key=key),
            N_("write {key} as 0 or more", key=key),
        )
        return None
    return metres, unit
