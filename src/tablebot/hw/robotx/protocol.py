"""The ROBO TX Controller's "fish.X1" online protocol on the wire: frames, checksums, payloads; encode and
decode only (no I/O).

Sources (see docs/controllers.md for every fact):

- fischertechnik/MSC, *Programming the ROBO TX Controller, Part 1: PC programming* V1.5, ch. 13.1 "Fish.X1
  interface protocol" (copy in ``ski7777/fttxpy``, ``TXC-Programming/PC_Programming_RoboTXC_en_V1-5.pdf``):
  the frame ``STX 0x55 | length (H,L) | FROM | TO | TID | SID | command | n | n x (TA id, data) | CRC (H,L) |
  ETX``, the bus addresses, TID and SID.
- ``TXC-Programming/ROBO_TX_FW.h`` and the ftMscLib manual (same folder): the meaning of every field of the
  transfer area (input modes, counters, PWM 0..512, the 10 ms cycle).
- The wire layouts (the in-memory structs of ROBO_TX_FW.h are packed tighter on the wire) and command codes:
  ``fischertechniker/ROBO-Pro-for-ftDuino`` (``fishx1.h``, ``fishx1.ino``: an ftDuino answering ROBO Pro as
  a ROBO TX), ``mr-kubikus/fx1-arduino-parser`` (``fx1sample/fx1.h``, ``fx1parser.ino``) and the host side
  ``ski7777/fttxpy`` (``fttxpy/tx_serial.py``, ``low_level.py``). They agree on every field used here.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import IntEnum

from tablebot.i18n import N_

STX, MARK, ETX = 0x02, 0x55, 0x03
HEADER_BYTES = 20  # FROM, TO, TID, SID, command, n: what the length field counts besides the payload
#: The largest frame we accept: a header and nine transfer areas (master + 8 extensions) of 64 bytes.
MAX_LENGTH = HEADER_BYTES + 9 * (4 + 64)
ADDR_WILDCARD, ADDR_MASTER = 1, 2  # PC manual: BUS_ADR_WILDCARD=1, BUS_ADR_MASTER=2
TA_LOCAL = 0  # the transfer area of the controller on the cable (extensions are 1..8)

N_INPUTS, N_COUNTERS, N_MOTORS, N_OUTPUTS = 8, 4, 4, 8
MAX_DUTY = 512


class Command(IntEnum):
    """Request codes; each reply carries the request's code + 100 (fishx1.h, fttxpy CommandCodes.py)."""

    ECHO = 1  # connect: the controller answers 101 with no data
    EXCHANGE = 2  # TA_OUTPUT out, TA_INPUT back
    CONFIG = 5  # TA_CONFIG out
    INFO = 6  # TA_INFO back: name, Bluetooth address, versions
    STATE = 7  # TA_STATE back: extensions and Bluetooth channels

    @property
    def reply(self) -> int:
        return self.value + 100


class InputMode(IntEnum):
    """``enum input_mode_e`` of ROBO_TX_FW.h (on the wire ``mode | 0x80`` for a digital input)."""

    VOLTAGE = 0  # MODE_U: mV, 10 V range
    RESISTANCE = 1  # MODE_R: ohm, 5 kOhm range (digital: a switch against a pull-up)
    ULTRASONIC = 3  # cm


DIGITAL_FLAG = 0x80

_HEAD = struct.Struct("<IIHHII")  # FROM, TO, TID, SID, command, number of transfer areas
_TA_ID = struct.Struct("<I")
_OUTPUT = struct.Struct("<4H4B8h4H4H")  # cnt_reset_cmd_id, master, duty, distance, motor_ex_cmd_id: 44 B
_INPUT = struct.Struct("<8h4B4h2h4H4H")  # uni, cnt_in, counter, buttons, cnt_resetted, motor_pos_reached: 48 B
_CONFIG = struct.Struct("<4B8B4B32x")  # motor, uni (mode | digital), cnt: 48 B
_INFO = struct.Struct("<17s18sx3I4s4s4s4x")  # TA_INFO: 64 B
OUTPUT_BYTES, INPUT_BYTES, CONFIG_BYTES, INFO_BYTES = _OUTPUT.size, _INPUT.size, _CONFIG.size, _INFO.size


class WireError(ValueError):
    """Bytes that are not a well-formed fish.X1 frame (or not the payload they should be)."""


@dataclass(frozen=True)
class Frame:
    """One fish.X1 frame: header fields and its transfer areas as (TA id, payload) pairs."""

    command: int
    tid: int
    sid: int
    areas: tuple[tuple[int, bytes], ...] = ()
    src: int = ADDR_MASTER
    dst: int = ADDR_WILDCARD

    def area(self, ta: int = TA_LOCAL) -> bytes | None:
        return next((data for ident, data in self.areas if ident == ta), None)


@dataclass(frozen=True)
class Config:
    """TA_CONFIG: which output pairs are motors, each input's mode and digital flag, each counter's mode
    (0: counts 0->1, 1: counts 1->0). Defaults as fttxpy sends them: motors, digital 5 kOhm, mode 1."""

    motors: tuple[bool, ...] = (True,) * N_MOTORS
    inputs: tuple[tuple[InputMode, bool], ...] = ((InputMode.RESISTANCE, True),) * N_INPUTS
    counters: tuple[int, ...] = (1,) * N_COUNTERS


@dataclass(frozen=True)
class Inputs:
    """TA_INPUT: I1..I8 (0/1, mV, ohm or cm by mode), counter input levels and counts C1..C4."""

    universal: tuple[int, ...]
    counter_levels: tuple[int, ...]
    counter_values: tuple[int, ...]  # counted since the counter's last reset (16 bit)


