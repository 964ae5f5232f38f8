"""An interpreter of the ROBO Pro elements the generated program uses, to run a .rpp against scripted
inputs and see the decisions it takes, tick by tick (a tick ends at each Wait).

It reads any .rpp made of these elements, not only ours: the flow follows the wires pin by pin (through
``dynamic`` pins where flows merge), and data is evaluated where it is read. What each element does, and
where that comes from (no ROBO Pro installation was available to watch; fischertechnik's manual was found
only as a table of contents, "RoboPro-En", sections 5.4 Timers, 5.6 Lists, 5.7 Operators):

* ``ftProProcessStart`` (each Start of the main program is a process of its own, as olagino/roproparser's
  ``roSubroutine.run`` runs one thread per Start and its test/multi.rpp, a real program, flashes two lamps in
  two), ``ftProFlowDelay`` (waits ``value`` × 10^``scale`` ms),
  ``ftProSubroutineRef`` / ``FlowIn`` / ``FlowOut`` (a call enters at the FlowIn whose ``uniqueID`` is the
  pin id of the call's input and leaves by the output whose pin id is the FlowOut's ``uniqueID``): how the
  corpus wires them, and olagino/roproparser (GitHub, ``code/roObject.py``, a ROBO Pro interpreter in
  Python) runs them the same way.
* ``ftProFlowIf`` with a data input: ``operation`` 0 ">", 1 "≥", 2 "=", 3 "≤", 4 "<", 5 "≠" against
  ``value``, Y (pin id 0) if true: olagino/roproparser ``code/roObject.py``. The corpus cannot tell "> 0"
  from "≠ 0" for operation 0, so a branch on a negative value with operation 0 is an error here; the
  generator never makes one.
* ``ftProFlowCmpr2``: leaves by the output named ``<``, ``=`` or ``>`` for A against B (its pin names).
* ``ftProDataMssg``: sends ``command value`` (the value at its data input when one is wired) to every
  input on its output's wire: ``=``, ``+``, ``-`` to a variable; ``cw``, ``ccw`` (speed) and ``Stop`` to a
  motor (olagino/roproparser); ``=`` to a list's I input sets its index.
* ``ftProDataOutSngl`` (a lamp on output O(``output`` + 1)): ``On`` with a brightness 0–8, ``Off``; as
  olagino/roproparser's test/regal_test.rpp (a real ROBO Pro 4.2.4 program) sends them to its lamps.
* ``ftProDataVariable`` (value at its output), ``ftProDataConst``, ``ftProDataIn`` (``input`` 160 + n − 1
  reads In, 176 + n − 1 the count of Cn), ``ftProDataOutDual``: as the corpus wires them. A variable of
  ``scope`` 1 is global, one value for every copy of its name (olagino/roproparser; in the corpus, names
  used in several subprograms are scope 1 for 121 names and scope 0 for 9); the generator uses only those.
* ``ftProDataArray1D``: R gives the value at the index its I input gives (a wired variable, or the last
  ``=`` sent to I); values are the ``init`` children: the corpus's lists.
* ``ftProDataOprt`` ``+ - AND OR XOR SHL SHR`` on 16-bit integers; a result beyond −32768…32767 is an
  overflow error (``nooverflowcheck="false"``); SHR of a negative number is an error (logical or
  arithmetic shift cannot be told apart from the corpus, which also has ASR).

Time: elements take none; a Wait takes its milliseconds. Processes run one after the other at the same moment
(each until it waits, or, given a ``seed``, switching at random after any element, as ROBO Pro's scheduler
may), and time moves on to the next wake-up when every process waits. A tick lasts from the moment the first
process (the main program's first Start) wakes until it wakes again after the first Wait it enters.
"""

from __future__ import annotations

import random
import xml.etree.ElementTree as ET
from collections.abc import Callable, Generator, Iterator
from dataclasses import dataclass, field

from tablebot.robopro.nets import InterpreterError, pins_of

MIN, MAX = -32768, 32767
STEP_LIMIT = 200_000  # elements per tick before the program is taken to be stuck
COMPARE: dict[str, Callable[[int, int], bool]] = {
    "0": lambda a, b: a > b, "1": lambda a, b: a >= b, "2": lambda a, b: a == b,
    "3": lambda a, b: a <= b, "4": lambda a, b: a < b, "5": lambda a, b: a != b}


def _int(value: int, what: str) -> int:
    if not MIN <= value <= MAX:
        raise InterpreterError(f"{what}: {value} overflows a 16-bit integer")
    return value


OPERATIONS: dict[str, Callable[[int, int], int]] = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "AND": lambda a, b: a & b, "OR": lambda a, b: a | b,
    "XOR": lambda a, b: a ^ b, "SHL": lambda a, b: a << b, "SHR": lambda a, b: a >> b,
}


