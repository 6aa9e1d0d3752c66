"""Real eigen-decomposition (LAPACK dgeev) for the exact kernels.

numba's ``np.linalg.eig`` refuses a real matrix with complex eigenvalues ("domain change"), and
the complex route (zgeev on a complex copy) costs about twice as much and returns the members of a
conjugate pair as conjugates only to its round-off. ``eig_real`` calls dgeev through the bridge
numba's own ``eig`` uses (``numba_ez_rgeev`` of numba's helper library, resolved by name, so the
kernels stay cacheable) and returns LAPACK's real form: eigenvalues wr + i wi with each complex
pair adjacent (wi > 0 first, then exactly its conjugate) and eigenvectors vr[j] for a real
eigenvalue, vr[j] +- i vr[j + 1] for a pair.
"""

import numpy as np
from numba import types
from numba.np.linalg import _LAPACK

from restitution.jit import njit

_rgeev = _LAPACK().numba_ez_rgeev(types.float64)
_KIND = ord("d")  # double precision
_NO = ord("N")
_YES = ord("V")


@njit(cache=True)
def eig_real(a):
    """(wr, wi, vr, info) of the real square matrix a (left unchanged); info != 0: LAPACK did not
    converge (the other outputs are then meaningless)."""
    n = a.shape[0]
    buf = np.empty(n * n)  # column-major copy: dgeev overwrites its input
    for j in range(n):
        for i in range(n):
            buf[i + j * n] = a[i, j]
    wr = np.empty(n)
    wi = np.empty(n)
    vl = np.empty((n, 1))
    vr = np.empty((n, n))  # row j = LAPACK's column j
    info = _rgeev(
        _KIND, _NO, _YES, n, buf.ctypes, n, wr.ctypes, wi.ctypes, vl.ctypes, 1, vr.ctypes, n
    )
    return wr, wi, vr, info
