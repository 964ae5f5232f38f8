"""The generated ``tb_board.h`` of a firmware: this robot's wiring as C (input sampling, outputs,
encoder counting), the tick timer and UART settings, and the trace frame size.
"""

from __future__ import annotations

from tablebot.codegen.packing import Layout
from tablebot.diagnostics import fail
from tablebot.escape import c_comment
from tablebot.firmware.boards import Wiring
from tablebot.firmware.framing import tick_payload
from tablebot.i18n import N_
from tablebot.machine import Machine

PRESCALERS = (
    (1, "(1 << CS10)"),
    (8, "(1 << CS11)"),
    (64, "((1 << CS11) | (1 << CS10))"),
    (256, "(1 << CS12)"),
    (1024, "((1 << CS12) | (1 << CS10))"),
)
#: Pin-change interrupt group per port, and external interrupts, of each MCU.
PCINT = {"atmega328p": {"B": 0, "C": 1, "D": 2}, "atmega32u4": {"B": 0}}
EXTINT = {"atmega328p": {"PD2": 0, "PD3": 1}, "atmega32u4": {"PD0": 0, "PD1": 1, "PD2": 2, "PD3": 3}}
#: ftDuino: which MC33879 output bit switches each O terminal high or low (Ftduino.cpp output_set).
FT_HIGHSIDE = (2, 6, 4, 5)
FT_LOWSIDE = (8, 1, 7, 3)
FT_THRESHOLD = 512  # half scale: below it an input is pulled low (closed switch, lit sensor)


def tx_size(payload: int) -> int:
    """The UART ring: room for two whole frames, a power of two for cheap wrapping."""
    size = 32
    while size < 2 * (payload + 3):
        size *= 2
    return size


def timer_setting(f_cpu: int, tick_ms: int, where: str = "robot") -> tuple[int, str]:
    """(compare value, clock-select bits) of Timer1 for an exact tick, finest prescaler first."""
    for prescaler, bits in PRESCALERS:
        counts, rest = divmod(f_cpu * tick_ms, prescaler * 1000)
        if rest == 0 and 0 < counts <= 65536:
            return counts - 1, bits
    raise fail(
        where,
        N_("tick_ms = {tick_ms} cannot be timed exactly by a 16-bit timer at {f_cpu} Hz", tick_ms=tick_ms, f_cpu=f_cpu),
        N_("use a tick of at most 4000 ms (above 1048 ms, a multiple of 8 ms)"),
    )


def ubrr(f_cpu: int, baud: int) -> int:
    """The UART divider in double-speed mode (U2X), rounded."""
    return round(f_cpu / (8 * baud)) - 1


def _pin(spec: str) -> tuple[str, int]:
    return spec[1], int(spec[2])


# --- inputs -------------------------------------------------------------------------------------


def _inputs_uno(machine: Machine, wiring: Wiring) -> list[str]:
    lines = ["    tb_event_t ev = 0;"]
    ports = sorted({_pin(wiring.board.inputs[t])[0] for n, t in wiring.inputs.items() if n in machine.input_bits})
    lines += [f"    uint8_t p{p.lower()} = PIN{p};" for p in ports]
    for name, terminal in wiring.inputs.items():
        if name not in machine.input_bits:
            continue
        port, bit = _pin(wiring.board.inputs[terminal])
        test = f"p{port.lower()} & (1u << {bit})"
        cond = test if name in wiring.active_high else f"!({test})"
        polarity = "high" if name in wiring.active_high else "low"
        note = c_comment(f"{name} on {terminal}, 1 = {polarity}")
        lines.append(f"    if ({cond}) ev |= {machine.input_bits[name]}u; /* {note} */")
    lines.append("    return ev;")
    return lines


def _inputs_ftduino(machine: Machine, wiring: Wiring) -> list[str]:
    lines = ["    tb_event_t ev = 0;", "    uint8_t in = ft_inputs;", "    (void)in;"]
    for name, terminal in wiring.inputs.items():
        if name not in machine.input_bits:
            continue
        channel = int(terminal[1:]) - 1
        test = f"in & (1u << {channel})"
        cond = f"!({test})" if name in wiring.active_high else test
        lines.append(f"    if ({cond}) ev |= {machine.input_bits[name]}u; /* {c_comment(f'{name} on {terminal}')} */")
    lines.append("    return ev;")
    return lines