class Program:
    """A parsed .rpp: its subprograms (function element and pins), ready to run."""

    def __init__(self, text: str) -> None:
        root = ET.fromstring(text.encode("utf-8"))
        self.functions = {f.get("name", ""): f for f in root.iter("o")
                          if f.get("classname") == "ftProSubroutineFunction"}
        self.pins = {name: pins_of(f) for name, f in self.functions.items()}
        self.main = next(name for name, f in self.functions.items()
                         if any(e.get("classname") == "ftProProcessStart" for e in f.findall("o")))
        self.starts = [e for e in self.functions[self.main].findall("o") if e.get("classname") == "ftProProcessStart"]


@dataclass
class Tick:
    """What the program did in one tick: its variables, motors and lamps when the tick ended, and which
    subprogram exits were taken."""

    variables: dict[str, int]
    motors: dict[int, tuple[str, int]]
    exits: list[tuple[str, str]]
    lamps: dict[int, int] = field(default_factory=dict)


@dataclass
class _Process:
    """A process: its flow (yields None after each element, the milliseconds of each Wait it enters) and the
    time it may run again."""

    flow: Iterator[int | None]
    wake: int = 0


class Run:
    """The program running against scripted inputs: ``digital[n]`` is terminal In's level, ``counts[n]``
    counter Cn's count. ``seed``: switch processes at random after any element (None: each runs until it
    waits, in the order of the Starts)."""

    def __init__(self, program: Program, seed: int | None = None) -> None:
        self.program = program
        self.variables: dict[str, int] = {}
        self.lists: dict[str, list[int]] = {}
        self.index: dict[str, int] = {}
        self.motors: dict[int, tuple[str, int]] = {}
        self.lamps: dict[int, int] = {}
        self.digital: dict[int, int] = {}
        self.counts: dict[int, int] = {}
        self.exits: list[tuple[str, str]] = []
        self.steps = 0
        self.time = 0  # ms
        self._memo: dict[tuple, object] = {}  # per element and pin: what the wiring says, worked out once
        self._rng = None if seed is None else random.Random(seed)
        self._processes = [_Process(self._process(start)) for start in program.starts]

    def tick(self, digital: dict[int, int], counts: dict[int, int]) -> Tick:
        """Set the inputs, run every process to the end of the tick, and report."""
        self.digital, self.counts = dict(digital), dict(counts)
        self.exits, self.steps = [], 0
        first, end = self._processes[0], None
        while True:
            runnable = [p for p in self._processes if p.wake <= self.time]
            if not runnable:
                wake = min(p.wake for p in self._processes)
                if end is not None and wake >= end:
                    self.time = end
                    break
                self.time = wake
                continue
            process = runnable[0] if self._rng is None else self._rng.choice(runnable)
            waited = self._advance(process)
            if waited is not None and process is first and end is None:
                end = process.wake
        return Tick(dict(self.variables), dict(self.motors), list(self.exits), dict(self.lamps))

    def _advance(self, process: _Process) -> int | None:
        """Run ``process`` until it waits (the milliseconds), or, switching at random, one element (None)."""
        while True:
            waited = next(process.flow)
            if waited is not None:
                process.wake = self.time + waited
                return waited
            if self._rng is not None:
                return None

    # --- flow -------------------------------------------------------------------------------------

    def _process(self, start: ET.Element) -> Iterator[int | None]:
        yield from self._run(self.program.main, start)
        raise InterpreterError("a process of the main program ended")

    def _run(self, sub: str, element: ET.Element) -> Generator[int | None, None, str | None]:
        """Run ``sub`` from ``element`` until a FlowOut (whose uniqueID is the generator's value)."""
        pins = self.program.pins[sub]
        entered: ET.Element | None = None  # the flow input the flow came in by (a call's names the entry)
        switching = self._rng is not None
        while True:
            if switching:  # a chance for another process after every element
                yield None
            self.steps += 1
            if self.steps > STEP_LIMIT:
                raise InterpreterError(f"no Wait within {STEP_LIMIT} elements: the program is stuck in {sub}")
            kind = element.get("classname")
            if kind == "ftProSubroutineFlowOut":
                self.exits.append((sub, element.get("name", "")))
                return element.get("uniqueID")
            if kind == "ftProProcessStop":
                raise InterpreterError("the program stopped")
            out = yield from self._do(sub, element, entered)
            nxt = pins.next_flow.get(out)
            if nxt is None:
                raise InterpreterError(f"{sub}: the flow leaves {kind} by an unwired output")
            element, entered = pins.owner[nxt], pins.pin[nxt]

    def _outputs(self, element: ET.Element) -> dict[str, str]:
        """Flow output pin id by pin name (and by pin id as text)."""
        key = ("outs", id(element))
        if key in self._memo:
            return self._memo[key]  # type: ignore[return-value]
        found: dict[str, str] = {}
        self._memo[key] = found
        for p in element.findall("o"):
            if p.get("pinclass") == "flowobjectoutput":
                found[p.get("name", "")] = p.get("id", "")
                found["#" + p.get("pinid", "")] = p.get("id", "")
        return found

    def _do(self, sub: str, element: ET.Element, entered: ET.Element | None) -> Generator[int | None, None, str]:
        kind = element.get("classname")
        outs = self._outputs(element)
        if kind in ("ftProProcessStart", "ftProSubroutineFlowIn"):
            return outs["#0"]
        if kind == "ftProFlowDelay":
            yield int(element.get("value", "0")) * 10 ** int(element.get("scale", "0"))
            return outs["#0"]
        if kind == "ftProFlowIf":
            a = self._input(sub, element, "A")
            operation = element.get("operation", "")
            if operation == "0" and a < 0:
                raise InterpreterError("a branch with operation 0 on a negative value: '> 0' or '≠ 0'?")
            test = COMPARE.get(operation)
            if test is None or element.get("style") != "1":
                raise InterpreterError(f"unknown branch operation {operation!r}")
            return outs["#0" if test(a, int(element.get("value", "0"))) else "#1"]
        if kind == "ftProFlowCmpr2":
            a, b = self._input(sub, element, "A"), self._input(sub, element, "B")
            return outs["<" if a < b else "=" if a == b else ">"]
        if kind == "ftProDataMssg":
            self._send(sub, element)
            return outs["#0"]
        if kind == "ftProSubroutineRef":
            assert entered is not None
            return (yield from self._call(sub, element, entered, outs))
        raise InterpreterError(f"{sub}: element {kind} is not one this interpreter runs")

    def _call(self, sub: str, ref: ET.Element, entered: ET.Element,
              outs: dict[str, str]) -> Generator[int | None, None, str]:
        name = ref.get("name", "")
        target = self.program.functions.get(name)
        if target is None:
            raise InterpreterError(f"{sub} calls {name!r}, which the program does not have")
        entry = next((e for e in target.findall("o") if e.get("classname") == "ftProSubroutineFlowIn"
                      and e.get("uniqueID") == entered.get("pinid")), None)
        if entry is None:
            raise InterpreterError(f"{name} has no entry with uniqueID {entered.get('pinid')}")
        unique = yield from self._run(name, entry)
        return outs["#" + str(unique)]

    # --- data -------------------------------------------------------------------------------------

    def _data_pin(self, element: ET.Element, name: str | None, pinclass: str) -> ET.Element | None:
        key = ("pin", id(element), name, pinclass)
        if key not in self._memo:
            self._memo[key] = next((p for p in element.findall("o") if p.get("pinclass") == pinclass
                                    and (name is None or p.get("name") == name)), None)
        return self._memo[key]  # type: ignore[return-value]

    def _input(self, sub: str, element: ET.Element, name: str | None) -> int:
        pin = self._data_pin(element, name, "dataobjectinput")
        if pin is None:
            raise InterpreterError(f"{element.get('classname')} has no data input {name!r}")
        return self._net_value(sub, pin.get("id", ""))

    def _net_value(self, sub: str, pin_id: str) -> int:
        return self._reader(sub, pin_id)()

    def _reader(self, sub: str, pin_id: str) -> Callable[[], int]:
        """A function giving the value at data input ``pin_id`` now, built once from the wiring."""
        key = ("reader", sub, pin_id)
        if key not in self._memo:
            pins = self.program.pins[sub]
            sources = [p for p in pins.members.get(pins.net.get(pin_id, -1), ())
                       if pins.pin[p].get("pinclass") == "dataobjectoutput"]
            if len(sources) != 1:
                raise InterpreterError(f"{sub}: a data input has {len(sources)} sources")
            self._memo[key] = self._source(sub, sources[0])
        return self._memo[key]  # type: ignore[return-value]

    def _source(self, sub: str, pin_id: str) -> Callable[[], int]:
        """A function giving the value output ``pin_id`` gives now."""
        pins = self.program.pins[sub]
        element, pin = pins.owner[pin_id], pins.pin[pin_id]
        kind = element.get("classname")
        if kind == "ftProDataVariable":
            name, init = element.get("name", ""), int(element.get("init", "0"))
            return lambda: self.variables.setdefault(name, init)
        if kind == "ftProDataConst":
            value = int(element.get("value", "0"))
            return lambda: value
        if kind == "ftProDataIn":
            code = int(element.get("input", "0"))
            if 160 <= code <= 167:
                return lambda: self.digital.get(code - 159, 0)
            if 176 <= code <= 179:
                return lambda: self.counts.get(code - 175, 0)
            raise InterpreterError(f"input {code} is not one this interpreter knows")
        if kind == "ftProDataOprt":
            return self._operator(sub, element)
        if kind == "ftProDataArray1D" and pin.get("pinid") == "2":
            def read() -> int:
                values, index = self._list(element), self._index(sub, element)
                if not 0 <= index < len(values):
                    raise InterpreterError(f"list {element.get('name')}: index {index} outside 0..{len(values) - 1}")
                return values[index]
            return read
        raise InterpreterError(f"{kind} gives no value this interpreter knows")

    def _operator(self, sub: str, element: ET.Element) -> Callable[[], int]:
        operation = element.get("operation", "")
        if operation not in OPERATIONS or element.get("N") != "2":
            raise InterpreterError(f"operator {operation!r} is not one this interpreter runs")
        pin_a, pin_b = (self._data_pin(element, n, "dataobjectinput") for n in ("A", "B"))
        assert pin_a is not None and pin_b is not None
        a_of, b_of = self._reader(sub, pin_a.get("id", "")), self._reader(sub, pin_b.get("id", ""))
        apply = OPERATIONS[operation]

        def compute() -> int:
            a, b = a_of(), b_of()
            if operation in ("SHR", "SHL") and (a < 0 or b < 0):
                raise InterpreterError(f"{operation} of {a} by {b}: a negative shift is ambiguous here")
            return _int(apply(a, b), f"{a} {operation} {b}")
        return compute

    def _list(self, element: ET.Element) -> list[int]:
        name = element.get("globalname") or element.get("name") or ""
        if name not in self.lists:
            self.lists[name] = [int(i.get("value", "0")) for i in element.findall("init")]
        return self.lists[name]

    def _index(self, sub: str, element: ET.Element) -> int:
        key = ("index", id(element))
        if key not in self._memo:
            pin = next(p for p in element.findall("o") if p.get("pinclass") == "dataobjectinput"
                       and p.get("pinid") == "1")
            pins = self.program.pins[sub]
            wired = [p for p in pins.members.get(pins.net.get(pin.get("id", ""), -1), ())
                     if pins.pin[p].get("pinclass") == "dataobjectoutput"
                     and pins.owner[p].get("classname") != "ftProDataMssg"]
            self._memo[key] = pin.get("id", "") if wired else None
        wired_pin = self._memo[key]
        if wired_pin is not None:
            return self._net_value(sub, wired_pin)  # type: ignore[arg-type]
        return self.index.get(element.get("name", ""), 0)

    def _send(self, sub: str, message: ET.Element) -> None:
        command = message.get("command", "")
        data_in = self._data_pin(message, None, "dataobjectinput")
        value = self._net_value(sub, data_in.get("id", "")) if data_in is not None and data_in.get("resolveid") \
            else int(message.get("value", "0"))
        key = ("targets", id(message))
        pins = self.program.pins[sub]
        if key not in self._memo:
            out = self._data_pin(message, None, "dataobjectoutput")
            assert out is not None
            net = pins.members.get(pins.net.get(out.get("id", ""), -1), ())
            self._memo[key] = [(pins.owner[t], pins.pin[t]) for t in net
                               if pins.pin[t].get("pinclass") == "dataobjectinput"]
        for element, pin in self._memo[key]:  # type: ignore[attr-defined]
            self._receive(element, pin, command, value)

    def _receive(self, element: ET.Element, pin: ET.Element, command: str, value: int) -> None:
        kind = element.get("classname")
        if kind == "ftProDataVariable":
            name = element.get("name", "")
            old = self.variables.setdefault(name, int(element.get("init", "0")))
            new = {"=": value, "+": old + value, "-": old - value}.get(command)
            if new is None:
                raise InterpreterError(f"command {command!r} sent to variable {name}")
            self.variables[name] = _int(new, f"variable {name}")
        elif kind == "ftProDataOutDual":
            if command not in ("cw", "ccw", "Stop"):
                raise InterpreterError(f"command {command!r} sent to a motor")
            speed = 0 if command == "Stop" else value
            if not 0 <= speed <= 8:
                raise InterpreterError(f"motor speed {speed} outside 0..8")
            self.motors[int(element.get("output", "0")) + 1] = (command, speed)
        elif kind == "ftProDataOutSngl":
            if command not in ("On", "Off") or (command == "On" and not 0 <= value <= 8):
                raise InterpreterError(f"command {command} {value} sent to a lamp")
            self.lamps[int(element.get("output", "0")) + 1] = value if command == "On" else 0
        elif kind == "ftProDataArray1D" and pin.get("pinid") == "1" and command == "=":
            self.index[element.get("name", "")] = value
        else:
            raise InterpreterError(f"command {command!r} sent to {kind}, which this interpreter does not take")
