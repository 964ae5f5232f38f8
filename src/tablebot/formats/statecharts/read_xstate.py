"""``import --from xstate``: the tables in an XState machine config that ``export --to xstate`` wrote, and nothing
else.

The JSON is read by the standard library (data only); the robot and its rows are read from ``meta`` and the
transitions, the tables are exported again, and the file must be that config, key for key and value for value: the
first place it differs is the error, named by its JSON path (``$.states.s2.always[0].target``), with what tablebot
would have written there.
"""

from __future__ import annotations

import json
from typing import Any

from tablebot.diagnostics import fail
from tablebot.formats.statecharts.chart import chart_of, state_of
from tablebot.formats.statecharts.rebuild import Found, FoundRow, FoundTable, build
from tablebot.formats.statecharts.xstate import FORMAT, xstate_config
from tablebot.i18n import N_
from tablebot.robot import Counter, StateId
from tablebot.table import Table

__all__ = ["read_xstate"]

HINT = N_("import reads what tablebot export --to xstate wrote (machine.json), unchanged")
#: The deepest JSON read (the export nests eight deep).
MAX_DEPTH = 64


class _At:
    """A value of the config and its JSON path, for located errors."""

    def __init__(self, value: Any, path: str, file: str) -> None:
        self.value, self.path, self.file = value, path, file

    def error(self, message: str) -> Exception:
        return fail(self.file, N_("{path}: {message}", path=self.path, message=message), HINT)

    def __getitem__(self, key: str | int) -> _At:
        value = self.value
        if isinstance(key, int):
            if not isinstance(value, list) or not -len(value) <= key < len(value):
                raise self.error(N_("is no list with an item {key}", key=key))
            return _At(value[key], f"{self.path}[{key}]", self.file)
        if not isinstance(value, dict) or key not in value:
            raise self.error(N_("has no key {key!r}", key=key))
        return _At(value[key], f"{self.path}.{key}", self.file)

    def get(self, key: str, default: Any) -> Any:
        return self.value.get(key, default) if isinstance(self.value, dict) else default

    def of(self, kind: type, what: str) -> Any:
        if not isinstance(self.value, kind) or (isinstance(self.value, bool) and kind is not bool):
            raise self.error(N_("is {value}, not {what}", value=json.dumps(self.value)[:60], what=what))
        return self.value

    def items(self) -> list[tuple[str, _At]]:
        return [(k, self[k]) for k in self.of(dict, N_("an object"))]

    def list(self) -> list[_At]:
        return [self[i] for i in range(len(self.of(list, N_("a list"))))]

    def names(self) -> tuple[str, ...]:
        return tuple(item.of(str, N_("a name")) for item in self.list())


def read_xstate(text: str, path: str) -> tuple[Table, ...]:
    """The tables of an XState machine config (the main one first), or a located error."""
    try:
        config = json.loads(text)
    except json.JSONDecodeError as exc:
        raise fail(path, N_("not JSON: {error}", error=exc.msg), HINT, exc.lineno, exc.colno) from None
    except RecursionError:
        raise fail(path, N_("nested too deep"), HINT) from None
    root = _At(config, "$", path)
    tables = build(_found(root), path)
    _same(config, xstate_config(chart_of(tables)), "$", path, 0)
    return tables


def _found(root: _At) -> Found:
    meta = root["meta"]["tablebot"]
    if meta["format"].value != FORMAT:
        raise meta["format"].error(
            N_("is {value!r}: this tablebot reads format {format}", value=meta["format"].value, format=FORMAT)
        )
    counters = tuple(
        Counter(c["name"].of(str, N_("a name")), c["motor"].of(str, N_("a name"))) for c in meta["counters"].list()
    )
    found = Found(
        root["id"].of(str, N_("a name")),
        meta["tickMs"].of(int, N_("a whole number")),
        meta["inputs"].names(),
        meta["motors"].names(),
        meta["lamps"].names(),
        counters,
    )
    tables = meta["tables"].list()
    if not tables:
        raise meta["tables"].error(N_("names no table"))
    several = len(tables) > 1
    for entry in tables:
        name = entry["name"].of(str, N_("a name"))
        prefix = f"{name}_" if several else ""
        holder = root["states"][name] if several else root
        table = FoundTable(
            name,
            entry["events"].names(),
            entry["match"].of(str, N_("a rule")),
            _state(holder["initial"], prefix),
            root["context"][f"{prefix}timer"].of(int, N_("a number")),
            entry["writes"].names(),
        )
        for ident, state in holder["states"].items():
            source = _state(_At(ident, f"{state.path}", state.file), prefix)
            table.rows.extend(_row(t, source, table, prefix) for t in state["always"].list() if _is_row(t))
        found.tables.append(table)
    return found