# --- outputs ------------------------------------------------------------------------------------


def _ft_bits(wiring: Wiring, terminal: str) -> tuple[int, int]:
    """(highside, lowside) driver bits of an ftDuino O terminal."""
    k = wiring.board.outputs[terminal]
    shift = 8 if k < 4 else 0
    return (1 << (FT_HIGHSIDE[k & 3] - 1)) << shift, (1 << (FT_LOWSIDE[k & 3] - 1)) << shift


def _output_statements(machine: Machine, wiring: Wiring) -> list[str]:
    lines = []
    robot = machine.table.robot
    for i, name in enumerate(machine.output_names):
        if name in robot.motors:
            channel = wiring.motors[name]
            if wiring.board.name == "uno":
                call = f"{wiring.board.motors[channel]}(v);"
            else:
                first, second = (_ft_bits(wiring, o) for o in wiring.board.motors[channel].split())
                every = first[0] | first[1] | second[0] | second[1]
                left, right = first[1] | second[0], first[0] | second[1]
                call = f"ft_set(0x{every:04x}u, v > 0 ? 0x{left:04x}u : 0x{right:04x}u, (uint8_t)(v < 0 ? -v : v));"
            where = f"{name} on {channel}"
        else:
            terminal = wiring.lamps[name]
            if wiring.board.name == "uno":
                port, bit = _pin(wiring.board.inputs[terminal])
                call = f"if (v > 0) PORT{port} |= 1u << {bit}; else PORT{port} &= (uint8_t)~(1u << {bit});"
            else:
                high, low = _ft_bits(wiring, terminal)
                call = f"ft_set(0x{high | low:04x}u, 0x{high:04x}u, (uint8_t)v);"
            where = f"{name} on {terminal}"
        lines += [
            f"    v = out[{i}]; /* {c_comment(where)} */",
            f"    if (v != tb_last[{i}]) {{",
            f"        tb_last[{i}] = v;",
            f"        {call}",
            "    }",
        ]
    return lines


# --- counters -----------------------------------------------------------------------------------


def _counter_groups(machine: Machine, wiring: Wiring) -> tuple[dict[int, list], dict[int, int]]:
    """Counters by pin-change group {group: [(index, port, bit)]} and by external interrupt."""
    mcu = wiring.board.mcu
    groups: dict[int, list] = {}
    external: dict[int, int] = {}
    for i, name in enumerate(machine.table.robot.counter_names):
        pin = wiring.board.counters[wiring.counters[name]]
        port, bit = _pin(pin)
        if port in PCINT[mcu]:
            groups.setdefault(PCINT[mcu][port], []).append((i, port, bit))
        else:
            external[EXTINT[mcu][pin]] = i
    return groups, external


def _counter_code(machine: Machine, wiring: Wiring) -> tuple[list[str], list[str]]:
    """(top-level ISRs, init statements) counting rising edges on each counter pin."""
    n = len(machine.table.robot.counters)
    if not n:
        return [], []
    top = [
        f"static volatile uint8_t tb_count[{n}];",
        "#define TB_COUNT(i) do { if (tb_count[i] != 255) tb_count[i]++; } while (0)",
    ]
    init: list[str] = []
    pullup = wiring.board.name == "uno"  # the ftDuino has external pull-ups on C1..C4
    groups, external = _counter_groups(machine, wiring)
    for group, pins in groups.items():
        port = pins[0][1]
        top += [
            f"static uint8_t tb_pc_last{group};",
            f"ISR(PCINT{group}_vect)",
            "{",
            f"    uint8_t now = PIN{port};",
            f"    uint8_t rise = (uint8_t)(now & ~tb_pc_last{group});",
            f"    tb_pc_last{group} = now;",
        ]
        top += [f"    if (rise & (1u << {bit})) TB_COUNT({i});" for i, _, bit in pins]
        top.append("}")
        mask = sum(1 << bit for _, _, bit in pins)
        init += [f"    DDR{port} &= (uint8_t)~{mask}u;"]
        if pullup:
            init.append(f"    PORT{port} |= {mask}u;")
        init += [
            f"    tb_pc_last{group} = PIN{port};",
            f"    PCMSK{group} |= {mask}u;",
            f"    PCICR |= 1u << PCIE{group};",
        ]
    for number, i in external.items():
        top += [f"ISR(INT{number}_vect)", "{", f"    TB_COUNT({i});", "}"]
        init += [
            f"    EICRA |= (1u << ISC{number}1) | (1u << ISC{number}0); /* rising edge */",
            f"    EIMSK |= 1u << INT{number};",
        ]
    return top, init


