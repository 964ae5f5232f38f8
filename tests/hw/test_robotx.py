"""The ROBO TX Controller over fish.X1, against the fish.X1 emulator on a real pseudo-terminal: frames and
checksums, configuration, duty that follows the engine, counters, zero duty in the last exchange on every way a
run ends, and every fault (silence, garbage, a bad checksum, a wrong answer, a new session, a hang-up, a slow
device) as link_lost."""

from __future__ import annotations

import itertools
import statistics
from typing import TYPE_CHECKING

import pytest

from controller_helpers import BUMBER_WIRING, Record, StopAt, bumberbot, drive, eventually, settle
from tablebot.hw.robotx import link as robotx_link
from tablebot.hw.robotx import protocol as wire
from tablebot.hw.robotx.controller import RobotxRobot
from tablebot.hw.robotx.wiring import robotx_wiring
from tablebot.hw.serial_port import PortInfo
from tablebot.loop import LinkLost
from tablebot.testing.robotx_emulator import RobotxEmulator

pytestmark = [pytest.mark.realtime]

if TYPE_CHECKING:
    from tablebot.machine import Machine


def robot_on(emulator: RobotxEmulator, machine: Machine | None = None, timeout_s: float = 0.15) -> RobotxRobot:
    return RobotxRobot(robotx_wiring(machine or bumberbot("robotx")), emulator.device, link_timeout_s=timeout_s)


def test_a_frame_is_as_the_pc_programming_manual_draws_it() -> None:
    duty = wire.output([512] + [0] * 7)
    frame = wire.encode(wire.Frame(wire.Command.EXCHANGE, tid=0x1234, sid=7, areas=((0, duty),)))
    assert frame[:2] == b"\x02\x55" and frame[-1] == 0x03
    assert int.from_bytes(frame[2:4], "big") == 20 + 4 + 44 == len(frame) - 7  # length (H,L): header + payload
    assert frame[4:8] == (2).to_bytes(4, "little") and frame[8:12] == (1).to_bytes(4, "little")  # FROM, TO (L,H)
    assert frame[12:14] == b"\x34\x12" and frame[14:16] == b"\x07\x00"  # TID, SID (L,H)
    assert frame[16:20] == b"\x02\0\0\0" and frame[20:24] == b"\x01\0\0\0" and frame[24:28] == b"\0\0\0\0"
    assert (sum(frame[2:-3]) + int.from_bytes(frame[-3:-1], "big")) & 0xFFFF == 0  # CRC (H,L) over length..payload
    assert frame[28 + 12 : 28 + 14] == (512).to_bytes(2, "little")  # duty[0] after cnt_reset_cmd_id[4], master[4]
    assert wire.decode(frame).area() == wire.output([512] + [0] * 7)
    for broken in (b"\x02\x56" + frame[2:], frame[:-1] + b"\x04", frame[:-3] + b"\0\0\x03", frame[:10]):
        with pytest.raises(wire.WireError):
            wire.decode(broken)


def test_it_greets_configures_and_exchanges_every_10_ms_with_the_engines_duty() -> None:
    def script(n: int) -> tuple[list[int], list[int]]:
        return [0, 0, int(10 <= n < 25), 0, 0, 0, int(n >= 40), 0], [0, 0, 0, 0]

    machine, record = bumberbot("robotx"), Record()
    with RobotxEmulator(script) as emu:
        robot = robot_on(emu, machine)
        end = drive(machine, robot, ticks=60, sinks=(record,))
        settle(emu)
    assert end.reason == "done" and robot.info is not None and robot.info.device == "ROBO TX-000"
    assert robot.info.version_text == "1.30"
    assert emu.names()[:3] == ["echo", "info", "config"] and emu.bad_frames == 0
    config = emu.requests("config")[0].fields
    assert config["motors"] == [1, 1, 1, 1] and config["uni"] == [0x81] * 8 and config["size"] == 48
    exchanges = emu.requests("exchange")
    assert len(exchanges) == 1 + 60 + 1  # outputs off at open, one per tick, outputs off at the stop
    assert all(r.fields["sid"] == emu.session == 1 for r in exchanges)  # the session the echo opened
    assert [r.fields["tid"] for r in emu.log[:4]] == [1, 2, 3, 4]
    wiring = robotx_wiring(machine)
    assert [r.fields["duty"] for r in exchanges[1:61]] == [wiring.duty(b.outputs[0]) for b in record.blocks]
    assert exchanges[0].fields["duty"] == exchanges[-1].fields["duty"] == [0] * 8
    assert any(any(r.fields["duty"]) for r in exchanges)
    bits = machine.input_bits  # inputs served for exchange n are the engine's at tick n (one exchange old)
    assert [b.masks[0] for b in record.blocks] == [
        (bits["I3"] if 10 <= n < 25 else 0) | (bits["I7"] if n >= 40 else 0) for n in range(60)
    ]
    gaps = [b.t - a.t for a, b in itertools.pairwise(exchanges[1:-1])]
    assert 0.0085 < statistics.median(gaps) < 0.0115, gaps


