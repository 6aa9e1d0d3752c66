"""General chains now against the uniform chain as it was solved when the general model was asked
for (a script, not a test).

Usage: OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_then_now.py [--ref REF]

The general-chain issue asked that "a general chain costs no more per contact than today's
uniform chain of the same N", "today" being the code of its day: REF (default 1e27420, the last
commit before the general model, whose uniform chain kernel is kernels.linear.solve_linear).
bench_chain.py prints the stricter comparison, against the uniform chain solved by today's
kernel. Here the same general chains and the same contact-count-matched uniform chains as in
bench_chain.py section 2 are timed now, and the uniform ones again with REF's kernel: REF is
checked out into a temporary git worktree and timed in a subprocess (its own numba cache), since
two versions of the package cannot share one process. The contact counts of both versions are
compared scene by scene, so the two codes are timed on the same physics. One thread, best of 7.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numba
import numpy as np
from bench_chain import general, matched_uniform, pad, paper, per_contact

from restitution.kernels.exact_chain import solve_chain_batch
from restitution.kernels.layout import OUT_NCOL

ROOT = Path(__file__).resolve().parents[1]

# Run inside REF's worktree: its uniform-chain kernel on the scenes given as JSON on stdin.
_THEN = """
import json, sys, time
import numba, numpy as np
numba.set_num_threads(1)
from restitution.kernels.paper_chain import solve_linear_batch
rows = json.load(sys.stdin)
a = np.array([1.0, 2.0])
solve_linear_batch(a, a * 0 + 1e-3, a * 0 + 0.3, np.array([3, 2]), 1000)  # JIT warm-up
res = []
for s in rows:
    s = np.array(s)
    args = (s[:, 0].copy(), s[:, 1].copy(), s[:, 2].copy(), s[:, 3].astype(np.int64), 100000)
    ncol = solve_linear_batch(*args)[:, 1]
    best = 1e9
    for _ in range(7):
        t = time.perf_counter()
        solve_linear_batch(*args)
        best = min(best, time.perf_counter() - t)
    res.append({"us": best / ncol.sum() * 1e6, "ncol": ncol.tolist()})
json.dump(res, sys.stdout)
"""


def _paper_params(scene):
    """(alpha, beta, xi, n) of a paper scene built by bench_chain.paper (m1 = 1, omega = 1)."""
    m, k, c, kc = scene
    return [m[1] / m[0], 0.0 if kc == np.inf else k[0] / kc, c[0] / (2.0 * k[0]), m.size]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default="1e27420", help="commit whose uniform kernel is 'then'")
    args = ap.parse_args()
    numba.set_num_threads(1)
    rng = np.random.default_rng(1)  # the draws of bench_chain.py section 2
    per_contact([paper(2.0, 1e-3, 0.3, 3), paper(2.0, 0.0, 0.0, 2)], 1)  # JIT warm-up
    lines, scenes = [], []
    for n in (3, 5, 8):
        for beta, damped in ((0.0, False), (1e-3, False), (1e-3, True)):
            gen = [general(rng, n, beta, damped) for _ in range(20)]
            uni = matched_uniform(gen, n, beta, 0.3 if damped else 0.0)
            u_us, _, _ = per_contact(uni, 7)
            g_us, _, _ = per_contact(gen, 7)
            ncol = solve_chain_batch(*pad(uni), 100_000)[:, OUT_NCOL]
            lines.append((n, beta, damped, u_us, g_us, ncol))
            scenes.append([_paper_params(s) for s in uni])
    with tempfile.TemporaryDirectory() as tmp:
        tree = Path(tmp) / "then"
        subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(tree), args.ref],
            check=True,
        )
        try:
            env = dict(os.environ, PYTHONPATH=str(tree / "src"))
            env["NUMBA_CACHE_DIR"] = str(Path(tmp) / "numba")
            run = subprocess.run(
                [sys.executable, "-c", _THEN],
                input=json.dumps(scenes),
                capture_output=True,
                text=True,
                env=env,
                cwd=tmp,
                check=True,
            )
        finally:
            subprocess.run(
                ["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=True
            )
    then = json.loads(run.stdout)
    print(f"us per contact; 'then' = the uniform chain solved by {args.ref}'s kernel")
    for (n, beta, damped, u_us, g_us, ncol), old in zip(lines, then, strict=True):
        same = np.array_equal(np.asarray(old["ncol"]), ncol)
        print(
            f"   N = {n}, beta = {beta:g}{' damped' if damped else ''}: uniform then "
            f"{old['us']:.2f}, uniform now {u_us:.2f}, general now {g_us:.2f}; general now / "
            f"uniform then {g_us / old['us']:.2f} (target <= 1)"
            + ("" if same else "  [contact counts differ between the versions]")
        )


if __name__ == "__main__":
    main()
