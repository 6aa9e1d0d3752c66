"""Measured cost scaling: time per scene against alpha and chain length N, and a solve_many sweep.

* ``alpha_scaling``: one scene at a time, exact solver (and solve_ivp up to a smaller alpha, at
  matched accuracy: the loosest rtol whose COR is within ``match_error`` of the exact one); the
  number of contacts grows like alpha**0.8 (paper Eq. 19), and so should the exact cost.
* ``chain_scaling``: the exact chain solver against the number of masses N.
* ``sweep_scaling``: ``restitution.solve_many`` over n scenes on 1 and 2 numba threads.

Times use ``harness.time_call`` (median of repeats filling ``min_time``) after an untimed warm-up
call at every point (a new chain length or sweep size can reach kernel code not yet compiled).
``fit_exponents`` fits log(y) = log(A) + p log(x) by least squares (numpy.polyfit, standard error
from its covariance) and returns one row per (kind, family, quantity).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from restitution_workflow.bench.harness import time_call
from restitution_workflow.bench.ivp import solve_ivp_scene

SCALING_COLUMNS = (
    "kind",
    "family",
    "x",
    "threads",
    "n_scenes",
    "n_collisions",
    "time_s",
    "time_per_scene_s",
    "status",
    "setting",
    "cor_error",
)


def _timed(fn, min_time, min_repeats):
    fn()  # warm-up, untimed
    return time_call(fn, min_time, min_repeats)


def _row(kind, family, x, threads, n_scenes, ncol, seconds, status, setting=math.nan,
         error=math.nan):  # fmt: skip
    return dict(
        kind=kind,
        family=family,
        x=float(x),
        threads=int(threads),
        n_scenes=int(n_scenes),
        n_collisions=int(ncol),
        time_s=seconds,
        time_per_scene_s=seconds / n_scenes,
        status=status,
        setting=float(setting),
        cor_error=float(error),
    )


def matched_setting(alpha, beta, reference, ivp_method, ivp_rtols, match_error, time_budget,
                    atol_over_rtol=1.0):  # fmt: skip
    """(rtol, |COR error|, result, True) of the loosest rtol of ``ivp_rtols`` whose solve_ivp
    run has the reference's contact count and a COR within ``match_error`` of it; the tightest
    rtol tried with False when none does."""
    tried = None
    for rtol in sorted(ivp_rtols, reverse=True):
        r = solve_ivp_scene(alpha, beta, method=ivp_method, rtol=rtol, atol=rtol * atol_over_rtol,
                            time_budget=time_budget)  # fmt: skip
        err = abs(r.cor - reference.cor) if r.success else math.inf
        tried = (rtol, err, r)
        if r.success and r.n_collisions == reference.n_collisions and err <= match_error:
            return rtol, err, r, True
    return (*tried, False)


def alpha_scaling(alphas, beta, ivp_method, ivp_rtols, ivp_alpha_max, min_time, min_repeats,
                  time_budget, match_error=1e-6, atol_over_rtol=1.0):  # fmt: skip
    """Rows of (family, alpha, contacts, time, setting, error) for the exact solver and one
    solve_ivp method at matched accuracy: at every alpha the loosest rtol of ``ivp_rtols``
    whose COR is within ``match_error`` of the exact one with the same contact count (found by
    untimed runs, then timed). The exact rows' error is their own error estimate (far below
    ``match_error``: the comparison favours solve_ivp). An alpha where no rtol matches is a row
    with status ``not_matched`` (the tightest rtol's time and error)."""
    from restitution.api import solve

    solve(alpha=1.0, beta=beta)  # warm-up: compile or load the kernel
    rows, exact = [], {}
    for a in alphas:
        r, t, _, _ = _timed(lambda a=a: solve(alpha=a, beta=beta), min_time, min_repeats)
        exact[a] = r
        rows.append(_row("alpha", "exact", a, 1, 1, r.n_collisions, t, r.status,
                         error=r.error_estimate))  # fmt: skip
    for a in (a for a in alphas if a <= ivp_alpha_max):
        rtol, err, _, matched = matched_setting(
            a, beta, exact[a], ivp_method, ivp_rtols, match_error, time_budget, atol_over_rtol
        )
        r, t, _, _ = _timed(
            lambda a=a, rtol=rtol: solve_ivp_scene(
                a,
                beta,
                method=ivp_method,
                rtol=rtol,
                atol=rtol * atol_over_rtol,
                time_budget=time_budget,
            ),  # fmt: skip
            min_time,
            min_repeats,
        )
        status = r.status if matched else "not_matched"
        rows.append(_row("alpha", ivp_method, a, 1, 1, r.n_collisions, t, status, rtol, err))
    return rows


def chain_scaling(ns, alpha, beta, min_time, min_repeats):
    """Rows of (N, contacts, time) for the exact chain solver."""
    from restitution.api import solve

    solve(alpha=alpha, beta=beta, n_masses=3)  # warm-up
    rows = []
    for n in ns:
        r, t, _, _ = _timed(
            lambda n=n: solve(alpha=alpha, beta=beta, n_masses=int(n)), min_time, min_repeats
        )
        rows.append(_row("chain", "exact", n, 1, 1, r.n_collisions, t, r.status))
    return rows


def sweep_scaling(counts, threads, alpha_min, alpha_max, beta, min_time, min_repeats):
    """Rows of (n scenes, threads, total time) for ``solve_many`` on a log grid of alpha."""
    import numba

    from restitution.api import solve_many

    rows = []
    solve_many(pd.DataFrame({"alpha": [1.0, 2.0], "beta": beta}))  # warm-up
    for t in threads:
        numba.set_num_threads(int(t))
        for n in counts:
            grid = np.geomspace(alpha_min, alpha_max, int(n))
            scenes = pd.DataFrame({"alpha": grid, "beta": beta})
            out, sec, _, _ = _timed(lambda f=scenes: solve_many(f), min_time, min_repeats)
            bad = int((out["status"] != "ok").sum())
            status = "ok" if bad == 0 else f"{bad} rows not ok"
            rows.append(
                _row("sweep", "solve_many", n, t, n, int(out["n_collisions"].sum()), sec, status)
            )
    numba.set_num_threads(1)
    return rows


def frame(rows) -> pd.DataFrame:
    out = pd.DataFrame(rows, columns=list(SCALING_COLUMNS))
    for c in ("threads", "n_scenes", "n_collisions"):
        out[c] = out[c].astype(np.int64)
    return out


def _fit(x, y):
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 3:
        return math.nan, math.nan, math.nan
    coef, cov = np.polyfit(np.log(x), np.log(y), 1, cov=True)
    return float(coef[0]), float(math.sqrt(max(cov[0, 0], 0.0))), float(math.exp(coef[1]))


def fit_exponents(
    table: pd.DataFrame, alpha_fit_min: float, chain_fit_min: float, sweep_fit_min: float
) -> pd.DataFrame:
    """Fitted exponents p of y = A x**p for time (and contacts) against alpha, N, n scenes."""
    rows = []
    ok = table[table["status"] == "ok"]
    ok = ok.assign(time_per_contact_s=ok["time_s"] / ok["n_collisions"].clip(lower=1))
    groups = [
        ("alpha", alpha_fit_min, "time_s", "time per scene vs alpha"),
        ("alpha", alpha_fit_min, "n_collisions", "contacts vs alpha"),
        ("alpha", alpha_fit_min, "time_per_contact_s", "time per contact vs alpha"),
        ("chain", chain_fit_min, "time_s", "time per scene vs N"),
        ("chain", chain_fit_min, "n_collisions", "contacts vs N"),
        ("chain", chain_fit_min, "time_per_contact_s", "time per contact vs N"),
        ("sweep", sweep_fit_min, "time_s", "sweep time vs number of scenes"),
    ]
    for kind, x_min, quantity, what in groups:
        sub = ok[(ok["kind"] == kind) & (ok["x"] >= x_min)]
        for (family, threads), g in sub.groupby(["family", "threads"]):
            p, se, a = _fit(g["x"], g[quantity])
            rows.append(
                dict(
                    kind=kind,
                    family=family,
                    threads=int(threads),
                    quantity=quantity,
                    description=what,
                    exponent=p,
                    stderr=se,
                    prefactor=a,
                    x_min=g["x"].min(),
                    x_max=g["x"].max(),
                    n_points=len(g),
                )
            )
    return pd.DataFrame(rows)