def test_counters_count_pulses_and_a_wiring_of_every_kind_configures_and_drives_its_terminals() -> None:
    """The BumberBot with counters, C1 on C3 and C2 on C1, I3 an ultrasonic threshold, I4 an inverted switch,
    M1 reversed on M2, M2 on M1; then a lamp's pair made single outputs."""
    wiring = {
        **BUMBER_WIRING,
        "I3": {"terminal": "I2", "mode": "ultrasonic", "below": 20},
        "I4": {"terminal": "I4", "mode": "switch", "pressed": 0},
        "M1": {"terminal": "M2", "reverse": True},
        "M2": "M1",
        "C1": "C3",
        "C2": "C1",
    }
    machine = bumberbot("robotx", wiring, "bumberbot-counters")
    counts = [0, 3, 3, 9, 65530, 4, 2]  # up 3, 0, 6; far back (a reset: 0); up 10 across the 16-bit wrap; back
    record = Record()

    def script(n: int) -> tuple[list[int], list[int]]:
        return [0, 10 if n % 2 else 50, 0, 1, 0, 0, 0, 0], [counts[min(n, 6)], 0, 2 * n, 0]

    with RobotxEmulator(script) as emu:
        end = drive(machine, robot_on(emu, machine), ticks=7, sinks=(record,))
        settle(emu)
    assert end.reason == "done"
    config = emu.requests("config")[0].fields
    assert config["motors"] == [1, 1, 1, 1] and config["uni"][1] == 0x03 and config["uni"][3] == 0x81
    assert [b.pulses[0] for b in record.blocks] == [(0, 0), (2, 3), (2, 0), (2, 6), (2, 0), (2, 10), (2, 0)]
    assert [b.extra["I3_raw"][0] for b in record.blocks] == [50, 10, 50, 10, 50, 10, 50]
    bits = machine.input_bits
    assert [b.masks[0] & (bits["I3"] | bits["I4"]) for b in record.blocks] == [0, bits["I3"]] * 3 + [0]
    assert robotx_wiring(machine).duty((5, -8)) == [0, 512, 0, 320, 0, 0, 0, 0]  # M2 back on O2, M1 back on O4
    lamp = bumberbot("robotx", {**BUMBER_WIRING, "M1": "M3"}, "bumberbot")
    assert robotx_wiring(lamp).config().motors == (True, True, True, True)


@pytest.mark.parametrize(
    ("how", "reason"), [("end", "done"), ("ctrl-c", "interrupted"), ("sigterm", "terminated"), ("bug", "error")]
)
def test_every_way_a_run_ends_sends_zero_duty_last(how: str, reason: str) -> None:
    with RobotxEmulator(lambda n: ([0] * 8, [0] * 4)) as emu:
        if how == "bug":
            with pytest.raises(RuntimeError, match="a bug in a sink"):
                drive(bumberbot("robotx"), robot_on(emu), ticks=30, sinks=(StopAt(15, how),))
            got = "error"
        else:
            got = drive(bumberbot("robotx"), robot_on(emu), ticks=30, sinks=(StopAt(15, how),)).reason
        settle(emu)
    assert got == reason
    duty = [r.fields["duty"] for r in emu.requests("exchange")]
    assert any(any(d) for d in duty) and duty[-1] == [0] * 8


