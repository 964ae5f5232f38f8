"""The BumberBot's physical parameters: defaults with their sources, validation, and the packed parameter row.
Values come, in rising priority, from :data:`DEFAULTS`, the robot file's ``[sim.*]`` sections and the
world file's sections of the same names.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tablebot.i18n import N_
from tablebot.sensors import Sensor
from tablebot.sim import columns as L
from tablebot.tomlfile import Source, known_keys, number, table_of

Number = int | float

# Each entry: (default, low, high, what it is and where the number comes from).
DEFAULTS: dict[str, dict[str, tuple[Any, Number, Number, str]]] = {
    "body": {
        # The ROBO Mobile Set's assembly drawings are not at hand: the body numbers are estimates on the
        # fischertechnik 15 mm grid (a 9-grid axle between the wheel centres, a 12 × 18 cm frame).
        "wheel_base": (0.135, 0.02, 2.0, "m between the wheel contact points (estimate)"),
        "wheel_diameter": (0.060, 0.005, 1.0, "m (estimate: fischertechnik 60 mm tyre)"),
        "front": (0.12, 0.01, 2.0, "m from the axle centre to the front bumper (estimate)"),
        "rear": (0.07, 0.01, 2.0, "m from the axle centre to the rear bumper (estimate)"),
        "half_width": (0.09, 0.01, 2.0, "m, half the body width over the wheels (estimate)"),
        "bumper_overlap": (
            0.012,
            0.0,
            1.0,
            "m each half of the front bumper reaches past the middle: "
            "a hit this close to the middle closes both switches (estimate)",
        ),
        "bumper_wrap": (0.02, 0.0, 1.0, "m each front bumper wraps round its corner (estimate)"),
        "switch_travel": (0.001, 0.0, 0.05, "m an obstacle may be from a bumper and still close it"),
        "gyration_radius": (0.07, 0.005, 2.0, "m; how a corner push splits into shift and turn (estimate)"),
    },
    "motor": {
        "levels": (8, 1, 64, "speed levels: the table's 1..8 are duty level/8 (ROBO Interface PWM)"),
        "speed_per_volt": (0.0, 0.0, 10.0, "wheel m/s per volt above friction; 0 = calibrate from spin"),
        "friction_volts": (0.3, 0.0, 5.0, "volts a motor needs before it turns at all (estimate)"),
        "time_constant": (0.05, 0.0, 5.0, "s for a wheel to reach 63% of a new speed (estimate)"),
        "spin_level": (2, 1, 64, "calibration: the document's Seek-Straight spin uses speed 2 ..."),
        "spin_ticks": (895, 1, 1_000_000, "... for 895 ticks of the timer ..."),
        "spin_degrees": (270.0, 1.0, 100_000.0, "... and the prose says it turns 270 degrees"),
    },
    "battery": {
        "charge": (1.0, 0.0, 1.0, "state of charge at the start: 1 = full, 0 = empty"),
        # fischertechnik Accu Set (art. 34969): 8.4 V NiMH pack, i.e. 7 cells; a NiMH cell reads about
        # 1.3 V charged and 1.0 V empty (standard NiMH figures, not a measurement of this pack).
        "full_volts": (9.1, 1.0, 50.0, "open-circuit volts of a full pack (7 × 1.3 V NiMH)"),
        "empty_volts": (7.0, 0.5, 50.0, "open-circuit volts of an empty pack (7 × 1.0 V)"),
        "capacity_mah": (1500.0, 1.0, 1e6, "mAh (Accu Set nominal capacity, estimate)"),
        "internal_ohms": (0.5, 0.0, 20.0, "ohms of pack and wiring: the sag under load (estimate)"),
        "idle_amps": (0.1, 0.0, 10.0, "A the interface draws (estimate)"),
        "motor_amps": (0.3, 0.0, 10.0, "A one motor draws at full duty under load (estimate)"),
    },
    "encoder": {
        # ftrobopy (setDistance docstring): "190 pulses per 3 axle turns, so 63 1/3 per turn" for the
        # TXT encoder motor; see also ../shared/notes/fischertechnik.md. Wheels sit on the output shaft.
        "pulses_per_turn": (190 / 3, 1.0, 100_000.0, "pulses per wheel turn (encoder motor: 63⅓)"),
    },
    "light": {
        "forward": (0.11, -2.0, 2.0, "m from the axle centre to the phototransistors (estimate)"),
        "sideways": (0.03, 0.0, 2.0, "m each phototransistor sits right/left of the middle (estimate)"),
        "toe_out": (10.0, 0.0, 90.0, "degrees each one points outward, so they see different sides"),
        "half_response": (20.0, 0.5, 89.0, "degrees off its axis at which a sensor gets half the light"),
        "field_of_view": (40.0, 1.0, 90.0, "degrees off axis beyond which it sees nothing (lens tube)"),
        "near": (0.05, 0.001, 1.0, "m; closer lamps count as this close (no infinite readings)"),
    },
    "distance": {
        # The fischertechnik ROBO TX ultrasonic distance sensor (art. 133009) reports whole centimetres:
        # harbaum/ftduino manual, section 9.2.16 ("liefert den Messwert ... in Zentimetern", values 0 to
        # 1023 cm, refreshed about twice a second on the ftDuino); ftrobopy's ultrasonic().distance()
        # returns cm as an integer. No published figure for its beam or useful range was found: those
        # below are typical of 40 kHz ultrasonic rangers and marked as estimates.
        "range": (4.0, 0.05, 10.23, "m beyond which nothing echoes and it reads this value (estimate)"),
        "blind": (0.03, 0.0, 1.0, "m closer than which it cannot measure and reads this value (estimate)"),
        "beam": (15.0, 0.5, 60.0, "degrees, half the opening angle of the beam (estimate: 30 degrees wide)"),
        "resolution": (0.01, 0.0001, 0.5, "m per step of the reading: whole centimetres (ftDuino manual 9.2.16)"),
    },
    "noise": {
        "motor_spread": (0.02, 0.0, 0.5, "relative sd of each motor's speed factor, drawn once per run"),
        "motor": (0.01, 0.0, 0.5, "relative sd of motor speed, drawn every tick"),
        "light": (0.05, 0.0, 0.5, "relative sd of light readings, drawn every tick"),
    },
}
SECTIONS = (*DEFAULTS, "wiring")
#: The calibration spin's ticks are the document's 10 ms ticks (895 of them: 8.95 s), whatever the tick of
#: the robot simulated: a table with another tick_ms runs on the same motors.
SPIN_TICK_S = 0.010
#: Which robot names play which part; the document's BumberBot wiring.
WIRING: dict[str, str] = {
    "right_motor": "M1",
    "left_motor": "M2",
    "front_right": "I3",
    "front_left": "I4",
    "rear": "I5",
    "light_right": "I7",
    "light_left": "I8",
}
INPUT_ROLES = ("front_right", "front_left", "rear", "light_right", "light_left")  # layout B_* order


@dataclass(frozen=True)
class Params:
    """Resolved parameters: ``values[section][key]`` plus the wiring of roles to robot names."""

    values: dict[str, dict[str, Any]]
    wiring: dict[str, str]
    wired: frozenset[str] = frozenset()  # roles a file set explicitly (the rest are the BumberBot's)

    def __getitem__(self, section: str) -> dict[str, Any]:
        return self.values[section]


def check_layer(src: Source, data: dict[str, Any], prefix: str = "") -> dict[str, dict[str, Any]]:
    """The parameter sections of one file (``[battery]`` … or ``[sim.battery]`` …), checked."""
    layer: dict[str, dict[str, Any]] = {}
    for section in (s for s in SECTIONS if s in data):
        name = prefix + section
        table = table_of(src, (name, None, None), data[section])
        known = tuple(WIRING) if section == "wiring" else tuple(DEFAULTS[section])
        known_keys(src, (name, None), table, known)
        read = _wiring_value if section == "wiring" else _parameter_value
        values = {key: read(src, name, key, value) for key, value in table.items() if key in known}
        layer[section] = {key: value for key, value in values.items() if value is not None}
    return layer


@dataclass(frozen=True)
class SimSection:
    """A robot file's ``[sim]``: its parameter layer (``[sim.battery]`` ...) and its default world."""

    layer: dict[str, dict[str, Any]]
    world: Path | None


