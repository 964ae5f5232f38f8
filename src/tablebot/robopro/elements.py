"""The ROBO Pro elements the generated program uses, each built exactly as real programs write it: the
attribute order, the attribute values and the pins (name, class, id, place, size) are ones the corpus
shows (``testing/rpp_vocabulary.json``; the tests check every one).

Inputs and outputs: ``ftProDataIn input`` is 160 + n − 1 for In (In = I1…I8: the corpus shows 160–163 for
I1–I4) and 176 + n − 1 for the value of counter Cn (the corpus's TeachIn robots read their encoder motors'
counts at 176 and 178); ``ftProDataOutDual output`` is k − 1 for Mk (0–3 all appear).
"""

from __future__ import annotations

from tablebot.robopro.rpp_write import Element, Pin, caption, frame

INPUT_BASE = 160  # I1
COUNTER_BASE = 176  # C1's count
DIGITAL = "1"  # inputMode of a switch or phototransistor ("digital 5 kOhm")
COUNTER_MODE = "6"  # inputMode of a counter's count


def _pins(*specs: tuple) -> list[Pin]:
    return [Pin(*spec) for spec in specs]


def start(x: int, y: int) -> Element:
    return Element(
        "ftProProcessStart", x, y, [("scope", "0"), ("scopeauto", "true")], _pins(("", "flowobjectoutput", 0, 0, 4))
    )


def flow_in(x: int, y: int, name: str, unique: int) -> Element:
    return Element(
        "ftProSubroutineFlowIn",
        x,
        y,
        [("uniqueID", str(unique))],
        _pins((name, "flowobjectoutput", 0, 0, 4)),
        name=name,
        properties=[("name", name)],
    )


def flow_out(x: int, y: int, name: str, unique: int) -> Element:
    return Element(
        "ftProSubroutineFlowOut",
        x,
        y,
        [("uniqueID", str(unique))],
        _pins((name, "flowobjectinput", 0, 0, -4)),
        name=name,
        properties=[("name", name)],
    )


def variable(x: int, y: int, name: str, init: int = 0) -> Element:
    """A global integer variable (every copy of the same name is the same variable)."""
    return Element(
        "ftProDataVariable",
        x,
        y,
        [("scope", "1"), ("namebound", "true"), ("datatype", "3"), ("init", str(init))],
        _pins(("", "dataobjectinput", 0, -8, 0), ("", "dataobjectoutput", 0, 8, 0)),
        name=name,
        properties=[("name", name)],
    )


def const(x: int, y: int, value: int) -> Element:
    return Element(
        "ftProDataConst",
        x,
        y,
        [("datatype", "3"), ("value", str(value)), ("scope", "1")],
        _pins(("", "dataobjectoutput", 0, 8, 0)),
    )


def operator(x: int, y: int, operation: str) -> Element:
    """A two-input operator: output on the right, A on the left, B 8 below A."""
    return Element(
        "ftProDataOprt",
        x,
        y,
        [
            ("N", "2"),
            ("operation", operation),
            ("scope", "0"),
            ("scopeauto", "true"),
            ("nooverflowcheck", "false"),
            ("datatype", "3"),
        ],
        _pins(
            ("", "dataobjectoutput", 0, 4, 0), ("A", "dataobjectinput", 1, -4, 0), ("B", "dataobjectinput", 2, -4, 8)
        ),
    )


def message(x: int, y: int, command: str, value: int | None = None) -> Element:
    """A command element: sends ``command value`` (or the value at its data input, when ``value`` is None)."""
    pins = [("", "dataobjectoutput", 0, 8, 0), ("", "flowobjectinput", 0, 0, -4), ("", "flowobjectoutput", 0, 0, 4)]
    if value is None:
        pins.append(("", "dataobjectinput", 0, -8, 0))
    return Element(
        "ftProDataMssg",
        x,
        y,
        [
            ("command", command),
            ("datatype", "3"),
            ("value", str(-32768 if value is None else value)),
            ("valuetext", ""),
        ],
        _pins(*pins),
    )


def branch(x: int, y: int, yes_down: bool) -> Element:
    """A branch on its data input A: ``A > 0`` leaves by Y (pin id 0), otherwise by N (pin id 1); one exit
    points down, the other right. The generator only branches on values that are never negative, so the
    test reads the same whether operation 0 means "> 0" or "≠ 0"."""
    down, right = (("Y", 0), ("N", 1)) if yes_down else (("N", 1), ("Y", 0))
    return Element(
        "ftProFlowIf",
        x,
        y,
        [("style", "1"), ("operation", "0"), ("datatype", "3"), ("value", "0")],
        [
            Pin("A", "dataobjectinput", 0, -12, 0, (6, 4)),
            Pin("", "flowobjectinput", 0, 0, -8),
            Pin(down[0], "flowobjectoutput", down[1], 0, 8, (4, 6)),
            Pin(right[0], "flowobjectoutput", right[1], 12, 0, (6, 4), "4"),
        ],
    )


def compare(x: int, y: int) -> Element:
    """Compare A with B: leaves by ``<``, ``=`` or ``>``."""
    return Element(
        "ftProFlowCmpr2",
        x,
        y,
        [],
        _pins(
            ("", "flowobjectinput", 0, 0, -8),
            ("<", "flowobjectoutput", 0, -8, 8),
            ("=", "flowobjectoutput", 1, 0, 8),
            (">", "flowobjectoutput", 2, 8, 8),
            ("A", "dataobjectinput", 0, -8, -4),
            ("B", "dataobjectinput", 1, -12, 4),
        ),
    )


