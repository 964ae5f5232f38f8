"""The data side of a ROBO Pro program as :mod:`tablebot.robopro.interpret` runs it: what a data wire carries
when it is read (variables, constants, inputs and counters, operators, lists) and what a message does where it
arrives (variables, motors, lamps, a list's index). The flow, which element runs next and when, is the
interpreter's; the module docstring there says what each element does and where that comes from."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable

from tablebot.robopro.nets import InterpreterError, Pins

MIN, MAX = -32768, 32767


def _int(value: int, what: str) -> int:
    if not MIN <= value <= MAX:
        raise InterpreterError(f"{what}: {value} overflows a 16-bit integer")
    return value


OPERATIONS: dict[str, Callable[[int, int], int]] = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "AND": lambda a, b: a & b,
    "OR": lambda a, b: a | b,
    "XOR": lambda a, b: a ^ b,
    "SHL": lambda a, b: a << b,
    "SHR": lambda a, b: a >> b,
}


class Dataflow:
    """The values of a running program (variables, lists and their indexes, motors, lamps) and the scripted
    inputs (``digital[n]``: terminal In's level; ``counts[n]``: counter Cn's count), read and set through the
    wiring of each subprogram's ``pins``."""

    def __init__(self, pins: dict[str, Pins]) -> None:
        self.pins = pins
        self.variables: dict[str, int] = {}
        self.lists: dict[str, list[int]] = {}
        self.index: dict[str, int] = {}
        self.motors: dict[int, tuple[str, int]] = {}
        self.lamps: dict[int, int] = {}
        self.digital: dict[int, int] = {}
        self.counts: dict[int, int] = {}
        self._memo: dict[tuple, object] = {}  # per element and pin: what the wiring says, worked out once

    def _data_pin(self, element: ET.Element, name: str | None, pinclass: str) -> ET.Element | None:
        key = ("pin", id(element), name, pinclass)
        if key not in self._memo:
            self._memo[key] = next(
                (
                    p
                    for p in element.findall("o")
                    if p.get("pinclass") == pinclass and (name is None or p.get("name") == name)
                ),
                None,
            )
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
            pins = self.pins[sub]
            sources = [
                p
                for p in pins.members.get(pins.net.get(pin_id, -1), ())
                if pins.pin[p].get("pinclass") == "dataobjectoutput"
            ]
            if len(sources) != 1:
                raise InterpreterError(f"{sub}: a data input has {len(sources)} sources")
            self._memo[key] = self._source(sub, sources[0])
        return self._memo[key]  # type: ignore[return-value]

    def _source(self, sub: str, pin_id: str) -> Callable[[], int]:
        """A function giving the value output ``pin_id`` gives now."""
        pins = self.pins[sub]
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
            pin = next(
                p for p in element.findall("o") if p.get("pinclass") == "dataobjectinput" and p.get("pinid") == "1"
            )
            pins = self.pins[sub]
            wired = [
                p
                for p in pins.members.get(pins.net.get(pin.get("id", ""), -1), ())
                if pins.pin[p].get("pinclass") == "dataobjectoutput"
                and pins.owner[p].get("classname") != "ftProDataMssg"
            ]
            self._memo[key] = pin.get("id", "") if wired else None
        wired_pin = self._memo[key]
        if wired_pin is not None:
            return self._net_value(sub, wired_pin)  # type: ignore[arg-type]
        return self.index.get(element.get("name", ""), 0)

    def _send(self, sub: str, message: ET.Element) -> None:
        command = message.get("command", "")
        data_in = self._data_pin(message, None, "dataobjectinput")
        value = (
            self._net_value(sub, data_in.get("id", ""))
            if data_in is not None and data_in.get("resolveid")
            else int(message.get("value", "0"))
        )
        key = ("targets", id(message))
        pins = self.pins[sub]
        if key not in self._memo:
            out = self._data_pin(message, None, "dataobjectoutput")
            assert out is not None
            net = pins.members.get(pins.net.get(out.get("id", ""), -1), ())
            self._memo[key] = [
                (pins.owner[t], pins.pin[t]) for t in net if pins.pin[t].get("pinclass") == "dataobjectinput"
            ]
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