@dataclass(frozen=True)
class Info:
    """TA_INFO: the controller's name ("ROBO TX-424" unless renamed), Bluetooth address, versions."""

    device: str
    bt_address: str
    hardware: bytes  # FT_VER a..d: a = 'A', 'B' or 'C'
    firmware: bytes  # FT_VER a..d: "V c.dd, DLL b"

    @property
    def version_text(self) -> str:
        return f"{self.firmware[2]}.{self.firmware[3]:02d}"


# --- frames -------------------------------------------------------------------------------------------


def checksum(data: bytes) -> int:
    """The frame's "CRC": the 16-bit two's complement of the byte sum from the length field to the payload's end."""
    return -sum(data) & 0xFFFF


def encode(frame: Frame) -> bytes:
    body = _HEAD.pack(frame.src, frame.dst, frame.tid, frame.sid, frame.command, len(frame.areas))
    body += b"".join(_TA_ID.pack(ta) + data for ta, data in frame.areas)
    if len(body) > 0xFFFF:
        raise ValueError(f"a fish.X1 frame holds at most 65535 bytes, not {len(body)}")
    checked = len(body).to_bytes(2, "big") + body
    return bytes((STX, MARK)) + checked + checksum(checked).to_bytes(2, "big") + bytes((ETX,))


def frame_length(start: bytes) -> int:
    """The whole frame's size from its first four bytes (STX, 0x55, length); WireError if they are not that."""
    if len(start) < 4 or start[0] != STX or start[1] != MARK:
        raise WireError(N_("not the start of a fish.X1 frame: {value}", value=start[:4].hex(" ")))
    length = int.from_bytes(start[2:4], "big")
    if not HEADER_BYTES <= length <= MAX_LENGTH:
        raise WireError(
            N_(
                "a frame length of {length} bytes (a fish.X1 frame has {HEADER_BYTES}..{MAX_LENGTH})",
                length=length,
                HEADER_BYTES=HEADER_BYTES,
                MAX_LENGTH=MAX_LENGTH,
            )
        )
    return 2 + 2 + length + 3


def decode(data: bytes) -> Frame:
    """A whole frame's fields; WireError for a wrong start, length, checksum, end mark or area layout."""
    size = frame_length(data)
    if len(data) != size:
        raise WireError(N_("a frame of {value} bytes where its length field says {size}", value=len(data), size=size))
    if data[-1] != ETX:
        raise WireError(N_("the frame does not end with ETX (0x03) but 0x{value:02x}", value=data[-1]))
    checked = data[2:-3]
    expected, got = checksum(checked), int.from_bytes(data[-3:-1], "big")
    if got != expected:
        raise WireError(N_("checksum 0x{got:04x} where the bytes give 0x{expected:04x}", got=got, expected=expected))
    src, dst, tid, sid, command, count = _HEAD.unpack_from(data, 4)
    payload = data[4 + _HEAD.size : -3]
    return Frame(command, tid, sid, _areas(payload, count), src, dst)


def _areas(payload: bytes, count: int) -> tuple[tuple[int, bytes], ...]:
    if count == 0:
        if payload:
            raise WireError(N_("{value} bytes of data in a frame that declares no transfer area", value=len(payload)))
        return ()
    if count > 9 or len(payload) % count or len(payload) // count < _TA_ID.size:
        raise WireError(N_("{value} bytes of data cannot be {count} transfer areas", value=len(payload), count=count))
    each = len(payload) // count
    return tuple(
        (_TA_ID.unpack_from(payload, i * each)[0], payload[i * each + 4 : (i + 1) * each]) for i in range(count)
    )


# --- payloads -----------------------------------------------------------------------------------------


def output(duty: list[int] | tuple[int, ...]) -> bytes:
    """TA_OUTPUT with O1..O8's duty (0..512 each); no counter resets, synchronisation or distances."""
    if len(duty) != N_OUTPUTS:
        raise ValueError(f"TA_OUTPUT needs {N_OUTPUTS} duty values, not {len(duty)}")
    clamped = [max(0, min(MAX_DUTY, int(v))) for v in duty]
    return _OUTPUT.pack(*([0] * N_COUNTERS), *([0] * N_MOTORS), *clamped, *([0] * N_MOTORS), *([0] * N_MOTORS))


def config(cfg: Config) -> bytes:
    uni = [int(mode) | (DIGITAL_FLAG if digital else 0) for mode, digital in cfg.inputs]
    return _CONFIG.pack(*(int(m) for m in cfg.motors), *uni, *cfg.counters)


def decode_inputs(data: bytes) -> Inputs:
    if len(data) != INPUT_BYTES:
        raise WireError(
            N_("TA_INPUT of {value} bytes (expected {INPUT_BYTES})", value=len(data), INPUT_BYTES=INPUT_BYTES)
        )
    values = _INPUT.unpack(data)
    return Inputs(universal=values[0:8], counter_levels=values[8:12], counter_values=values[12:16])


def decode_info(data: bytes) -> Info:
    if len(data) != INFO_BYTES:
        raise WireError(N_("TA_INFO of {value} bytes (expected {INFO_BYTES})", value=len(data), INFO_BYTES=INFO_BYTES))
    name, bt, _, _, _, hardware, firmware, _ = _INFO.unpack(data)
    return Info(_text(name), _text(bt), hardware, firmware)


def _text(raw: bytes) -> str:
    return raw.split(b"\0", 1)[0].decode("latin-1")
