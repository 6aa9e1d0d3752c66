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
import sys
import time
from pathlib import Path

import restitution as R

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import bench_scissor_precision as SP  # noqa: E402

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
        SP.run(a.out, a.reps, {k: R.Chain(**v) for k, v in scenes().items()}, RTOLS)
    if a.compare:
        SP.compare(a.compare[0], a.compare[1:], RTOLS, outside=True)


if __name__ == "__main__":
    main()
