"""Writing a ROBO Pro program (.rpp) from scratch: elements with their pins, wires between pins, and the
document around them, as text laid out the way ROBO Pro saves it.

Every classname, attribute order and pin place used here is one real programs show (the tests check the
output against ``testing/rpp_vocabulary.json``). Wires run between pin positions on a grid of 4; a wire that joins
another wire ends at a ``dynamic`` pin placed on that wire, as ROBO Pro stores converging flows.
"""

from __future__ import annotations

import itertools
import uuid
from collections.abc import Sequence
from dataclasses import dataclass, field

from tablebot.escape import xml_attr

FLAGS = " selectable visible draggable shadow filled snap"
WIRE_FLAGS = " selectable visible shadow filled snap"
HIT = " fill visible"
Point = tuple[int, int]


class Ids:
    """Ids as ROBO Pro writes them: positive, unique in the document."""

    def __init__(self, start: int = 100_000) -> None:
        self.next = start

    def __call__(self) -> int:
        self.next += 1
        return self.next


@dataclass(eq=False)
class Pin:
    """An element's connector (``ftProObjectPin``) at an offset from the element's origin."""

    name: str
    pinclass: str  # flowobjectinput, flowobjectoutput, dataobjectinput, dataobjectoutput
    pinid: int
    dx: int
    dy: int
    size: tuple[int, int] = (4, 4)
    orientation: str | None = None
    id: int = 0
    resolve: int | None = None
    owner: Element | None = None

    @property
    def at(self) -> Point:
        assert self.owner is not None
        return self.owner.x + self.dx, self.owner.y + self.dy


@dataclass(eq=False)
class Element:
    """A program element: its class, place, attributes (in ROBO Pro's order, after ``transform``), pins,
    and children written before its pins (properties, a symbol's frame and caption) or after (inits)."""

    classname: str
    x: int
    y: int
    attrs: list[tuple[str, str]]
    pins: list[Pin] = field(default_factory=list)
    name: str | None = None
    properties: list[tuple[str, str]] = field(default_factory=list)
    before: list[str] = field(default_factory=list)  # pre-rendered children (frame, caption)
    after: list[str] = field(default_factory=list)  # pre-rendered children after the pins (inits)
    hit: str = HIT
    id: int = 0

    def pin(self, key: str | int) -> Pin:
        """A pin by name, or by position among the element's pins."""
        if isinstance(key, int):
            return self.pins[key]
        found = [p for p in self.pins if p.name == key]
        assert len(found) == 1, f"{self.classname} has {len(found)} pins named {key!r}"
        return found[0]

    def pins_of(self, pinclass: str) -> list[Pin]:
        return [p for p in self.pins if p.pinclass == pinclass]


@dataclass(eq=False)
class Wire:
    """A flow or data wire from an output pin to an input pin (or to a dynamic pin on another wire)."""

    kind: str  # "flow" or "data"
    points: list[Point]
    begin: Pin  # the output it starts at
    end: Pin | WirePin  # the input (or dynamic pin) it ends at
    id: int = 0
    begin_id: int = 0
    end_id: int = 0
    dynamics: list[WirePin] = field(default_factory=list)


@dataclass(eq=False)
class WirePin:
    """A ``dynamic`` pin on a wire, where another wire joins it."""

    at: Point
    pinclass: str
    id: int = 0
    resolve: int = 0


