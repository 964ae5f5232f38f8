"""What a Dask worker for tablebot can load as it starts, before any sweep reaches it:
``dask worker tcp://HOST:8786 --preload tablebot.fleet.worker``.

numba (as tablebot.jit imports it, without scipy), numpy's random module and numba's runtime for arrays: a
fresh worker otherwise spends about half a second of CPU on them inside the first sweep that reaches it,
on cores the sweep shares. Nothing compiled is loaded here: the client still chooses the worker's cache folder
and sends it its compiled code (:func:`tablebot.fleet.work.ready_worker`), which a worker started without
this preload gets just the same.
"""

from __future__ import annotations

import os
from typing import Any


def dask_setup(worker: Any = None) -> None:
    """Dask's preload hook, run in the worker process as it starts (``worker``: Dask's, unused)."""
    from tablebot.fleet import work

    # ready_worker keeps a NUMBA_CACHE_DIR the user set, and tablebot.jit sets one when it is imported
    work.cache_dir_given = bool(os.environ.get("NUMBA_CACHE_DIR"))
    import numpy.random  # noqa: F401  (a fleet's Generators)

    from tablebot import jit  # noqa: F401  (numba, its cache folder to be chosen by ready_worker)

    try:  # numba's runtime for arrays (what every first load of compiled code starts; see tablebot.jit)
        from numba.core.registry import cpu_target
        from numba.core.runtime import nrt

        nrt.rtsys.initialize(cpu_target.target_context)
    except (ImportError, AttributeError):  # another numba: the first load starts it, as without this
        pass
