"""The row order of the parallel batch kernels and the thread pool of the chain batches
(restitution.kernels.parallel)."""

import numba
import numpy as np
import pytest

from restitution.jit import njit
from restitution.kernels.layout import N_HIST
from restitution.kernels.parallel import BLOCK, MIN_BLOCKS, over_threads, row_blocks, spread_order
from restitution.kernels.rigid2 import rigid2, rigid2_batch


def _order(n):
    nb, size, p = row_blocks(n)
    return [
        i for k in range(nb) for i in range((k * p) % nb * size, min(n, (k * p) % nb * size + size))
    ]


@pytest.mark.parametrize("n", [0, 1, 2, 3, 4, 5, 7, 12, 100, 210, 1023, 1024, 1025, 20_000, 30_031])
def test_every_row_once(n):
    assert sorted(_order(n)) == list(range(n))


@pytest.mark.parametrize("n", [100, 1000, 20_000])
@pytest.mark.parametrize("threads", [2, 3, 4, 8])
def test_threads_get_even_samples_of_a_sorted_sweep(n, threads):
    """Cost growing steeply along the table (a sorted sweep): the contiguous share of the
    iterations a thread gets under a static schedule costs within 5 % of its fair share once it
    holds 25 rows or more (in table order the last thread's share costs 1.75-2.6 times it)."""
    order = np.array(_order(n))
    cost = 1.0 + np.arange(n) ** 2
    fair = cost.sum() / threads
    spread = max(cost[part].sum() for part in np.array_split(order, threads)) / fair
    in_order = max(cost[part].sum() for part in np.array_split(np.arange(n), threads)) / fair
    assert in_order > 1.7
    assert spread < (1.05 if n >= 25 * threads else 1.2)


def test_blocked_batch_matches_rows_for_any_thread_count():
    """A table large enough for blocks (with a short last block) gives the rows rigid2 gives."""
    n = BLOCK * MIN_BLOCKS + 5
    alpha = np.geomspace(0.05, 50.0, n)
    xi = np.where(np.arange(n) % 2 == 0, 0.0, 0.3)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = rigid2_batch(alpha, xi, 5000)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = rigid2_batch(alpha, xi, 5000)
    finally:
        numba.set_num_threads(before)
    rows = np.array(
        [rigid2(a, x, 5000, np.zeros((0, N_HIST))) for a, x in zip(alpha, xi, strict=True)]
    )
    assert np.array_equal(one, rows, equal_nan=True)
    assert np.array_equal(two, rows, equal_nan=True)


@pytest.mark.parametrize("n", [0, 1, 5, 1023, 1025, 20_000])
def test_spread_order_is_the_block_order(n):
    assert spread_order(n).tolist() == _order(n)


@njit(nogil=True)
def _count_rows(out, order, start, stop):
    for j in range(start, stop):
        out[order[j]] += 1.0 + order[j]


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("n", [1, 3, 100, 2049])
def test_over_threads_visits_every_row_once(n, threads):
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        out = np.zeros(n)
        over_threads(_count_rows, n, out)
    finally:
        numba.set_num_threads(before)
    assert np.array_equal(out, 1.0 + np.arange(n))


def _count_in_child(n, queue):
    out = np.zeros(n)
    over_threads(_count_rows, n, out)
    queue.put(out.tolist())


def test_over_threads_in_a_forked_child():
    """A child forked after a batch ran (multiprocessing's default on Linux) runs its own: the
    pool's threads do not survive a fork."""
    import multiprocessing

    if numba.config.NUMBA_NUM_THREADS < 2 or "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("needs two threads and fork")
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(2)
        over_threads(_count_rows, 50, np.zeros(50))  # the parent's pool exists
        context = multiprocessing.get_context("fork")
        queue = context.Queue()
        child = context.Process(target=_count_in_child, args=(50, queue))
        child.start()
        try:
            got = queue.get(timeout=60)
        finally:
            child.join(timeout=5)
            if child.is_alive():  # (hung: do not leave it behind)
                child.kill()
    finally:
        numba.set_num_threads(before)
    assert got == (1.0 + np.arange(50)).tolist()
