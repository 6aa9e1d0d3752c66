"""Kernel calls run with one BLAS thread (restitution.solvers.blas), and the user's setting comes
back."""

import numpy as np
import pandas as pd
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

import restitution
from restitution.kernels import exact_chain as chain_kernels
from restitution.solvers import blas


def blas_threads() -> set:
    return {i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}


@pytest.fixture
def two_threads():
    """Two BLAS threads outside (the default on a two-core machine), whatever the environment."""
    blas._get_controller()  # loads scipy's LAPACK, so that threadpoolctl sees every BLAS
    with threadpool_limits(limits=2, user_api="blas"):
        assert blas_threads() == {2}
        yield


def test_one_thread_inside_and_restored_after(two_threads):
    with blas.one_thread():
        assert blas_threads() == {1}
    assert blas_threads() == {2}
    with blas.one_thread(blas.SMALL_N - 1):  # small scenes: no limit (it costs ~12 us)
        assert blas_threads() == {2}


def test_a_long_chain_solves_under_the_limit(two_threads, monkeypatch):
    seen = []
    real = chain_kernels.solve_chain

    def spy(*args, **kwargs):
        seen.append(blas_threads())
        return real(*args, **kwargs)

    monkeypatch.setattr(chain_kernels, "solve_chain", spy)
    n = blas.SMALL_N + 4
    masses = np.linspace(1.0, 2.0, n).tolist()
    r = restitution.solve(masses=masses, springs=[1.0] * (n - 1))
    assert r.status == "ok" and seen == [{1}]
    assert blas_threads() == {2}


def test_a_batch_runs_under_the_limit(two_threads, monkeypatch):
    seen = []
    real = chain_kernels.solve_chain_batch

    def spy(*args):
        seen.append(blas_threads())
        return real(*args)

    monkeypatch.setattr(chain_kernels, "solve_chain_batch", spy)
    table = pd.DataFrame({"masses": [[1.0, 0.5, 2.0]] * 3, "springs": [[0.3, 1.2]] * 3})
    out = restitution.solve_many(table, progress=False)
    assert (out["status"] == "ok").all() and seen == [{1}]
    assert blas_threads() == {2}
