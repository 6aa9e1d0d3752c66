"""Do the numerical methods' error estimates bound their actual errors? Random sweeps against
independent references (a script, not a test: the tests hold the scenes these sweeps found).

Usage: ``NUMBA_CACHE_DIR=.cache/numba .venv/bin/python benchmarks/bench_estimates.py [--scenes N]``

Sweeps (two-mass scenes, log-uniform parameters; seeds fixed, so a rerun gives the same scenes):

- ``reference``: scipy's DOP853 with events (``method="reference"``, rtol 1e-8 and 1e-9) on
  damped linear scenes (alpha 0.1-100, beta 1e-4-1, xi 0.01-10) against the exact kernels.
- ``verlet``: step 0.01, 0.005, 0.002 on linear scenes (xi 0 or 0.01-10) against the exact kernels.
- ``adaptive``: rtol 1e-6, 1e-8, 1e-10 on plastic (eta 0.3-1.6, most not half-integers) and
  Hunt-Crossley (n 1-2.5) contacts against scipy's reference at rtol 1e-12 (plastic) or
  ``adaptive`` at rtol 1e-13 (Hunt-Crossley, which the reference does not take).
- ``reference-scissor``: the reference on scissor links against ``adaptive`` at rtol 1e-13 (23 of
  300 rows outside, the worst 39 times, until the reference held the link's branch: 0, worst
  0.034 with its check at rtol/10; docs/solvers.md).

Per sweep: rows, rows outside (|error| > own estimate + the referee's, or another contact count)
and the worst |error| / estimate. A row whose solve is not ``ok`` is counted apart.
"""

from __future__ import annotations

import argparse
import math
import time
import warnings

import numpy as np

import restitution as R


def _log(rng, lo, hi):
    return float(10.0 ** rng.uniform(math.log10(lo), math.log10(hi)))


def _score(rows, got, ref):
    """Append (outside, ratio) of one row; None if either solve is not ok."""
    if got.status != "ok" or ref.status != "ok":
        rows.append(None)
        return
    err = abs(got.cor - ref.cor)
    bound = got.error_estimate + ref.error_estimate
    rows.append((err > bound or got.n_collisions != ref.n_collisions, err / got.error_estimate))


def reference(n):
    rng, rows = np.random.default_rng(11), []
    for _ in range(n):
        kw = dict(alpha=_log(rng, 0.1, 100), beta=_log(rng, 1e-4, 1), xi=_log(rng, 0.01, 10))
        exact = R.solve(**kw)
        for rtol in (1e-8, 1e-9):
            _score(rows, R.solve(**kw, method="reference", rtol=rtol), exact)
    return rows


def verlet(n):
    rng, rows = np.random.default_rng(22), []
    for _ in range(n):
        xi = float(rng.choice([0.0, _log(rng, 0.01, 10)]))
        kw = dict(alpha=_log(rng, 0.1, 100), beta=_log(rng, 1e-4, 1), xi=xi)
        exact = R.solve(**kw)
        for step in (0.01, 0.005, 0.002):
            _score(rows, R.solve(**kw, method="verlet", step=step), exact)
    return rows


def adaptive(n):
    rng, rows = np.random.default_rng(7), []
    for i in range(n):
        a, xi = _log(rng, 0.3, 30), float(rng.choice([0.0, _log(rng, 0.01, 3)]))
        if i % 2 == 0:
            eta = float(rng.uniform(0.3, 1.6))
            dr = max(float(rng.uniform(0.3, 0.7)), (1 - eta) / 2 + 0.01)
            kw = dict(alpha=a, beta=_log(rng, 1e-3, 1), xi=xi, contact="plastic", eta=eta, dr=dr)
            ref = R.solve(**kw, method="reference", rtol=1e-12)
        else:
            k2 = a / (1 + a)
            law = {"law": "hunt_crossley", "k": _log(rng, 1, 1000)}
            law.update(alpha=float(rng.uniform(0, 0.3)), n=float(rng.uniform(1.0, 2.5)))
            kw = dict(masses=[1.0, a], springs=[k2], dashpots=[2 * xi * k2], contact=law)
            try:
                ref = R.solve(**kw, method="adaptive", rtol=1e-13)
            except R.SceneError:  # a damping too strong for the law's range: not a scene
                continue
        for rtol in (1e-6, 1e-8, 1e-10):
            _score(rows, R.solve(**kw, method="adaptive", rtol=rtol), ref)
    return rows


def reference_scissor(n):
    rng, rows = np.random.default_rng(41), []
    for _ in range(n):
        xi = float(rng.choice([0.0, _log(rng, 0.01, 3)]))
        kw = dict(alpha=_log(rng, 0.3, 30), beta=_log(rng, 1e-3, 1), xi=xi, structure="scissor")
        kw.update(ks_ratio=0.01, L=_log(rng, 1, 100))
        ref = R.solve(**kw, method="adaptive", rtol=1e-13)
        for rtol in (1e-8, 1e-9):
            _score(rows, R.solve(**kw, method="reference", rtol=rtol), ref)
    return rows


SWEEPS = {
    "reference": reference,
    "verlet": verlet,
    "adaptive": adaptive,
    "reference-scissor": reference_scissor,
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=150, help="scenes per sweep")
    parser.add_argument("--only", choices=sorted(SWEEPS), help="one sweep")
    args = parser.parse_args()
    warnings.filterwarnings("ignore")  # scipy's and the laws' warnings on hard scenes
    print(f"{'sweep':18} {'rows':>5} {'not ok':>6} {'outside':>7} {'worst err/est':>13} {'s':>5}")
    for name, sweep in SWEEPS.items():
        if args.only and name != args.only:
            continue
        t0 = time.perf_counter()
        rows = sweep(args.scenes)
        done = [r for r in rows if r is not None]
        outside = sum(r[0] for r in done)
        worst = max((r[1] for r in done), default=math.nan)
        print(
            f"{name:18} {len(done):5d} {len(rows) - len(done):6d} {outside:7d} {worst:13.3g} "
            f"{time.perf_counter() - t0:5.0f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
