"""Work-precision of scissor links with a power-law contact (Hertz, the plastic law): the adaptive
kernel against the mpmath reference (issue 27: nonlinear contact at the exact solvers' standard).

Usage:
  .venv/bin/python benchmarks/bench_scissor_powerlaw.py --reference ref.json [--only NAME ...]
  .venv/bin/python benchmarks/bench_scissor_powerlaw.py --out run.json [--reps 5]
  .venv/bin/python benchmarks/bench_scissor_powerlaw.py --compare ref.json run.json [more.json]

Scenes: those of ``tests/test_scissor_powerlaw.py`` (hand-picked short scissors whose lock lies
within the first contact's sigma stretch, and its seeded random draw). ``--reference`` solves
them by ``restitution.solvers.precise_scissor`` at 30 digits checked at 40 and prints the
test's REFERENCE rows (minutes per scene). A plain run times ``restitution.solve`` (method
``adaptive``, one thread, its check run at rtol/10 included, median of ``--reps``) at rtol 1e-8,
1e-10, 1e-12 and finds its work in right-hand-side evaluations of one run; it uses the public
API and the kernel entry only, so it runs unchanged on an older checkout (before/after numbers).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

import restitution as R

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from bench_scissor_precision import work  # noqa: E402

from test_scissor_powerlaw import scenes  # noqa: E402

RTOLS = (1e-8, 1e-10, 1e-12)


def reference(path, only=None):
    from restitution.solvers.precise_scissor import reference as precise

    out = {}
    for name, spec in scenes().items():
        if only and not any(o in name for o in only):
            continue
        t = time.perf_counter()
        ch = R.Chain(**spec)
        r = precise(ch)
        cor, ncol, log = r["cor"], r["contacts"], r["crossed"]
        bound = max(r["bound"], math.ulp(cor) / 2)
        out[name] = dict(cor=cor, contacts=ncol, bound=bound, crossed=log)
        print(f"    {name!r}: ({cor!r}, {ncol}, {bound:.1e}, {tuple(log)!r}),  "
              f"# {time.perf_counter() - t:.0f} s", flush=True)  # fmt: skip
    with open(path, "w") as f:
        json.dump(out, f, indent=1)


def run(path, reps):
    out = {}
    for name, spec in scenes().items():
        ch = R.Chain(**spec)
        rows = {}
        for rtol in RTOLS:
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


def compare(ref_path, paths):
    ref = json.load(open(ref_path))
    runs = [json.load(open(p)) for p in paths]
    print(
        "| scene | rtol | " + " | ".join(f"{p}: error / estimate / ms / work" for p in paths) + " |"
    )
    for name, r in ref.items():
        for rtol in RTOLS:
            cells = []
            for run_ in runs:
                row = run_[name][repr(rtol)]
                err = abs(row["cor"] - r["cor"]) if row["status"] == "ok" else math.nan
                flag = "" if err <= row["est"] - r["bound"] else " OUTSIDE"
                cells.append(
                    f"{err:.1e} / {row['est']:.1e} / {1e3 * row['time']:.2f} / {row['work']}{flag}"
                )
            print(f"| {name} | {rtol:.0e} | " + " | ".join(cells) + " |")
        print(f"  (reference {r['cor']!r}, {r['contacts']} contacts, bound {r['bound']:.1e}, "
              f"crossed {r['crossed']})")  # fmt: skip


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reference")
    ap.add_argument("--only", nargs="+", help="reference: only scenes whose name contains one")
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
