"""Loading the back-ends when they are first needed, not when ``tablebot`` is imported.

Every back-end registers itself, and its robot-file section, when its module is imported
(:func:`tablebot.catalog.load_all` imports them all). Those modules bring the table and robot-file machinery
with them, which ``tablebot --help`` and a library user who only wants ``tablebot.i18n`` do not need: so
``tablebot`` hands :func:`tablebot.catalog.load_all` to :func:`defer`, and the registry and the robot-file
reader call :func:`load` before they look anything up. This module sits below both (it imports nothing of
tablebot's), so neither imports the back-ends above it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

__all__ = ["defer", "load"]

_loaders: list[Callable[[], None]] = []
_lock = threading.RLock()
_done = False
_loading = False


def defer(loader: Callable[[], None]) -> None:
    """Run ``loader`` at the first :func:`load` (at once if that has happened)."""
    with _lock:
        _loaders.append(loader)
        if _done:
            loader()


def load() -> None:
    """Run every deferred loader, once per process. Another thread waits until they have run; a call made
    while they run, from their own thread (a back-end's module that asks the registry as it is imported), returns
    at once."""
    global _done, _loading
    if _done:
        return
    with _lock:
        if _done or _loading:
            return
        _loading = True
        try:
            for loader in _loaders:
                loader()
            _done = True
        finally:
            _loading = False
