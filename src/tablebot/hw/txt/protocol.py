"""The TXT "online" protocol on the wire: command and reply ids, struct layouts and sizes, encode/decode.

Written from fischertechnik's published header ``ftProInterface2013SocketCom.h`` (repository
``fischertechnik/txt_demo_c_online``, folder ``SolutionOnLineSamples/Common``) and the ``FTX1_CONFIG``
layout of ``FtShmemTxt.h`` beside it: little-endian C structs, each request starting with a 32-bit
command id and each reply with its own 32-bit response id. Sizes are the C ``sizeof`` of the structs,
padding included (the official client sends ``sizeof(command)``). Only the uncompressed ("simple")
exchange is used. See docs/controllers.md for every fact and its source.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import IntEnum

from tablebot.i18n import N_

PORT = 65000  # camera 65001, I2C 65002 (not used)
N_OUTPUTS = 8  # O1..O8, PWM 0..512 each
N_MOTORS = 4  # M1..M4: motor n drives O(2n-1) forward and O(2n) backward
N_INPUTS = 8  # I1..I8
N_COUNTERS = 4  # C1..C4
MAX_PWM = 512
#: fischertechnik's own online client refuses older firmware: ``BeginTransfer`` in
#: SolutionOnLineSamples/Common/ftProInterface2013TransferAreaCom.cpp, ``if( GetVersion()<0x04060600 )``.
MIN_VERSION = 0x04060600


class Command(IntEnum):
    QUERY_STATUS = 0xDC21219A
    START_ONLINE = 0x163FF61D
    UPDATE_CONFIG = 0x060EF27E
    EXCHANGE_DATA = 0xCC3597BA
    STOP_ONLINE = 0x9BE5082C


#: The response id each command's reply starts with.
REPLY_ID = {
    Command.QUERY_STATUS: 0xBAC9723E,
    Command.START_ONLINE: 0xCA689F75,
    Command.UPDATE_CONFIG: 0x9689A68C,
    Command.EXCHANGE_DATA: 0x4EEFAC41,
    Command.STOP_ONLINE: 0xFBF600D2,
}


class InputMode(IntEnum):
    """``enum InputMode`` of FtShmemTxt.h: what a universal input measures."""

    VOLTAGE = 0  # MODE_U: millivolts (digital: 1 above a threshold)
    RESISTANCE = 1  # MODE_R: ohms, 5 kOhm range (digital: a switch or phototransistor against a pull-up)
    RESISTANCE_15K = 2  # MODE_R2
    ULTRASONIC = 3  # centimetres


# struct formats ('<': little-endian, no automatic padding; 'x' is the C compiler's padding)
_ID = struct.Struct("<I")
_STATUS = struct.Struct("<I16sI")
_START = struct.Struct("<I64s")
_CONFIG = struct.Struct("<IhhBB2x4B" + "BB2x" * N_INPUTS + "B3x" * N_COUNTERS + "16h")
_EXCHANGE = struct.Struct("<I8h4h4h4h4h3H2x")
_EXCHANGE_REPLY = struct.Struct("<I8h4h4h4h4hH" + "4bB" * 5 + "x")

#: Bytes of each request and of its reply.
REQUEST_SIZE = {
    Command.QUERY_STATUS: _ID.size,
    Command.START_ONLINE: _START.size,
    Command.UPDATE_CONFIG: _CONFIG.size,
    Command.EXCHANGE_DATA: _EXCHANGE.size,
    Command.STOP_ONLINE: _ID.size,
}
REPLY_SIZE = {
    Command.QUERY_STATUS: _STATUS.size,
    Command.START_ONLINE: _ID.size,
    Command.UPDATE_CONFIG: _ID.size,
    Command.EXCHANGE_DATA: _EXCHANGE_REPLY.size,
    Command.STOP_ONLINE: _ID.size,
}


class WireError(ValueError):
    """Bytes that are not the reply they should be (wrong size or wrong response id)."""


@dataclass(frozen=True)
class Status:
    """The QueryStatus reply: the controller's name and firmware version (0x04060600 = 4.6.6)."""

    device: str
    version: int

    @property
    def version_text(self) -> str:
        return f"{self.version >> 24 & 0xFF}.{self.version >> 16 & 0xFF}.{self.version >> 8 & 0xFF}"


