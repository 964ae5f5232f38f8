"""numba, set up once: its on-disk cache goes to the user's cache folder, never into the installed package.

Every compiled function in tablebot is made with :func:`njit` from here, so the cache folder is
chosen before numba is first imported; read-only installs and cluster workers then work alike.
"""

from __future__ import annotations

import functools
import hashlib
import os
import sys
import uuid
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

from tablebot import jit_inlining
from tablebot.i18n import N_, _, localise

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


#: The files of the tablebot package whose functions are compiled (they call :func:`njit`) and those whose
#: functions or constants compiled code reads though they compile nothing themselves (tick.py, sim/columns.py,
#: sensors.py), in the order their paths sort: the sources of the cache folder's name. Named here rather than
#: found by reading all ~300 files for ``njit`` (~10 ms of every process that runs a robot);
#: tests/test_numba_imports.py holds the list to that search.
COMPILED_FILES = (
    "engine_batch.py",
    "fleet/kernel.py",
    "jit.py",
    "sensors.py",
    "sim/columns.py",
    "sim/physics/broad.py",
    "sim/physics/contacts.py",
    "sim/physics/geometry.py",
    "sim/physics/kernel.py",
    "sim/physics/layout.py",
    "sim/physics/normals.py",
    "sim/physics/sensing.py",
    "sim/physics/several.py",
    "sim/physics/shadows.py",
    "sim/physics/step.py",
    "sinks/trace_text.py",
    "tick.py",
)


ROOT = Path(__file__).resolve().parent  # the tablebot package


@functools.lru_cache(maxsize=1)
def sources_digest() -> str:
    """A short digest of the tablebot sources that end up in compiled code (:data:`COMPILED_FILES`). Worked out
    once a process (a sweep asks twice): the process's cache folder is named after it when it is first imported."""
    digest = hashlib.sha1()
    for name in COMPILED_FILES:
        digest.update(name.encode() + b"\0" + (ROOT / name).read_bytes())
    return digest.hexdigest()[:12]


def compiled_sources() -> list[Path]:
    """The tablebot source files that define compiled functions."""
    return [ROOT / name for name in COMPILED_FILES if b"njit" in (ROOT / name).read_bytes()]


os.environ.setdefault(ENV, cache_dir())  # before numba's first import, which reads its configuration
# numba's OpenMP threads wait for their next job asleep, not spinning: a fleet's call is milliseconds of work,
# against the microseconds of a wake-up, and a spinning thread takes a core from whoever runs meanwhile (the
# calling thread's Python between blocks, small fleets run on it alone, other programs) -- on a busy 2-core
# machine a 1-robot fleet's tick took 31 us with spinning threads, 0.9 us without. Read when OpenMP starts.
os.environ.setdefault("OMP_WAIT_POLICY", "passive")


def _import_numba() -> ModuleType:
    """numba, imported without importing scipy, coverage or yaml, which it imports for what tablebot never uses.

    numba's ``__init__`` imports scipy only to check that it is not older than 1.0 (skipped when scipy is
    absent), and that import is a tenth of numba's own; nothing tablebot compiles uses scipy. It imports coverage
    (where installed: ~0.1 s, with sqlite3 and multiprocessing) to tell a coverage run which lines it compiled,
    and no run is measuring this process when coverage is not imported yet (a run imports it before the code it
    measures); and yaml, to read a ``.numba_config.yaml`` in the working folder, held off only when there is
    none. Each stays importable as ever: whoever needs it imports it as usual (evolve's archive, scipy), and a
    compile that uses BLAS has numba import scipy then.
    """
    if "numba" in sys.modules:
        import numba

        return numba
    held = [
        name
        for name in ("scipy", "coverage", "yaml")
        if name not in sys.modules and not (name == "yaml" and os.path.isfile(".numba_config.yaml"))
    ]
    for name in held:
        sys.modules[name] = None  # type: ignore[assignment]  # `import NAME` raises ImportError meanwhile
    try:
        import numba
    finally:
        for name in held:
            if name in sys.modules and sys.modules[name] is None:
                del sys.modules[name]
    return numba


numba = _import_numba()  # after the cache folder is set

if not numba.config.CACHE_DIR:  # numba was imported before us: its cache locator reads this at use
    numba.config.CACHE_DIR = os.environ[ENV]

prange = numba.prange


