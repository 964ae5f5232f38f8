"""The firmware's UART trace framing, both ways: frames to core trace lines (``monitor``) and back.
The frame layout is documented in docs/firmware.md and at the constants below."""

from __future__ import annotations

import struct
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

from tablebot.codegen.host import trace_line
from tablebot.codegen.packing import Layout, plan
from tablebot.i18n import N_
from tablebot.machine import NO_ROW, Machine

# A frame is 0x7E TYPE PAYLOAD CHECK; CHECK makes the 8-bit sum of TYPE, PAYLOAD and CHECK zero.
# 'H' (once after reset): version, table hash u32, states u16, rows u16, event bytes, outputs, counters.
# 'T' (each tick): tick u16, event, row (all ones = none), state, timer u16, outputs i8, counters u16.
# Little-endian; event, row and state widths come from the generated C layout.
SYNC = 0x7E
HELLO = ord("H")
TICK = ord("T")
VERSION = 1
HELLO_FORMAT = "<BIHHBBB"
HELLO_PAYLOAD = struct.calcsize(HELLO_FORMAT)


@dataclass(frozen=True)
class Hello:
    """What the firmware says about itself after a reset."""

    version: int
    table_hash: int
    n_states: int
    n_rows: int
    event_bytes: int
    n_outputs: int
    n_counters: int


def tick_payload(machine: Machine, layout: Layout) -> int:
    """Bytes of a tick frame's payload: tick, event, row, state, timer, outputs, counters."""
    return (
        2
        + layout.event.size
        + layout.row.size
        + layout.state.size
        + 2
        + len(machine.output_names)
        + 2 * len(machine.table.robot.counters)
    )


def checksum(body: bytes) -> int:
    return -sum(body) & 0xFF


class FrameStream(Protocol):
    """What :func:`take_frames` keeps of a stream: the bytes not yet a whole frame, how many came before them, and
    the problems found."""

    buffer: bytearray
    consumed: int
    problems: list[str]


def take_frames(
    stream: FrameStream, data: bytes, lengths: Mapping[int, int], take: Callable[[int, bytes], None]
) -> None:
    """Every whole frame in ``stream``'s buffer with ``data`` added, as ``take(type, payload)``, in order: a frame's
    payload length is ``lengths[type]``; a byte that starts no known frame is skipped, and after a bad checksum
    the stream resynchronises on the next sync byte (a problem noted at its byte in the stream). What is left is
    the start of a frame still to come."""
    stream.buffer += data
    buf, at = stream.buffer, 0
    while True:
        at = buf.find(SYNC, at)
        if at < 0 or at + 2 > len(buf):
            break
        length = lengths.get(buf[at + 1])
        if length is None:
            at += 1  # not a frame start: resynchronise on the next sync byte
            continue
        end = at + 2 + length + 1
        if end > len(buf):
            break
        body = bytes(buf[at + 1 : end])
        if sum(body) & 0xFF:
            stream.problems.append(N_("bad checksum at byte {at}; resynchronising", at=stream.consumed + at))
            at += 1
            continue
        take(body[0], body[1:-1])
        at = end
    done = at if at >= 0 else len(buf)
    del buf[:done]
    stream.consumed += done


def _frame(kind: int, payload: bytes) -> bytes:
    body = bytes([kind]) + payload
    return bytes([SYNC]) + body + bytes([checksum(body)])


