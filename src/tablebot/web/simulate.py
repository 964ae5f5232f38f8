"""A tab's arena: the world (with the start pose and lamp the user moved), its settings (seed, battery,
speed), the live run of the table in it, and the frames the page draws."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

from tablebot.analysis.diagram import to_graphviz
from tablebot.analysis.graphviz_run import INSTALL, NOT_FOUND, GraphvizFailed, NoGraphviz, draw
from tablebot.diagnostics import TableBotError, fail
from tablebot.i18n import N_, Message, current
from tablebot.loading import Loaded
from tablebot.machine import Machine
from tablebot.sim.model.scene import Scene
from tablebot.sim.model.world import World
from tablebot.sim.simrobot import SimRobot
from tablebot.table import Table
from tablebot.tables import RobotTables
from tablebot.web.errors import Refused
from tablebot.web.live import SPEEDS, LiveRun
from tablebot.web.worldview import moved, world_json

MAX_SEED = 2**31 - 1


def _number(message: dict[str, Any], key: str, low: float, high: float) -> float | None:
    value = message.get(key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise Refused(N_('"{key}" must be a number', key=key))
    if not low <= value <= high:
        raise Refused(N_('"{key}" must be from {low:g} to {high:g}', key=key, low=low, high=high))
    return float(value)


@dataclass(frozen=True)
class ArenaSettings:
    seed: int = 1
    charge: float | None = None  # None: the world's (or robot's) battery charge
    start: tuple[float, float, float] | None = None  # None: the world's start pose
    lamp: tuple[float, float] | None = None
    speed: str = "1"
    paused: bool = True

    @classmethod
    def of(cls, message: dict[str, Any], old: ArenaSettings) -> ArenaSettings:
        """The settings a reset message asks for; what it leaves out stays as it was."""
        seed = _number(message, "seed", 0, MAX_SEED)
        charge = _number(message, "charge", 0.0, 1.0)
        start, lamp = old.start, old.lamp
        if "start" in message:
            x, y, heading = (_number({"v": v}, "v", -1e3, 1e3) for v in _triple(message["start"]))
            start = (x, y, heading)  # type: ignore[assignment]
        if "lamp" in message:
            pair = message["lamp"]
            if not isinstance(pair, list) or len(pair) != 2:
                raise Refused(N_('"lamp" must be [x, y]'))
            lamp = (_number({"v": pair[0]}, "v", -1e3, 1e3), _number({"v": pair[1]}, "v", -1e3, 1e3))  # type: ignore
        speed = message.get("speed", old.speed)
        if speed not in SPEEDS:
            raise Refused(_speeds())
        paused = message.get("paused", old.paused)
        return cls(
            int(seed) if seed is not None else old.seed,
            charge if charge is not None else old.charge,
            start,
            lamp,
            speed,
            bool(paused),
        )


def _speeds() -> Message:
    return N_("speed must be one of {speeds}", speeds=", ".join(SPEEDS))


def _triple(value: Any) -> list[Any]:
    if not isinstance(value, list) or len(value) != 3:
        raise Refused(N_('"start" must be [x, y, heading]'))
    return value


class Arena:
    """The live robot of one tab (None until the table reads)."""

    def __init__(self) -> None:
        self.settings = ArenaSettings()
        self.run: LiveRun | None = None
        self.table: Table | None = None
        self.machine: Machine | None = None
        self._diagram: tuple[Any, str] | None = None
        self.problem: str | None = None
        self.tables: RobotTables | None = None
        self._view = ""  # the table the page shows, by name ("": the main one): the frames speak of it

    @property
    def view(self) -> str:
        return self._view

    @view.setter
    def view(self, name: str) -> None:
        self._view = name
        if self.run is not None:
            shown = self.tables is not None and name and name != self.tables.names[0]
            self.run.sink.colour_by = f"{name}.state" if shown else None

    def reset(
        self, table: Table, machine: Machine, settings: ArenaSettings, tables: RobotTables | None = None
    ) -> dict[str, Any]:
        """Start the table over in the world with ``settings`` (``tables``: the robot's, all of them run, the
        main one ``table``); a world problem is reported, not raised."""
        self.close()
        self.settings, self.table, self.machine, self.tables = settings, table, machine, tables
        try:
            # the table as edited, with the world the CLI would find for it
            loaded = (
                Loaded(table, machine) if tables is None else Loaded(tables.table, tables.machines[0], tables=tables)
            )
            robot_world = loaded.robot_world()
            if robot_world is not None and robot_world.exists() and not robot_world.is_file():
                raise fail(
                    robot_world,
                    N_("the robot's world is not a regular file (a folder, pipe or device)"),
                    N_("name a world .toml file in the robot file's [sim] section"),
                )
            base: World = loaded.default_world()
            world = moved(base, settings.start, settings.lamp)
            overrides = {"battery": {"charge": settings.charge}} if settings.charge is not None else {}
            scene = loaded.scene(world, overrides, every_table=True)
            self.machine = scene.machine  # a robot of several tables: wired for every input any of them reads
        except TableBotError as exc:
            self.problem = str(exc)
            return {"ok": False, "problem": self.problem}
        self.problem = None
        self.run = LiveRun(scene, _robot(scene, settings.seed), settings.speed, settings.paused)
        self.view = self._view  # the path coloured by the table shown
        return {
            "ok": True,
            "world": world_json(world, scene.params),
            "tick_ms": table.robot.tick_ms,
            "settings": {
                "seed": settings.seed,
                "charge": scene.params["battery"]["charge"],
                "speed": settings.speed,
                "start": list(world.start),
            },
            **self.status(),
        }

    def control(self, action: str, message: dict[str, Any]) -> None:
        run = self.run
        if run is None:
            raise Refused(self.problem or N_("the robot is not running: fix the table first"))
        if action == "play":
            run.play()
        elif action == "pause":
            run.pause()
        elif action == "step":
            run.step()
        elif action == "speed":
            speed = message.get("speed")
            if speed not in SPEEDS:
                raise Refused(_speeds())
            run.set_speed(speed)
            self.settings = replace(self.settings, speed=speed)
        elif action == "hold":
            self._hold(run, message)
        elif action == "script":
            masks = message.get("masks")
            if not isinstance(masks, list) or not all(type(m) is int and 0 <= m < 2**31 for m in masks):
                raise Refused(N_('"masks" must be a list of whole numbers'))
            run.play_script(masks)  # at once, slowing down before the end, and paused on its last tick
        else:
            raise Refused(N_("unknown action {action}", action=repr(action)))

    def _hold(self, run: LiveRun, message: dict[str, Any]) -> None:
        assert self.machine is not None
        name, on = message.get("input"), message.get("on")
        bits = self.machine.input_bits
        if name not in bits:
            raise Refused(
                N_("unknown input {name}: the robot's inputs are {inputs}", name=repr(name), inputs=", ".join(bits))
            )
        if on not in (True, False, None):
            raise Refused(N_('"on" must be true, false or null'))
        run.hold(bits[name], on)

    def status(self) -> dict[str, Any]:
        run = self.run
        if run is None:
            return {"running": False, "paused": True, "speed": self.settings.speed, "held": {}}
        bits = self.machine.input_bits if self.machine else {}
        held = {name: run.robot.forced[bit] for name, bit in bits.items() if bit in run.robot.forced}
        return {
            "running": run.running,
            "paused": run.paused,
            "speed": run.speed,
            "held": held,
            "scripted": len(run.robot.script),
            "error": run.error,
        }

    def frame(self, explain: Callable[..., list[dict[str, Any]]]) -> dict[str, Any] | None:
        run = self.run
        if run is None or self.table is None or self.machine is None:
            return None
        data = run.sink.frame()
        if data is None:
            return None
        latest = data["latest"]
        states = self.machine.states
        extra = latest.extra or {}
        frame = {
            "type": "frame",
            "tick": latest.tick,
            "state": latest.state,
            "state_id": str(states[latest.state]),
            "prev_state": latest.prev_state,
            "timer": latest.timer,
            "event": latest.event,
            "mask": latest.mask,
            "row": latest.row,
            "outputs": list(latest.outputs),
            "fired": data["fired"],
            # by state id: the page colours a point by its state, and an edit may reorder the states
            "path": data["path"],  # [x, y, state id]: coloured by the table shown
            "pose": [extra.get("x"), extra.get("y"), extra.get("heading")],
            "bumpers": extra.get("bumpers", 0),
            "light": list(extra.get("light", (0.0, 0.0))),
            "battery_v": extra.get("battery_v"),
            "late_ms": extra.get("late_ms"),
            **self.status(),
        }
        # each lamp's output this tick (0: off, up to 8: full), drawn on the robot
        frame["lamps"] = {
            name: latest.outputs[i]
            for i, name in enumerate(self.machine.output_names)
            if name in self.table.robot.lamps
        }
        if self.tables is not None and self.view and self.view != self.tables.names[0]:
            shown = viewed(self.tables, self.view, extra, latest.tick)
            if run.paused:
                shown["why"] = why_viewed(self.tables, self.view, latest.prev_extra, extra, explain)
            return {**frame, **shown}
        if run.paused:
            frame["why"] = explain(self.table, self.machine, latest.prev_state, latest.event)
        return frame

    def diagram(self, table: Table) -> str:
        """The state diagram as SVG text in the language in use (cached per table and language; Graphviz takes
        tens of milliseconds)."""
        key = (table.rows, table.events, table.robot, current())
        if self._diagram is None or self._diagram[0] != key:
            svg = studio_diagram(table)
            self._diagram = (key, svg)
        return self._diagram[1]

    def close(self) -> None:
        if self.run is not None:
            self.run.close()
            self.run = None


def studio_diagram(table: Table) -> str:
    """The CLI's diagram without its title and legend (the page shows both), as SVG text; without it, the
    sentence saying why, which the page shows in the diagram's place (not starting with "<")."""
    graph = to_graphviz(table)
    graph.graph_attr.update(label="", ranksep="0.5", nodesep="0.25")
    graph.body[:] = [line for line in graph.body if "__legend" not in line]  # the grid's header says it all
    try:
        return draw(graph.source, "svg").decode("utf-8")
    except NoGraphviz:
        return N_("No diagram: {why}. To draw it: {how}; then reopen the table.", why=NOT_FOUND, how=INSTALL)
    except GraphvizFailed as exc:
        return N_("No diagram: {why}", why=str(exc))