def wait(x: int, y: int, ms: int) -> Element:
    """Wait ``ms`` milliseconds: ``value`` in units of 10^scale ms (``uservalue`` is the same in seconds)."""
    scale, value = (1, ms // 10) if ms > 10_000 and ms % 10 == 0 else (0, ms)
    return Element(
        "ftProFlowDelay",
        x,
        y,
        [
            ("scale", str(scale)),
            ("static", "false"),
            ("value", str(value)),
            ("userscale", "0"),
            ("uservalue", f"{ms / 1000:g}"),
        ],
        _pins(("", "flowobjectinput", 0, 0, -4), ("", "flowobjectoutput", 0, 0, 4)),
    )


def digital_input(x: int, y: int, terminal: int) -> Element:
    return _data_in(x, y, INPUT_BASE + terminal - 1, DIGITAL)


def counter_input(x: int, y: int, counter: int) -> Element:
    return _data_in(x, y, COUNTER_BASE + counter - 1, COUNTER_MODE)


def _data_in(x: int, y: int, code: int, mode: str) -> Element:
    return Element(
        "ftProDataIn",
        x,
        y,
        [
            ("input", str(code)),
            ("module", "IF1"),
            ("image", "0"),
            ("inputMode", mode),
            ("scope", "1"),
            ("scopeauto", "true"),
        ],
        _pins(("", "dataobjectoutput", 0, 8, 0)),
    )


def motor(x: int, y: int, output: int) -> Element:
    """Motor output Mk (``output`` k); speeds in 8 steps (resolution 0)."""
    return Element(
        "ftProDataOutDual",
        x,
        y,
        [("output", str(output - 1)), ("module", "IF1"), ("image", "0"), ("resolution", "0")],
        _pins(("", "dataobjectinput", 0, -8, 0)),
    )


def lamp(x: int, y: int, output: int) -> Element:
    """Lamp output Ok (``output`` k): a single output, levels 0–8 (resolution 0). No program of the corpus has
    one; real ROBO Pro programs outside it write it so (olagino/roproparser's test/regal_test.rpp, ROBO Pro
    4.2.4: ``ftProDataOutSngl``, ``output`` k − 1, ``image`` 1, one data input as the motor's)."""
    return Element(
        "ftProDataOutSngl",
        x,
        y,
        [("output", str(output - 1)), ("module", "IF1"), ("image", "1"), ("resolution", "0")],
        _pins(("", "dataobjectinput", 0, -8, 0)),
    )


def array(x: int, y: int, name: str, values: list[int], indent: str) -> Element:
    """A global list pre-filled with ``values``: S (command) and I (index) in, R (value at I) and I out."""
    inits = [f'{indent}    <init value="{v}">\n{indent}    </init>\n' for v in values]
    return Element(
        "ftProDataArray1D",
        x,
        y,
        [
            ("globalname", name),
            ("scope", "1"),
            ("namebound", "true"),
            ("indexscope", "1"),
            ("indexnamebound", "true"),
            ("N", str(max(len(values), 1))),
            ("datatype", "3"),
            ("initcsvcolumn", "-1"),
        ],
        _pins(
            ("S", "dataobjectinput", 0, -8, -4),
            ("I", "dataobjectinput", 1, -8, 4),
            ("R", "dataobjectoutput", 2, 8, -4),
            ("I", "dataobjectoutput", 3, 8, 4),
        ),
        name=name,
        after=inits,
    )


def symbol_pins(inputs: list[tuple[str, int]], outputs: list[tuple[str, int]]) -> tuple[list[Pin], int, int]:
    """Pins of a subprogram's symbol: flow inputs along the top, flow outputs along the bottom, 8 apart
    (names and pin ids from the subprogram's FlowIn / FlowOut elements); the frame's width and height."""
    width = max(32, 8 * (max(len(inputs), len(outputs)) + 1))
    pins = [
        Pin(name, "flowobjectinput", unique, 8 * i - 4 * (len(inputs) - 1), -8)
        for i, (name, unique) in enumerate(inputs)
    ]
    pins += [
        Pin(name, "flowobjectoutput", unique, 8 * i - 4 * (len(outputs) - 1), 8)
        for i, (name, unique) in enumerate(outputs)
    ]
    return pins, width, 16


def subprogram_box(
    name: str, guid: str, pins: list[Pin], width: int, height: int, indent: str, caption_id: int
) -> tuple[list[tuple[str, str]], list[str]]:
    """The properties and the frame + caption a subprogram's symbol (and every call of it) carries."""
    inner = indent + "    "
    before = [frame(inner, -width // 2, -height // 2, width, height), caption(inner, caption_id, name, (0, 0))]
    return [("guid", guid), ("name", name)], before


def call(
    x: int, y: int, name: str, guid: str, pins: list[Pin], width: int, height: int, indent: str, caption_id: int
) -> Element:
    """A call of subprogram ``name`` (``ftProSubroutineRef``), drawn as its symbol."""
    props, before = subprogram_box(name, guid, pins, width, height, indent, caption_id)
    copies = [Pin(p.name, p.pinclass, p.pinid, p.dx, p.dy) for p in pins]
    return Element(
        "ftProSubroutineRef",
        x,
        y,
        [("version", "1"), ("scope", "0"), ("scopeauto", "true")],
        copies,
        name=name,
        properties=props,
        before=before,
    )
