"""Array copies for the kernels, written as loops.

In a numba kernel a slice or row assignment (``y[:] = ynew``, ``out[i, :] = row``) makes an array
view, which in a kernel with reference counts costs two atomic operations each time (about 7 % of
a plastic scene's adaptive run, 2026-11-27), and compiles numpy's shape-mismatch error with it:
its message formatting (string concatenation, repr of the shapes) was about a dozen extra
compiled functions and 1-2 s of a first call. These loops do neither; they copy the same values.
"""

from __future__ import annotations

from restitution.jit import njit


@njit(cache=True, error_model="numpy", refcount=False)
def copy_into(dst, src):
    """The first min(len(dst), len(src)) entries of src into dst (1-D)."""
    for i in range(min(dst.shape[0], src.shape[0])):
        dst[i] = src[i]


@njit(cache=True, error_model="numpy", refcount=False)
def copy_row(dst, A, r):
    """dst[:] = A[r]."""
    for i in range(dst.shape[0]):
        dst[i] = A[r, i]


@njit(cache=True, error_model="numpy", refcount=False)
def put_row(A, r, src):
    """A[r, :] = src."""
    for i in range(A.shape[1]):
        A[r, i] = src[i]


@njit(cache=True, error_model="numpy", refcount=False)
def put_rows(dst, src):
    """dst[:] = src (2-D), over the rows both have."""
    for i in range(min(dst.shape[0], src.shape[0])):
        for j in range(dst.shape[1]):
            dst[i, j] = src[i, j]


@njit(cache=True, error_model="numpy", refcount=False)
def fill_2d(A, value):
    """A[:, :] = value."""
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            A[i, j] = value
