"""Say so when the numba kernels are about to be compiled (a cold cache costs tens of seconds).

numba compiles a kernel on its first call and stores the machine code in its cache
(``NUMBA_CACHE_DIR`` or ``__pycache__``). A kernel with no compiled signature in this process and
no index file in the cache is about to be compiled: ``announce`` prints one line on stderr then,
once per process, so the first call after an install is not twenty seconds of silence.
"""

from __future__ import annotations

import os
import sys
import tempfile

_announced = False
_warm = set()  # dispatchers known to be compiled or cached (checked once each)


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
    todo = [d for d in dispatchers if d not in _warm]
    if not todo:
        return
    cold_ones = [d for d in todo if cold(d)]
    _warm.update(d for d in todo if d not in cold_ones)
    if cold_ones:
        _announced = True
        print(
            "restitution: compiling the numba kernels (first run after installation; about 20 s "
            "per kernel; later runs use the cache)...",
            file=sys.stderr,
            flush=True,
        )


def _writable(path: str) -> bool:
    """True if ``path`` is (or can be made) a directory this process can write files into."""
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError:
        return False
    return True


def ensure_cache() -> str | None:
    """Make sure numba's cache is one this process can write, before any kernel is defined.

    A ``NUMBA_CACHE_DIR`` that cannot be written (owned by another user, e.g. root, or on a
    read-only file system) made numba look elsewhere and, where it found no writable place,
    fail at import with a traceback. Then a private cache is used instead,
    ``<tmp>/restitution-numba-<uid>`` (created 0700), with one line on stderr saying so.
    Returns the cache directory chosen here, or None when the given one is kept.
    """
    given = os.environ.get("NUMBA_CACHE_DIR")
    if not given or _writable(given):
        return None
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    private = os.path.join(tempfile.gettempdir(), f"restitution-numba-{uid}")
    try:
        os.makedirs(private, mode=0o700, exist_ok=True)
    except OSError:
        private = tempfile.mkdtemp(prefix="restitution-numba-")
    if not _writable(private) or os.stat(private).st_uid != os.getuid():
        private = tempfile.mkdtemp(prefix="restitution-numba-")  # (someone else's folder)
    os.environ["NUMBA_CACHE_DIR"] = private
    if "numba" in sys.modules:  # numba read the variable when it was imported
        from numba.core import config

        config.CACHE_DIR = private
    print(
        f"restitution: the numba cache NUMBA_CACHE_DIR={given} is not writable by this user; "
        f"using a private cache {private} instead",
        file=sys.stderr,
        flush=True,
    )
    return private
