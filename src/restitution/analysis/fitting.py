"""Least-squares fits of the paper's laws (Section 2.2) with uncertainties and goodness of fit.

Every fit is :func:`least_squares_fit`: ``scipy.optimize.least_squares`` on a residual vector,
standard errors from the Jacobian at the optimum, ``cov = s^2 (J^T J)^-1`` with
``s^2 = SSR / (m - k)`` (m residuals, k parameters), plus R^2, RMS and max residual. The data are
exact (root-solved, restitution.analysis.special_points), so the residuals measure how far the
*law* is
from the physics, not noise: read the standard errors as the spread of the law's misfit, not as
a statistical confidence interval.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from restitution.analysis import approx
from restitution.analysis import special_points as sp


@dataclass
class Fit:
    """Result of one fit; ``paper`` holds the paper's values of the same parameters."""

    name: str
    params: dict
    stderr: dict
    r2: float
    rms: float
    max_abs_residual: float
    n_points: int
    paper: dict = field(default_factory=dict)
    note: str = ""

    def to_dict(self) -> dict:
        return asdict(self)


def least_squares_fit(name, residuals, p0, names, y, *, paper=None, note="", **kwargs) -> Fit:
    """Minimise ``sum(residuals(p)**2)``; ``y`` is the fitted data (for R^2 = 1 - SSR/SST)."""
    res = least_squares(residuals, np.asarray(p0, dtype=float), x_scale="jac", **kwargs)
    r = res.fun
    m, k = r.size, res.x.size
    ssr = float(r @ r)
    dof = max(m - k, 1)
    J = res.jac
    cov = ssr / dof * np.linalg.pinv(J.T @ J)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    y = np.asarray(y, dtype=float)
    sst = float(np.sum((y - y.mean()) ** 2))
    return Fit(
        name=name,
        params={n: float(v) for n, v in zip(names, res.x, strict=True)},
        stderr={n: float(v) for n, v in zip(names, se, strict=True)},
        r2=1.0 - ssr / sst if sst > 0 else float("nan"),
        rms=float(np.sqrt(ssr / m)),
        max_abs_residual=float(np.max(np.abs(r))),
        n_points=int(m),
        paper=paper or {},
        note=note,
    )


def fit_power(x, y, *, scale=False, name="power", p0=1.0, exponent="p", paper=None, note=""):
    """Fit ``y = x**p`` (or ``y = A x**p`` with ``scale``) by least squares in y; returns a Fit."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if scale:
        return least_squares_fit(
            name, lambda t: t[0] * x ** t[1] - y, [1.0, p0], ["A", exponent], y, paper=paper,
            note=note,
        )  # fmt: skip
    return least_squares_fit(
        name, lambda t: x ** t[0] - y, [p0], [exponent], y, paper=paper, note=note
    )


# ---------------------------------------------------------------------------------------------
# The paper's laws
# ---------------------------------------------------------------------------------------------
def fit_unity_law(points: pd.DataFrame, n_min: int = 2) -> Fit:
    """Eq. 19, n = 1 + alpha#**p (paper p = 0.8); n = 1 (alpha# = 0) holds for any p."""
    d = points[points["n"] >= n_min]
    return fit_power(
        d["alpha_unity"], d["n"] - 1.0, name="eq19_unity", p0=0.8, paper={"p": 0.8},
        note=f"n = 1 + alpha#_n**p, n = {n_min}..{int(d['n'].max())}, residuals in n",
    )  # fmt: skip


def fit_gap_law(points: pd.DataFrame, n_min: int = 1, scale: bool = False) -> Fit:
    """Eq. 22, alpha*_n - alpha#_n = n**q (paper q = 0.21); ``scale``: A n**q.

    n = 1 does not constrain q (1**q = 1) but its residual shows the law's misfit there.
    """
    d = points[points["n"] >= n_min]
    return fit_power(
        d["n"], d["alpha_star"] - d["alpha_unity"], scale=scale, p0=0.21, exponent="q",
        name=f"eq22_gap{'_scaled' if scale else ''}_n{n_min}", paper={"q": 0.21},
        note=f"alpha*_n - alpha#_n = {'A ' if scale else ''}n**q, n = {n_min}..{int(d['n'].max())}",
    )  # fmt: skip


def fit_minima_law(points: pd.DataFrame, n_min: int = 1) -> Fit:
    """e*_n = (alpha*_n - c)/(1 + alpha*_n) (paper c = 0.4), residuals in the COR."""
    d = points[points["n"] >= n_min]
    a, e = d["alpha_star"].to_numpy(), d["e_star"].to_numpy()
    return least_squares_fit(
        f"minima_c_n{n_min}", lambda t: (a - t[0]) / (1.0 + a) - e, [0.4], ["c"], e,
        paper={"c": 0.4}, note=f"e*_n = (alpha*_n - c)/(1 + alpha*_n), n = {n_min}..{d['n'].max()}",
    )  # fmt: skip


