"""numba, set up once: its on-disk cache goes to the user's cache folder, never into the installed package.

Every compiled function in tablebot is made with :func:`njit` from here, so the cache folder is
chosen before numba is first imported; read-only installs and cluster workers then work alike.
"""

from __future__ import annotations

import hashlib
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

ENV = "NUMBA_CACHE_DIR"


def cache_dir() -> str:
    """``$NUMBA_CACHE_DIR`` when set, else ``<user cache>/tablebot/numba-<python>-<sources>``: per user,
    per Python, and per version of tablebot's sources.

    The sources are part of the name because numba checks only the file that defines a function: a
    cached kernel would otherwise keep running an old copy of the physics it calls from another file.
    """
    if os.environ.get(ENV):
        return os.environ[ENV]
    import platformdirs

    tag = f"py{sys.version_info.major}{sys.version_info.minor}"
    return os.path.join(platformdirs.user_cache_dir("tablebot"), f"numba-{tag}-{sources_digest()}")


#: Files whose constants compiled code reads, though they hold no compiled function themselves.
COMPILED_CONSTANTS = ("tick.py", "columns.py")


def sources_digest() -> str:
    """A short digest of the tablebot sources that end up in compiled code (every file that compiles a
    function, and the constants they read)."""
    root = Path(__file__).resolve().parent
    digest = hashlib.sha1()
    for path in sorted(root.rglob("*.py")):
        text = path.read_bytes()
        if b"njit" in text or path.name in COMPILED_CONSTANTS:
            digest.update(str(path.relative_to(root)).encode() + b"\0" + text)
    return digest.hexdigest()[:12]


os.environ.setdefault(ENV, cache_dir())  # before numba's first import, which reads its configuration

import numba  # noqa: E402  (after the cache folder is set)

if not numba.config.CACHE_DIR:  # numba was imported before us: its cache locator reads this at use
    numba.config.CACHE_DIR = os.environ[ENV]

prange = numba.prange


def njit(*args: Any, refcounts: bool = True, **kwargs: Any) -> Callable[..., Any]:
    """``numba.njit`` with the on-disk cache on: ``@njit`` or ``@njit(parallel=True)``.

    ``refcounts=False`` compiles the function without numba's reference counting (its ``_nrt`` option):
    every array a compiled function receives or slices is otherwise counted with an atomic increment and
    decrement, and in the simulator's per-tick functions -- small, many, each handed a dozen arrays -- those
    were half of a tick's time. Such a function must not create arrays (it cannot free them); it may use
    the arrays it is given, and views of them, freely.
    """
    kwargs.setdefault("cache", True)
    if not refcounts:
        kwargs["_nrt"] = False
    if args and callable(args[0]) and len(args) == 1 and not kwargs.keys() - {"cache"}:
        return numba.njit(cache=kwargs["cache"])(args[0])
    return numba.njit(*args, **kwargs)