def _is_row(transition: _At) -> bool:
    """A row's transition, or the idle one (last in every state); any other is refused here."""
    guard = transition["guard"]
    kind = guard.get("type", None)
    if kind not in ("row", "idle"):
        raise guard.error(
            N_("is {value}, not a row's guard (type row) or the idle one", value=json.dumps(guard.value)[:60])
        )
    return bool(kind == "row")


def _state(at: _At, prefix: str) -> StateId:
    state = state_of(at.of(str, N_("a state id")), prefix)
    if state is None:
        raise at.error(N_("{ident!r} is no state id tablebot writes (s12, n_ and a name)", ident=at.value))
    return state


def _event(flag: str, prefix: str) -> str:
    return "T" if flag == f"{prefix}has_T" else flag.removeprefix("has_")


def _row(transition: _At, state: StateId, table: FoundTable, prefix: str) -> FoundRow:
    params = transition["guard"]["params"]
    events = {_event(flag, prefix) for flag in params["flags"].names()}
    events |= {cross["column"].of(str, N_("a column")) for cross in params["cross"].list()}
    unknown = sorted(events - set(table.events))
    if unknown:
        raise params.error(N_("names {name!r}, which is no event column of the table", name=unknown[0]))
    fire = transition["actions"][0]["params"]
    meta = transition["meta"]
    return FoundRow(
        state=state,
        events=frozenset(events),
        outputs={name: value.of(int, N_("a number")) for name, value in fire["set"].items()},
        timer=fire["load"].of(int, N_("a number")),
        next=_state(transition["target"], prefix),
        description=_optional(transition, "description", str, ""),
        written=meta["row"].of(int, N_("a number")),
        group=_optional(meta, "group", str, ""),
        index=_optional(meta, "index", int, 0),
    )


def _optional(at: _At, key: str, kind: type, default: Any) -> Any:
    """A key the export writes only sometimes (a group row's group and index), of its type when there."""
    if key not in at.of(dict, N_("an object")):
        return default
    return at[key].of(kind, N_("a number") if kind is int else N_("text"))


def _same(read: Any, made: Any, where: str, path: str, depth: int) -> None:
    """The file's config is the export's, or the first JSON path where it is not is the error."""
    if depth > MAX_DEPTH:
        raise fail(path, N_("{where}: nested deeper than {most}", where=where, most=MAX_DEPTH), HINT)
    if isinstance(made, dict) and isinstance(read, dict):
        for key in {**made, **read}:
            if key not in read or key not in made:
                raise fail(
                    path,
                    N_("{where}: has no key {key!r}", where=where, key=key)
                    if key not in read
                    else N_("{where}: has a key {key!r} tablebot does not write", where=where, key=key),
                    HINT,
                )
            _same(read[key], made[key], f"{where}.{key}", path, depth + 1)
    elif isinstance(made, list) and isinstance(read, list) and len(made) == len(read):
        for i, (got, want) in enumerate(zip(read, made, strict=True)):
            _same(got, want, f"{where}[{i}]", path, depth + 1)
    elif read != made or type(read) is not type(made):
        raise fail(
            path,
            N_(
                "{where}: is {value}, where tablebot writes {made}",
                where=where,
                value=json.dumps(read)[:80],
                made=json.dumps(made)[:80],
            ),
            HINT,
        )
