"""Work-precision of the nonlinear contact scenes: the adaptive kernel against solve_ivp, both
scored against an independent reference (issue 27).

Usage: .venv/bin/python benchmarks/bench_nonlinear_precision.py [--quick]

Scenes: Hertz contact on two masses and on the three-mass chain of the issue, and the paper's
plastic contact (the hard suite's ``plastic`` scene: eta = 0.5, reloads past the maximum). The
reference is ``benchmarks/mp_nonlinear.py`` (mpmath Taylor series, sigma = sqrt(x) at the power
law's ends) at 30 and 40 digits; its bound is their difference. For every rtol the adaptive
method's median time per solve (one thread, checks included: ``restitution.solve`` runs the
setting and its check at rtol/100; rtol/10 until 2026-11-27), its actual COR error and its
``error_estimate`` are printed; for the two-mass scenes the same for scipy's ``solve_ivp``
(DOP853, LSODA, Radau, RK45, with terminal events; ``restitution.solvers.reference``). Then,
per target error, the fastest setting of each family that reached it, and the ratio. Runs
unchanged on an older checkout (public API only), for before/after numbers.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import mp_nonlinear as MP  # noqa: E402

import restitution as R  # noqa: E402
from restitution.kernels import layout as LY  # noqa: E402
from restitution.model import laws  # noqa: E402
from restitution.solvers.numerical import packed  # noqa: E402
from restitution.solvers.reference import solve_reference  # noqa: E402

# One grid of half decades for both families, so neither is scored at a setting far tighter than
# it needs (a decade grid moved the ratios by up to 2x). It reaches rtol 1e-4 for both: since the
# adaptive method returns its rtol/100 run (2026-11-27), its results at rtol 1e-6 were already
# near 1e-9, and a grid starting there scored it at a setting tighter than the 1e-8 target needs.
RTOLS = (1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11,
         1e-11, 3e-12, 1e-12, 3e-13, 1e-13)  # fmt: skip
ADAPTIVE_RTOLS = (*RTOLS, 1e-14)
IVP_RTOLS = RTOLS
IVP_METHODS = ("DOP853", "LSODA", "Radau", "RK45")
TARGETS = (1e-8, 1e-10, 1e-12)


def scenes():
    """(name, Chain, mp chain) of each scene; the plastic scene in the paper's kernel units."""
    out = []
    a = 2.0
    k2 = a / (1 + a)
    out.append(
        (
            "hertz2",
            R.Chain([1.0, a], [k2], v0=1.0, contact={"law": "hertz", "k": 20.0}),
            MP.Chain([1.0, a], [k2], None, ("hertz", 20.0)),
        )
    )
    out.append(
        (
            "hertz3",
            R.Chain([1, 0.5, 2], [0.3, 1.2], contact={"law": "hertz", "k": 50}),
            MP.Chain([1, 0.5, 2], [0.3, 1.2], None, ("hertz", 50.0)),
        )
    )
    ch = R.Chain.paper(5.0, 1e-2)
    ms, lk, _, _, _, _ = packed(ch)
    k2 = float(lk[0][laws.SP_K2])
    pch = R.Chain(
        list(ms), [k2], v0=1.0, contact={"law": "plastic", "k": k2 / 1e-2, "eta": 0.5, "dr": 0.3}
    )
    _, _, _, cp, _, _ = packed(pch)
    out.append(
        (
            "plastic",
            pch,
            MP.Chain(list(ms), [k2], None, ("plastic", cp[1], cp[2], cp[3])),
        )
    )
    return out


def reference(mpch, v0=1.0):
    lo = MP.solve(mpch, v0, 30)
    hi = MP.solve(mpch, v0, 40)
    assert lo["contacts"] == hi["contacts"]
    bound = float(abs(lo["cor"] - hi["cor"])) * 10 + 2**-53
    return float(hi["cor"]), hi["contacts"], bound


def timed(fn, min_time):
    fn()
    t0 = time.perf_counter()
    r = fn()
    once = time.perf_counter() - t0
    number = max(1, int(min_time / max(once, 1e-7) / 3))
    runs = []
    for _ in range(3):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        runs.append((time.perf_counter() - t0) / number)
    return r, statistics.median(runs)


def ivp_runner(ch, method, rtol):
    ms, lk, cs, cp, _, _ = packed(ch)
    alpha, v0, sp = float(ms[1]), float(ch.v0), lk[0]
    xi = float(cs[0]) / (2.0 * float(sp[laws.SP_K2]))

    def run():
        out, _ = solve_reference(
            alpha, v0, xi, cp, sp, rtol, 10_000, np.zeros(5), math.inf,
            method=method, atol=rtol * v0, steps_per_period=None, minima=False, branches=False,
        )  # fmt: skip
        return out

    return run


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="shorter timings (0.05 s per setting)")
    args = ap.parse_args(argv)
    min_time = 0.05 if args.quick else 0.3
    import numba

    numba.set_num_threads(1)
    for name, ch, mpch in scenes():
        ref, ncol, bound = reference(mpch)
        print(f"\n## {name}: reference COR {ref!r}, {ncol} contacts, bound {bound:.1e}")
        print(f"{'family':10s} {'rtol':>7s} {'time':>10s} {'error':>9s} {'estimate':>9s} ncol")
        best = {}
        t_last = {}
        rows = [("adaptive", rtol) for rtol in ADAPTIVE_RTOLS]
        if ch.n_masses == 2:
            rows += [(m, rtol) for m in IVP_METHODS for rtol in IVP_RTOLS]
        for family, rtol in rows:
            if family == "adaptive":

                def run(ch=ch, rtol=rtol):
                    return R.solve(ch, method="adaptive", rtol=rtol)

                r, t = timed(run, min_time)
                cor, n, est, ok = r.cor, r.n_collisions, r.error_estimate, r.status == "ok"
            else:
                if t_last.get(family, 0) > 2.0:
                    continue  # tighter settings only take longer
                r, t = timed(ivp_runner(ch, family, rtol), min_time)
                cor, n, est = r[LY.OUT_COR], int(r[LY.OUT_NCOL]), math.nan
                ok = r[LY.OUT_STATUS] == LY.STATUS_OK
            t_last[family] = t
            err = abs(cor - ref) if ok else math.nan
            print(f"{family:10s} {rtol:7.0e} {t * 1e6:8.0f}us {err:9.1e} {est:9.1e} {n}")
            for target in TARGETS:
                if ok and n == ncol and err + bound <= target:
                    key = (family, target)
                    if key not in best or t < best[key][0]:
                        best[key] = (t, rtol)
        print(f"fastest setting within each target error (reference bound {bound:.0e} added):")
        for target in TARGETS:
            a = best.get(("adaptive", target))
            ivp = [(best[(m, target)], m) for m in IVP_METHODS if (m, target) in best]
            line = f"  {target:.0e}: adaptive " + (
                f"{a[0] * 1e6:.0f}us (rtol {a[1]:.0e})" if a else "not reached"
            )
            if ivp:
                (ti, ri), m = min(ivp)
                line += f"; best solve_ivp {m} {ti * 1e6:.0f}us (rtol {ri:.0e})"
                if a:
                    line += f"; ratio {ti / a[0]:.0f}x"
            elif ch.n_masses == 2:
                line += "; no solve_ivp method reached it"
            print(line)
        print(f"per contact phase (adaptive, two runs per solve): see time / (2 x {ncol})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
