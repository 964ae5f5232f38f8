"""What a tab's trace player plays: a trace file of the folder, or a property's counterexample (replayed on
the table, or scripted into the arena robot)."""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable
from dataclasses import dataclass

from tablebot.i18n import N_
from tablebot.web.analyse import Analysis
from tablebot.web.arena_robot import ArenaRobot
from tablebot.web.errors import Refused
from tablebot.web.protocol import Counterexample, Message, Trace, TraceMsg
from tablebot.web.tracefile import MAX_PLAYER_TRACE_BYTES, read_trace_bytes, trace_columns
from tablebot.web.workspace import Kind, Workspace

Say = Callable[[Message], Awaitable[None]]


@dataclass(eq=False)
class TracePlayer:
    workspace: Workspace
    say: Say
    analysis: Callable[[], Analysis | None]
    robot: ArenaRobot

    async def open(self, op: Trace) -> None:
        opened = await asyncio.to_thread(self.workspace.read, op.path, Kind.TRACE, MAX_PLAYER_TRACE_BYTES)
        lines = await asyncio.to_thread(read_trace_bytes, opened.data, opened.name)
        await self.say(TraceMsg(opened.name, trace_columns(lines)))

    async def counterexample(self, op: Counterexample) -> None:
        """A property's counterexample: replayed on the table (trace player) or scripted into the arena."""
        analysis = self.analysis()
        if analysis is None or analysis.report is None:
            raise Refused(N_("fix the table's errors first"))
        result = next((r for r in analysis.report.results if r.prop.name == op.name), None)
        if result is None or not result.inputs:
            raise Refused(N_("property {name} has no counterexample", name=repr(op.name)))
        if op.where == "arena":
            await self.robot.script([t.mask for t in result.inputs])
            return
        from tablebot.replay import replay, replay_several

        # a robot of several tables: all of them replayed, the player shows the tab's table and says the others
        lines = list(
            replay(analysis.report.machine, result.inputs)
            if analysis.tables is None
            else replay_several(analysis.tables, result.inputs)
        )
        await self.say(TraceMsg(f"counterexample: {op.name}", trace_columns(lines), result.at_tick))
