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
from dataclasses import dataclass
from typing import Any

from tablebot.tomlfile import Source, is_number

#: What each ``sensor =`` word is simulated as: a floor (track) sensor, an ultrasonic ray cast, or light.
KINDS = {"line": "line", "distance": "distance", "ultrasonic": "distance",
         "phototransistor": "light", "photoresistor": "light", "light": "light"}
KEYS = ("sensor", "at", "angle", "below", "above", "hysteresis")
#: Lengths accept these units (the value is kept in metres); light levels are plain numbers.
LENGTH_UNITS = {"mm": 0.001, "cm": 0.01, "m": 1.0}
LENGTH_RE = re.compile(r"^\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+))\s*(mm|cm|m)\s*$")
MAX_OFFSET = 2.0  # metres: a sensor further than this from the axle centre is a typo, not a robot


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
        """What the simulator models: ``line``, ``distance`` or ``light``."""
        return KINDS[self.model]

    def switch_points(self) -> tuple[float, float]:
        """The reading at which the event turns on, and the one at which it turns off again."""
        back = self.hysteresis if self.direction == "below" else -self.hysteresis
        return self.threshold, self.threshold + back

    def describe(self) -> str:
        """``distance below 20 cm (hysteresis 5 cm)`` — the declaration in words, for reports."""
        if self.kind == "line":
            return f"{self.model} sensor: 1 over a line"
        text = f"{self.model} {self.direction} {self._show(self.threshold)}"
        return text + (f" (hysteresis {self._show(self.hysteresis)})" if self.hysteresis else "")

    def _show(self, value: float) -> str:
        if not self.unit:
            return f"{value:g}"
        return f"{value / LENGTH_UNITS[self.unit]:g} {self.unit}"


def parse_sensors(src: Source, inputs: dict[str, str]) -> tuple[Sensor, ...]:
    """Every ``[sensors]`` entry, checked; problems go to ``src``'s collector with their line."""
    section = src.data.get("sensors")
    if section is None:
        return ()
    if not isinstance(section, dict):
        src.key_error(("", None, "sensors"), "[sensors] must be a table of INPUT = { sensor = ... }",
                  'for example: I1 = { sensor = "line", at = [0.1, 0.01] }')
        return ()
    found = [_sensor(src, name, value, inputs) for name, value in section.items()]
    return tuple(s for s in found if s is not None)


def _sensor(src: Source, name: str, value: Any, inputs: dict[str, str]) -> Sensor | None:
    where = ("sensors", None, name)
    if name not in inputs:
        src.key_error(where, f"[sensors] {name} is not an input of the robot",
                  f"add {name} to [inputs] first (its column in the table is the sensor's event)")
        return None
    if not isinstance(value, dict):
        src.key_error(where, f"[sensors] {name} must be a table like {{ sensor = \"distance\", ... }}, not {value!r}",
                  f'for example: {name} = {{ sensor = "distance", below = "20 cm", at = [0.12, 0] }}')
        return None
    unknown = sorted(set(value) - set(KEYS))
    if unknown:
        src.key_error(where, f"[sensors] {name}: unknown key{'s' * (len(unknown) > 1)} {', '.join(unknown)}",
                  f"known keys: {', '.join(KEYS)}")
    model = value.get("sensor")
    if model not in KINDS:
        src.key_error(where, f"[sensors] {name}: sensor = {model!r} is not a sensor kind tablebot knows",
                  f"write sensor = one of {', '.join(repr(k) for k in KINDS)}")
        return None
    at = _at(src, name, value.get("at"))
    angle = _angle(src, name, value)
    if KINDS[model] == "line":
        return _line(src, name, model, value, at, angle)
    threshold = _threshold(src, name, model, value)
    if at is None or angle is None or threshold is None:
        return None
    direction, level, unit = threshold
    hysteresis = _amount(src, name, "hysteresis", value.get("hysteresis", 0), KINDS[model])
    if hysteresis is None:
        return None
    return Sensor(name, model, at, angle, direction, level, hysteresis[0], unit)


def _line(src: Source, name: str, model: str, value: dict[str, Any], at: tuple[float, float] | None,
          angle: float | None) -> Sensor | None:
    """A floor sensor reads the floor straight below it: no threshold, no direction."""
    extra = [k for k in ("below", "above", "hysteresis", "angle") if k in value]
    if extra:
        src.key_error(("sensors", None, name), f"[sensors] {name}: a line sensor has no {', '.join(extra)}",
                  "it reads 1 over a line and 0 elsewhere; give only sensor and at")
    return None if at is None or angle is None or extra else Sensor(name, model, at)


def _at(src: Source, name: str, value: Any) -> tuple[float, float] | None:
    ok = isinstance(value, list) and len(value) == 2 and all(is_number(v) and abs(v) <= MAX_OFFSET for v in value)
    if not ok:
        src.key_error(("sensors", None, name), f"[sensors] {name}: at must be [forward, left] in metres from the axle "
                  f"centre, not {value!r}", f"for example: at = [0.12, 0] (each within ±{MAX_OFFSET:g} m)")
        return None
    return float(value[0]), float(value[1])


def _angle(src: Source, name: str, value: dict[str, Any]) -> float | None:
    angle = value.get("angle", 0.0)
    if not is_number(angle) or not -180 <= angle <= 180:
        src.key_error(("sensors", None, name), f"[sensors] {name}: angle must be degrees from -180 to 180, "
                  f"not {angle!r}", "0 points straight ahead, positive to the left")
        return None
    return float(angle)


def _threshold(src: Source, name: str, model: str, value: dict[str, Any]) -> tuple[str, float, str] | None:
    """(below|above, threshold in metres or light units, unit written)."""
    given = [k for k in ("below", "above") if k in value]
    if len(given) != 1:
        example = '"20 cm"' if KINDS[model] == "distance" else "1.5"
        src.key_error(("sensors", None, name), f"[sensors] {name}: a {model} sensor needs "
                  f"{'one of below or above, not both' if given else 'a threshold'}",
                  f"write below = {example} (the event is 1 while the reading is below it) or above = {example}")
        return None
    direction = given[0]
    amount = _amount(src, name, direction, value[direction], KINDS[model])
    return None if amount is None else (direction, *amount)


def _amount(src: Source, name: str, key: str, raw: Any, kind: str) -> tuple[float, str] | None:
    """A threshold or hysteresis and the unit written: a length with its unit for distances (the value in
    metres; a bare 0 counts as cm), a plain number for light (unit "")."""
    where = ("sensors", None, name)
    unit = ""
    if kind == "distance":
        if raw == 0:
            return 0.0, "cm"
        match = LENGTH_RE.match(raw) if isinstance(raw, str) else None
        if match is None:
            src.key_error(where, f"[sensors] {name}: {key} must be a length with its unit, not {raw!r}",
                      f'write it in quotes with mm, cm or m: {key} = "20 cm"')
            return None
        metres, unit = float(match[1]) * LENGTH_UNITS[match[2]], match[2]
    else:
        if not is_number(raw):
            src.key_error(where, f"[sensors] {name}: {key} must be a light level (a number), not {raw!r}",
                      f"1 is the level at which a phototransistor switches: {key} = 1.5")
            return None
        metres = float(raw)
    if metres < 0 or not math.isfinite(metres):
        src.key_error(where, f"[sensors] {name}: {key} must not be negative", f"write {key} as 0 or more")
        return None
    return metres, unit
