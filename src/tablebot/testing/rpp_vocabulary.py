"""What a ROBO Pro program may contain, as real programs show it (``rpp_vocabulary.json``, derived from the
corpus by :mod:`tablebot.testing.rpp_corpus`), and the check of a document against it and against the
invariants every real program keeps: unique ids, and every ``resolveid`` pointing back. The tests hold the
generated program to it; the generator itself never reads it."""

from __future__ import annotations

import copy
import json
import re
import xml.etree.ElementTree as ET
from functools import cache
from pathlib import Path
from typing import Any

VOCABULARY = Path(__file__).with_name("rpp_vocabulary.json")
TEXT = "#text"
INT_RE = re.compile(r"-?\d+")
DECIMAL_RE = re.compile(r"-?\d+(\.\d+)?")
MATRIX_RE = re.compile(r"matrix\( 1 0 0 1 -?\d+(\.\d+)? -?\d+(\.\d+)? \)")
INTERFACE_PINS = frozenset(
    {
        "ftProSubroutineRef",
        "ftProSubroutineSymbol",
        "ftProSubroutineFlowIn",
        "ftProSubroutineFlowOut",
        "ftProSubroutineDataIn",
        "ftProSubroutineDataOut",
    }
)


#: Numbering rules real programs show in part, and the generator extends: the corpus has inputs I1–I4 as
#: ``ftProDataIn input`` 160–163 (the TeachIn robots) and the counts of counters C1 and C3 as 176 and 178 (its
#: ROBO TX variant's encoder motors); the same series give I5–I8 (164–167) and C2, C4 (177, 179). Real
#: programs outside the corpus agree: olagino/roproparser's test/Teleskop.rpp (GitHub) reads I5–I8 as
#: 164–167 in the same digital mode.
SERIES: dict[tuple[str, str], tuple[range, ...]] = {("ftProDataIn", "input"): (range(160, 168), range(176, 180))}


_FLAGS = " selectable visible draggable shadow filled snap"
#: What the generator writes that no program of the corpus shows, as real programs outside it write it: ROBO
#: Pro's lamp output (a single output O1–O8, ``output`` 0–7, with one data input as the motor output's) and the
#: ``On``/``Off`` commands sent to it. olagino/roproparser (GitHub) keeps such programs as test data:
#: test/regal_test.rpp (ROBO Pro 4.2.4, lamps on O5–O8 driven by ``On`` 8 and ``Off``) and test/multi.rpp
#: (4.4.4, two processes flashing two lamps).
BEYOND_CORPUS: dict[str, Any] = {
    "ftProDataOutSngl": {
        "attribute_orders": [
            ["classname", "id", "flags", "hitflags", "transform", "output", "module", "image", "resolution"]
        ],
        "attributes": {
            "classname": {"values": ["ftProDataOutSngl"]},
            "id": {"kind": "int"},
            "flags": {"values": [_FLAGS]},
            "hitflags": {"values": [" fill visible"]},
            "transform": {"kind": "matrix"},
            "output": {"values": [str(n) for n in range(8)]},
            "module": {"values": ["IF1"]},
            "image": {"values": ["1"]},
            "resolution": {"values": ["0"]},
        },
        "children": ["ftProObjectPin"],
        "pins": [[["", "dataobjectinput", "0", "matrix( 1 0 0 1 -8 0 )", "4", "4", ""]]],
    },
}
BEYOND_COMMANDS = ("On", "Off")


@cache
def vocabulary() -> dict[str, Any]:
    return json.loads(VOCABULARY.read_text(encoding="utf-8"))


def with_beyond(known: dict[str, Any]) -> dict[str, Any]:
    """``known`` (a corpus's vocabulary) with :data:`BEYOND_CORPUS`: the lamp output where subprograms hold
    elements, and its commands."""
    merged = copy.deepcopy(known)
    elements = merged["elements"]
    elements.update(copy.deepcopy(BEYOND_CORPUS))
    elements["ftProSubroutineFunction"]["children"] = sorted(
        {*elements["ftProSubroutineFunction"]["children"], *BEYOND_CORPUS}
    )
    command = elements["ftProDataMssg"]["attributes"]["command"]
    command["values"] = sorted({*command["values"], *BEYOND_COMMANDS})
    return merged


