"""The random accuracy suite: linear chains whose exact results are checked against the
independent high-precision reference (restitution.solvers.precise). Used by tests/test_accuracy.py
and
benchmarks/bench_accuracy.py (the plot of docs/accuracy.md)."""

from __future__ import annotations

import math

import numpy as np


def random_chain(seed: int, family: str):
    """A random linear chain (m, k, c, kc): ``uniform`` ratios in 0.3..3, ``long`` (the masses
    behind m1 10-100 times heavier: long sequences), ``wide`` ratios in 1e-2..1e2. A quarter
    each of rigid / contact spring x undamped / damped; N = 2..8."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 9))
    if family == "wide":
        m = 10 ** rng.uniform(-2, 2, n)
        k = 10 ** rng.uniform(-2, 2, n - 1)
    else:
        m = rng.uniform(0.3, 3, n)
        k = rng.uniform(0.3, 3, n - 1)
    m[0] = 1.0
    if family == "long":
        m[1:] *= 10 ** rng.uniform(1.0, 2.0)
    kind = rng.integers(0, 4)
    c = np.zeros(n - 1)
    kc = math.inf
    if kind in (1, 3):
        kc = k[0] / 10 ** rng.uniform(-3, 0)
    if kind in (2, 3):
        c = rng.uniform(0, 0.1, n - 1) * (rng.random(n - 1) < 0.6)
    return m, k, c, kc


def suite_scenes(scale: int = 1):
    """(family, seed) of the accuracy suite; ``scale`` > 1 draws that many times more seeds
    (the benchmark's larger run)."""
    return (
        [("uniform", s) for s in range(0, 12 * scale)]
        + [("long", s) for s in range(100, 100 + 18 * scale)]
        + [("wide", s) for s in range(200, 200 + 16 * scale)]
    )