def read_robot_sim(src: Source, sim: Any, robot: Any) -> SimSection:
    """``[sim]`` of a robot file, checked (errors go to ``src``): parameter sections and ``world``."""
    if not isinstance(sim, dict):
        src.error(("", None, "sim"), N_("[sim] must be a table"), N_("write [sim.battery] etc."))
        return SimSection({}, None)
    known_keys(src, ("sim", None), sim, (*SECTIONS, "world"))
    layer = check_layer(src, sim, prefix="sim.")
    world = sim.get("world")
    path = Path(src.path).parent / world if isinstance(world, str) else None
    if world is not None and not isinstance(world, str):
        src.error(
            ("sim", None, "world"),
            N_("sim.world must be a file name"),
            N_("for example: {example}", example='world = "arena.toml"'),
        )
    elif path is not None and not path.is_file():
        src.error(
            ("sim", None, "world"),
            N_("sim.world: {path} is not a file", path=str(path)),
            N_("name a world file, relative to the robot file's folder"),
        )
        path = None
    return SimSection(layer, path)


def _parameter_value(src: Source, name: str, key: str, value: Any) -> Number | None:
    """A number within the parameter's range (an integer where its default is one), else None after an error."""
    default, low, high, _ = DEFAULTS[name.rsplit(".", 1)[-1]][key]  # [battery] or [sim.battery]
    return number(src, (name, None, key), value, low, high, integer=isinstance(default, int))