def key(element: ET.Element) -> str:
    """An element's name in the vocabulary: its classname for ``<o>``, else its tag."""
    return element.get("classname", element.tag) if element.tag == "o" else element.tag


def pin_signature(kind: str, pin: ET.Element) -> list[str]:
    size = [pin.get("width", ""), pin.get("height", ""), pin.get("orientation", "")]
    if kind in INTERFACE_PINS:
        return [pin.get("pinclass", ""), *size]
    return [pin.get("name", ""), pin.get("pinclass", ""), pin.get("pinid", ""), pin.get("transform", ""), *size]


def _fits(rule: dict[str, Any], value: str, series: tuple[range, ...] = ()) -> bool:
    if any(INT_RE.fullmatch(value) and int(value) in numbers for numbers in series):
        return True
    if "values" in rule:
        return value in rule["values"]
    kind = rule["kind"]
    if kind == "int":  # the observed range is information: a program's own numbers go beyond it
        return bool(INT_RE.fullmatch(value))
    if kind == "decimal":
        return bool(DECIMAL_RE.fullmatch(value))
    if kind == "matrix":
        return bool(MATRIX_RE.fullmatch(value))
    return True


def _element_problems(
    element: ET.Element, parent: ET.Element | None, where: str, elements: dict[str, Any]
) -> list[str]:
    kind = key(element)
    known = elements.get(kind)
    if known is None:
        return [f"{where}: element {kind!r} appears in no real program"]
    problems = []
    if list(element.attrib) not in known["attribute_orders"]:
        problems.append(
            f"{where}: {kind} with attributes {list(element.attrib)} in this order: no real program writes them so"
        )
    values = dict(element.attrib)
    if element.tag != "o" and element.text and element.text.strip():
        values[TEXT] = element.text.strip()
    for name, value in values.items():
        rule = known["attributes"].get(name)
        if rule is None or not _fits(rule, value, SERIES.get((kind, name), ())):
            problems.append(f"{where}: {kind} {name}={value!r} is not a value real programs use")
    holder = elements.get(key(parent)) if parent is not None else None
    if parent is not None and holder is not None and kind not in holder["children"]:
        problems.append(f"{where}: {kind} inside {key(parent)}: no real program nests them so")
    pins = [pin_signature(kind, c) for c in element if c.get("classname") == "ftProObjectPin"]
    allowed = known.get("pins")
    if allowed is not None:
        if kind in INTERFACE_PINS:
            bad = [pin for pin in pins if [pin] not in allowed]
            problems += [f"{where}: {kind} pin {pin} is not a pin real programs use" for pin in bad]
        elif pins not in allowed:
            problems.append(f"{where}: {kind} with pins {pins}: no real program's {kind} has them")
    return problems


def problems(text: str, known: dict[str, Any] | None = None) -> list[str]:
    """Everything in an .rpp document that real programs do not show (``known``: a vocabulary, by default
    the committed one; with :data:`BEYOND_CORPUS`), and every broken invariant."""
    known = with_beyond(known or vocabulary())
    found: list[str] = []
    first_line = text.split("\n", 1)[0].strip()
    if first_line not in known["declarations"]:
        found.append(f"line 1: XML declaration {first_line!r} is not the one real programs have")
    root = ET.fromstring(text.encode("utf-8"))
    header = [key(c) for c in root]
    if header not in known["headers"]:
        found.append(f"document header {header} differs from every real program's")
    parents = {child: parent for parent in root.iter() for child in parent}
    for number, element in enumerate(root.iter()):
        where = f"element {number} ({element.get('name') or element.get('id') or key(element)})"
        found += _element_problems(element, parents.get(element), where, known["elements"])
    return found + invariant_problems(root)


def invariant_problems(root: ET.Element) -> list[str]:
    """Ids are unique and every ``resolveid`` names an element whose own ``resolveid`` names it back."""
    found = []
    by_id: dict[str, ET.Element] = {}
    for element in root.iter():
        ident = element.get("id")
        if ident is None:
            continue
        if ident in by_id:
            found.append(f"id {ident} is used twice")
        by_id[ident] = element
    for element in root.iter():
        target = element.get("resolveid")
        if target is None:
            continue
        other = by_id.get(target)
        if other is None:
            found.append(f"resolveid {target} of {element.get('id')} names no element")
        elif other.get("resolveid") != element.get("id"):
            found.append(f"resolveid {target} of {element.get('id')} does not point back")
    return found