def viewed(tables: RobotTables, name: str, extra: dict[str, Any], tick: int) -> dict[str, Any]:
    """A frame's state, row, timer and event as table ``name`` (not the main one) had them on its latest tick:
    what the page shows while that table's tab is open. Its row is the first of the rows as run (a group's row
    is one per state) written as the trace's, so the grid lights the line the file has."""
    table = tables.tables[tables.index(name)]
    written = extra.get(f"{name}.row")
    row = next((r.index for r in table.rows if r.as_written == written), -1) if written is not None else -1
    state = extra.get(f"{name}.state")
    states = tables.machines[tables.index(name)].states
    return {
        "state": states.index(state) if state in states else 0,
        "state_id": str(state),
        "row": row,
        "timer": extra.get(f"{name}.timer", 0),
        "event": extra.get(f"{name}.event", 0),
        "fired": [[tick, row]] if row >= 0 else [],
    }


def why_viewed(
    tables: RobotTables,
    name: str,
    before: dict[str, Any] | None,
    extra: dict[str, Any],
    explain: Callable[..., list[dict[str, Any]]],
) -> list[dict[str, Any]]:
    """Why each row of table ``name``'s state fired or not on the latest tick: its state before the tick (the
    tick before's ``NAME.state``; on the first, its start) and its events then."""
    k = tables.index(name)
    table, machine = tables.tables[k], tables.machines[k]
    state = (before or {}).get(f"{name}.state", table.robot.initial_state)
    index = machine.states.index(state) if state in machine.states else 0
    return explain(table, machine, index, int(extra.get(f"{name}.event", 0)))


def _robot(scene: Scene, seed: int) -> SimRobot:
    robot = SimRobot(scene, record_history=False)
    robot.reset(seed=seed)
    return robot
