"""Loading the back-ends when they are first needed, not when ``tablebot`` is imported.

Every back-end registers itself, and its robot-file section, when its module is imported
(:func:`tablebot.catalog.load_all` imports them all). Those modules bring the table and robot-file machinery
with them, which ``tablebot --help`` and a library user who only wants ``tablebot.i18n`` do not need: so
``tablebot`` hands :func:`tablebot.catalog.load_all` to :func:`defer`, and the registry calls :func:`load`
before it looks anything up. A robot file's reader needs only the readers of the sections the file has:
``tablebot`` names each section's module here (:func:`defer_section`, from :data:`tablebot.catalog.SECTIONS`),
and the reader calls :func:`load_sections` -- a sweep reading the BumberBot's ``[txt]``, ``[robotx]`` and
``[roboif]`` wiring then imports neither the ROBO Pro writer nor the C, statechart and firmware exporters
(~20 ms of every sweep, sim and check process). This module sits below both (it imports nothing of
tablebot's), so neither imports the back-ends above it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable

__all__ = ["defer", "defer_section", "load", "load_sections", "sections"]

_loaders: list[Callable[[], None]] = []
_sections: dict[str, Callable[[], object]] = {}  # a robot-file section -> what registers its reader
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


def defer_section(name: str, loader: Callable[[], object]) -> None:
    """``loader`` registers the reader of the robot-file section ``[name]`` (it imports its back-end's module);
    run by :func:`load_sections` when a file has that section, or by :func:`load` among the rest."""
    with _lock:
        _sections[name] = loader


def sections() -> list[str]:
    """The robot-file sections named by :func:`defer_section`, in the order they were named."""
    return list(_sections)


def load_sections(names: Iterable[str]) -> None:
    """The readers of these robot-file sections registered, each by its own loader; a name no loader is known
    for (a section a back-end registers without naming it here, or a mistake) loads every back-end, so that
    whether it is known is decided as before."""
    if _done:
        return
    with _lock:
        if _done or _loading:  # (_loading: a back-end's module reading a robot file as it is imported)
            return
        wanted = list(names)
        if any(name not in _sections for name in wanted):
            load()
            return
        for name in wanted:
            _sections[name]()  # an import: a second time costs a dictionary lookup
