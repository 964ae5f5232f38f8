"""What :meth:`tablebot.engine.Engine.run` gives back (:class:`Batch`), and the masks its compiled loop takes."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


class Batch:
    """Per-tick results of :meth:`Engine.run`: event mask, fired row (-1: none), state index, timer.

    The compiled path fills integer arrays (:attr:`arrays`); the list attributes are made from them
    on first use, so a caller that only wants the arrays (or nothing) pays nothing for lists.
    """

    FIELDS = ("events", "rows", "states", "timers")

    def __init__(
        self, events: Sequence[int], rows: Sequence[int], states: Sequence[int], timers: Sequence[int]
    ) -> None:
        self._columns: dict[str, Sequence[int]] = dict(zip(self.FIELDS, (events, rows, states, timers), strict=True))

    def _list(self, name: str) -> list[int]:
        column = self._columns[name]
        if not isinstance(column, list):
            column = self._columns[name] = np.asarray(column).tolist()
        return column

    @property
    def events(self) -> list[int]:
        return self._list("events")

    @property
    def rows(self) -> list[int]:
        return self._list("rows")

    @property
    def states(self) -> list[int]:
        return self._list("states")

    @property
    def timers(self) -> list[int]:
        return self._list("timers")

    @property
    def arrays(self) -> tuple[np.ndarray, ...]:
        """events, rows, states, timers as integer numpy arrays (no copy on the compiled path)."""
        return tuple(np.asarray(self._columns[name]) for name in self.FIELDS)

    def __len__(self) -> int:
        return len(self._columns["events"])

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Batch):
            return NotImplemented
        return all(self._list(name) == other._list(name) for name in self.FIELDS)

    __hash__ = None  # type: ignore[assignment]  # mutable caches; equality is by value

    def __repr__(self) -> str:
        return f"Batch({', '.join(f'{name}={self._list(name)!r}' for name in self.FIELDS)})"


def mask_array(masks: Sequence[int] | np.ndarray, width: int) -> np.ndarray:
    """Masks as a contiguous uint8 or int64 array (the two types the kernel is compiled for), each
    checked to be a mask of ``width`` event columns.

    A list of masks below 256 (any table with at most eight event columns) goes through
    ``bytearray``, about 2 ns per tick, where ``np.array(list)`` costs about 17.
    """
    if isinstance(masks, np.ndarray):
        array = np.ascontiguousarray(masks, dtype=np.uint8 if masks.dtype == np.uint8 else np.int64)
    else:
        try:
            array = np.frombuffer(bytearray(masks), dtype=np.uint8)
        except (TypeError, ValueError):  # a mask of 256 or more (or a negative one): the general path
            array = np.asarray(masks, dtype=np.int64)
    if len(array) and (array.min() < 0 or int(array.max()) >> width):
        bad = next(int(v) for v in array.tolist() if v < 0 or v >> width)
        raise ValueError(
            f"input mask {bad} is not a mask of this table's {width} event columns (0..{(1 << width) - 1})"
        )
    return array
