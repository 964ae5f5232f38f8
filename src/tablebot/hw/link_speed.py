"""Whether a controller's link can keep the table's tick, judged before anything moves: each live back-end
times its link's round trip during the handshake (the request every tick makes, with every output off, or the
nearest harmless one) and this module weighs it against the robot file's ``tick_ms``.

A link that needs more than 80 % of the tick cannot keep it — the rest of the tick belongs to the host (the
engine, the trace, the scheduler) — so the run is refused with an error located at ``tick_ms`` that says what
to do; more than half the tick runs, with a warning. ``--behind-limit 0`` accepts slow timers: the refusal
becomes a warning, as it also stops the run loop from judging the pace (:class:`tablebot.loop.Pace`).
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from tablebot.diagnostics import TableBotError, fail
from tablebot.i18n import N_, Message
from tablebot.loop import LinkLost

if TYPE_CHECKING:
    from tablebot.machine import Machine
    from tablebot.registry import LinkOptions
    from tablebot.robot import Robot

PROBES = 7  # round trips timed; their median is the link's time (one slow wake-up of a busy host does not count)
REFUSE_ABOVE = 0.8  # of the tick: the link cannot keep it
WARN_ABOVE = 0.5  # of the tick: it keeps it only on a quiet machine and link


@dataclass(frozen=True)
class LinkTime:
    """What one tick's round trip takes on a link, as measured during the handshake (a link whose line has a
    fixed speed also says what the line alone needs, which explains the figure)."""

    target: str  # the --on address: roboif:///dev/ttyUSB0
    what: str  # "one exchange with the ROBO Interface"
    measured_s: float  # the median of the timed round trips
    line: str = ""  # "its 38 bytes alone take 9.9 ms on the 38400-baud line"
    faster: str = ""  # a faster way to the controller, for the hint


class Connected(Protocol):
    """A live robot whose controller answered (nothing moves yet)."""

    @property
    def target(self) -> str: ...

    def close(self) -> None: ...


def check_link(
    bot: Connected,
    machine: Machine,
    options: LinkOptions,
    probe: Callable[[], object],
    what: str,
    *,
    line: str = "",
    faster: str = "",
    connect_hint: str = "",
) -> tuple[str, ...]:
    """Time ``probe`` (one round trip on the link of a connected ``bot``, moving nothing) and :func:`judge` it
    (``--behind-limit 0``, :attr:`~tablebot.registry.LinkOptions.accept_slow`, accepts slow timers). Refused,
    or lost while being timed, ``bot`` is closed first."""
    try:
        link = LinkTime(bot.target, what, median_round_trip(probe), line, faster)
    except LinkLost as exc:
        bot.close()
        raise fail("--on", exc.args[0], connect_hint) from None
    try:
        return judge(machine, link, accept_slow=options.accept_slow)
    except TableBotError:
        bot.close()
        raise


def median_round_trip(
    probe: Callable[[], object], probes: int = PROBES, now: Callable[[], float] = time.perf_counter
) -> float:
    """The median time ``probe()`` takes over ``probes`` calls (seconds)."""
    times = []
    for _ in range(probes):
        started = now()
        probe()
        times.append(now() - started)
    return statistics.median(times)


def judge(machine: Machine, link: LinkTime, accept_slow: bool) -> tuple[str, ...]:
    """Warnings for a link that keeps the tick only just (or, with ``accept_slow``, not at all); for one that
    cannot keep it, a located error at the robot file's ``tick_ms`` saying what to do."""
    robot = machine.table.robot
    tick_s, need = robot.tick_s, link.measured_s
    took = _took(link)
    if need <= WARN_ABOVE * tick_s:
        return ()
    suggested = suggest_tick_ms(machine, need)
    if need <= REFUSE_ABOVE * tick_s:
        return (
            N_(
                "{target}: {took}, {share:.0%} of the table's {tick_ms} ms tick: ticks will start late when this "
                "machine or the link is busy (tick_ms = {suggested} would leave room)",
                target=link.target,
                took=took,
                share=need / tick_s,
                tick_ms=robot.tick_ms,
                suggested=suggested,
            ),
        )
    late = format(100 * (need / tick_s - 1), ".0f") + " %"  # outside the msgid: "% s" would read as printf's
    slow = N_("at least {percent} slow", percent=late) if need > tick_s else N_("slow")
    if accept_slow:
        return (
            N_(
                "{target}: {took}, more than the table's {tick_ms} ms tick can hold: running anyway "
                "(--behind-limit 0), so the table's timers will run {slow}",
                target=link.target,
                took=took,
                tick_ms=robot.tick_ms,
                slow=slow,
            ),
        )
    where, line = _tick_ms_place(robot)
    raise fail(
        where,
        N_(
            "{target}: {took}, more than the table's {tick_ms} ms tick can hold (tick_ms = {tick_ms}): "
            "every tick would start late and the table's timers would run {slow}",
            target=link.target,
            took=took,
            tick_ms=robot.tick_ms,
            slow=slow,
        ),
        _advice(machine, suggested, link, slow),
        line=line,
        column=None if line is None else 1,
    )


def suggest_tick_ms(machine: Machine, need_s: float) -> int:
    """The shortest tick a link needing ``need_s`` keeps without a warning; where one exists up to twice that,
    one that every timer of the table is a whole number of (so its timers can be written as the same times)."""
    least = max(1, math.ceil(1000 * need_s / WARN_ABOVE))
    whole = _timers_gcd_ms(machine)
    fitting = [d for d in range(least, 2 * least + 1) if whole and whole % d == 0]
    return fitting[0] if fitting else 5 * math.ceil(least / 5)


def _timers_gcd_ms(machine: Machine) -> int:
    """The longest time every timer of the table is a whole number of (ms; 0: the table loads no timer)."""
    robot = machine.table.robot
    loads = [row.timer for row in machine.table.rows] + [robot.initial_timer]
    return math.gcd(*(ticks * robot.tick_ms for ticks in loads if ticks))


def _took(link: LinkTime) -> Message:
    if link.line:
        return N_(
            "{what} takes {ms:.1f} ms (measured; {line})", what=link.what, ms=1000 * link.measured_s, line=link.line
        )
    return N_("{what} takes {ms:.1f} ms (measured)", what=link.what, ms=1000 * link.measured_s)


def _advice(machine: Machine, suggested: int, link: LinkTime, slow: str) -> Message:
    robot = machine.table.robot
    timers = [row.timer for row in machine.table.rows if row.timer]
    example = (
        N_(", e.g. {ms}ms for a timer of {timer}", ms=timers[0] * robot.tick_ms, timer=timers[0]) if timers else ""
    )
    fits = (
        N_(" (every timer of this table is a whole number of such ticks)")
        if _timers_gcd_ms(machine) % suggested == 0 and timers
        else ""
    )
    faster = (
        N_("; or use a faster link ({faster})", faster=link.faster) if link.faster else N_("; or use a faster link")
    )
    return N_(
        "give tick_ms = {suggested}{fits} and write the table's timers as times{example}, so that they keep "
        "their length (a timer in ticks would last {times:g} times as long){faster}; or accept timers {slow} "
        "with --behind-limit 0",
        suggested=suggested,
        fits=fits,
        example=example,
        times=suggested / robot.tick_ms,
        faster=faster,
        slow=slow,
    )


def _tick_ms_place(robot: Robot) -> tuple[str, int | None]:
    """The robot file and the line of its ``tick_ms`` (the file alone when it leaves tick_ms at 10; ``--on``
    for the built-in robot)."""
    if robot.toml is None:
        return "--on", None
    return robot.toml.path, robot.line("", "tick_ms")