def fit_eta(points: pd.DataFrame, alpha, exact_cor, exact_gamma=True) -> Fit:
    """eta1, eta2 of Eq. 21 (paper 2, 2) fitted to the exact COR on the exact special points.

    ``exact_gamma``: gamma at the minima from the exact e*_n (else alpha*_1 as in the paper).
    Use alphas above alpha*_1: below it the exact branch is known and Eq. 21 is not needed.
    """
    a, e = np.asarray(alpha, dtype=float), np.asarray(exact_cor, dtype=float)
    star, unity = points["alpha_star"].to_numpy(), points["alpha_unity"].to_numpy()
    gamma = points["gamma_star"].to_numpy() if exact_gamma else star[0]

    def resid(t):
        return approx.eq21_cor(a, star, unity, gamma, t[0], t[1]) - e

    return least_squares_fit(
        "eq21_eta", resid, [2.0, 2.0], ["eta1", "eta2"], e, paper={"eta1": 2.0, "eta2": 2.0},
        bounds=([0.05, 0.05], [10.0, 10.0]),
        note=f"exact alpha*, alpha#, {'exact gamma*_n' if exact_gamma else 'gamma* = alpha*_1'}; "
        f"alpha in [{a.min():.4g}, {a.max():.4g}], {a.size} points, residuals in the COR",
    )  # fmt: skip


def fit_universal_shape(table: pd.DataFrame, n_min: int = 2, n_max: int | None = None) -> Fit:
    """One set (a1, a2, a3, b0, b1, b2) of the improved model's shapes for all windows.

    Residuals are COR errors on the samples that
    :func:`restitution.analysis.approx.fit_window_shape`
    uses, pooled over windows n_min..n_max.
    """
    n_max = int(table["n"].max()) if n_max is None else n_max
    blocks = []
    for n in range(n_min, n_max + 1):
        s, F, w, G, a_r, a_f = approx._branch_samples(table, n)
        gs = table["gamma_star"].to_numpy()
        wr, wf = 2.0 * gs[n - 2] / (1.0 + a_r), 2.0 * gs[n - 1] / (1.0 + a_f)
        B, C = approx.rising_basis(s), approx.falling_basis(w)
        blocks.append((B * wr[:, None], F * wr, C * wf[:, None], G * wf))
    B = np.concatenate([b[0] for b in blocks])
    yF = np.concatenate([b[1] for b in blocks])
    C = np.concatenate([b[2] for b in blocks])
    yG = np.concatenate([b[3] for b in blocks])

    def resid(t):
        return np.concatenate([B[:, 0] + B[:, 1:] @ t[:3] - yF, C[:, 0] + C[:, 1:] @ t[3:] - yG])

    return least_squares_fit(
        "improved_shape", resid, [0, 0, 0, 1, 0, 0], ["a1", "a2", "a3", "b0", "b1", "b2"],
        np.concatenate([yF, yG]), note=f"pooled windows n = {n_min}..{n_max}, COR residuals",
    )  # fmt: skip


def law_residuals(points: pd.DataFrame, fits: dict) -> pd.DataFrame:
    """Per-n comparison of the exact points with the paper's and our fitted laws."""
    n = points["n"].to_numpy(dtype=float)
    h, a, e = (points[c].to_numpy() for c in ("alpha_unity", "alpha_star", "e_star"))
    p, q = fits["eq19_unity"].params["p"], fits["eq22_gap_n1"].params["q"]
    c = fits["minima_c_n1"].params["c"]
    return pd.DataFrame(
        {
            "n": points["n"].to_numpy(),
            "alpha_unity": h,
            "n_eq19_paper": 1.0 + h**0.8,
            "n_eq19_fit": 1.0 + h**p,
            "gap": a - h,
            "gap_eq22_paper": n**0.21,
            "gap_eq22_fit": n**q,
            "alpha_star": a,
            "e_star": e,
            "e_star_paper": (a - 0.4) / (1.0 + a),
            "e_star_fit": (a - c) / (1.0 + a),
        }
    )


def fit_all(points: pd.DataFrame, alpha_min=0.01, alpha_max=200.0, n_eta=20_000) -> dict:
    """Every fit of the issue; returns ``name -> Fit``.

    The laws are fitted on the points with alpha*_n <= alpha_max; eta1, eta2 on the exact COR at
    ``n_eta`` log-spaced alphas in (alpha*_1, alpha_max] (``points`` must cover alpha_max).
    """
    law = points[points["alpha_star"] <= alpha_max].reset_index(drop=True)
    fits = {}
    for f in (
        fit_unity_law(law),
        fit_power(law["alpha_unity"][1:], law["n"][1:] - 1.0, scale=True, name="eq19_scaled",
                  p0=0.8, note="n = 1 + A alpha#_n**p (two parameters), n >= 2"),
        fit_gap_law(law, 1),
        fit_gap_law(law, 2, scale=True),
        fit_minima_law(law, 1),
        fit_minima_law(law, 2),
    ):  # fmt: skip
        fits[f.name] = f
    a = np.geomspace(max(alpha_min, points["alpha_star"].iloc[0] * (1 + 1e-9)), alpha_max, n_eta)
    exact = sp.rigid_reference(a)["cor"].to_numpy()
    fits["eq21_eta"] = fit_eta(points, a, exact)
    return fits


__all__ = [
    "Fit",
    "fit_all",
    "fit_eta",
    "fit_gap_law",
    "fit_minima_law",
    "fit_power",
    "fit_unity_law",
    "fit_universal_shape",
    "law_residuals",
    "least_squares_fit",
]
