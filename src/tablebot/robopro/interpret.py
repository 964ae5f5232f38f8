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

from tablebot.robopro.dataflow import Dataflow
from tablebot.robopro.nets import InterpreterError, pins_of

STEP_LIMIT = 200_000  # elements per tick before the program is taken to be stuck
COMPARE: dict[str, Callable[[int, int], bool]] = {
    "0": lambda a, b: a > b,
    "1": lambda a, b: a >= b,
    "2": lambda a, b: a == b,
    "3": lambda a, b: a <= b,
    "4": lambda a, b: a < b,
    "5": lambda a, b: a != b,
}


class Program:
    """A parsed .rpp: its subprograms (function element and pins), ready to run."""

    def __init__(self, text: str) -> None:
        root = ET.fromstring(text.encode("utf-8"))
        self.functions = {
            f.get("name", ""): f for f in root.iter("o") if f.get("classname") == "ftProSubroutineFunction"
        }
        self.pins = {name: pins_of(f) for name, f in self.functions.items()}
        self.main = next(
            name
            for name, f in self.functions.items()
            if any(e.get("classname") == "ftProProcessStart" for e in f.findall("o"))
        )
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


class Run(Dataflow):
    """The program running against scripted inputs: ``digital[n]`` is terminal In's level, ``counts[n]``
    counter Cn's count. ``seed``: switch processes at random after any element (None: each runs until it
    waits, in the order of the Starts)."""

    def __init__(self, program: Program, seed: int | None = None) -> None:
        super().__init__(program.pins)
        self.program = program
        self.exits: list[tuple[str, str]] = []
        self.steps = 0
        self.time = 0  # ms
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

    def _call(
        self, sub: str, ref: ET.Element, entered: ET.Element, outs: dict[str, str]
    ) -> Generator[int | None, None, str]:
        name = ref.get("name", "")
        target = self.program.functions.get(name)
        if target is None:
            raise InterpreterError(f"{sub} calls {name!r}, which the program does not have")
        entry = next(
            (
                e
                for e in target.findall("o")
                if e.get("classname") == "ftProSubroutineFlowIn" and e.get("uniqueID") == entered.get("pinid")
            ),
            None,
        )
        if entry is None:
            raise InterpreterError(f"{name} has no entry with uniqueID {entered.get('pinid')}")
        unique = yield from self._run(name, entry)
        return outs["#" + str(unique)]

    # --- data -------------------------------------------------------------------------------------
