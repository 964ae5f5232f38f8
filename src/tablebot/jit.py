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


#: Files whose functions or constants compiled code reads, though they compile nothing themselves.
COMPILED_CONSTANTS = ("tick.py", "columns.py", "sensors.py")


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


def compiled(*functions: Any) -> bool:
    """Whether each of ``functions`` (made with :func:`njit`) has machine code in the on-disk cache: if one
    has not, its first call compiles it (tens of seconds for the simulator), which a user should be told."""
    for function in functions:
        try:
            index = function._cache._cache_file._index_path  # numba's FunctionCache: <cache>/<module>.<name>-<line>.nbi
        except AttributeError:  # another numba: assume compiled rather than announce what may not happen
            continue
        if not os.path.exists(index):
            return False
    return True


def say_compiling(what: str, *functions: Any) -> None:
    """One line on stderr when ``functions`` are about to be compiled, not loaded from the cache: the first
    run of a new tablebot (or Python) spends tens of seconds there, which must not look like a hang."""
    if not compiled(*functions):
        print(f"compiling {what} for this machine (first run only, about half a minute; later runs start at "
              "once)…", file=sys.stderr, flush=True)


def njit(*args: Any, **kwargs: Any) -> Callable[..., Any]:
    """``numba.njit`` with the on-disk cache on: ``@njit`` or ``@njit(parallel=True)``."""
    kwargs.setdefault("cache", True)
    if args and callable(args[0]) and len(args) == 1 and not kwargs.keys() - {"cache"}:
        return numba.njit(cache=kwargs["cache"])(args[0])
    return numba.njit(*args, **kwargs)
