"""The nonlinear path before and after one stack (issue 25 item 4): the same scenes solved by
REF's code and by this checkout, compared row by row (a script, not a test).

Usage: ``NUMBA_CACHE_DIR=.cache/numba .venv/bin/python benchmarks/compare_numerical_stack.py
[--ref 3b69718] [--out results/compare_numerical_stack.parquet]``

REF (default 3b69718, the last commit with a separate two-mass stack) solved two-mass scenes by
its own kernels (closed-form free flight, the exact highest frequency for Verlet's step); now
every numerical row runs on the chain kernels. Scenes, all through ``restitution.solve_many`` in
both versions (paper form with law columns):

* Fig. 4: the plastic curves of panels (b)-(d) of config/config.yaml on their alpha grid;
* Fig. 5(b): the scissor curves (every L at v0, every v0 at the fixed L) on their alpha grid;
* random scenes: plastic, scissor, both, with and without a dashpot, adaptive (rtol 1e-9) and
  Verlet (step 0.01).

Printed: per group the rows, status and contact-count disagreements, and the largest
|cor_now - cor_then| / (estimate_now + estimate_then) over rows ok in both (<= 1: the two
agree within their error estimates).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
import then  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

# Reads the scenes from the parquet file named on stdin, writes the results next to it (parquet:
# every float bit for bit, inf included; JSON would round them to 10 digits).
_SNIPPET = """
import sys
import pandas as pd
import restitution
path = sys.stdin.read().strip()
frame = pd.read_parquet(path)
out = []
for method, part in frame.groupby("method", sort=False):
    res = restitution.solve_many(part, max_events=10000)
    out.append(res[["cor", "n_collisions", "status", "error_estimate"]])
pd.concat(out).sort_index().to_parquet(path + ".out.parquet")
"""


def log_grid(lo, hi, n):
    return np.exp(np.linspace(math.log(lo), math.log(hi), n))


def scenes(seed: int = 25) -> pd.DataFrame:
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    rows = []
    f4 = cfg["fig4"]
    grid4 = log_grid(f4["sweep"]["alpha_min"], f4["sweep"]["alpha_max"], f4["sweep"]["n_alpha"])
    for name in ("b", "c", "d"):
        p = f4[name]
        laws = (
            [(p["eta"], d) for d in p["drs"]] if "drs" in p else [(e, p["dr"]) for e in p["etas"]]
        )
        for eta, dr in laws:
            for a in grid4:
                rows.append(dict(group=f"fig4{name}", alpha=a, beta=p["beta"], contact="plastic",
                                 eta=eta, dr=dr, rtol=f4["sweep"]["rtol"]))  # fmt: skip
    s, b = cfg["fig5"]["spring"], cfg["fig5"]["b"]
    grid5 = log_grid(b["alpha_min"], b["alpha_max"], b["n_alpha"])
    law = dict(structure="scissor", ks_ratio=s["ks_over_k1"] / s["beta"],
               theta0=math.radians(s["theta0_deg"]), corner=s["corner"])  # fmt: skip
    curves = [(L, b["v0"]) for L in b["Ls"]] + [(b["velocity"]["L"], v) for v in
                                                b["velocity"]["v0s"]]  # fmt: skip
    for L, v0 in curves:  # noqa: N806
        for a in grid5:
            rows.append(dict(group="fig5b", alpha=a, beta=s["beta"], L=L, v0=v0,
                             rtol=b["rtol"], **law))  # fmt: skip
    rng = np.random.default_rng(seed)
    for method in ("adaptive", "verlet"):
        for kind in ("plastic", "scissor", "both"):
            for _ in range(100 if method == "adaptive" else 30):
                r = dict(
                    group=f"random-{kind}-{method}",
                    alpha=10 ** rng.uniform(-1, 1),
                    xi=float(rng.choice([0.0, 10 ** rng.uniform(-3, -0.7)])),
                    method=method,
                )
                if kind in ("plastic", "both"):
                    eta = rng.uniform(0.5, 1.5)
                    r.update(
                        contact="plastic",
                        eta=eta,
                        dr=rng.uniform(max(0.0, (1 - eta) / 2) + 0.01, 0.8),
                        beta=10 ** rng.uniform(-2.5, -0.5),
                    )
                if kind in ("scissor", "both"):
                    th = rng.uniform(0.4, 1.1)
                    r.update(
                        structure="scissor",
                        L=10 ** rng.uniform(-0.3, 0.9),
                        theta0=th,
                        ks_ratio=rng.uniform(0.05, 0.8) * math.tan(th) ** 2,
                        corner=rng.uniform(0.5, 2.0),
                        v0=10 ** rng.uniform(-0.3, 0.3),
                    )
                    r.setdefault("beta", 10 ** rng.uniform(-1, 0))
                if method == "adaptive":
                    r["rtol"] = 1e-9
                else:
                    r["step"] = 0.01
                rows.append(r)  # fmt: skip
    frame = pd.DataFrame(rows)
    frame["method"] = frame["method"].fillna("adaptive")
    frame["xi"] = frame["xi"].fillna(0.0)
    return frame


def solve(tree, frame: pd.DataFrame, threads: int) -> pd.DataFrame:
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        path = str(Path(tmp) / "scenes.parquet")
        frame.drop(columns="group").to_parquet(path)
        then.run(tree, _SNIPPET, path, threads=threads)
        return pd.read_parquet(path + ".out.parquet")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default="3b69718")
    ap.add_argument("--out", default="results/compare_numerical_stack.parquet")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--then-only", action="store_true", help="solve (and cache) REF's rows only")
    args = ap.parse_args()
    frame = scenes()
    cache = Path(args.out).with_name(f"compare_numerical_stack_then_{args.ref}.parquet")
    if cache.exists():
        old = pd.read_parquet(cache)
    else:
        old = solve(then.export(args.ref), frame, args.threads)
        cache.parent.mkdir(parents=True, exist_ok=True)
        old.to_parquet(cache)
    if args.then_only:
        return
    new = solve(None, frame, args.threads)
    both = frame.join(old.add_suffix("_then")).join(new.add_suffix("_now"))
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    both.to_parquet(args.out)
    ok = (both["status_then"] == "ok") & (both["status_now"] == "ok")
    est = both["error_estimate_then"] + both["error_estimate_now"]
    both["ratio"] = (both["cor_now"] - both["cor_then"]).abs() / est
    print(f"{len(both)} rows; then = {args.ref}, now = this checkout")
    print(f"{'group':<24}{'rows':>6}{'status≠':>8}{'ncol≠':>7}{'max|d|':>11}{'max ratio':>11}")
    for g, part in both.groupby("group", sort=False):
        pok = part[ok[part.index]]
        print(
            f"{g:<24}{len(part):>6}{int((part.status_then != part.status_now).sum()):>8}"
            f"{int((pok.n_collisions_then != pok.n_collisions_now).sum()):>7}"
            f"{(pok.cor_now - pok.cor_then).abs().max():>11.2e}{pok.ratio.max():>11.3g}"
        )
    diff = both[both.status_then != both.status_now]
    if len(diff):
        print("status changes:")
        print(diff[["group", "alpha", "beta", "status_then", "status_now"]].to_string())
    worst = both[ok & both["ratio"].notna()].sort_values("ratio").tail(5)
    print("largest |d|/(estimate_then + estimate_now):")
    cols = ["group", "alpha", "beta", "cor_then", "cor_now", "error_estimate_then",
            "error_estimate_now", "ratio"]  # fmt: skip
    print(worst[cols].to_string())


if __name__ == "__main__":
    main()
