"""The vocabulary of real ROBO Pro programs, read from a folder of .rpp files: which elements exist, the
attributes each writes (in ROBO Pro's order), the values of every enumerated attribute, the pins each
element carries and the order of a document's header. The generator may write only what this holds.

It is derived, never copied: ``python -m tablebot.testing.rpp_corpus CORPUS_DIR`` writes the facts to
``src/tablebot/testing/rpp_vocabulary.json`` (the committed copy, which tests compare with a fresh reading
of the corpus when it is present). The corpus itself (79 programs from public repositories that state no
licence) stays outside the project: ``$TABLEBOT_RPP_CORPUS`` or ``../shared/rpp-corpus`` beside the
repository.
"""

from __future__ import annotations

import json
import os
import sys
import xml.etree.ElementTree as ET
from collections import defaultdict
from collections.abc import Iterable
from pathlib import Path

from tablebot.testing.rpp_vocabulary import (
    DECIMAL_RE,
    INT_RE,
    INTERFACE_PINS,
    MATRIX_RE,
    TEXT,
    VOCABULARY,
    key,
    pin_signature,
)

REPO = Path(__file__).resolve().parents[3]

#: Attributes whose values are a program's data, not its vocabulary: positions, ids, names, texts,
#: numbers the user typed. They are recorded by kind (an integer range, a decimal, a matrix, text);
#: every other attribute is an enumeration and may only take a value some real program has.
FREE: dict[str, frozenset[str]] = {
    "*": frozenset(
        {
            "id",
            "resolveid",
            "transform",
            "name",
            "text",
            "caret",
            "documentation",
            "points",
            "x",
            "y",
            "uniqueID",
            "uniqueIDs",
            "version",
            "refid",
            "libname",
            "funcname",
            "panelname",
            "panelitem",
            "label",
        }
    ),
    "ftProDataArray1D": frozenset({"globalname", "N", "savecsvcolumnname"}),
    "ftProDataConst": frozenset({"value", "value0", "value1", "value2"}),
    "ftProDataMssg": frozenset({"value", "value0", "value1", "value2", "valuetext"}),
    "ftProDataVariable": frozenset({"init", "init0", "init1", "init2"}),
    "ftProFlowIf": frozenset({"value", "value0", "value1", "value2"}),
    "ftProFlowDelay": frozenset({"value", "uservalue"}),
    "wxDocviewStringProperty": frozenset({"value"}),
    "wxCanvasRect": frozenset({"width", "height"}),
    "init": frozenset({"value", "value0", "value1", "value2"}),
    "title": frozenset({TEXT}),
}
PIN_CLASSES = frozenset({"ftProObjectPin", "wxCanvasPin"})


def corpus_dir() -> Path | None:
    """The corpus's folder of .rpp files: ``$TABLEBOT_RPP_CORPUS``, else ``shared/rpp-corpus`` beside the
    repository (``../shared``; from a worktree, the nearest ancestor that has one); None if absent."""
    given = os.environ.get("TABLEBOT_RPP_CORPUS")
    candidates = [Path(given)] if given else [up / "shared" / "rpp-corpus" for up in REPO.parents]
    for candidate in candidates:
        folder = candidate / "files" if (candidate / "files").is_dir() else candidate
        if folder.is_dir() and any(folder.glob("*.rpp")):
            return folder
    return None


def is_free(kind: str, attribute: str) -> bool:
    return attribute in FREE["*"] or attribute in FREE.get(kind, frozenset())


def value_kind(values: Iterable[str]) -> dict[str, object]:
    """How a free attribute's values look: an integer range, decimals, a translation matrix, or text."""
    values = list(values)
    if all(INT_RE.fullmatch(v) for v in values):
        numbers = [int(v) for v in values]
        return {"kind": "int", "min": min(numbers), "max": max(numbers)}
    if all(DECIMAL_RE.fullmatch(v) for v in values):
        return {"kind": "decimal"}
    if all(MATRIX_RE.fullmatch(v) for v in values):
        return {"kind": "matrix"}
    return {"kind": "text"}