class Canvas:
    """One subprogram's drawing: its elements and wires; ids come from the document's counter."""

    def __init__(self, ids: Ids) -> None:
        self.ids = ids
        self.elements: list[Element] = []
        self.wires: list[Wire] = []
        self.comments: list[str] = []  # pre-rendered texts on the canvas

    def add(self, element: Element) -> Element:
        element.id = self.ids()
        for pin in element.pins:
            pin.id = self.ids()
            pin.owner = element
        self.elements.append(element)
        return element

    def connect(self, begin: Pin, end: Pin, via: Sequence[Point] = ()) -> Wire:
        """A wire from output ``begin`` to input ``end`` through the corner points ``via``."""
        kind = "flow" if begin.pinclass.startswith("flow") else "data"
        assert begin.pinclass.endswith("output") and end.pinclass.endswith("input"), (begin, end)
        assert end.resolve is None, f"input {end.name!r} of {end.owner and end.owner.classname} is already wired"
        wire = Wire(kind, [begin.at, *via, end.at], begin, end, self.ids(), self.ids(), self.ids())
        begin.resolve, end.resolve = wire.begin_id, wire.end_id
        self.wires.append(_straight(wire))
        return wire

    def join(self, begin: Pin, onto: Wire, at: Point, via: Sequence[Point] = ()) -> Wire:
        """A flow wire from ``begin`` that ends on the wire ``onto`` at point ``at`` (a converging flow)."""
        assert _on(onto.points, at), f"{at} is not on the wire {onto.points}"
        dynamic = WirePin(at, "flowobjectinput" if onto.kind == "flow" else "dataobjectinput", self.ids())
        wire = Wire(onto.kind, [begin.at, *via, at], begin, dynamic, self.ids(), self.ids(), self.ids())
        begin.resolve, dynamic.resolve = wire.begin_id, wire.end_id
        onto.dynamics.append(dynamic)
        self.wires.append(_straight(wire))
        return wire

    def bounds(self) -> tuple[int, int, int, int]:
        xs = [e.x for e in self.elements] + [x for w in self.wires for x, _ in w.points]
        ys = [e.y for e in self.elements] + [y for w in self.wires for _, y in w.points]
        return min(xs), min(ys), max(xs), max(ys)


def _straight(wire: Wire) -> Wire:
    for (x0, y0), (x1, y1) in zip(wire.points, wire.points[1:], strict=False):
        assert x0 == x1 or y0 == y1, f"wire segment {(x0, y0)}-{(x1, y1)} is not horizontal or vertical"
    return wire


def _on(points: Sequence[Point], at: Point) -> bool:
    x, y = at
    return any(
        min(x0, x1) <= x <= max(x0, x1) and min(y0, y1) <= y <= max(y0, y1)
        for (x0, y0), (x1, y1) in itertools.pairwise(points)
    )


# --- text ------------------------------------------------------------------------------------------


def attrs_text(pairs: Sequence[tuple[str, str]]) -> str:
    return " ".join(f'{k}="{xml_attr(v)}"' for k, v in pairs)


def matrix(x: int, y: int) -> str:
    return f"matrix( 1 0 0 1 {x} {y} )"


def open_tag(indent: str, head: Sequence[tuple[str, str]], at: Point | None, tail: Sequence[tuple[str, str]]) -> str:
    """``<o …>`` as ROBO Pro writes it: the transform and the attributes after it on lines of their own."""
    if at is None:
        return f"{indent}<o {attrs_text([*head, *tail])}>\n"
    rest = f"\n{indent}     {attrs_text(tail)}" if tail else ""
    return f'{indent}<o {attrs_text(head)}\n{indent}     transform="{matrix(*at)}"{rest}>\n'


def properties(indent: str, pairs: Sequence[tuple[str, str]]) -> str:
    if not pairs:
        return ""
    items = "".join(
        f'{indent}        <o classname="wxDocviewStringProperty" '
        f"{attrs_text([('name', k), ('value', v)])}>\n{indent}        </o>\n"
        for k, v in pairs
    )
    return f"{indent}    \n{indent}    <properties>\n{items}{indent}    </properties>\n{indent}    \n"


def colours(indent: str, fill: str, stroke: str, width: str = "0.25", fill_attrs: str | None = None) -> str:
    fill_text = fill_attrs if fill_attrs is not None else f'colour="{fill}"'
    return (
        f"{indent}    \n{indent}    <properties>\n"
        f'{indent}        <o classname="wxDocviewRefObjectProperty" name="fill">\n'
        f'{indent}            <o classname="wxCanvasOneColourFill" {fill_text}>\n{indent}            </o>\n'
        f"{indent}        </o>\n"
        f'{indent}        <o classname="wxDocviewRefObjectProperty" name="stroke">\n'
        f'{indent}            <o classname="wxCanvasOneColourStroke" colour="{stroke}" width="{width}">\n'
        f"{indent}            </o>\n{indent}        </o>\n{indent}    </properties>\n{indent}    \n"
    )


def pin_text(indent: str, pin: Pin) -> str:
    head = [
        ("classname", "ftProObjectPin"),
        ("id", str(pin.id)),
        ("name", pin.name),
        ("flags", FLAGS),
        ("hitflags", HIT),
    ]
    tail = [("width", str(pin.size[0])), ("height", str(pin.size[1])), ("pinclass", pin.pinclass)]
    if pin.resolve is not None:
        tail.append(("resolveid", str(pin.resolve)))
    tail.append(("pinid", str(pin.pinid)))
    if pin.orientation is not None:
        tail.append(("orientation", pin.orientation))
    return open_tag(indent, head, (pin.dx, pin.dy), tail) + f"{indent}</o>\n{indent}\n"