@pytest.mark.parametrize(
    ("fault", "says"),
    [
        ("silent", "no answer"),
        ("late", "no answer"),
        ("garbage", "garbage"),
        ("bad_crc", "checksum"),
        ("wrong_tid", "wrong answer"),
        ("wrong_code", "reply code 105"),
        ("new_session", "new session"),
        ("short", "wrong answer"),
        ("hang_up", "disconnected|Input/output error"),
    ],
)
def test_every_fault_ends_the_run_as_link_lost_with_zero_duty_sent_where_the_link_allows(fault: str, says: str) -> None:
    with RobotxEmulator(lambda n: ([0] * 8, [0] * 4), fault=(fault, 12)) as emu:
        end = drive(bumberbot("robotx"), robot_on(emu, timeout_s=0.1), ticks=60)
        # the device still reads what it is sent (after a hang-up nothing more can be): zero duty comes last
        stopped = fault == "hang_up" or eventually(lambda: emu.requests("exchange")[-1].fields["duty"] == [0] * 8)
    assert end.reason == "link_lost" and end.exit_code == 3 and end.ticks == 12, end
    assert any(word in end.message for word in says.split("|")), end.message
    assert stopped


def test_a_slow_device_falls_behind_and_one_stall_too_long_ends_the_run_as_behind() -> None:
    with RobotxEmulator(delay_s=0.013) as emu:  # each reply 13 ms after the request: slower than the 10 ms tick
        end = drive(bumberbot("robotx"), robot_on(emu), ticks=400, behind_limit_s=0.2)
        settle(emu)
    assert end.reason == "behind" and end.late_ticks >= 3 and "cannot keep the table's 10 ms tick" in end.message
    assert emu.requests("exchange")[-1].fields["duty"] == [0] * 8
    with RobotxEmulator(fault=("late", 10), late_s=0.3) as emu:
        end = drive(bumberbot("robotx"), robot_on(emu, timeout_s=1.0), ticks=30, behind_limit_s=0.2)
        settle(emu)
    assert end.reason == "behind" and emu.requests("exchange")[-1].fields["duty"] == [0] * 8


def test_a_shell_prompt_before_the_first_frame_is_skipped_and_a_device_that_speaks_no_fish_x1_is_refused() -> None:
    with RobotxEmulator(junk=b"\r\nROBO TX-511\\USB>") as emu:
        assert robot_on(emu).connect().device == "ROBO TX-000"
    with RobotxEmulator(fault=("silent", 0)) as emu:
        emu.device_name = "x"
        # a shell that answers no frame (the ignore: this one emulator's echo handler is replaced, on purpose)
        emu._echo = lambda *args: emu.send(b"\r\nbad command\r\n")  # type: ignore[method-assign]
        robot = robot_on(emu)
        robot.link.setup_timeout_s = 0.2
        with pytest.raises(LinkLost, match="no answer"):
            robot.connect()


def test_auto_finds_the_controller_by_its_usb_id_then_checks_it_answers_fish_x1() -> None:
    ports = [
        PortInfo("/dev/ttyUSB0", 0x0403, 0x6001, "FT232R"),
        PortInfo("/dev/rfcomm0"),
        PortInfo("/dev/ttyACM3", 0x221D, 0x1000, "ROBO TX Controller"),
        PortInfo("/dev/ttyS0"),
    ]
    assert [p.device for p in robotx_link.candidates(ports)] == ["/dev/ttyACM3", "/dev/rfcomm0"]
    with RobotxEmulator() as emu, RobotxEmulator(fault=("silent", 0)) as other:
        other._echo = lambda *args: None  # type: ignore[method-assign]  # a port that never answers, on purpose
        found = robotx_link.find(
            [PortInfo(other.device, 0x221D, 0x1000), PortInfo(emu.device, 0x221D, 0x1000)], timeout_s=0.2
        )
    assert found is not None and found[0] == emu.device and found[1].device == "ROBO TX-000"


def test_a_reply_cut_short_by_ctrl_c_is_skipped_and_the_next_exchange_is_in_step() -> None:
    import signal

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    with RobotxEmulator(lambda n: ([n % 2, 0, 0, 0, 0, 0, 0, 0], [n, 0, 0, 0]), delay_s=0.05) as emu:
        link = robotx_link.RobotxLink(emu.device, reply_timeout_s=0.5)
        link.connect()
        link.hello()
        previous = signal.signal(signal.SIGALRM, interrupt)
        try:
            signal.setitimer(signal.ITIMER_REAL, 0.02)  # while the reply is still on its way
            with pytest.raises(KeyboardInterrupt):
                link.exchange([0] * 8)
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)
        got = link.exchange([64] * 8)  # the owed reply is read and dropped first
        link.close()
    assert got.counter_values[0] == 1 and got.universal[0] == 1  # the second exchange's own reply
    assert [r.fields["tid"] for r in emu.requests("exchange")] == [3, 4]
