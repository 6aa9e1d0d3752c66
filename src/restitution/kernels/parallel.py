"""Row order of the parallel batch kernels: every thread gets an even sample of the table; and
``over_threads``, which runs a serial row kernel on numba's thread count.

numba's ``prange`` gives each thread one contiguous block of iterations. Scene tables are mostly
sweeps sorted by a parameter that sets the cost of a row (the number of contacts grows with
alpha), so contiguous blocks left one thread with nearly all the work: 20,000 rows of a sorted
alpha sweep took as long on two threads as on one (41 ms; now 23 ms). The batch kernels
therefore split the rows into ``nb`` blocks of ``size`` consecutive rows and visit block
``(k * p) % nb`` at iteration k, with a step p coprime with nb near nb / phi (golden ratio): a
Weyl sequence, so any run of consecutive iterations - whatever a thread gets, for any thread
count - is an even sample of the table. Rows inside a block stay in order (a sweep's neighbours
run alike; visiting single rows in the spread order cost 7 % on one thread). Rows stay
independent: results are bit-identical for any thread count.

The chain batches (``paper_chain``, ``exact_chain``, ``stepping``) do not use ``prange``: a
``parallel=True`` kernel compiles everything it calls twice more (its parallel region is a
kernel of its own), 15 s against 4 s for the same loop serial (2026-11-26, quiet). They are a
serial row kernel (``nogil``) over a slice of ``spread_order(n)``, which ``over_threads`` runs
in chunks on a pool of ``numba.get_num_threads()`` threads (so ``numba.set_num_threads`` and
``NUMBA_NUM_THREADS`` still set how many run).

Use::

    nb, size, p = row_blocks(n)
    for k in prange(nb):
        b = (k * p) % nb
        for i in range(b * size, min(n, b * size + size)):
            ...  # row i
"""

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from restitution.jit import njit

CHUNKS_PER_THREAD = 4  # chunks of the spread order per thread (the pool balances what is left)
BLOCK = 16  # rows per block on large tables
MIN_BLOCKS = 64  # below BLOCK * MIN_BLOCKS rows, blocks of one row (balance first)
_INV_PHI = 0.6180339887498949


@njit(cache=True)
def row_blocks(n):
    """(nb, size, p): n rows as nb blocks of size rows (the last may be short), visited in the
    order k -> (k * p) % nb (every block once; consecutive k spread evenly)."""
    size = BLOCK if n >= BLOCK * MIN_BLOCKS else 1
    nb = (n + size - 1) // size
    return nb, size, _step(nb)


@njit(cache=True)
def _step(nb):
    """A step coprime with nb near nb / phi (1 for nb < 3)."""
    if nb < 3:
        return 1
    p = int(nb * _INV_PHI)
    while _gcd(p, nb) != 1:
        p += 1
    return p


@njit(cache=True)
def _gcd(a, b):
    while b:
        a, b = b, a % b
    return a


def spread_order(n: int) -> np.ndarray:
    """The rows 0..n-1 in the order the blocks of ``row_blocks(n)`` are visited (int64)."""
    nb, size, p = row_blocks(n)
    starts = (np.arange(nb, dtype=np.int64) * p) % nb * size
    order = (starts[:, None] + np.arange(size, dtype=np.int64)[None, :]).ravel()
    return order[order < n]


def over_threads(kernel, n: int, *args) -> None:
    """``kernel(*args, order, start, stop)`` for consecutive slices [start, stop) of
    ``order = spread_order(n)`` covering every row once, on ``numba.get_num_threads()``
    threads (the kernel must be ``nogil`` and write row ``order[j]`` only). A kernel error is
    raised here once every chunk has ended."""
    import numba

    from restitution.kernels.compiling import announce

    announce(kernel)
    order = spread_order(n)
    threads = min(numba.get_num_threads(), n)
    if threads <= 1:
        kernel(*args, order, 0, n)
        return
    if not getattr(kernel, "signatures", True):  # (a plain function under NUMBA_DISABLE_JIT)
        kernel(*args, order, 0, 0)  # compile (or load) it once, before the threads call it
    edges = np.linspace(0, n, min(n, threads * CHUNKS_PER_THREAD) + 1).astype(np.int64).tolist()
    chunks = iter(range(len(edges) - 1))
    lock = threading.Lock()

    def work():  # each thread takes the next chunk until none is left (dynamic balance)
        while True:
            with lock:
                c = next(chunks, None)
            if c is None:
                return
            kernel(*args, order, edges[c], edges[c + 1])

    helpers = [_pool(threads).submit(work) for _ in range(threads - 1)]
    try:
        work()  # the calling thread is one of the threads
    finally:
        for helper in helpers:
            helper.result()


_pools = {}


def _pool(threads: int) -> ThreadPoolExecutor:
    """The pool of this many threads, kept for later calls (starting one costs ~0.3 ms, five
    times a small table's kernel); its threads, idle when no batch runs, end with the process."""
    # keyed by process too: a forked child inherits the pool without its threads (a task
    # submitted there would wait for ever)
    key = (os.getpid(), threads)
    if key not in _pools:
        _pools[key] = ThreadPoolExecutor(threads - 1, thread_name_prefix="restitution-rows")
    return _pools[key]
