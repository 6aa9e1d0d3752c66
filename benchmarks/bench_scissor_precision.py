"""Work-precision of the scissor scenes: the adaptive kernel against the mpmath reference
(issue 27: the scissor spring at 1e-12).

Usage:
  .venv/bin/python benchmarks/bench_scissor_precision.py --reference ref.json   # mpmath, slow
  .venv/bin/python benchmarks/bench_scissor_precision.py --out run.json [--reps 5]
  .venv/bin/python benchmarks/bench_scissor_precision.py --compare ref.json run.json [more.json]

Scenes: the hard suite's ``scissor`` scene (Fig. 5(b): beta = 1, ks = k1/100, alpha = 1, L = 54,
its peak compression just past the lock) and chains that reach every branch point of the law
(the pads' cap, the lock, the tension cap) with a rigid wall or a linear contact. ``--reference``
solves them by ``restitution.solvers.precise_scissor`` (30 digits checked at 40). A plain run
times ``restitution.solve`` (method ``adaptive``, one thread, its check run at rtol/10 included,
median of ``--reps``) at rtol 1e-8..1e-12 and finds its work in right-hand-side evaluations (the
smallest work budget the kernel finishes with, by bisection on ``max_work``). It uses the public
API and the kernel entry only, so it runs unchanged on an older checkout: before/after numbers.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time

import numpy as np

import restitution as R
from restitution.model.chain import paper_with_laws

RTOLS = (1e-8, 1e-9, 1e-10, 1e-11, 1e-12)


def scenes():
    """name -> Chain."""
    sc = dict(law="scissor")
    out = {}
    paper, _ = paper_with_laws(
        1.0, 1.0, 0.0, 2, {"structure": "scissor", "ks_ratio": 0.01, "L": 54.0}
    )
    out["hard-suite scissor (alpha 1, beta 1, L 54)"] = paper
    # tests/test_hard.py's soft scissor: an elastic scene whose COR is 1 - 2.7e-9
    soft, _ = paper_with_laws(
        1.0, 0.01, 0.0, 2, {"structure": "scissor", "ks_ratio": 0.01, "L": 1.0}
    )
    out["soft scissor (alpha 1, beta 0.01, L 1)"] = soft
    out["rigid wall, L 2 (pads, lock)"] = R.Chain(
        masses=[1.0, 2.0], springs=[1.0], links=[dict(sc, L=2.0, ks=0.01)]
    )
    out["contact, theta0 1.2, corner 0.3 (lock, cap)"] = R.Chain(
        masses=[1.0, 0.5],
        springs=[2.0],
        k_contact=4.0,
        links=[dict(sc, L=0.5, ks=0.3, theta0=1.2, corner=0.3)],
    )
    out["N 3 rigid, scissor + linear"] = R.Chain(
        masses=[1.0, 1.5, 0.7],
        springs=[1.0, 2.0],
        links=[dict(sc, L=1.0, ks=0.05), dict(law="linear")],
    )
    out["N 4 contact, two scissors, dashpot"] = R.Chain(
        masses=[1.0, 0.8, 1.2, 0.6],
        springs=[1.5, 1.0, 2.0],
        dashpots=[0.0, 0.05, 0.0],
        k_contact=3.0,
        links=[
            dict(sc, L=0.8, ks=0.02, theta0=0.4),
            dict(law="linear"),
            dict(sc, L=0.3, ks=1.5, theta0=1.1),
        ],
    )
    return out


def reference(path, only=None):
    from restitution.solvers.precise_scissor import solve_precise_scissor

    out = {}
    for name, ch in scenes().items():
        if only and only not in name:
            continue
        t = time.perf_counter()
        cor, ncol, bound, crossed = solve_precise_scissor(ch)
        out[name] = dict(cor=cor, contacts=ncol, bound=bound, points=sorted(crossed))
        print(f"{name}: {cor!r} ({ncol} contacts, bound {bound:.1e}, points {sorted(crossed)}, "
              f"{time.perf_counter() - t:.0f} s)", flush=True)  # fmt: skip
    with open(path, "w") as f:
        json.dump(out, f, indent=1)


def work(ch, rtol):
    """Right-hand-side evaluations of one kernel run (no check run): the smallest budget it
    finishes with."""
    from restitution.kernels import stepping
    from restitution.solvers.numerical import packed

    m, lk, c, cp, _, _ = packed(ch)

    def ok(budget):
        out = stepping.solve_scene(
            m, lk, c, cp, float(ch.v0), 0, rtol, 0.0, 1.0, 100_000, float(budget),
            np.zeros((0, 6)), np.zeros(stepping.N_ACCT), True,
        )  # fmt: skip
        return out[0] == out[0]  # a finished run has a COR, an unfinished one NaN

    lo, hi = 0, 1_000
    while not ok(hi):
        lo, hi = hi, hi * 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return hi


def run(path, reps, chains=None, rtols=RTOLS):
    """Time and score ``restitution.solve`` on every scene (name -> Chain; default this
    module's ``scenes()``) at every rtol; writes the rows to ``path`` (JSON)."""
    out = {}
    for name, ch in (scenes() if chains is None else chains).items():
        rows = {}
        for rtol in rtols:
            r = R.solve(ch, method="adaptive", rtol=rtol)
            times = []
            for _ in range(reps):
                t = time.perf_counter()
                R.solve(ch, method="adaptive", rtol=rtol)
                times.append(time.perf_counter() - t)
            rows[repr(rtol)] = dict(
                cor=r.cor, est=r.error_estimate, status=r.status, contacts=r.n_collisions,
                time=statistics.median(times), work=work(ch, rtol),
            )  # fmt: skip
            print(name, rtol, rows[repr(rtol)], flush=True)
        out[name] = rows
    with open(path, "w") as f:
        json.dump(out, f, indent=1)


def compare(ref_path, paths, rtols=RTOLS, outside=False):
    """The markdown table of runs against the reference; ``outside``: mark a row whose error is
    not within its estimate less the reference's bound, and leave out the reference lines."""
    ref = json.load(open(ref_path))
    runs = [json.load(open(p)) for p in paths]
    print(
        "| scene | rtol | " + " | ".join(f"{p}: error / estimate / ms / work" for p in paths) + " |"
    )
    for name, r in ref.items():
        for rtol in rtols:
            cells = []
            for run_ in runs:
                row = run_[name][repr(rtol)]
                err = abs(row["cor"] - r["cor"]) if row["status"] == "ok" else math.nan
                flag = " OUTSIDE" if outside and not err <= row["est"] - r["bound"] else ""
                cells.append(
                    f"{err:.1e} / {row['est']:.1e} / {1e3 * row['time']:.2f} / {row['work']}{flag}"
                )
            print(f"| {name} | {rtol:.0e} | " + " | ".join(cells) + " |")
        if not outside:
            print(f"  (reference {r['cor']!r}, bound {r['bound']:.1e}, points {r['points']})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reference")
    ap.add_argument("--only", help="reference: only the scenes whose name contains this")
    ap.add_argument("--out")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--compare", nargs="+")
    a = ap.parse_args()
    if a.reference:
        reference(a.reference, a.only)
    if a.out:
        run(a.out, a.reps)
    if a.compare:
        compare(a.compare[0], a.compare[1:])


if __name__ == "__main__":
    main()