def _wiring_value(src: Source, name: str, key: str, value: Any) -> str | None:
    """The robot name a role is wired to ("" for a sensor that is "none"), else None after an error."""
    if isinstance(value, str) and (value or not key.endswith("motor")):
        return "" if value.lower() == "none" else value
    src.error(
        (name, None, key),
        N_("[{name}] {key} must name a robot input or motor", name=name, key=key),
        N_('for example: {key} = "{value}" (a sensor may be "none")', key=key, value=WIRING[key]),
    )
    return None


def merged(*layers: dict[str, Any]) -> Params:
    """Defaults overlaid by each layer (already validated): ``{section: {key: value}}``."""
    values = {sec: {k: spec[0] for k, spec in keys.items()} for sec, keys in DEFAULTS.items()}
    wiring = dict(WIRING)
    wired: set[str] = set()
    for layer in layers:
        for section, keys in layer.items():
            (wiring if section == "wiring" else values[section]).update(keys)
            if section == "wiring":
                wired |= set(keys)
    return Params(values, wiring, frozenset(wired))


def problems(params: Params) -> list[tuple[str, str, str]]:
    """Combinations no single value shows: (section, key, message)."""
    found: list[tuple[str, str, str]] = []
    bat, body = params["battery"], params["body"]
    if bat["empty_volts"] >= bat["full_volts"]:
        found.append(("battery", "empty_volts", N_("empty_volts must be below full_volts")))
    if params["distance"]["blind"] >= params["distance"]["range"]:
        found.append(("distance", "blind", N_("blind must be below range")))
    if body["bumper_overlap"] > body["half_width"]:
        found.append(("body", "bumper_overlap", N_("bumper_overlap must not exceed half_width")))
    try:
        speed_per_volt(params)
    except ValueError as exc:
        found.append(("motor", "friction_volts", exc.args[0]))  # the message itself: said in the reader's language
    return found


def spin_speed(params: Params) -> float:
    """Wheel surface speed (m/s) the calibration spin needs: 270° in 8.95 s about the axle centre."""
    m = params["motor"]
    radians = math.radians(m["spin_degrees"])
    return radians / (m["spin_ticks"] * SPIN_TICK_S) * params["body"]["wheel_base"] / 2


def _formulas() -> tuple[Callable[..., float], Callable[..., float]]:
    """The physics core's ``duty`` and ``pack_volts``, run as the plain Python they are written in.

    Planning calls each a few times per scene; called compiled, each would first load its machine code
    (tens of ms in a fresh process). Compiled without fast-math, the same arithmetic gives the same bits
    in Python (tests/sim/test_sim_params_formulas.py).
    """
    from tablebot.sim.physics.step import duty, pack_volts  # numba is imported, never run, for these

    return duty.py_func, pack_volts.py_func


def terminal_volts(params: Params, charge: float, levels: tuple[int, ...]) -> float:
    """Battery volts under the load of motors at these speed levels, by the physics core's formula."""
    duty, pack_volts = _formulas()
    b, m = params["battery"], params["motor"]
    amps = b["idle_amps"] + b["motor_amps"] * sum(duty(v, m["levels"]) for v in levels)
    return pack_volts(b["full_volts"], b["empty_volts"], charge, amps, b["internal_ohms"])


