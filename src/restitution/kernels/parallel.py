"""Row order of the parallel batch kernels: every thread gets an even sample of the table.

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

Use::

    nb, size, p = row_blocks(n)
    for k in prange(nb):
        b = (k * p) % nb
        for i in range(b * size, min(n, b * size + size)):
            ...  # row i
"""

from restitution.kernels.jit import njit

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
