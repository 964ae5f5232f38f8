"""Building blocks of the loaders' fuzzing (tests/formats/test_fuzz_loaders.py): the settings (``TABLEBOT_FUZZ``:
``ci``, ``long`` or a number of examples), strategies for TOML documents, CSV text and awkward values, bytes
mangled as files arrive, and the checks that only a located TableBotError, and through the CLI no internal
error, ever escapes."""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from tablebot.cli import app
from tablebot.diagnostics import TableBotError

_MODE = os.environ.get("TABLEBOT_FUZZ", "ci")
_LONG = _MODE != "ci"
_EXAMPLES = int(_MODE) if _MODE.isdigit() else 1500 if _LONG else 60
FUZZ = settings(
    max_examples=_EXAMPLES, derandomize=not _LONG, deadline=None, database=None, suppress_health_check=list(HealthCheck)
)
runner = CliRunner()

HUGE = st.sampled_from([2**63, -(2**63) - 1, 10**400, 65536, -1, 0, 1, 7, 8, 9, 32767, 1e308, 1e-308])
WEIRD_TEXT = st.sampled_from(
    [
        "",
        " ",
        "\x00",
        "²",
        "٣",
        "1e9",
        "-0",
        "+1",
        "1.5",
        "=",
        "keep",
        "NaN",
        "inf",
        '"',
        '""',
        "a,b",
        "a;b",
        "\n",
        "\r",
        "\t",
        "T",
        "state",
        "next",
        "I3",
        "M1",
        "*/",
        "[bold]",
        "\ud800",
        "x" * 1000,
        "1" * 400,
    ]
)
TEXT = st.one_of(WEIRD_TEXT, st.text(max_size=12), HUGE.map(str))


def toml_key(key: str) -> str:
    return json.dumps(key, ensure_ascii=False)


def toml_value(value: Any) -> str:
    """A TOML value (inline tables and arrays nest; JSON's string escapes are TOML's)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return {"inf": "inf", "-inf": "-inf", "nan": "nan"}.get(repr(value), repr(value))
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{toml_key(k)} = {toml_value(v)}" for k, v in value.items()) + "}"


SCALAR = st.one_of(st.booleans(), HUGE, st.integers(), st.floats(), TEXT.filter(lambda s: "\ud800" not in s))
VALUE = st.recursive(
    SCALAR,
    lambda inner: st.one_of(st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=4), inner, max_size=3)),
    max_leaves=8,
)


def document(keys: list[str], sections: dict[str, list[str]]) -> st.SearchStrategy[str]:
    """TOML text whose keys are (mostly) the loader's own, each with a value of any type."""

    def key(known: list[str]) -> st.SearchStrategy[str]:
        return st.one_of(st.sampled_from(known), st.text(min_size=1, max_size=5))

    top = st.dictionaries(key(keys), VALUE, max_size=6)
    parts = st.dictionaries(
        st.sampled_from(list(sections)),
        st.one_of(
            st.dictionaries(
                st.text(max_size=1).flatmap(lambda _: key([k for ks in sections.values() for k in ks])),
                VALUE,
                max_size=5,
            ),
            VALUE,
        ),
        max_size=4,
    )

    def render(values: tuple[dict, dict]) -> str:
        head, body = values
        lines = [f"{toml_key(k)} = {toml_value(v)}" for k, v in head.items() if k not in body]
        for name, table in body.items():
            if isinstance(table, dict):
                lines.append(f"[{toml_key(name)}]")
                lines += [f"{toml_key(k)} = {toml_value(v)}" for k, v in table.items()]
            else:
                lines.insert(0, f"{toml_key(name)} = {toml_value(table)}")
        return "\n".join(lines) + "\n"

    return st.tuples(top, parts).map(render)


def deep(text: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    """Also deep nesting (past any recursion limit) and raw bytes spliced in."""
    nested = st.integers(30, 600).map(lambda n: f"x = {'[' * n}1{']' * n}\n")
    return st.one_of(text, text, nested, st.tuples(text, nested).map("".join))


def mangle(text: str, data: st.DataObject) -> bytes:
    """The text's UTF-8 bytes, sometimes with a NUL, a Latin-1 byte or a cut in the middle."""
    raw = text.encode("utf-8", "surrogatepass")
    how = data.draw(st.sampled_from(["keep", "keep", "nul", "latin1", "cut", "bom16"]))
    at = data.draw(st.integers(0, len(raw)))
    return {
        "keep": raw,
        "nul": raw[:at] + b"\x00" + raw[at:],
        "latin1": raw[:at] + b"\xe9\xff" + raw[at:],
        "cut": raw[:at],
        "bom16": b"\xff\xfe" + raw,
    }[how]


def csv_text(header: list[str]) -> st.SearchStrategy[str]:
    cells = st.one_of(st.sampled_from(["", "1", "0", "3", "-3", "=", "7"]), TEXT)
    row = st.lists(cells, min_size=0, max_size=len(header) + 2)
    head = st.one_of(
        st.just(header),
        st.permutations(header),
        st.lists(st.one_of(st.sampled_from(header), TEXT), max_size=len(header) + 2),
    )
    sep = st.sampled_from([",", ";", "\t"])

    def render(values: tuple[list[str], list[list[str]], str, bool]) -> str:
        first, rows, delimiter, quote = values

        def line(cells: list[str]) -> str:
            return delimiter.join(f'"{c}"' if quote and '"' not in c else c for c in cells)

        return "\n".join([line(first), *(line(r) for r in rows)]) + "\n"

    return st.tuples(head, st.lists(row, max_size=6), sep, st.booleans()).map(render)


def expect_located(load: Callable[[], Any]) -> None:
    """The load succeeds or fails with located TableBotErrors; anything else is a bug."""
    try:
        load()
    except TableBotError as exc:
        assert exc.diagnostics and all(d.path and d.message for d in exc.diagnostics)


def in_folder(files: dict[str, bytes], run: Callable[[Path], Any]) -> None:
    folder = Path(tempfile.mkdtemp(prefix="tb-fuzz-"))
    try:
        for name, data in files.items():
            (folder / name).write_bytes(data)
        run(folder)
    finally:
        shutil.rmtree(folder)


def no_internal_error(*args: object) -> None:
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    assert result.exit_code in (0, 1, 2), result.output
