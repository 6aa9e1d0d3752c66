"""Say so when the numba kernels are about to be compiled (a cold cache costs tens of seconds).

numba compiles a kernel on its first call and stores the machine code in its cache
(``NUMBA_CACHE_DIR`` or ``__pycache__``). A kernel with no compiled signature in this process and
no index file in the cache is about to be compiled: ``announce`` prints one line on stderr then,
once per process, so the first call after an install is not twenty seconds of silence.
"""

from __future__ import annotations

import os
import sys

_announced = False


def cold(dispatcher) -> bool:
    """True if calling ``dispatcher`` will compile (nothing in memory, nothing in the cache)."""
    if getattr(dispatcher, "signatures", None):
        return False
    try:
        index = dispatcher._cache._cache_file._index_path  # numba's FunctionCache internals
    except AttributeError:  # another numba layout: do not guess
        return False
    return not os.path.exists(index)


def announce(*dispatchers) -> None:
    """One line on stderr if any of the kernels will be compiled now (once per process)."""
    global _announced
    if _announced:
        return
    if any(cold(d) for d in dispatchers):
        _announced = True
        print(
            "restitution: compiling the numba kernels (first run after installation; about 20 s "
            "per kernel; later runs use the cache)...",
            file=sys.stderr,
            flush=True,
        )