def _load_cached_code_directly() -> None:
    """Let numba load a function's machine code from its cache without first readying its whole compiler.

    Before each load from the cache numba "refreshes" its compiler: it imports its ~200 modules of typing and
    lowering rules (and scipy.linalg, to see whether BLAS is there) and installs them -- 0.6-0.8 s of every
    tablebot process that runs a robot, on this 2-core machine, against ~10 ms for the load itself. Running
    machine code needs none of it: only numba's runtime for arrays (initialised here, as the refresh would),
    and the parallel back-end, which the cached code starts itself (its ``reload_init``). A function not in
    the cache, or one whose load fails, takes numba's own path (the refresh, then the load or a compile, and
    every compile refreshes by itself), so a load can only be faster, never different: the same machine code
    runs either way.
    """
    from numba.core.caching import Cache
    from numba.core.runtime import nrt

    original = Cache.load_overload
    if (
        getattr(original, "direct", False)
        or not hasattr(Cache, "_load_overload")
        or not hasattr(nrt.rtsys, "initialize")
    ):
        return  # done already, or another numba: keep its own path

    def load_overload(self: Any, sig: Any, target_context: Any) -> Any:
        try:
            nrt.rtsys.initialize(target_context)
            loaded = self._load_overload(sig, target_context)
        except Exception:  # whatever failed, numba's own path tries again and reports it
            loaded = None
        return loaded if loaded is not None else original(self, sig, target_context)

    load_overload.direct = True  # type: ignore[attr-defined]
    Cache.load_overload = load_overload  # type: ignore[method-assign]


_load_cached_code_directly()

jit_inlining.copy_each_scope_once()  # when numba's inliner is first imported: on a process's first compile


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


#: How long a first compile of the simulator takes, as a user is told (2 cores: a first `sim` 23 s idle, 38 s beside
#: two busy programs; a first sweep 26 s).
USUALLY = "usually 20-40 s"


def say_compiling(what: str, *functions: Any) -> None:
    """One line on stderr when ``functions`` are about to be compiled, not loaded from the cache: the first
    run of a new tablebot (or Python) spends tens of seconds there, which must not look like a hang."""
    if not compiled(*functions):
        print(
            _("compiling {what} for this machine (first run only, usually 20-40 s; later runs start at once)…").format(
                what=localise(what)
            ),
            file=sys.stderr,
            flush=True,
        )


class Compiling:
    """Tells the user, on stderr, all the while ``functions`` compile (a first run's tens of seconds must not
    look like a hang, nor like a progress bar stuck at 0 %): what, how long it usually takes, and the seconds
    so far -- on a terminal one line with a spinner, redrawn; elsewhere (a pipe, a log) a line at the start
    and one every ``every_s`` (:class:`tablebot.talk.Talking`). :meth:`done` ends it with the time taken.
    Nothing at all when the functions are in the cache already (``active`` is False)."""

    def __init__(self, what: str, *functions: Any, every_s: float = 10.0, stream: Any = None) -> None:
        from tablebot.talk import Talking

        self.active = not compiled(*functions)
        self.talking = (
            Talking(
                N_("compiling {what} for this machine", what=what),
                N_("first run only, usually 20-40 s; later runs start at once"),
                N_("compiled {what} in {{s}} s (kept in the cache: later runs start at once)", what=what),
                every_s=every_s,
                stream=stream,
            )
            if self.active
            else None
        )

    def done(self, finished: bool = True) -> None:
        """The compile is over: stop talking and, when it ``finished`` (not cut short by an error or Ctrl-C),
        say how long it took. Only the first call does anything."""
        if self.talking is not None:
            self.talking.done(finished)


def njit(*args: Any, refcounts: bool = True, **kwargs: Any) -> Callable[..., Any]:
    """``numba.njit`` with the on-disk cache on: ``@njit`` or ``@njit(parallel=True)``.

    ``refcounts=False`` compiles the function without numba's reference counting (its ``_nrt`` option):
    every array a compiled function receives or slices is otherwise counted with an atomic increment and
    decrement, and in the simulator's per-tick functions -- small, many, each handed a dozen arrays -- those
    were half of a tick's time. Such a function must not create arrays (it cannot free them); it may use
    the arrays it is given, and views of them, freely.

    The simulator's per-tick functions are also made with ``inline="always"`` (numba inlines them into
    their caller before compiling it): numba hands each array to a call as seven machine words, and the
    physics' calls of a dozen arrays each cost more than the small functions' own work (a BumberBot tick
    ~630 -> ~420 ns). Inlining everything down to the geometry would take ten times as long to compile
    and run no faster, so the leaves stay calls.
    """
    kwargs.setdefault("cache", True)
    if not refcounts:
        kwargs["_nrt"] = False
    if args and callable(args[0]) and len(args) == 1 and not kwargs.keys() - {"cache"}:
        return _loading_first(numba.njit(cache=kwargs["cache"])(args[0]))
    decorate = numba.njit(*args, **kwargs)
    return lambda function: _loading_first(decorate(function))


