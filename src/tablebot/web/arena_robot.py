"""A tab's arena robot: the simulated robot that runs the tab's table live (:class:`~tablebot.web.simulate.Arena`),
reset, played, paused, stepped and held from the page, and the frames of what it did."""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field
from typing import Any

from tablebot.i18n import N_
from tablebot.table import Table
from tablebot.web.analyse import Analysis, explain
from tablebot.web.errors import Refused
from tablebot.web.protocol import ArenaMsg, ControlMsg, FrameMsg, Message, Sim
from tablebot.web.simulate import Arena, ArenaSettings

Say = Callable[[Message], Awaitable[None]]


@dataclass(eq=False)
class ArenaRobot:
    """``analysis`` gives the tab's current analysis (the robot runs only a table that reads)."""

    say: Say
    analysis: Callable[[], Analysis | None]
    arena: Arena = field(default_factory=Arena)

    def restart(self) -> None:
        """A new table: the old robot stops, and the arena starts over from its defaults."""
        self.arena.close()
        self.arena = Arena()

    def runs(self, analysis: Analysis) -> bool:
        """Whether the robot runs the robot of ``analysis`` already (one of its several tables): a tab of another
        of its tables is shown without starting it over."""
        running, tables = self.arena.tables, analysis.tables
        return running is not None and tables is not None and running.robot.source == tables.robot.source

    def view(self, name: str) -> None:
        """The page shows table ``name`` of the robot: the frames say its state and row."""
        self.arena.view = name

    def diagram(self, table: Table) -> str:
        return self.arena.diagram(table)

    async def reset(self, fields: dict[str, Any]) -> None:
        """Put the robot at its start (with the settings ``fields`` changes) and send the arena."""
        analysis = self.analysis()
        if analysis is None or analysis.table is None or analysis.machine is None:
            raise Refused(N_("fix the table's errors first: the robot runs only a table that reads"))
        settings = ArenaSettings.of(fields, self.arena.settings)
        tables = analysis.tables
        main = (analysis.table, analysis.machine) if tables is None else (tables.table, tables.machines[0])
        info = await asyncio.to_thread(self.arena.reset, *main, settings, tables)
        await self.say(ArenaMsg(info))

    async def control(self, op: Sim) -> None:
        if op.action == "reset":
            await self.reset(dict(op.fields))
            return
        self.arena.control(op.action, dict(op.fields))
        await self.say(ControlMsg(self.arena.status()))

    async def script(self, masks: list[int]) -> None:
        """Play these input masks from the start, then pause (a counterexample in the arena)."""
        await self.reset({})
        self.arena.control("script", {"masks": masks})
        await self.say(ControlMsg(self.arena.status()))

    async def frame(self) -> None:
        """Send what the robot did since the last frame (called by the app's timer)."""
        frame = self.arena.frame(explain)
        if frame is not None:
            await self.say(FrameMsg(frame))

    def close(self) -> None:
        self.arena.close()