def speed_per_volt(params: Params) -> float:
    """The motor constant: given, or solved from the calibration spin on a full battery (the document's
    Seek-Straight spin: M1 back, M2 forward, speed 2, 895 ticks, turns 270°)."""
    m = params["motor"]
    if m["speed_per_volt"] > 0:
        return float(m["speed_per_volt"])
    level = m["spin_level"]
    volts = terminal_volts(params, 1.0, (level, level))
    duty, _ = _formulas()
    drive = duty(level, m["levels"]) * volts - m["friction_volts"]
    if drive <= 0:
        raise ValueError(N_("the calibration spin's speed level cannot overcome friction_volts"))
    return spin_speed(params) / drive


def top_speed(params: Params) -> float:
    """The fastest steady wheel speed (m/s): both motors at full duty on a full battery, without noise."""
    levels = params["motor"]["levels"]
    volts = terminal_volts(params, 1.0, (levels, levels))
    return speed_per_volt(params) * max(0.0, volts - params["motor"]["friction_volts"])


def param_row(params: Params, tick_s: float, sensors: tuple[Sensor, ...] = ()) -> np.ndarray:
    """The packed row the physics core reads (layout ``P_*``), with ``sensors`` in slots 0, 1, ..."""
    body, motor, bat, light, noise = (params[s] for s in ("body", "motor", "battery", "light", "noise"))
    p = np.zeros(L.N_PARAM)
    p[L.P_DT] = tick_s
    p[L.P_BASE], p[L.P_WHEEL_R] = body["wheel_base"], body["wheel_diameter"] / 2
    p[L.P_FRONT], p[L.P_REAR], p[L.P_HALF_W] = body["front"], body["rear"], body["half_width"]
    p[L.P_OVERLAP], p[L.P_WRAP], p[L.P_GAP] = body["bumper_overlap"], body["bumper_wrap"], body["switch_travel"]
    p[L.P_GYR2] = body["gyration_radius"] ** 2
    p[L.P_KV], p[L.P_VF] = speed_per_volt(params), motor["friction_volts"]
    tau = motor["time_constant"]
    p[L.P_ALPHA] = 1.0 if tau <= 0 else 1.0 - math.exp(-tick_s / tau)
    p[L.P_LEVELS] = motor["levels"]
    p[L.P_VFULL], p[L.P_VEMPTY], p[L.P_RINT] = bat["full_volts"], bat["empty_volts"], bat["internal_ohms"]
    p[L.P_CAP] = bat["capacity_mah"] * 3.6  # ampere-seconds
    p[L.P_IIDLE], p[L.P_IMOTOR] = bat["idle_amps"], bat["motor_amps"]
    p[L.P_PPR] = params["encoder"]["pulses_per_turn"]
    p[L.P_LX], p[L.P_LY], p[L.P_TOE] = light["forward"], light["sideways"], math.radians(light["toe_out"])
    p[L.P_COS_FOV] = math.cos(math.radians(light["field_of_view"]))
    p[L.P_EXP] = math.log(0.5) / math.log(math.cos(math.radians(light["half_response"])))
    p[L.P_DMIN] = light["near"]
    p[L.P_NMOTOR], p[L.P_NLIGHT] = noise["motor"], noise["light"]
    dist = params["distance"]
    p[L.P_DRANGE], p[L.P_DMIN_RANGE] = dist["range"], dist["blind"]
    p[L.P_DBEAM], p[L.P_DRES] = math.radians(dist["beam"]), dist["resolution"]
    for k, sensor in enumerate(sensors[: L.MAX_SENSORS]):
        p[L.P_SENSOR + k * L.SENSOR_FIELDS : L.P_SENSOR + (k + 1) * L.SENSOR_FIELDS] = sensor_fields(sensor)
    return p


def sensor_fields(sensor: Sensor) -> list[float]:
    """One sensor slot (layout ``F_*``): a kind without a threshold (a line sensor) is "above 0.5" of its 1/0
    reading."""
    fields = [0.0] * L.SENSOR_FIELDS
    kind = sensor.sensor_kind
    fields[L.F_KIND] = kind.code
    fields[L.F_X], fields[L.F_Y], fields[L.F_AIM] = sensor.at[0], sensor.at[1], math.radians(sensor.angle)
    if not kind.units:
        fields[L.F_ON], fields[L.F_OFF], fields[L.F_SIGN] = 0.5, 0.5, 1.0
    else:
        fields[L.F_ON], fields[L.F_OFF] = sensor.switch_points()
        fields[L.F_SIGN] = -1.0 if sensor.direction == "below" else 1.0
    return fields
