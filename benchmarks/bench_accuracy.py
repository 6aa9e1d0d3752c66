"""Accuracy of the exact kernels' error estimates, and the cost of the replica check (a script,
not a test).

Usage: .venv/bin/python benchmarks/bench_accuracy.py [--scale 3] [--plot docs/accuracy.png]

1. The random accuracy suite (restitution_workflow.bench.accuracy, ``scale`` times the test's
seeds):
   every scene solved by ``restitution.solve`` and by the independent mpmath reference
   (restitution.solvers.precise, 30 digits checked at 50). Prints, per family, the rows that are ok,
   refused, outside their estimate, and the largest actual error / estimate; plots the actual
   error against the estimate (every point must lie below the diagonal).
2. The cost of the replica check: one thread, best of 5, microseconds per contact of the exact
   kernels with the check (the public kernels) and without it (the same run alone), for the
   paper's two masses (rigid wall and beta = 1e-3, alpha sweeps) and random chains.
"""

from __future__ import annotations

import argparse
import math
import time
from multiprocessing import Pool

import numpy as np

import restitution as R
from restitution.solvers.precise import solve_precise
from restitution_workflow.bench.accuracy import random_chain, suite_scenes

FLOOR = 1e-17  # actual errors of 0 are drawn here


def _row(scene):
    family, seed = scene
    m, k, c, kc = random_chain(seed, family)
    r = R.solve(masses=m, springs=k, dashpots=c, k_contact=kc, max_events=2000)
    ref = solve_precise(m, k, c, kc, dps=30, max_events=2000)
    actual = abs(r.cor - ref.cor) if r.status == "ok" else math.nan
    return family, seed, r.status, r.n_collisions, ref.n_collisions, actual, r.error_estimate


def accuracy(scale: int, plot: str | None) -> None:
    with Pool(2) as pool:
        rows = pool.map(_row, suite_scenes(scale), chunksize=1)
    print(f"accuracy suite: {len(rows)} random chains against the 30-digit reference")
    print(f"{'family':8} {'rows':>5} {'ok':>4} {'refused':>8} {'outside':>8} {'max err/est':>12}")
    for fam in ("uniform", "long", "wide", "all"):
        sel = [r for r in rows if fam in ("all", r[0])]
        ok = [r for r in sel if r[2] == "ok"]
        outside = sum(not (r[5] <= r[6]) or r[3] != r[4] for r in ok)
        ratio = max((r[5] / r[6] for r in ok), default=math.nan)
        print(
            f"{fam:8} {len(sel):5d} {len(ok):4d} {len(sel) - len(ok):8d} {outside:8d} {ratio:12.3g}"
        )
    long = sum(r[3] >= 30 for r in rows)
    print(f"rows with >= 30 contacts: {long}; most contacts: {max(r[3] for r in rows)}")
    if plot:
        _plot(rows, plot)


def _plot(rows, path):
    from restitution import plotting as P

    P.use_style()
    fig = P.new_figure("single", aspect=0.85)
    ax = fig.add_subplot()
    markers = {"uniform": ("o", "ratios 0.3-3"), "long": ("s", "long sequences"),
               "wide": ("^", "ratios 1e-2-1e2")}  # fmt: skip
    for fam, (mk, text) in markers.items():
        ok = [r for r in rows if r[0] == fam and r[2] == "ok"]
        est = np.array([r[6] for r in ok])
        act = np.maximum([r[5] for r in ok], FLOOR)
        ax.plot(est, act, mk, ms=3.5, mfc="none", mew=0.8, color="0.15", ls="none",
                label=f"{text} ({len(ok)})")  # fmt: skip
    lo, hi = 1e-17, 1e-3
    ax.plot([lo, hi], [lo, hi], color="0.55", lw=1.0, ls="--", label="actual = estimate")
    ax.set(xscale="log", yscale="log", xlim=(1e-15, hi), ylim=(lo, hi))
    ax.set_xlabel("error_estimate")
    ax.set_ylabel("actual COR error (vs 30-digit reference)")
    refused = sum(r[2] != "ok" for r in rows)
    ax.set_title(f"{len(rows)} random chains, {refused} refused", fontsize="medium")
    ax.legend(loc="upper left", fontsize="small")
    fig.savefig(path, metadata=P.METADATA.get("png"))
    print(f"wrote {path}")


def _time(fn, reps=5):
    best = math.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        n = fn()
        best = min(best, time.perf_counter() - t0)
    return best, n


def cost() -> None:
    import numba

    from restitution.kernels.constants import V_STICK_RIGID2
    from restitution.kernels.exact_chain import WORK_MAX, _normalise, _solve_stiff, _solve_units
    from restitution.kernels.layout import N_HIST, OUT_NCOL
    from restitution.kernels.rigid2 import _rigid2, rigid2

    numba.set_num_threads(1)
    nohist = np.zeros((0, N_HIST))
    alphas = np.geomspace(0.5, 100, 200)

    def paper(beta, checked):
        def run():
            n = 0
            for a in alphas:
                m, k, c, kc = np.array([1.0, a]), np.array([a / (1 + a)]), np.zeros(1), math.inf
                if beta > 0:
                    kc = k[0] / beta
                if beta == 0:
                    out = (
                        rigid2(a, 0.0, 100_000, nohist)
                        if checked
                        else _rigid2(a, 0.0, 100_000, nohist, V_STICK_RIGID2)
                    )
                else:
                    ms, ks, cs, kcs = _normalise(m, k, c, kc)
                    out = (
                        _solve_stiff(ms, ks, cs, kcs, 100_000, nohist, WORK_MAX, True)
                        if checked
                        else _solve_units(ms, ks, cs, kcs, 100_000, nohist, WORK_MAX, True, 0.0, 0)
                    )
                n += int(out[OUT_NCOL])
            return n

        return run  # fmt: skip

    chains = [_normalise(*random_chain(s, "uniform")) for s in range(40)]

    def general(checked):
        def run():
            n = 0
            for ms, ks, cs, kcs in chains:
                if checked:
                    out = _solve_stiff(ms, ks, cs, kcs, 100_000, nohist, WORK_MAX, True)
                else:
                    out = _solve_units(ms, ks, cs, kcs, 100_000, nohist, WORK_MAX, True, 0.0, 0)
                n += int(out[OUT_NCOL])
            return n

        return run

    cases = [
        ("two masses, rigid wall, alpha 0.5-100", paper(0.0, True), paper(0.0, False)),
        ("two masses, beta = 1e-3, alpha 0.5-100", paper(1e-3, True), paper(1e-3, False)),
        ("40 random chains N = 2..8 (uniform)", general(True), general(False)),
    ]
    print("\ncost of the replica check (one thread, best of 5), us per contact:")
    print(f"{'scenes':42} {'contacts':>9} {'without':>9} {'with':>9} {'ratio':>6}")
    for name, with_, without in cases:
        with_()
        without()  # compile
        tw, n = _time(with_)
        t0, _ = _time(without)
        print(f"{name:42} {n:9d} {1e6 * t0 / n:9.3f} {1e6 * tw / n:9.3f} {tw / t0:6.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", type=int, default=3)
    ap.add_argument("--plot", default=None, help="PNG of actual error against the estimate")
    ap.add_argument("--skip-accuracy", action="store_true")
    ap.add_argument("--skip-cost", action="store_true")
    args = ap.parse_args()
    if not args.skip_accuracy:
        accuracy(args.scale, args.plot)
    if not args.skip_cost:
        cost()


if __name__ == "__main__":
    main()
