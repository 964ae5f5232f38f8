"""The ROBO Interface's online protocol on its serial port: the bytes of each message, encode and decode only.

Source: ``nxdefiant/libroboint`` (LGPL; the open-source twin of Knobloch's ftlib; also vendored by
``ftCommunity/gorobointerface`` in ``libs/``), ``lib/libroboint.c``: ``OpenFtCommDevice`` (38400 baud 8N1;
"\\xA1ft-Robo-ON-V1" answered by 5 bytes, the first 0x5E), ``FtThread`` (the 17-byte exchange 0xF2 for
``FT_ROBO_IF_COM``, its 21-byte reply, one every 10 ms), ``CloseFtDevice`` (0xA2 answered by 0x5D); field
meanings from ``lib/roboint.h`` (``FT_TRANSFER_AREA``). Over USB libroboint sends the same 17 bytes as an
interrupt transfer (endpoint 0x01, reply on 0x81) with no greeting: tablebot speaks only the serial form.

The reply has no header and no checksum: a reply of the right length cannot be told from noise, only a
short, late or overlong one (see :mod:`tablebot.hw.roboif.link`).
"""

from __future__ import annotations

from dataclasses import dataclass

from tablebot.i18n import N_

BAUD = 38400
HELLO = b"\xa1ft-Robo-ON-V1"  # 14 bytes
HELLO_REPLY_BYTES, HELLO_OK = 5, 0x5E
BYE, BYE_OK = b"\xa2", 0x5D
EXCHANGE = 0xF2
REQUEST_BYTES, REPLY_BYTES = 17, 21
N_INPUTS, N_OUTPUTS, N_MOTORS = 8, 8, 4
MAX_PWM = 7  # three bits per output
#: The time one exchange needs on the line alone: request and reply, 10 bits a byte (8N1) at 38400 baud.
EXCHANGE_LINE_S = (REQUEST_BYTES + REPLY_BYTES) * 10 / BAUD


class WireError(ValueError):
    """Bytes that are not the reply they should be."""


@dataclass(frozen=True)
class Inputs:
    """One exchange's reply: digital inputs I1..I8 and the master module's analog inputs (10 bit each):
    AX, AY (resistance), A1, A2 (voltage), AZ, AV (supply), D1, D2 (distance sensors)."""

    digital: int  # bit n = I(n+1)
    analog: dict[str, int]
    ir: int = 0
    modules: int = 0  # extension modules on the bus


def exchange(directions: int, pwm: list[int] | tuple[int, ...]) -> bytes:
    """The exchange request: the master module's output bits (bit 2n-2 = Mn "A", 2n-1 = Mn "B", i.e. O1..O8)
    and each output's PWM 0..7; extension modules 1..3 all off."""
    if len(pwm) != N_OUTPUTS:
        raise ValueError(f"the exchange needs {N_OUTPUTS} PWM values, not {len(pwm)}")
    packed = 0  # eight 3-bit fields, output 1 in the lowest bits, sent low byte first
    for i, value in enumerate(pwm):
        packed |= max(0, min(MAX_PWM, int(value))) << (3 * i)
    return bytes((EXCHANGE, directions & 0xFF)) + packed.to_bytes(3, "little") + bytes(12)


def decode(data: bytes) -> Inputs:
    if len(data) != REPLY_BYTES:
        raise WireError(
            N_("a reply of {value} bytes (expected {REPLY_BYTES})", value=len(data), REPLY_BYTES=REPLY_BYTES)
        )

    def ten(low: int, high_byte: int, shift: int) -> int:
        return data[low] | ((data[high_byte] >> shift) & 0x3) << 8

    analog = {
        "AX": ten(4, 8, 0),
        "AY": ten(5, 8, 2),
        "A1": ten(6, 8, 4),
        "A2": ten(7, 8, 6),
        "AZ": ten(9, 13, 0),
        "D1": ten(10, 13, 2),
        "D2": ten(11, 13, 4),
        "AV": ten(12, 13, 6),
    }
    return Inputs(digital=data[0], analog=analog, ir=data[14], modules=data[15])
