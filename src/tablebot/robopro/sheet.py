"""Laying out one subprogram on ROBO Pro's grid: the flow runs down one column; a branch's other exit
leads to a side column on the right and joins the column again further down; the data each element reads
is a tree of variables, constants, inputs, lists and operators spreading to the left of it. Wires only go
left into inputs and right out of outputs, so they do not cross; a flow that rejoins the column, or loops
back, runs in a lane right of everything and ends on the column's wire, as ROBO Pro stores a merge.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from tablebot.robopro import elements as el
from tablebot.robopro.rpp_write import Canvas, Element, Pin, Point, Wire

GRID = 4
SIDE = 40  # from the column to a side column


@dataclass(frozen=True)
class Var:
    name: str


@dataclass(frozen=True)
class Const:
    value: int


@dataclass(frozen=True)
class Input:
    terminal: int


@dataclass(frozen=True)
class Count:
    counter: int


@dataclass(frozen=True)
class Op:
    operation: str
    a: Tree
    b: Tree


@dataclass(frozen=True)
class ListAt:
    """A list's value at the index a tree gives (the list's I input)."""

    name: str
    values: tuple[int, ...]
    index: Tree


Tree = Var | Const | Input | Count | Op | ListAt


def extent(tree: Tree) -> int:
    """How far left of the input it feeds a tree reaches."""
    if isinstance(tree, Op):
        return 16 + max(extent(tree.a), extent(tree.b) + 8)
    if isinstance(tree, ListAt):
        return 24 + extent(tree.index)
    return 24


@dataclass
class Join:
    """A flow waiting to rejoin the column: it leaves ``pin`` (a side column's last exit, which first
    steps down, or a branch's exit pointing right) and runs down a lane right of everything."""

    pin: Pin
    bottom: int  # lowest y the flow's own elements reach


class Sheet:
    """A subprogram being laid out: a column at ``x`` whose flow continues from ``tail``."""

    def __init__(self, canvas: Canvas, x: int, inits: dict[str, int], indent: str) -> None:
        self.canvas, self.x, self.inits, self.indent = canvas, x, inits, indent
        self.tail: Pin | None = None
        self.y = 0  # lowest y used so far in the column
        self.joins: list[Join] = []
        self.held: list[Join] = []  # joins that land further down than the next step
        self.right = x + SIDE  # rightmost x elements use so far (lanes go beyond it)
        self.lanes = 0  # rightmost lane used so far
        self.last_wire: Wire | None = None  # the flow wire into the latest step
        self.sides = x  # x of the rightmost side column
        self.notes: list[tuple[int, str]] = []  # (y, text): comments beside the column, placed at the end

    # --- data trees -------------------------------------------------------------------------------

    def feed(self, tree: Tree, pin: Pin) -> int:
        """Place ``tree`` left of input ``pin`` and wire it there; returns the lowest y it uses."""
        low, out = self._place(tree, pin.at)
        self.canvas.connect(out, pin)
        return low

    def _feed_below(self, tree: Tree, pin: Pin, y: int) -> int:
        """Like :meth:`feed`, with the tree's output at row ``y`` (at or below the pin) and a jog up."""
        px, py = pin.at
        if y == py:
            return self.feed(tree, pin)
        low, out = self._place(tree, (px, y))
        self.canvas.connect(out, pin, via=[(px - 4, y), (px - 4, py)])
        return low

    def _place(self, tree: Tree, target: Point) -> tuple[int, Pin]:
        """Place ``tree`` with its output 8 left of ``target``: (the lowest y it uses, its output pin)."""
        tx, ty = target
        if isinstance(tree, Op):
            op = self.canvas.add(el.operator(tx - 12, ty, tree.operation))
            low = self.feed(tree.a, op.pin("A"))
            low_b = self._feed_below(tree.b, op.pin("B"), max(op.pin("B").at[1], low + 8))
            return max(low, low_b), op.pin(0)
        if isinstance(tree, ListAt):
            array = self.canvas.add(el.array(tx - 16, ty + 4, tree.name, list(tree.values), self.indent + "    "))
            return max(ty + 8, self.feed(tree.index, array.pin(1))), array.pin("R")
        return ty, self._leaf(tree, tx - 16, ty).pins_of("dataobjectoutput")[0]

    def _leaf(self, tree: Tree, x: int, y: int) -> Element:
        if isinstance(tree, Var):
            return self.canvas.add(el.variable(x, y, tree.name, self.inits.get(tree.name, 0)))
        if isinstance(tree, Const):
            return self.canvas.add(el.const(x, y, tree.value))
        if isinstance(tree, Input):
            return self.canvas.add(el.digital_input(x, y, tree.terminal))
        assert isinstance(tree, Count)
        return self.canvas.add(el.counter_input(x, y, tree.counter))

    # --- the column ----------------------------------------------------------------------------------

    def begin(self, element: Element) -> Element:
        """The column's first element (Start or a subprogram's entry)."""
        self.canvas.add(element)
        self.tail = element.pins_of("flowobjectoutput")[0]
        self.y = element.y + 4
        return element

    def step(
        self,
        make: Callable[[int, int], Element],
        data: Tree | None = None,
        gap: int = 8,
        entry: Callable[[Element], Pin] | None = None,
        dx: int = 0,
        release: bool = False,
    ) -> Element:
        """Place the next element below the column's tail, wire the flow in (and the pending joins onto
        that wire; with ``release``, the held ones too), and feed ``data`` to its data input; the column
        continues from its lower exit."""
        assert self.tail is not None
        if release:
            self.joins, self.held = self.held + self.joins, []
        top = max(self.y, max((j.bottom for j in self.joins), default=self.y)) + gap + 8 * len(self.joins)
        probe = make(0, 0)
        flow_in = (entry or (lambda e: e.pins_of("flowobjectinput")[0]))(probe)
        y = top - flow_in.dy
        element = self.canvas.add(make(self.x + dx, y))
        flow_in = (entry or (lambda e: e.pins_of("flowobjectinput")[0]))(element)
        tx, ty = self.tail.at
        fx, fy = flow_in.at
        mid = ty + 4 if fx != tx else None
        via = [(tx, mid), (fx, mid)] if mid is not None else []
        wire = self.canvas.connect(self.tail, flow_in, via=via)
        self.last_wire = wire
        self._join_all(wire, fx, fy)
        low = y + 4
        if data is not None:
            low = max(low, self.feed(data, element.pins_of("dataobjectinput")[0]))
        downs = [p for p in element.pins_of("flowobjectoutput") if p.dy > 0 and p.dx <= 0]
        self.tail = downs[-1] if downs else None
        self.y = max(low, (self.tail.at[1] if self.tail else low))
        return element

    def _join_all(self, wire: Wire, x: int, y_in: int) -> None:
        """Every pending join ends on ``wire`` above the input at (x, y_in). A lone side column's exit goes
        straight down and left; otherwise the first join takes the outermost lane and the lowest point,
        each later one a lane further in and a point higher, so no two cross."""
        count = len(self.joins)
        base = max(self.right, self.lanes)  # beyond every element and every lane drawn so far
        for n, join in enumerate(self.joins):
            lane = base + 8 * (count - n)
            at = (x, y_in - 4 - 8 * n)
            px, py = join.pin.at
            if join.pin.dx > 0 and join.pin.dy == 0:  # a branch's exit to the right
                via = [(lane, py), (lane, at[1])]
            elif px < x or count == 1:  # straight down, then across to the column
                via = [(px, at[1])]
            else:
                via = [(px, py + 4), (lane, py + 4), (lane, at[1])]
                self.lanes = max(self.lanes, lane)
            if join.pin.dx > 0 and join.pin.dy == 0:
                self.lanes = max(self.lanes, lane)
            self.canvas.join(join.pin, wire, at, via=via)
        self.joins = []

    def side(
        self,
        exit_pin: Pin,
        makers: list[Callable[[int, int], Element]],
        data: list[Tree | None] | None = None,
        extra: Callable[[Element], object] | None = None,
        rejoin: bool = True,
        hold: bool = False,
    ) -> tuple[list[Element], Wire | None]:
        """A side column right of the column, entered from ``exit_pin``: the elements ``makers`` make, in a
        chain; its last exit rejoins the column below (or, with no elements, the exit itself does)."""
        data = data or [None] * len(makers)
        pending = self.held if hold else self.joins
        sx = self.x + SIDE + max((extent(tree) for tree in data if tree is not None), default=0)
        if not makers:
            pending.append(Join(exit_pin, exit_pin.at[1]))
            return [], None
        ex, ey = exit_pin.at
        tail, placed, low, first = exit_pin, [], ey, None
        for n, (make, tree) in enumerate(zip(makers, data, strict=True)):
            probe = make(0, 0)
            dy_in = probe.pins_of("flowobjectinput")[0].dy
            down = exit_pin.dy > 0  # an exit pointing down steps down before it turns right
            y = (ey + (12 if down else 8) if n == 0 else low + 12) - dy_in
            element = self.canvas.add(make(sx, y))
            flow_in = element.pins_of("flowobjectinput")[0]
            via = ([(ex, ey + 4), (sx, ey + 4)] if down else [(sx, ey)]) if n == 0 else []
            wire = self.canvas.connect(tail, flow_in, via=via)
            first = first or wire
            if tree is not None:
                low = max(low, self.feed(tree, element.pins_of("dataobjectinput")[0]))
            if extra is not None:
                extra(element)
            outs = element.pins_of("flowobjectoutput")
            tail = outs[-1] if outs else tail
            low = max(low, y + 8, tail.at[1])
            placed.append(element)
            self.right = max(self.right, sx + 40)
        self.sides = max(self.sides, sx)
        if rejoin and tail.pinclass == "flowobjectoutput":
            pending.append(Join(tail, low))
        self.y = max(self.y, low)
        return placed, first

    def release(self) -> None:
        """The held joins land on the next step."""
        self.joins, self.held = self.held + self.joins, []

    def note(self, y: int, text: str) -> None:
        self.notes.append((y, text))

    def lane(self) -> int:
        """A lane right of every element and every lane so far (for a flow that spans many steps)."""
        self.lanes = max(self.right, self.lanes) + 8
        return self.lanes

    def loop_back(self, pin: Pin, onto: Wire, at: Point) -> None:
        """A flow from ``pin`` back up to ``at`` on the column's wire ``onto``, by the rightmost lane."""
        lane = self.lane()
        px, py = pin.at
        self.canvas.join(pin, onto, at, via=[(px, py + 4), (lane, py + 4), (lane, at[1])])
