"""``solve_many`` on 1,000 plastic rows, before and after numerical rows ran in compiled batches
(issue 25 item 2; a script, not a test).

Usage: ``NUMBA_CACHE_DIR=.cache/numba .venv/bin/python benchmarks/bench_numerical_rows.py
[--ref 3b69718] [--threads 2] [--rows 1000]``

The same table (paper form, plastic contact: alpha log-spaced over Fig. 4's 0.1..100, beta
0.01 and 0.1, eta 0.5, 1, 1.5, DR 0.5; method auto = adaptive, rtol 1e-9) is solved by
``restitution.solve_many`` with REF's code (default 3b69718: numerical rows one by one through
``solve``) and with this checkout's (rows in parallel batches), each in its own process with
``NUMBA_NUM_THREADS`` threads, after one warm-up call; best of 3. The contact counts of the two
are compared row by row, so both timed the same physics.

On a machine busier than its cores (the threads then do not run side by side) the script also
prints the split of this checkout's time on one thread into the batch kernels (which the
threads share) and the rest (table checks, packing, result columns: serial), and the time that
split gives for ``--threads`` free cores.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import then  # noqa: E402

_SNIPPET = """
import json, sys, time
import numpy as np, pandas as pd
import restitution
rows = int(sys.stdin.read())
alpha = np.geomspace(0.1, 100.0, rows)
frame = pd.DataFrame({"alpha": alpha, "beta": np.where(np.arange(rows) % 2, 0.1, 0.01),
                      "contact": "plastic", "eta": np.array([0.5, 1.0, 1.5])[np.arange(rows) % 3],
                      "dr": 0.5})
restitution.solve_many(frame.head(8))  # warm-up (compilation or cache load)
best = 1e9
for _ in range(3):
    t = time.perf_counter()
    out = restitution.solve_many(frame)
    best = min(best, time.perf_counter() - t)
json.dump({"s": best, "ncol": out["n_collisions"].tolist(),
           "ok": int((out["status"] == "ok").sum())}, sys.stdout)
"""


_SPLIT = """
import json, sys, time
import numba
import numpy as np, pandas as pd
import restitution
from restitution.solvers import numerical
from restitution.tables.scene_table import scene_table
numba.set_num_threads(1)
rows = int(sys.stdin.read())
alpha = np.geomspace(0.1, 100.0, rows)
frame = pd.DataFrame({"alpha": alpha, "beta": np.where(np.arange(rows) % 2, 0.1, 0.01),
                      "contact": "plastic", "eta": np.array([0.5, 1.0, 1.5])[np.arange(rows) % 3],
                      "dr": 0.5})
restitution.solve_many(frame.head(8))
table = scene_table(frame)
chains = [table.chain(i) for i in range(rows)]
total = kernel = 1e9
for _ in range(3):
    t = time.perf_counter()
    restitution.solve_many(frame)
    total = min(total, time.perf_counter() - t)
    t = time.perf_counter()
    numerical.solve_chains(chains)
    kernel = min(kernel, time.perf_counter() - t)
json.dump({"total": total, "kernel": kernel}, sys.stdout)
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default="3b69718")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rows", type=int, default=1000)
    args = ap.parse_args()
    old = json.loads(then.run(then.export(args.ref), _SNIPPET, str(args.rows), args.threads))
    new = json.loads(then.run(None, _SNIPPET, str(args.rows), args.threads))
    same = old["ncol"] == new["ncol"]
    print(f"solve_many, {args.rows} plastic rows, {args.threads} threads, best of 3:")
    print(f"  then ({args.ref}, rows one by one): {old['s']:.3f} s, {old['ok']} ok")
    print(f"  now (batches on the threads):      {new['s']:.3f} s, {new['ok']} ok")
    print(f"  speed-up {old['s'] / new['s']:.2f}x (target >= 1.8)"
          + ("" if same else "  [contact counts differ between the versions]"))  # fmt: skip
    split = json.loads(then.run(None, _SPLIT, str(args.rows), 1))
    rest = split["total"] - split["kernel"]
    free = rest + split["kernel"] / args.threads
    print(f"  now on 1 thread: {split['total']:.3f} s = batch kernels {split['kernel']:.3f} s"
          f" + the rest {rest:.3f} s; on {args.threads} free cores that is {free:.3f} s,"
          f" {old['s'] / free:.2f}x the 'then' time above")  # fmt: skip


if __name__ == "__main__":
    main()
