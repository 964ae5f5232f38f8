"""Whatever is done to an exported statechart, import answers with the tables or a located error, never a traceback:
SCXML text cut, with characters dropped, doubled or replaced (random places), and XState configs with a random
value anywhere replaced by another JSON value (hypothesis)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from tablebot.diagnostics import TableBotError
from tablebot.formats.statecharts.read_scxml import read_scxml
from tablebot.formats.statecharts.read_xstate import read_xstate
from tablebot.formats.statecharts.scxml import export_scxml
from tablebot.formats.statecharts.xstate import export_xstate
from tablebot.formats.table_read import load_table

TABLE = load_table(Path(__file__).resolve().parents[1] / "examples" / "bumberbot-counters" / "table.csv")
SCXML = export_scxml([TABLE])
CONFIG = json.loads(export_xstate([TABLE]))
EDITS = st.lists(st.tuples(st.integers(0, len(SCXML) - 1), st.sampled_from(["drop", "double", "put"]),
                           st.sampled_from(list('<>/="& \n-_x1')) | st.characters()), min_size=1, max_size=4)
JSON = st.recursive(st.none() | st.booleans() | st.integers(-3, 70000) | st.text(max_size=8),
                    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner, max_size=3),
                    max_leaves=6)


def _paths(value: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    found = [path]
    if isinstance(value, dict):
        for key, item in value.items():
            found += _paths(item, (*path, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            found += _paths(item, (*path, i))
    return found


PATHS = _paths(CONFIG)


@settings(max_examples=300, deadline=None)
@given(EDITS)
def test_an_edited_scxml_is_read_or_refused_with_a_location(edits: list[tuple[int, str, str]]) -> None:
    text = SCXML
    for at, how, char in sorted(edits, reverse=True):  # from the end, so that each place is still where it was
        if at < len(text):
            text = text[:at] + {"drop": "", "double": text[at] * 2, "put": char}[how] + text[at + 1:]
    try:
        read_scxml(text, "in.scxml")
    except TableBotError as exc:
        assert all(d.path == "in.scxml" and d.line for d in exc.diagnostics), exc


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(PATHS[1:]), JSON)
def test_an_edited_xstate_config_is_read_or_refused_with_its_json_path(path: tuple[Any, ...], value: Any) -> None:
    config = json.loads(json.dumps(CONFIG))
    holder = config
    for key in path[:-1]:
        holder = holder[key]
    holder[path[-1]] = value
    try:
        read_xstate(json.dumps(config), "in.json")
    except TableBotError as exc:
        assert all(d.message.startswith("$") for d in exc.diagnostics), exc