def cached_signatures(function: Any) -> list[Any]:
    """The argument types whose machine code ``function`` (made with :func:`njit`) has in the on-disk cache for this
    machine and these sources (uses numba's cache internals: another numba finds none, and nothing changes)."""
    try:
        cache, codegen = function._cache, function.targetctx.codegen()
        keys = list(cache._cache_file._load_index())
        return [key[0] for key in keys if cache._index_key(key[0], codegen) == key]
    except Exception:  # another numba, no cache, or no index yet
        return []


def _loading_first(dispatcher: Any) -> Any:
    """``dispatcher`` with a first call (for each new set of argument types) that loads the machine code the cache
    holds for them without numba's compilation chain set-up. numba runs that set-up before compiling or loading any
    call it has no code for yet -- ``init_all``: reading every installed package's entry points for numba extensions,
    18-26 ms of a sweep here, on its critical path -- though loading needs none of it, and tablebot compiles with no
    extension. Types the cache lacks, and any failure, take numba's own path: the set-up, then the compile."""
    original = getattr(dispatcher, "_compile_for_args", None)
    if original is None:  # another numba: as it is
        return dispatcher

    def compile_for_args(*args: Any, **kws: Any) -> Any:
        if not kws:
            try:
                types = tuple(dispatcher.typeof_pyval(arg) for arg in args)
                if types in cached_signatures(dispatcher):
                    return dispatcher.compile(types)  # the entry point, as numba's own returns it
            except Exception:  # numba's own path says what is wrong
                pass
        return original(*args, **kws)

    dispatcher._compile_for_args = compile_for_args
    return dispatcher


# --- handing compiled code to another process (a fresh cluster worker) -------------------------------------------
#
# numba keeps each function's machine code in its cache folder as an index (FUNCTION-LINE.pyXY.nbi: which
# signature and CPU is in which data file, stamped with a hash of the source file's bytes) and data files
# (FUNCTION-LINE.pyXY.N.nbc); the folder is named after the source file's directory. Nothing in them names
# the path, so the files of one install serve another install of the same sources: copied into the folder
# numba looks in there, they load instead of compiling (a worker of another CPU model, or with other sources,
# finds no matching entry and compiles as before).


def _cache_folder(source: Path) -> Path:
    from numba.core.caching import UserProvidedCacheLocator

    return Path(numba.config.CACHE_DIR) / UserProvidedCacheLocator.get_suitable_cache_subpath(str(source))


def cache_files() -> dict[str, dict[str, bytes]]:
    """tablebot's compiled code in this process's numba cache: per source file (relative to the package),
    every index and data file by name."""
    out: dict[str, dict[str, bytes]] = {}
    for source in compiled_sources():
        folder = _cache_folder(source)
        if not folder.is_dir():
            continue
        found = {
            path.name: path.read_bytes()
            for path in folder.iterdir()
            if path.name.startswith(source.stem + ".") and path.suffix in (".nbi", ".nbc")
        }
        if found:
            out[source.relative_to(ROOT).as_posix()] = found
    return out


def install_cache_files(files: dict[str, dict[str, bytes]]) -> int:
    """Put another process's compiled code (:func:`cache_files`) into this process's numba cache, for every
    function this cache has no index of (an index here is never replaced, nor its data files touched);
    returns the files written. Each file is written under a temporary name and renamed into place, data
    files before their index, so a process loading meanwhile sees a whole function or none."""
    written = 0
    for relative, found in files.items():
        source = ROOT / relative
        if not source.is_file():
            continue
        folder = _cache_folder(source)
        folder.mkdir(parents=True, exist_ok=True)
        functions: dict[str, list[str]] = defaultdict(list)
        for name in found:
            functions[name[:-4] if name.endswith(".nbi") else name.rsplit(".", 2)[0]].append(name)
        for function, names in functions.items():
            if (folder / f"{function}.nbi").exists():
                continue
            for name in sorted(names, key=lambda n: n.endswith(".nbi")):  # the index last
                temporary = folder / f"{name}.{uuid.uuid4().hex[:12]}.tmp"
                temporary.write_bytes(found[name])
                os.replace(temporary, folder / name)
                written += 1
    return written
