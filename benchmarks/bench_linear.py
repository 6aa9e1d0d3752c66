"""Timings of the exact piecewise-linear kernel (a script, not a test).

Usage: NUMBA_NUM_THREADS=1 .venv/bin/python benchmarks/bench_linear.py [--reference] [--sweep N]

Prints the time per scene (best of several repeats, after JIT warm-up, one thread) for the
paper's hard cases (beta = 1e-3, alpha = 100 and 200, xi in {0, 0.3, 3}), an N = 32 chain and an
alpha sweep at beta = 1e-3, and the COR difference to the solve_ivp reference of
tests/test_linear.py where that is affordable (--reference adds the expensive ones).
"""

import argparse
import math
import os
import sys
import time

import numba
import numpy as np

from restitution.kernels.layout import N_HIST, OUT_COR, OUT_NCOL, OUT_STATUS
from restitution.kernels.paper_chain import solve_linear, solve_linear_batch

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))
from test_linear import reference  # noqa: E402

NOHIST = np.zeros((0, N_HIST))


def best_time(fn, repeat=5):
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reference", action="store_true", help="also run the slow references")
    ap.add_argument("--sweep", type=int, default=2000, help="number of alphas in the sweep")
    args = ap.parse_args()
    numba.set_num_threads(1)
    solve_linear(1.0, 1e-3, 0.3, 3, 10, NOHIST)  # JIT warm-up (or cache load)
    solve_linear_batch(np.ones(2), np.full(2, 1e-3), np.zeros(2), np.full(2, 2), 10)

    cases = [
        (200.0, 1e-3, 0.0, 2, False),
        (200.0, 1e-3, 0.3, 2, False),
        (200.0, 1e-3, 3.0, 2, False),
        (100.0, 1e-3, 0.0, 2, False),
        (100.0, 1e-3, 0.3, 2, False),
        (100.0, 1e-3, 3.0, 2, False),
        (2.2, 0.1, 0.0, 2, True),
        (2.2, 0.1, 0.3, 2, True),
        (10.0, 1e-3, 0.0, 32, False),
        (10.0, 1e-3, 0.3, 32, False),
        (1.0, 1e-2, 0.0, 32, True),
    ]
    print(
        f"{'alpha':>7} {'beta':>7} {'xi':>4} {'N':>3} {'contacts':>8} {'COR':>12} "
        f"{'ms/scene':>9} {'|dCOR| vs ref':>14}"
    )
    for alpha, beta, xi, n, cheap in cases:
        out = solve_linear(alpha, beta, xi, n, 100_000, NOHIST)
        dt = best_time(lambda a=alpha, b=beta, x=xi, k=n: solve_linear(a, b, x, k, 100_000, NOHIST))
        diff = "-"
        if cheap or args.reference:
            cor = reference(alpha, beta, xi, n, max_contacts=100_000)[0]
            diff = f"{abs(cor - out[OUT_COR]):.1e}"
        flag = "" if out[OUT_STATUS] == 0 else f" status={int(out[OUT_STATUS])}"
        print(
            f"{alpha:7g} {beta:7g} {xi:4g} {n:3d} {int(out[OUT_NCOL]):8d} {out[OUT_COR]:12.9f} "
            f"{dt * 1e3:9.3f} {diff:>14}{flag}"
        )

    k = args.sweep
    alphas = np.geomspace(0.01, 200.0, k)
    for xi in (0.0, 0.3):
        beta = np.full(k, 1e-3)
        xis = np.full(k, xi)
        ns = np.full(k, 2, np.int64)
        t0 = time.perf_counter()
        out = solve_linear_batch(alphas, beta, xis, ns, 100_000)
        dt = time.perf_counter() - t0
        ok = np.count_nonzero(out[:, OUT_STATUS] == 0)
        print(
            f"sweep: {k} alphas in [0.01, 200], beta = 1e-3, xi = {xi}: "
            f"{dt / k * 1e3:.3f} ms/scene (one thread), {ok}/{k} status OK, "
            f"max contacts {int(out[:, OUT_NCOL].max())}"
        )


if __name__ == "__main__":
    main()