class Reader:
    """Accumulates the facts of many documents (one pass each, by iterparse)."""

    def __init__(self) -> None:
        self.files = 0
        self.headers: set[tuple[str, ...]] = set()
        self.orders: dict[str, set[tuple[str, ...]]] = defaultdict(set)
        self.values: dict[str, dict[str, set[str]]] = defaultdict(lambda: defaultdict(set))
        self.pins: dict[str, set[tuple[tuple[str, ...], ...]]] = defaultdict(set)
        self.children: dict[str, set[str]] = defaultdict(set)
        self.declarations: set[str] = set()

    def read(self, path: Path) -> None:
        data = path.read_bytes()
        self.declarations.add(data.split(b"\n", 1)[0].strip().decode("ascii"))
        stack: list[ET.Element] = []
        for event, element in ET.iterparse(path, events=("start", "end")):
            if event == "start":
                stack.append(element)
                continue
            stack.pop()
            self._element(element, stack[-1] if stack else None)
            del element[:]  # its children are read; it keeps its own attributes for its parent
        self.files += 1

    def _element(self, element: ET.Element, parent: ET.Element | None) -> None:
        kind = key(element)
        attributes = element.attrib
        self.orders[kind].add(tuple(attributes))
        for name, value in attributes.items():
            self.values[kind][name].add(value)
        if element.tag != "o" and element.text and element.text.strip():
            self.values[kind][TEXT].add(element.text.strip())
        if parent is not None:
            self.children[key(parent)].add(kind)
        pins = tuple(tuple(pin_signature(kind, c)) for c in element if c.get("classname") == "ftProObjectPin")
        if kind in INTERFACE_PINS:  # any number of author-named pins: each pin on its own
            self.pins[kind].update((pin,) for pin in pins)
        elif pins or kind.startswith("ftPro"):
            self.pins[kind].add(pins)
        if parent is None:
            self.headers.add(tuple(key(c) for c in element))

    def vocabulary(self) -> dict[str, object]:
        elements: dict[str, object] = {}
        for kind in sorted(self.orders):
            attributes = {}
            for name, values in sorted(self.values[kind].items()):
                attributes[name] = value_kind(values) if is_free(kind, name) else {"values": sorted(values)}
            entry: dict[str, object] = {
                "attribute_orders": sorted(list(order) for order in self.orders[kind]),
                "attributes": attributes,
                "children": sorted(self.children.get(kind, ())),
            }
            if kind in self.pins and kind not in PIN_CLASSES:
                entry["pins"] = sorted([list(p) for p in sig] for sig in self.pins[kind])
            elements[kind] = entry
        return {
            "files": self.files,
            "declarations": sorted(self.declarations),
            "headers": sorted(list(h) for h in self.headers),
            "elements": elements,
        }


def read_corpus(folder: Path) -> dict[str, object]:
    """The vocabulary of every .rpp file in ``folder``."""
    reader = Reader()
    for path in sorted(folder.glob("*.rpp")):
        reader.read(path)
    return reader.vocabulary()


def dump(vocabulary: dict[str, object]) -> str:
    """JSON with one element per line, so that a change in the corpus shows as a readable diff."""

    def compact(value: object) -> str:
        return json.dumps(value, ensure_ascii=False, sort_keys=True, separators=(",", ":"))

    elements = vocabulary["elements"]
    assert isinstance(elements, dict)
    head = {k: v for k, v in vocabulary.items() if k != "elements"}
    lines = [f" {compact(k)}: {compact(v)}," for k, v in sorted(head.items())]
    body = ",\n".join(f"  {compact(k)}: {compact(v)}" for k, v in sorted(elements.items()))
    return "{\n" + "\n".join(lines) + '\n "elements": {\n' + body + "\n }\n}\n"


def main(argv: list[str]) -> int:
    folder = Path(argv[0]) if argv else corpus_dir()
    if folder is None or not folder.is_dir():
        print("usage: python -m tablebot.testing.rpp_corpus CORPUS_DIR (a folder of .rpp files)", file=sys.stderr)
        return 2
    folder = folder / "files" if (folder / "files").is_dir() else folder
    text = dump(read_corpus(folder))
    tmp = VOCABULARY.with_suffix(".json.tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(VOCABULARY)
    print(f"wrote {VOCABULARY} from {folder}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