@dataclass(frozen=True)
class InputConfig:
    """One universal input: its measuring mode and whether the controller reports it as 0/1."""

    mode: InputMode = InputMode.RESISTANCE
    digital: bool = True


@dataclass(frozen=True)
class Config:
    """``FTX1_CONFIG``: which output pairs are motors, how each input and counter measures.

    The defaults are the official client's (``SetDefaultConfig``): motors on all pairs, every input a
    digital 5 kOhm input, every counter in mode 1.
    """

    motors: tuple[bool, ...] = (True,) * N_MOTORS
    inputs: tuple[InputConfig, ...] = (InputConfig(),) * N_INPUTS
    counters: tuple[int, ...] = (1,) * N_COUNTERS


@dataclass(frozen=True)
class Inputs:
    """The ExchangeData reply: inputs I1..I8 (0/1, mV, ohm or cm by mode), counters C1..C4."""

    universal: tuple[int, ...]
    counter_inputs: tuple[int, ...]  # the logic level of each counter input
    counter_values: tuple[int, ...]  # pulses counted since the counter's last reset (16 bit)
    counter_command_ids: tuple[int, ...] = (0,) * N_COUNTERS
    motor_command_ids: tuple[int, ...] = (0,) * N_MOTORS


def _id(data: bytes, expected: int, what: str) -> None:
    if len(data) < 4:
        raise WireError(N_("{what}: {value} bytes is too short for a reply", what=what, value=len(data)))
    (got,) = _ID.unpack_from(data)
    if got != expected:
        raise WireError(
            N_(
                "{what}: wrong response id 0x{got:08X} (expected 0x{expected:08X})",
                what=what,
                got=got,
                expected=expected,
            )
        )


def check_reply(command: Command, data: bytes) -> None:
    """Raise :class:`WireError` unless ``data`` is a whole reply to ``command`` with its response id."""
    _id(data, REPLY_ID[command], command.name)
    if len(data) != REPLY_SIZE[command]:
        raise WireError(
            N_(
                "{name}: reply of {value} bytes (expected {value2})",
                name=command.name,
                value=len(data),
                value2=REPLY_SIZE[command],
            )
        )


# --- requests ---------------------------------------------------------------------------------------


def query_status() -> bytes:
    return _ID.pack(Command.QUERY_STATUS)


def start_online(name: str = "tablebot") -> bytes:
    """StartOnline with the client's name (at most 63 bytes, NUL-terminated)."""
    return _START.pack(Command.START_ONLINE, name.encode("ascii", "replace")[:63])


def update_config(config: Config, config_id: int, extension: int = 0) -> bytes:
    """UpdateConfig; ``config_id`` should change with every new configuration (the official client counts up)."""
    fields: list[int] = [Command.UPDATE_CONFIG, config_id, extension, 0, 0]  # pgm_state_req, old_FtTransfer
    fields += [int(m) for m in config.motors]
    for inp in config.inputs:
        fields += [int(inp.mode), int(inp.digital)]
    fields += list(config.counters)
    fields += [0] * 16  # motor_config[4][4]: "not in use on the TXT"
    return _CONFIG.pack(*fields)


def exchange(pwm: tuple[int, ...] | list[int]) -> bytes:
    """ExchangeData (simple): PWM 0..512 of O1..O8; no distance, sync, counter reset or sound commands."""
    if len(pwm) != N_OUTPUTS:
        raise ValueError(f"exchange needs {N_OUTPUTS} PWM values, not {len(pwm)}")
    clamped = [max(0, min(MAX_PWM, int(v))) for v in pwm]
    return _EXCHANGE.pack(Command.EXCHANGE_DATA, *clamped, *([0] * 16), 0, 0, 0)


def stop_online() -> bytes:
    return _ID.pack(Command.STOP_ONLINE)


# --- replies ----------------------------------------------------------------------------------------


def decode_status(data: bytes) -> Status:
    check_reply(Command.QUERY_STATUS, data)
    _, name, version = _STATUS.unpack(data)
    return Status(name.split(b"\0", 1)[0].decode("latin-1"), version)


def decode_exchange(data: bytes) -> Inputs:
    check_reply(Command.EXCHANGE_DATA, data)
    values = _EXCHANGE_REPLY.unpack(data)
    return Inputs(
        universal=values[1:9],
        counter_inputs=values[9:13],
        counter_values=values[13:17],
        counter_command_ids=values[17:21],
        motor_command_ids=values[21:25],
    )
