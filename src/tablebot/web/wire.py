"""How the studio reads an operation's fields from the page's JSON (:mod:`tablebot.web.protocol`): one reader
per kind of field, chosen by the field's type (:data:`READERS`), each refusing a wrong value in the studio's words
(a :class:`~tablebot.i18n.Message`, said in the tab's language)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import field
from typing import Any

from tablebot.i18n import N_
from tablebot.web.errors import Refused

__all__ = ["MAX_COLUMNS", "MAX_ROWS", "READERS", "Reader", "any_text", "text", "wire"]

MAX_ROWS = 20_000  # a restored draft: far more than a table a person edits in a grid
MAX_COLUMNS = 200

Reader = Callable[[Mapping[str, Any], str], Any]


def wire(read: Reader) -> Any:
    """A field of an operation read from the page's message by ``read(message, name)``, not by its type's."""
    return field(metadata={"read": read})


def text(message: Mapping[str, Any], key: str, allow_empty: bool = False) -> str:
    value = message.get(key)
    if not isinstance(value, str) or (not value and not allow_empty):
        raise Refused(N_('"{key}" must be text', key=key))
    return value


def any_text(message: Mapping[str, Any], key: str) -> str:
    return text(message, key, allow_empty=True)


def _int(message: Mapping[str, Any], key: str) -> int:
    value = message.get(key)
    if not isinstance(value, int) or isinstance(value, bool):
        raise Refused(N_('"{key}" must be a whole number', key=key))
    return value


def _as_is(message: Mapping[str, Any], key: str) -> Any:
    """A value the page gets back unread (an edit's ``seq``)."""
    return message.get(key)


def _rows(message: Mapping[str, Any], key: str, single: bool = False) -> list[list[str]]:
    """A list of rows of text (``single``: one row) from the page."""
    value = message.get(key)
    rows = [value] if single else value
    if (
        not isinstance(rows, list)
        or len(rows) > MAX_ROWS
        or not all(
            isinstance(row, list) and len(row) <= MAX_COLUMNS and all(isinstance(c, str) for c in row) for row in rows
        )
    ):
        limits = {"key": key, "rows": f"{MAX_ROWS:,}", "columns": MAX_COLUMNS}
        raise Refused(
            N_('"{key}" must be a row of text (at most {rows} rows of {columns} cells)', **limits)
            if single
            else N_('"{key}" must be rows of text (at most {rows} rows of {columns} cells)', **limits)
        )
    return rows


def _row(message: Mapping[str, Any], key: str) -> list[str]:
    return _rows(message, key, single=True)[0]


def _force(message: Mapping[str, Any], key: str) -> bool | str:
    force = message.get(key, False)
    if not isinstance(force, bool | str):
        raise Refused(N_('"force" must be the version the conflict named ("theirs")'))
    return force


def _optional_text(message: Mapping[str, Any], key: str) -> str | None:
    value = message.get(key)
    return value if isinstance(value, str) else None


#: How a field of an operation is read from the page's message, by its type (unless its :func:`wire` says).
READERS: dict[str, Reader] = {
    "str": text,
    "int": _int,
    "Any": _as_is,
    "list[str]": _row,
    "list[list[str]]": _rows,
    "bool | str": _force,
    "str | None": _optional_text,
}
