"""numba's cache: one location for every entry point, and a notice before a compilation.

numba compiles a kernel on its first call and stores the machine code in its cache. Every entry
point (``make``, the ``restitution`` command, Python, the workflow's jobs, the notebooks) uses
the same cache: ``NUMBA_CACHE_DIR`` if it is set, else ``default_cache_dir()`` (a source
checkout's ``.cache/numba``, the folder ``make`` uses; for an installed wheel the user's cache
folder), set by ``ensure_cache`` when the package is imported, before any kernel is defined
(numba's own default, ``__pycache__`` next to each module, would give every entry point that
does not set the variable a cache of its own). ``restitution warmup`` fills it.

Within that location the kernels live in a folder named by ``source_key()``, a hash of the
package's numba-compiled sources. numba checks a cached kernel against its own file's time
stamp only, while a kernel compiles in the functions and constants it calls from other files:
after an edit of ``exact_chain.py`` the cached ``paper_chain.solve_linear`` still ran the old
``exact_chain`` code (found when a kernel edit did not change the paper scenes' results). A new
version of those sources is a new folder, so no stale machine code is ever loaded.

A kernel with no compiled signature in this process and no index file in the cache, or a stale
one (its source file edited since), is about to be compiled: ``announce`` prints one line on
stderr then, once per process, so the first call after an install or a kernel edit is not
minutes of silence.
"""

from __future__ import annotations

import hashlib
import logging
import os
import sys
import tempfile

_announced = False
_warm = set()  # dispatchers known to be compiled or cached (checked once each)


def cold(dispatcher) -> bool:
    """True if calling ``dispatcher`` will compile: nothing in memory, and no index in the cache
    or a stale one (written for another version of the kernel's source file, e.g. after an edit
    or a checkout: numba then compiles again, minutes for the chain kernels)."""
    if getattr(dispatcher, "signatures", None):
        return False
    try:
        cache_file = dispatcher._cache._cache_file  # numba's FunctionCache internals
        index = cache_file._index_path
    except AttributeError:  # another numba layout: do not guess
        return False
    if not os.path.exists(index):
        return True
    try:
        # numba's own reading of the index: empty when its source stamp is not the file's.
        return not cache_file._load_index()
    except Exception:  # an unreadable index, another numba layout: do not guess
        return False


def announce(*dispatchers) -> None:
    """One line on stderr (and an INFO record of this module's logger) if any of the kernels
    will be compiled now (once per process)."""
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
        message = (
            "compiling the numba kernels (the first run after installing or after a kernel "
            "edit takes up to a minute per kind of scene; `restitution warmup` compiles them all "
            "ahead; later runs load them from the cache)..."
        )
        print(f"restitution: {message}", file=sys.stderr, flush=True)
        # Into a configured log too (a workflow job's log: its minutes without a line explained
        # there); logging that nobody configured drops INFO.
        logging.getLogger(__name__).info(message)


def _writable(path: str) -> bool:
    """True if ``path`` is (or can be made) a directory this process can write files into."""
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError:
        return False
    return True


def default_cache_dir() -> str:
    """The cache when ``NUMBA_CACHE_DIR`` is not set: ``<checkout>/.cache/numba`` when the
    package runs from a source checkout (``src/restitution`` next to ``pyproject.toml``), else
    ``$XDG_CACHE_HOME/restitution/numba`` (``~/.cache`` when that is not set)."""
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    root = os.path.dirname(os.path.dirname(package))
    if os.path.basename(os.path.dirname(package)) == "src" and os.path.isfile(
        os.path.join(root, "pyproject.toml")
    ):
        return os.path.join(root, ".cache", "numba")
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "restitution", "numba")


# The numba-compiled sources, relative to the package: every module a kernel may compile in.
_COMPILED = ("jit.py", "kernels", "model", os.path.join("analysis", "special_points.py"))
_key = None


def source_key() -> str:
    """A hash (12 hex digits) of the bytes of the package's numba-compiled sources."""
    global _key
    if _key is None:
        package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        files = []
        for entry in _COMPILED:
            path = os.path.join(package, entry)
            if os.path.isdir(path):
                files += [os.path.join(path, f) for f in os.listdir(path) if f.endswith(".py")]
            else:
                files.append(path)
        digest = hashlib.sha1()
        for f in sorted(files):
            digest.update(os.path.relpath(f, package).encode())
            with open(f, "rb") as fh:
                digest.update(fh.read())
        _key = digest.hexdigest()[:12]
    return _key


def _keyed(path: str) -> str:
    """``path``/source_key() (``path`` itself if it is already that folder: a child process)."""
    key = source_key()
    return path if os.path.basename(os.path.normpath(path)) == key else os.path.join(path, key)


def _use(path: str) -> None:
    """Make ``path`` numba's cache for this process and the processes it starts."""
    os.environ["NUMBA_CACHE_DIR"] = path
    if "numba" in sys.modules:  # numba read the variable when it was imported
        from numba.core import config

        config.CACHE_DIR = path


def ensure_cache() -> str | None:
    """Make sure numba's cache is the one location and one this process can write, before any
    kernel is defined.

    Without ``NUMBA_CACHE_DIR``, ``default_cache_dir()`` is used. Either way the kernels go
    into its folder ``source_key()`` (exported, so that the processes this one starts share
    it). A cache that cannot be written (owned by another user,
    e.g. root, or on a read-only file system) made numba look elsewhere and, where it found no
    writable place, fail at import with a traceback. Then a private cache is used instead,
    ``<tmp>/restitution-numba-<uid>`` (created 0700), with one line on stderr saying so.
    Returns the cache directory chosen here, or None when the given one is kept.
    """
    given = os.environ.get("NUMBA_CACHE_DIR")
    if given:
        keyed = _keyed(given)
        if _writable(keyed):
            if keyed == given:
                return None
            _use(keyed)
            return keyed
    else:
        given = _keyed(default_cache_dir())
        if _writable(given):
            _use(given)
            return given
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    private = os.path.join(tempfile.gettempdir(), f"restitution-numba-{uid}", source_key())
    try:
        os.makedirs(private, mode=0o700, exist_ok=True)
    except OSError:
        private = tempfile.mkdtemp(prefix="restitution-numba-")
    if not _writable(private) or os.stat(private).st_uid != os.getuid():
        private = tempfile.mkdtemp(prefix="restitution-numba-")  # (someone else's folder)
    _use(private)
    print(
        f"restitution: the numba cache {given} is not writable by this user; "
        f"using a private cache {private} instead",
        file=sys.stderr,
        flush=True,
    )
    return private