def _init_statements(machine: Machine, wiring: Wiring) -> list[str]:
    lines: list[str] = []
    if wiring.board.name == "uno":
        for name, terminal in wiring.inputs.items():
            port, bit = _pin(wiring.board.inputs[terminal])
            lines.append(f"    DDR{port} &= (uint8_t)~(1u << {bit}); /* {c_comment(name)} */")
            if name not in wiring.active_high:  # an active-high sensor drives the pin: no pull-up
                lines.append(f"    PORT{port} |= 1u << {bit};")
        for name, terminal in wiring.lamps.items():
            port, bit = _pin(wiring.board.inputs[terminal])
            lines.append(f"    DDR{port} |= 1u << {bit}; /* {c_comment(name)} */")
    return lines


def board_header(machine: Machine, wiring: Wiring, layout: Layout, payload: int | None = None) -> str:
    """The whole ``tb_board.h`` for one table on one board (``payload``: a tick frame's bytes, when it is not
    one table's frame: a robot of several tables, tablebot.firmware.several)."""
    board, robot = wiring.board, machine.table.robot
    payload = tick_payload(machine, layout) if payload is None else payload
    if payload + 3 > 128:
        raise fail(
            machine.table.path,
            N_("a trace frame of {size} bytes is too long for the UART ring", size=payload + 3),
            N_("use fewer outputs and counters"),
        )
    top, ticks = timer_setting(board.f_cpu, robot.tick_ms, robot.source)
    isrs, counter_init = _counter_code(machine, wiring)
    channels = [int(t[1:]) - 1 for n, t in wiring.inputs.items() if n in machine.input_bits]
    n_out = max(1, len(machine.output_names))
    wiring_note = "; ".join(
        f"{n}={t}" for kind in (wiring.inputs, wiring.motors, wiring.lamps, wiring.counters) for n, t in kind.items()
    )
    lines = [
        f"/* Generated by tablebot: {c_comment(robot.name)} on {c_comment(board.title)}. Do not edit.",
        f" * Wiring: {c_comment(wiring_note or 'none')}. */",
        "#ifndef TB_BOARD_H",
        "#define TB_BOARD_H",
        "",
        f"#define TB_TICK_TOP {top}u",
        f"#define TB_TICK_CS {ticks}",
        f"#define TB_UBRR {ubrr(board.f_cpu, board.baud)}u /* {board.baud} baud */",
        f"#define TB_TICK_PAYLOAD {payload}u",
        f"#define TB_TX_SIZE {tx_size(payload)}u",
    ]
    if board.name == "ftduino":
        lines += [
            f"#define TB_FT_N_CHANNELS {len(channels)}",
            "#define TB_FT_CHANNELS {" + ", ".join(map(str, channels)) + "}",
            f"#define TB_FT_THRESHOLD {FT_THRESHOLD}u",
        ]
    lines += [
        f'#include "board_{board.name}.h"',
        "",
        *isrs,
        "",
        f"static int8_t tb_last[{n_out}]; /* outputs as last driven */",
        "",
        "static inline void tb_wiring_init(void)",
        "{",
        *_init_statements(machine, wiring),
        *counter_init,
        "}",
        "",
        "static inline tb_event_t tb_wiring_inputs(void)",
        "{",
        *(_inputs_uno if board.name == "uno" else _inputs_ftduino)(machine, wiring),
        "}",
        "",
        "static inline void tb_wiring_pulses(uint16_t *p)",
        "{",
    ]
    lines += [f"    p[{i}] = tb_count[{i}];\n    tb_count[{i}] = 0;" for i in range(len(robot.counters))]
    lines += [
        "    (void)p;",
        "}",
        "",
        "static inline void tb_wiring_outputs(const int8_t *out)",
        "{",
        "    int8_t v;",
        *_output_statements(machine, wiring),
        "    (void)v;",
        "    (void)out;",
        "}",
        "",
        "#endif",
        "",
    ]
    return "\n".join(lines)
