"""Putting a simulation together: table + robot ``[sim]`` + world → arrays the runner and physics core use.

Finds the default arena, merges parameter layers (defaults < robot file < world file), checks the
wiring of sensors and motors against the robot, and checks the start pose is free.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from tablebot.diagnostics import Diagnostic, TableBotError, fail
from tablebot.engine.as_one import robot_machine
from tablebot.i18n import N_, NP_, Message
from tablebot.machine import FLAT_BITS, Machine
from tablebot.robot import Robot
from tablebot.sim import columns as L
from tablebot.sim.model.params import (
    INPUT_ROLES,
    Params,
    merged,
    param_row,
    problems,
    top_speed,
)
from tablebot.sim.model.world import Geometry, World, default_world, geometry, load_world
from tablebot.sim.physics.contacts import body_corners, deepest_contact
from tablebot.table import Table
from tablebot.tables import RobotTables

MAX_STEP_M = 0.04  # the most the robot may move in one tick: well under half its length, so contacts stay found
SIDE_COLUMNS = {"right_motor": L.PUL_R, "left_motor": L.PUL_L}


@dataclass(frozen=True)
class Scene:
    """Everything fixed for one run: the machine, the world, the parameters and their packed arrays."""

    table: Table
    machine: Machine
    world: World
    params: Params
    geometry: Geometry
    P: np.ndarray  # (1, N_PARAM)
    bits: np.ndarray  # event bits of the BumberBot roles (B_*), then of each declared sensor; 0 = not wired
    drive: tuple[int, int]  # output indices of the right and left motor
    pulse_columns: tuple[int, ...]  # per robot counter: state column of its motor's pulses, -1 = none
    lamp_outputs: tuple[int, ...]  # output indices of the robot's lamps
    #: A robot of several tables run whole (every table, issue 36): ``machine`` is then
    #: :func:`tablebot.engine.as_one.robot_machine`'s (the robot-wide input layout ``bits`` is in) and the run
    #: steps a RobotEngine tick by tick. None: the one table of ``machine`` (or a robot's main table alone).
    tables: RobotTables | None = None

    @property
    def tick_s(self) -> float:
        return self.table.robot.tick_s


def sensor_columns(scene: Scene) -> list[tuple[str, int, float, int]]:
    """What a trace adds for each declared sensor: (key, state column, scale, decimals), e.g. the distance
    sensor I3 as ``"I3_cm": 23.0``, a light sensor as ``"I4_light": 1.2345``, a line sensor as ``"I1_line": 1``."""
    columns = []
    for k, sensor in enumerate(scene.table.robot.sensors[: L.MAX_SENSORS]):
        suffix, scale, decimals = sensor.sensor_kind.trace
        columns.append((f"{sensor.name}_{suffix}", L.READING + k, scale, decimals))
    return columns


def robot_layer(robot: Robot) -> tuple[dict[str, Any], Path | None]:
    """The robot file's ``[sim]`` parameter sections (checked when the robot file was read) and its
    default world (``sim.world``)."""
    sim = robot.sections.get("sim")
    return (sim.layer, sim.world) if sim is not None else ({}, None)


def find_world(table: Table, world_path: Path | None, robot_world: Path | None) -> World:
    """--world, else the robot's sim.world, else arena.toml beside the table, else an empty room."""
    for candidate in (world_path, robot_world):
        if candidate is not None:
            return load_world(candidate)
    beside = Path(table.path).parent / "arena.toml"
    return load_world(beside) if beside.is_file() else default_world()


def scene_for(
    table: Table,
    machine: Machine,
    world_path: Path | None = None,
    overrides: dict[str, Any] | None = None,
    tables: RobotTables | None = None,
) -> Scene:
    """The whole chain for one table (or, with ``tables``, every table of the robot): its robot's [sim], its
    world (see :func:`find_world`), checked and packed."""
    layer, robot_world = robot_layer(table.robot)
    return prepare(table, machine, find_world(table, world_path, robot_world), layer, overrides, tables)