@dataclass
class Decoder:
    """Feed it UART bytes in any chunks; it returns core trace lines and notes what went wrong."""

    machine: Machine
    layout: Layout | None = None
    hellos: list[Hello] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    buffer: bytearray = field(default_factory=bytearray)
    last_tick: int | None = None
    consumed: int = 0  # bytes of the stream before ``buffer``: positions in problems count from the start
    ticks: int = 0  # tick frames decoded so far
    rejected: int = 0  # whole tick frames this table's engine could not have sent

    def __post_init__(self) -> None:
        if self.layout is None:
            self.layout = plan(self.machine)
        self.n_outputs = len(self.machine.output_names)
        self.n_counters = len(self.machine.table.robot.counters)
        self.lengths = {HELLO: HELLO_PAYLOAD, TICK: tick_payload(self.machine, self.layout)}  # payload per type

    def feed(self, data: bytes) -> list[dict[str, Any]]:
        lines: list[dict[str, Any]] = []

        def take(kind: int, payload: bytes) -> None:
            line = self._frame(kind, payload)
            if line is not None:
                lines.append(line)

        take_frames(self, data, self.lengths, take)
        self.ticks += len(lines)
        return lines

    def _frame(self, kind: int, payload: bytes) -> dict[str, Any] | None:
        if kind == HELLO:
            hello = Hello(*struct.unpack(HELLO_FORMAT, payload))
            self.hellos.append(hello)
            self.last_tick = None  # the firmware restarted: its tick count starts again at 0
            return None
        return self._tick(payload)

    def _tick(self, payload: bytes) -> dict[str, Any] | None:
        lay = self.layout
        assert lay is not None
        values = []
        at = 0
        for size in (2, lay.event.size, lay.row.size, lay.state.size, 2):
            values.append(int.from_bytes(payload[at : at + size], "little"))
            at += size
        tick16, event, row, state, timer = values
        row = NO_ROW if row == lay.no_row else row
        wrong = self._impossible(event, row, state, timer)
        if wrong:
            self.problems.append(N_("tick frame {tick} {wrong}: not this table's firmware?", tick=tick16, wrong=wrong))
            self.rejected += 1
            return None
        outputs = [b - 256 if b > 127 else b for b in payload[at : at + self.n_outputs]]
        at += self.n_outputs
        counters = [int.from_bytes(payload[at + 2 * i : at + 2 * i + 2], "little") for i in range(self.n_counters)]
        tick = self._unwrap(tick16)
        return trace_line(self.machine, tick, event, row, state, timer, outputs, counters)

    def _impossible(self, event: int, row: int, state: int, timer: int) -> str:
        """What this table's engine could never report ("" when nothing), so that frames of another
        table's firmware are not read as this one's: a fired row sets its next state and timer; with
        no row fired, none matches and T is present exactly when the timer is 0."""
        machine = self.machine
        if state >= len(machine.states):
            return N_("names state index {state}", state=state)
        if event >> len(machine.table.events):
            return N_(
                "has event bits {bits:#x} beyond the table's {count} events",
                bits=event,
                count=len(machine.table.events),
            )
        if row == NO_ROW:
            if machine.lookup(state, event) != NO_ROW:
                return N_("says no row fired, but row {row} matches its events", row=machine.lookup(state, event))
            if machine.timer_bit and (timer == 0) != bool(event & machine.timer_bit):
                return (
                    N_("has timer {timer} but no T event", timer=timer)
                    if timer == 0
                    else N_("has timer {timer} but T event", timer=timer)
                )
            return ""
        if row >= len(machine.rows):
            return N_("names row {row}", row=row)
        fired = machine.rows[row]
        if (fired.next, fired.timer) != (state, timer) or fired.mask & event != fired.mask:
            return N_("says row {row} fired, but its events, state or timer are not that row's", row=row)
        return ""

    def _unwrap(self, tick16: int) -> int:
        """Full tick numbers from their low 16 bits; a jump means frames were lost."""
        if self.last_tick is None:
            tick = tick16
        else:
            tick = self.last_tick + ((tick16 - self.last_tick) & 0xFFFF)
            if tick != self.last_tick + 1:
                self.problems.append(
                    N_("ticks {first}..{last} missing from the stream", first=self.last_tick + 1, last=tick - 1)
                )
        self.last_tick = tick
        return tick


def hello_frame(machine: Machine, layout: Layout) -> bytes:
    """The hello frame the firmware of this machine sends."""
    payload = struct.pack(
        HELLO_FORMAT,
        VERSION,
        layout.table_hash,
        len(machine.states),
        len(machine.rows),
        layout.event.size,
        len(machine.output_names),
        len(machine.table.robot.counters),
    )
    return _frame(HELLO, payload)


def tick_frame(machine: Machine, layout: Layout, line: dict[str, Any]) -> bytes:
    """One trace line as the firmware frames it (for tests and for replaying traces to a monitor)."""
    row = layout.no_row if line["row"] is None else line["row"]
    payload = bytearray((line["tick"] & 0xFFFF).to_bytes(2, "little"))
    payload += line["event"].to_bytes(layout.event.size, "little")
    payload += row.to_bytes(layout.row.size, "little")
    payload += machine.states.index(line["state"]).to_bytes(layout.state.size, "little")
    payload += line["timer"].to_bytes(2, "little")
    payload += bytes(line[name] & 0xFF for name in machine.output_names)
    for name in machine.table.robot.counter_names:
        payload += line[name].to_bytes(2, "little")
    return _frame(TICK, bytes(payload))


def encode(machine: Machine, lines: Iterable[dict[str, Any]], layout: Layout | None = None) -> bytes:
    """A whole stream: hello, then one tick frame per trace line."""
    layout = layout or plan(machine)
    return hello_frame(machine, layout) + b"".join(tick_frame(machine, layout, line) for line in lines)
