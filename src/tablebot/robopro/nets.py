"""How the wires of one ROBO Pro subprogram connect its elements' pins (for the interpreter,
:mod:`tablebot.robopro.interpret`): where each flow output leads, through the ``dynamic`` pins where flows
merge, and which data pins share a net."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field


class InterpreterError(Exception):
    """The program did something this interpreter does not know, or something ambiguous."""


@dataclass
class Pins:
    """Every pin of one subprogram and how the wires connect them."""

    owner: dict[str, ET.Element] = field(default_factory=dict)  # object pin id -> its element
    pin: dict[str, ET.Element] = field(default_factory=dict)  # object pin id -> the pin
    next_flow: dict[str, str] = field(default_factory=dict)  # flow output pin id -> the input it leads to
    net: dict[str, int] = field(default_factory=dict)  # data pin id -> its net
    members: dict[int, list[str]] = field(default_factory=dict)  # net -> data pin ids


def pins_of(function: ET.Element) -> Pins:
    found = Pins()
    wire_pins: dict[str, ET.Element] = {}
    wire_of: dict[str, ET.Element] = {}
    for element in function.findall("o"):
        for child in element.findall("o"):
            if child.get("classname") == "ftProObjectPin":
                found.owner[child.get("id", "")] = element
                found.pin[child.get("id", "")] = child
            elif child.get("classname") == "wxCanvasPin":
                wire_pins[child.get("id", "")] = child
                wire_of[child.get("id", "")] = element

    def end_of(wire: ET.Element) -> ET.Element:
        return next(p for p in wire.findall("o") if p.get("name") == "end")

    def arrive(wire_pin: ET.Element) -> str:
        """The object input a wire ending at ``wire_pin`` reaches (through the wires it joins)."""
        for _ in range(1000):
            target = wire_pin.get("resolveid", "")
            if target in found.pin:
                return target
            joined = wire_pins.get(target)
            if joined is None or joined.get("name") != "dynamic":
                raise InterpreterError(f"flow wire pin {wire_pin.get('id')} leads nowhere")
            wire_pin = end_of(wire_of[target])
        raise InterpreterError("flow wires join in a circle")

    parent: dict[str, str] = {}

    def find(x: str) -> str:
        while parent.get(x, x) != x:
            x = parent[x]
        return x

    for pid, pin in found.pin.items():
        begin = wire_pins.get(pin.get("resolveid", ""))
        if begin is None:
            continue
        wire = wire_of[begin.get("id", "")]
        if pin.get("pinclass") == "flowobjectoutput":  # the flow goes to the wire's other end
            other = (
                end_of(wire)
                if begin.get("name") == "begin"
                else next(p for p in wire.findall("o") if p.get("name") == "begin")
            )
            found.next_flow[pid] = arrive(other)
        elif pin.get("pinclass", "").startswith("data"):
            parent[find(pid)] = find(wire.get("id") or str(id(wire)))
    for wpid, wpin in wire_pins.items():  # dynamic pins tie the joining wire's net to the host's
        if wpin.get("name") == "dynamic" and wire_of[wpid].get("classname") == "ftProDataWire":
            host = wire_of.get(wpin.get("resolveid", ""))
            if host is not None:
                parent[find(wire_of[wpid].get("id") or "")] = find(host.get("id") or "")
    for pid, pin in found.pin.items():
        if pin.get("pinclass", "").startswith("data"):
            root = find(pid)
            number = found.net.setdefault(pid, hash(root))
            found.members.setdefault(number, []).append(pid)
    return found