def prepare(
    table: Table,
    machine: Machine,
    world: World,
    robot_params: dict[str, Any] | None = None,
    overrides: dict[str, Any] | None = None,
    tables: RobotTables | None = None,
) -> Scene:
    """Check that robot, table and world fit together and pack them for the physics core; with ``tables``,
    for every table of the robot (its inputs wired in the robot-wide layout)."""
    if tables is not None:
        machine = robot_machine(tables)
    robot_params = robot_params or {}
    params = _unwire_absent_sensors(merged(robot_params, world.params, overrides or {}), table.robot)
    found: list[tuple[str, str, str, str]] = [
        (section, key, message, N_("fix the value in the world or robot file"))
        for section, key, message in problems(params)
    ]
    found += _wiring_errors(params, table.robot)
    if found:
        raise TableBotError(
            Diagnostic(*_locate(section, key, world, table.robot, robot_params), None, message, hint)
            for section, key, message, hint in found
        )
    _check_tick(params, table.robot)
    tick_s = table.robot.tick_s
    _check_sensor_count(table.robot)
    _check_events(table)
    P = param_row(params, tick_s, table.robot.sensors)[None, :]
    geo = geometry(world)
    check_start(world, geo, P)
    outputs = machine.output_names
    robot = table.robot
    # the BumberBot roles' bits, then one per declared sensor (sensor slot k at B_SENSOR + k)
    bits = np.array(
        [machine.input_bits.get(params.wiring[role], 0) for role in INPUT_ROLES]
        + [machine.input_bits.get(sensor.name, 0) for sensor in robot.sensors],
        dtype=np.int64,
    )
    motor_roles = {params.wiring["right_motor"]: "right_motor", params.wiring["left_motor"]: "left_motor"}
    columns = tuple(SIDE_COLUMNS[motor_roles[c.motor]] if c.motor in motor_roles else -1 for c in robot.counters)
    return Scene(
        table=table,
        machine=machine,
        world=world,
        params=params,
        geometry=geo,
        P=P,
        bits=bits,
        drive=(outputs.index(params.wiring["right_motor"]), outputs.index(params.wiring["left_motor"])),
        pulse_columns=columns,
        lamp_outputs=tuple(outputs.index(lamp) for lamp in robot.lamps),
        tables=tables,
    )


def _locate(section: str, key: str, world: World, robot: Robot, robot_params: dict[str, Any]) -> tuple[str, int | None]:
    """The file and line that set ``[section] key`` (the world wins over the robot's ``[sim.*]``), else
    the section's line; a value no file set is the robot's to fix."""
    for whole in (False, True):
        found = None if whole else key
        if section in world.params and (whole or key in world.params[section]):
            return world.path, world.line(section, found)
        if section in robot_params and (whole or key in robot_params[section]):
            return robot.source, robot.line(f"sim.{section}", found)
    return robot.source, None


def _unwire_absent_sensors(params: Params, robot: Robot) -> Params:
    """Sensor roles left at the BumberBot's wiring stay unconnected on a robot without that input, or
    whose input is a sensor the robot file declares in [sensors]."""
    declared = {s.name for s in robot.sensors}
    wiring = {
        role: name
        if role.endswith("motor") or role in params.wired or (name in robot.inputs and name not in declared)
        else ""
        for role, name in params.wiring.items()
    }
    return replace(params, wiring=wiring)


def _wiring_errors(params: Params, robot: Robot) -> list[tuple[str, str, str, str]]:
    """Drive motors must be two motors of the robot; a sensor must name an input ("" = not connected)."""
    if len(robot.motors) < 2:
        return [
            (
                "wiring",
                "right_motor",
                NP_(
                    "the simulated robot drives two wheels, but robot {robot} has {n} motor",
                    "the simulated robot drives two wheels, but robot {robot} has {n} motors",
                    len(robot.motors),
                    robot=robot.name,
                ),
                N_("add a right and a left motor to [motors] in the robot file"),
            )
        ]
    errors: list[tuple[str, str, str, str]] = []
    for role, name in params.wiring.items():
        motor = role.endswith("motor")
        wanted = robot.motors if motor else robot.inputs
        if name in wanted or (not motor and name == ""):
            continue
        errors.append(("wiring", role, _not_wired(role, name, motor, robot.name), _wire_hint(role, wanted, motor)))
    declared = {s.name: s for s in robot.sensors}
    for role, name in params.wiring.items():
        if name in declared:
            errors.append(
                (
                    "wiring",
                    role,
                    N_(
                        "wiring: {role} = {name!r}, but {name} is declared in [sensors] as a {model} sensor",
                        role=role,
                        name=name,
                        model=declared[name].model,
                    ),
                    N_('wire {role} to another input, or to "none"', role=role),
                )
            )
    right, left = params.wiring["right_motor"], params.wiring["left_motor"]
    if right == left and right in robot.motors:
        errors.append(
            (
                "wiring",
                "left_motor",
                N_("wiring: right_motor and left_motor are both {right}", right=right),
                N_("the simulated robot drives two wheels: give each its own motor"),
            )
        )
    return errors


