"""One BLAS thread while the kernels run.

The exact chain kernels call LAPACK (eigen-decompositions of matrices up to 2N x 2N) from numba
code, through the OpenBLAS that scipy and numpy ship. OpenBLAS starts as many threads as the
machine has cores; for these small matrices, and inside numba's parallel loops or next to any
other busy thread, its threads cost far more than they give: a chain of N = 128 took 1.3 s with
two OpenBLAS threads on a two-core machine against 20 ms with one (N = 64: 0.43 s against 4 ms).
So every kernel call that can reach LAPACK runs under a limit of one BLAS thread, set with
threadpoolctl and restored afterwards (the user's own numpy keeps its setting). The limit costs
~12 us per call, so a single scene takes it only from ``SMALL_N`` masses on, where LAPACK's
threads start (below that the kernels' matrices are too small for OpenBLAS to thread them).
"""

from __future__ import annotations

import contextlib

SMALL_N = 16  # below this many masses a single solve skips the limit (see the module docstring)

_controller = None


def _get_controller():
    global _controller
    if _controller is None:
        import scipy.linalg.cython_lapack  # noqa: F401 - load the LAPACK numba calls first
        from threadpoolctl import ThreadpoolController

        _controller = ThreadpoolController()
    return _controller


def one_thread(n_masses: int | None = None):
    """Context manager: one BLAS thread inside (``n_masses`` below SMALL_N: no limit)."""
    if n_masses is not None and n_masses < SMALL_N:
        return contextlib.nullcontext()
    return _get_controller().limit(limits=1, user_api="blas")
