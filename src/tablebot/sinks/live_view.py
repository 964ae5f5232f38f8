"""A live terminal view of a running robot (rich): the state and its name, the inputs lit, a bar per motor,
lamp levels, counters, the robot's time and how many ticks ran late. Redrawn four times a second from the
latest tick by rich's own thread; the run loop never waits for the terminal."""

from __future__ import annotations

import re
from typing import Any

from rich.columns import Columns
from rich.console import Console, Group
from rich.live import Live
from rich.panel import Panel
from rich.table import Table
from rich.text import Text

from tablebot.i18n import _, localise
from tablebot.loop import Lateness, RunEnd, RunInfo, TickBlock
from tablebot.table import MAX_SPEED

BAR = 8  # characters per motor direction
#: C0 controls but tab and line feed, DEL and C1 controls: a NUL, a shift-out (\x0e switches a VT100's
#: character set) or a C1 CSI (\x9b, a one-byte ESC [) would act on the terminal.
_CONTROLS_RE = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")


def plain(text: str) -> str:
    """User text (labels, state names) made safe for the terminal: every control character removed.
    Rich ``Text`` never reads markup, so brackets stay brackets."""
    return _CONTROLS_RE.sub("", text)


def motor_bar(speed: int) -> Text:
    """``[    ████|        ] +4``: backward to the left of the bar's middle, forward to the right."""
    n = min(BAR, round(abs(speed) * BAR / MAX_SPEED))
    left = " " * (BAR - n) + "█" * n if speed < 0 else " " * BAR
    right = "█" * n + " " * (BAR - n) if speed > 0 else " " * BAR
    colour = "green" if speed > 0 else "red" if speed < 0 else "dim"
    bar = Text("[")
    bar.append(left, style=colour)
    bar.append("|")
    bar.append(right, style=colour)
    bar.append(f"] {speed:+d}" if speed else "]  0")
    return bar


class LiveView:
    """A :class:`tablebot.loop.Sink` drawing the run on ``console`` (give it stderr so stdout stays clean)."""

    def __init__(self, console: Console, device: str = "") -> None:
        self.console, self.device = console, device
        self.info: RunInfo | None = None
        self.last: dict[str, Any] = {}
        self.live: Live | None = None
        self.lateness: Lateness | None = None  # the run loop's rule for a late tick, counted from each block

    def start(self, info: RunInfo) -> None:
        self.info = info
        # A redraw takes a few ms of the interpreter: four a second keep the run loop's ticks on time.
        self.live = Live(self, console=self.console, refresh_per_second=4, transient=False)
        self.live.start()

    def block(self, block: TickBlock) -> None:
        i = len(block) - 1
        late = block.extra.get("late_ms")
        if late is not None and self.info is not None:
            self.lateness = self.lateness or Lateness(self.info.tick_s)
            for ms in late:
                self.lateness.note(ms / 1000)
        self.last = {
            "tick": block.start + i,
            "mask": int(block.masks[i]),
            "state": int(block.states[i]),
            "timer": int(block.timers[i]),
            "outputs": tuple(block.outputs[i]),
            "counters": tuple(block.counters[i]),
            "late_ms": None if late is None else late[i],
        }

    def end(self, end: RunEnd) -> None:
        if self.live is not None:
            self.live.stop()
            self.live = None

    def __rich__(self) -> Panel:
        assert self.info is not None
        machine = self.info.engine.machine
        last = self.last
        title = Text(
            _("tablebot run — {target}").format(target=plain(self.info.target))
            + (f" ({plain(str(localise(self.device)))})" if self.device else "")
        )
        if not last:
            return Panel(Text(_("connecting…"), style="dim"), title=title, title_align="left")
        state = machine.states[last["state"]]
        head = Text(_("state {state}").format(state=plain(str(state))), style="bold")
        name = machine.table.state_name(state)
        if name:
            head.append(f"  {plain(name)}", style="cyan")
        seconds = (last["tick"] + 1) * self.info.tick_s
        head.append(
            _("   timer {timer}   t {seconds:8.2f} s   tick {tick}").format(
                timer=last["timer"], seconds=seconds, tick=last["tick"]
            )
        )
        return Panel(
            Group(head, self._inputs(last["mask"]), self._outputs(last), self._lateness(last)),
            title=title,
            title_align="left",
        )

    def _inputs(self, mask: int) -> Columns:
        """One cell per input the table reads, lit while it reads 1; cells wrap to the terminal's width."""
        machine = self.info.engine.machine  # type: ignore[union-attr]
        cells = []
        for name, bit in machine.input_bits.items():
            lit = bool(mask & bit)
            cell = Text(f"{'●' if lit else '○'} {plain(name)}", style="bold yellow" if lit else "dim")
            label = machine.table.robot.labels.get(name)
            if label:
                cell.append(f" ({plain(label)})", style="yellow" if lit else "dim")
            cells.append(cell)
        return Columns(cells, padding=(0, 3))

    def _outputs(self, last: dict[str, Any]) -> Table:
        machine = self.info.engine.machine  # type: ignore[union-attr]
        robot = machine.table.robot
        grid = Table.grid(padding=(0, 2))
        for name, value in zip(machine.output_names, last["outputs"], strict=True):
            label = Text(f"{plain(name)} {plain(robot.labels.get(name, ''))}".strip())
            shown = motor_bar(int(value)) if name in robot.motors else Text(f"{'▮' * int(value):<8} {value}")
            grid.add_row(label, shown)
        for name, value in zip(robot.counter_names, last["counters"], strict=True):
            grid.add_row(Text(plain(name)), Text(_("{value} pulses to go").format(value=value)))
        return grid

    def _lateness(self, last: dict[str, Any]) -> Text:
        if last["late_ms"] is None:
            return Text("")
        count = self.lateness.count if self.lateness is not None else 0
        style = "red" if count else "dim"
        return Text(
            _("ticks late {count}   this tick {ms:.1f} ms late").format(count=count, ms=last["late_ms"]), style=style
        )