def _not_wired(role: str, name: str, motor: bool, robot: str) -> Message:
    if motor:
        return N_("wiring: {role} = {name!r} is not a motor of robot {robot}", role=role, name=name, robot=robot)
    return N_("wiring: {role} = {name!r} is not an input of robot {robot}", role=role, name=name, robot=robot)


def _wire_hint(role: str, wanted: tuple[str, ...] | list[str], motor: bool) -> Message:
    known = tuple(wanted) or (N_("none"),)
    if motor:
        return N_(
            "its motors are {known}; set [wiring] {role} in the world or [sim.wiring] in the robot file",
            known=known,
            role=role,
        )
    return N_(
        'its inputs are {known}; set [wiring] {role} in the world or [sim.wiring] in the robot file ("none": '
        "not connected)",
        known=known,
        role=role,
    )


def _check_sensor_count(robot: Robot) -> None:
    if len(robot.sensors) > L.MAX_SENSORS:
        raise fail(
            robot.source,
            N_(
                "the simulator models at most {most} sensors in [sensors], and robot {robot} declares {n}",
                most=L.MAX_SENSORS,
                robot=robot.name,
                n=len(robot.sensors),
            ),
            N_("declare fewer sensors"),
            robot.line("sensors"),
        )


def _check_events(table: Table) -> None:
    """The compiled simulator looks each tick's row up in a flat table of every event set: 2**events per state."""
    if len(table.events) > FLAT_BITS:
        raise fail(
            table.path,
            N_(
                "the table has {n} event columns (T, inputs and counters); the simulator takes at most {most}",
                n=len(table.events),
                most=FLAT_BITS,
            ),
            N_("simulate a table that looks at fewer inputs"),
            1,
        )


def _check_tick(params: Params, robot: Robot) -> None:
    """The robot moves once per tick: a coarse tick would carry it through thin walls unnoticed."""
    top = top_speed(params)
    step = robot.seconds(top)
    if step > MAX_STEP_M:
        raise fail(
            robot.source,
            N_(
                "tick_ms = {tick_ms} is too coarse for the simulator: the robot would move up "
                "to {cm:.0f} cm per tick, through thin walls",
                tick_ms=robot.tick_ms,
                cm=100 * step,
            ),
            N_(
                "simulate with tick_ms = {most} or less (the engine and the firmware take any tick)",
                most=math.floor(MAX_STEP_M / top * 1000),
            ),
            robot.line("", "tick_ms"),
        )


def check_start(world: World, geo: Geometry, P: np.ndarray) -> None:
    """A clear error when the robot of parameters ``P`` overlaps a wall or obstacle at the world's start pose."""
    x, y, heading = world.start
    s = np.zeros(L.N_STATE)
    s[L.X], s[L.Y], s[L.TH] = x, y, np.radians(heading)
    corners = np.empty((4, 2))
    body_corners(s, P[0], corners)
    hit = deepest_contact(s, P[0], corners, geo.verts, geo.pstart, geo.pbound, geo.circles)
    if hit[0] > 1e-9:
        raise fail(
            world.path,
            N_(
                "the robot at its start pose ({x:g}, {y:g}, heading {heading:g}°) overlaps a wall "
                "or obstacle near ({hx:.2f}, {hy:.2f})",
                x=x,
                y=y,
                heading=heading,
                hx=hit[3],
                hy=hit[4],
            ),
            N_("move [start] at, or turn it with heading"),
            world.line("start", "at"),
        )