def element_text(indent: str, e: Element) -> str:
    head = [("classname", e.classname), ("id", str(e.id))]
    if e.name is not None:
        head.append(("name", e.name))
    head += [("flags", FLAGS), ("hitflags", e.hit)]
    body = properties(indent, e.properties) + "".join(e.before)
    body += "".join(pin_text(indent + "    ", p) for p in e.pins) + "".join(e.after)
    return open_tag(indent, head, (e.x, e.y), e.attrs) + body + f"{indent}</o>\n{indent}\n"


def wire_text(indent: str, w: Wire) -> str:
    flow = w.kind == "flow"
    head = [
        ("classname", "ftProFlowWire" if flow else "ftProDataWire"),
        ("id", str(w.id)),
        ("layer", "2" if flow else "1"),
        ("flags", WIRE_FLAGS),
        ("hitflags", HIT),
        ("points", str(len(w.points))),
        ("invert", "false"),
        ("canbranch", "false" if flow else "true"),
        ("canconverge", "true"),
        ("pcobjbegin", "flowobjectoutput" if flow else "dataobjectoutput"),
        ("pcwirebegin", "flowwireoutput" if flow else "datawireoutput"),
        ("pcwireend", "flowwireinput" if flow else "datawireinput"),
    ]
    kind = "flow" if flow else "data"
    end_id = w.end.id
    pins = [
        ("begin", w.begin_id, w.points[0], f"{kind}wireoutput", w.begin.id, 7),
        ("end", w.end_id, w.points[-1], f"{kind}wireinput", end_id, 7),
    ]
    pins += [("dynamic", d.id, d.at, d.pinclass, d.resolve, 9) for d in w.dynamics]
    inner = indent + "    "
    text = f"{indent}<o {attrs_text(head)}>\n{inner}\n{inner}<properties>\n{inner}</properties>\n{inner}\n"
    for name, ident, at, pinclass, resolve, size in pins:
        text += open_tag(
            inner,
            [("classname", "wxCanvasPin"), ("id", str(ident)), ("name", name), ("flags", FLAGS), ("hitflags", HIT)],
            at,
            [("width", str(size)), ("height", str(size)), ("pinclass", pinclass), ("resolveid", str(resolve))],
        )
        text += f"{inner}</o>\n{inner}\n"
    text += f"{inner}\n" + "".join(f'{inner}<xy x="{x}" y="{y}"/>\n' for x, y in w.points)
    return text + f"{indent}</o>\n{indent}\n"


def caption(
    indent: str, ident: int, text: str, at: Point | None, size: int = 3, align: str = "0", linespace: str = "0.3"
) -> str:
    """A text on the canvas (``wxCanvasTextDc``): a comment, or a symbol's caption."""
    head = [("classname", "wxCanvasTextDc"), ("id", str(ident)), ("flags", FLAGS), ("hitflags", HIT)]
    tail = [
        ("fontsize", str(size)),
        ("linespace", linespace),
        ("caret", "0"),
        ("caretshow", "false"),
        ("text", text),
        ("up", "false"),
        ("family", "74"),
        ("style", "90"),
        ("weight", "90"),
        ("alignment", align),
    ]
    return (
        open_tag(indent, head, at, tail)
        + colours(indent, "", "BLACK", fill_attrs='style="1"')
        + f"{indent}</o>\n{indent}\n"
    )


def frame(indent: str, x: int, y: int, width: int, height: int) -> str:
    """A subprogram symbol's frame (``wxCanvasRect``), in ROBO Pro's subprogram colours."""
    head = [("classname", "wxCanvasRect"), ("flags", FLAGS), ("hitflags", HIT)]
    return (
        open_tag(indent, head, (x, y), [("width", str(width)), ("height", str(height))])
        + colours(indent, "#D5FFD5", "#00EA00")
        + f"{indent}</o>\n{indent}\n"
    )


def new_guid(seed: str) -> str:
    """A stable GUID per subprogram name: the same table gives the same file."""
    return str(uuid.uuid5(uuid.NAMESPACE_URL, "tablebot-robopro:" + seed))
