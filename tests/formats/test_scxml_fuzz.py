"""Whatever is done to an exported statechart, import answers with the tables or a located error, never a traceback:
SCXML text cut, with characters dropped, doubled or replaced (random places), and XState configs with a random
value anywhere replaced by another JSON value (hypothesis)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tablebot.diagnostics import TableBotError
from tablebot.formats.statecharts.read_scxml import read_scxml
from tablebot.formats.statecharts.read_xstate import read_xstate
from tablebot.formats.statecharts.scxml import export_scxml
from tablebot.formats.statecharts.xstate import export_xstate
from tablebot.formats.table_read import load_table
from tablebot.loading import Loaded

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
TABLE = load_table(EXAMPLES / "bumberbot-counters" / "table.csv")
SCXML = export_scxml([TABLE])
CONFIG = json.loads(export_xstate([TABLE]))
LIGHTS = Loaded.open(EXAMPLES / "bumberbot-lights").tables
assert LIGHTS is not None
#: Two tables with group rows (their group and index are written for them alone) and cross-table events.
SEVERAL = json.loads(export_xstate(LIGHTS.tables))
EDITS = st.lists(
    st.tuples(
        st.integers(0, len(SCXML) - 1),
        st.sampled_from(["drop", "double", "put"]),
        st.sampled_from(list('<>/="& \n-_x1')) | st.characters(),
    ),
    min_size=1,
    max_size=4,
)
JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-3, 70000) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner, max_size=3),
    max_leaves=6,
)


def _paths(value: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    found = [path]
    if isinstance(value, dict):
        for key, item in value.items():
            found += _paths(item, (*path, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            found += _paths(item, (*path, i))
    return found


PLACES = [(config, path) for config in (CONFIG, SEVERAL) for path in _paths(config)[1:]]


@settings(max_examples=300, deadline=None)
@given(EDITS)
def test_an_edited_scxml_is_read_or_refused_with_a_location(edits: list[tuple[int, str, str]]) -> None:
    text = SCXML
    for at, how, char in sorted(edits, reverse=True):  # from the end, so that each place is still where it was
        if at < len(text):
            text = text[:at] + {"drop": "", "double": text[at] * 2, "put": char}[how] + text[at + 1 :]
    try:
        read_scxml(text, "in.scxml")
    except TableBotError as exc:
        assert all(d.path == "in.scxml" and d.line for d in exc.diagnostics), exc


@settings(max_examples=400, deadline=None)
@given(st.sampled_from(PLACES), JSON)
def test_an_edited_xstate_config_is_read_or_refused_with_its_json_path(
    place: tuple[dict[str, Any], tuple[Any, ...]], value: Any
) -> None:
    original, path = place
    config = json.loads(json.dumps(original))
    holder = config
    for key in path[:-1]:
        holder = holder[key]
    holder[path[-1]] = value
    try:
        read_xstate(json.dumps(config), "in.json")
    except TableBotError as exc:
        assert all(d.message.startswith("$") for d in exc.diagnostics), exc


def test_a_group_rows_index_that_is_no_number_is_refused() -> None:
    """Found by fuzzing: a group row's meta.index of null was a TypeError where the rows were sorted."""
    config = json.loads(json.dumps(SEVERAL))
    transition = config["states"]["drive"]["states"]["drive_s1"]["always"][0]
    assert transition["meta"]["group"] == "seeking"
    transition["meta"]["index"] = None
    with pytest.raises(TableBotError, match=r"\$\.states\.drive\.states\.drive_s1\.always\[0\]\.meta\.index: is null"):
        read_xstate(json.dumps(config), "in.json")
