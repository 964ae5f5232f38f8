"""``import --from scxml``: the tables in an SCXML file that ``export --to scxml`` wrote, and nothing else.

The file is parsed by :mod:`.xmltree` (the standard library's expat, every DTD refused, so no entity is declared or
expanded: a table is data, and reading one runs nothing). The robot and its rows are read from the elements and
tablebot's attributes; the tables are then exported again and the file must be that document, element for
element and attribute for attribute: the first place it differs is the error, with its line and column and what
tablebot would have written there.
"""

from __future__ import annotations

from tablebot.diagnostics import fail
from tablebot.formats.statecharts.chart import WRAPPER, chart_of, state_of
from tablebot.formats.statecharts.rebuild import Found, FoundRow, FoundTable, build
from tablebot.formats.statecharts.scxml import scxml_tree
from tablebot.formats.statecharts.xmltree import Element, parse
from tablebot.i18n import N_
from tablebot.robot import Counter, StateId
from tablebot.table import Table

__all__ = ["read_scxml"]

HINT = N_("import reads what tablebot export --to scxml wrote, unchanged")


def read_scxml(text: str, path: str) -> tuple[Table, ...]:
    """The tables of an SCXML document (the main one first), or a located error."""
    root = parse(text, path)
    tables = build(_found(root, path), path, (root.line, root.column))
    _same(root, scxml_tree(chart_of(tables)), path)
    return tables


def _error(element: Element, path: str, message: str) -> Exception:
    return fail(path, message, HINT, element.line, element.column)


def _attr(element: Element, name: str, path: str) -> str:
    if name not in element.attrs:
        raise _error(element, path, N_("<{tag}> has no {name} attribute", tag=element.tag, name=name))
    return element.attrs[name]


def _int(element: Element, name: str, path: str) -> int:
    text = _attr(element, name, path)
    if not text.lstrip("-").isdigit() or len(text) > 9:
        raise _error(
            element, path, N_("{name}={text!r} on <{tag}> is not a whole number", name=name, text=text, tag=element.tag)
        )
    return int(text)


def _child(element: Element, tag: str, path: str, ident: str | None = None) -> Element:
    for child in element.children:
        if child.tag == tag and (ident is None or child.attrs.get("id") == ident):
            return child
    what = f"<{tag}>" if ident is None else f'<{tag} id="{ident}">'
    raise _error(element, path, N_("<{tag}> holds no {what}", tag=element.tag, what=what))


def _found(root: Element, path: str) -> Found:
    if root.tag != "scxml":
        raise _error(root, path, N_("the document is <{tag}>, not <scxml>", tag=root.tag))
    data = _child(root, "datamodel", path).children
    kinds = {
        kind: tuple(_attr(d, "id", path) for d in data if d.attrs.get("tb:kind") == kind) for kind in ("motor", "lamp")
    }
    counters = tuple(
        Counter(_attr(d, "id", path), _attr(d, "tb:motor", path)) for d in data if d.attrs.get("tb:kind") == "counter"
    )
    found = Found(
        _attr(root, "tb:name", path),
        _int(root, "tb:tick-ms", path),
        tuple(d.attrs["tb:input"] for d in data if "tb:input" in d.attrs),
        kinds["motor"],
        kinds["lamp"],
        counters,
    )
    values = {d.attrs.get("id", ""): d for d in data}
    wrapper = next((c for c in root.children if c.attrs.get("id") == WRAPPER), None)
    if wrapper is None:
        raise _error(root, path, N_('<scxml> holds no state with id="{id}"', id=WRAPPER))
    several = wrapper.tag == "parallel"
    holders = [c for c in wrapper.children if c.tag == "state"] if several else [wrapper]
    for holder in holders:
        name = _attr(holder, "id", path) if several else ""
        prefix = f"{name}_" if several else ""
        timer = values.get(f"{prefix}timer")
        if timer is None:
            raise _error(root, path, N_("the data model has no {prefix}timer", prefix=prefix))
        table = FoundTable(
            name,
            tuple(_attr(holder, "tb:events", path).split()),
            _attr(holder, "tb:match", path),
            _state(holder, _attr(holder, "initial", path), prefix, path),
            _int(timer, "expr", path),
            tuple(holder.attrs.get("tb:writes", "").split()),
        )
        for state in holder.children:
            if state.tag == "state" and state is not holder:
                table.rows.extend(_rows(state, table, prefix, found, path))
        found.tables.append(table)
    return found


def _state(element: Element, ident: str, prefix: str, path: str) -> StateId:
    state = state_of(ident, prefix)
    if state is None:
        raise _error(element, path, N_("{ident!r} is no state id tablebot writes (s12, n_ and a name)", ident=ident))
    return state


def _rows(element: Element, table: FoundTable, prefix: str, found: Found, path: str) -> list[FoundRow]:
    state = _state(element, _attr(element, "id", path), prefix, path)
    outputs = {*found.motors, *found.lamps, *(c.name for c in found.counters)}
    rows = []
    for transition in element.children:
        if transition.tag != "transition" or "tb:row" not in transition.attrs:
            continue
        events = transition.attrs.get("tb:events", "").split()
        unknown = [e for e in events if e not in table.events]
        if unknown:
            raise _error(
                transition, path, N_("tb:events names {name!r}, which is no event column of the table", name=unknown[0])
            )
        values = {a.attrs.get("location", ""): a for a in transition.children if a.tag == "assign"}
        timer = values.get(f"{prefix}timer")
        if timer is None:
            raise _error(transition, path, N_("this row does not load {prefix}timer", prefix=prefix))
        rows.append(
            FoundRow(
                state=state,
                events=frozenset(events),
                timer=_int(timer, "expr", path),
                outputs={name: _int(a, "expr", path) for name, a in values.items() if name in outputs},
                next=_state(transition, _attr(transition, "target", path), prefix, path),
                description=transition.attrs.get("tb:description", ""),
                written=_int(transition, "tb:row", path),
                group=transition.attrs.get("tb:group", ""),
                index=_int(transition, "tb:index", path) if "tb:index" in transition.attrs else 0,
            )
        )
    return rows


def _same(read: Element, made: Element, path: str) -> None:
    """The file's tree is the export's, or the first place it is not is a located error."""
    if read.tag != made.tag:
        raise _error(read, path, N_("<{tag}> where tablebot writes <{made}>", tag=read.tag, made=made.tag))
    for name in {**made.attrs, **read.attrs}:
        if read.attrs.get(name) != made.attrs.get(name):
            want = made.attrs.get(name)
            said = f"{name}={read.attrs[name]!r}" if name in read.attrs else N_("no {name}", name=name)
            wrote = f"{name}={want!r}" if want is not None else N_("no {name}", name=name)
            raise _error(
                read,
                path,
                N_("<{tag}> has {said}, where tablebot writes {wrote}", tag=read.tag, said=said, wrote=wrote),
            )
    for child, model in zip(read.children, made.children, strict=False):
        _same(child, model, path)
    if len(read.children) != len(made.children):
        extra = read.children[len(made.children)] if len(read.children) > len(made.children) else read
        raise _error(
            extra,
            path,
            N_(
                "<{tag}> holds {count} elements, where tablebot writes {made}",
                tag=read.tag,
                count=len(read.children),
                made=len(made.children),
            ),
        )
