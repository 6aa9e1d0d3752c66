"""Cheap approximations of the rigid-wall (beta = 0) two-mass COR, vectorised over alpha.

The paper's model (Section 2.2) writes ``e = 1 - 2 gamma / (1 + alpha)`` (Eq. 20) and, for
alpha in the n-contact window ``[alpha*_{n-1}, alpha*_n)`` with the unity point ``alpha#_n``
inside it, interpolates gamma between ``gamma* = alpha*_1`` at the minima and 0 at the unity
point with powers eta1, eta2 (Eq. 21). The points come from the laws ``n = 1 + alpha#**p``
(Eq. 19, p = 0.8) and ``alpha*_n - alpha#_n = n**q`` (Eq. 22, q = 0.21): :func:`paper_cor`.

The exact COR leaves each minimum like a square root (the newborn contact's impulse grows like
sqrt(alpha - alpha*_{n-1})) and reaches unity quadratically, which a power-2 interpolant cannot
follow. :func:`improved_cor` keeps Eq. 20 but uses the exact special points (a table,
:func:`exact_points`), the exact gamma*_n at each minimum, the exact single-contact branch
``(1 - alpha)/(1 + alpha)`` below alpha*_1, and shape functions with the right local behaviour:

    rising,  s = sqrt((alpha - alpha*_{n-1}) / (alpha#_n - alpha*_{n-1})):
        gamma = gamma*_{n-1} (1 - s)**2 (1 + a1 s + a2 s**2 + a3 s**3)
    falling, w = (alpha - alpha#_n) / (alpha*_n - alpha#_n):
        gamma = gamma*_n w**2 (1 + (1 - w)(b0 + b1 w + b2 w**2))

``(1 - s)**2`` alone already gives the sqrt cusp (1 - 2 s + ...) and the double zero at the
unity point. The six coefficients are fitted to the exact COR per window (a table row per n,
:func:`shape_table`) or once for all windows (``UNIVERSAL_SHAPE``, fitted by
:func:`restitution.analysis.fitting.fit_universal_shape`). Cost per alpha: one ``searchsorted`` and
a
few multiply-adds, the same as Eqs. 20-21.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pandas as pd

from restitution.analysis import special_points as sp

#: The paper's parameters: Eq. 19 (p), Eq. 22 (q), the minima law e* = (alpha* - c)/(1 + alpha*)
#: (c), Eq. 21 (eta1, eta2) and alpha*_1 = 0.6971 (Section 2.1, used as gamma* in Eq. 21).
PAPER = {"p": 0.8, "q": 0.21, "c": 0.4, "eta1": 2.0, "eta2": 2.0, "alpha_star_1": 0.6971}

#: Shape coefficients (a1, a2, a3, b0, b1, b2) fitted once over the windows n = 2..90 (see
#: restitution.analysis.fitting.fit_universal_shape; regenerate with
#: workflow/scripts/approx_fit.py).
UNIVERSAL_SHAPE = (0.026392, -0.16499, 0.065998, 1.5242, -1.6592, 0.75639)

_SAMPLES = 96  # samples per branch and window when fitting the per-window shapes


# ---------------------------------------------------------------------------------------------
# Special points: from the paper's laws or exact
# ---------------------------------------------------------------------------------------------
def law_points(n_max: int, p: float = 0.8, q: float = 0.21, alpha_star_1: float | None = 0.6971):
    """alpha#_n from Eq. 19 and alpha*_n from Eq. 22 for n = 1..n_max (a DataFrame).

    Eq. 22 at n = 1 gives alpha*_1 = 1, contradicting the paper's own alpha*_1 = 0.6971; the paper
    quotes the latter, so we use it for n = 1 unless ``alpha_star_1`` is None.
    """
    n = np.arange(1, n_max + 1, dtype=float)
    unity = (n - 1.0) ** (1.0 / p)
    star = unity + n**q
    if alpha_star_1 is not None:
        star[0] = alpha_star_1
    return pd.DataFrame({"n": n.astype(int), "alpha_unity": unity, "alpha_star": star})


@lru_cache(maxsize=8)
def _exact_points_cached(n_max: int) -> pd.DataFrame:
    return sp.special_points(n_max)


def exact_points(alpha_max: float = 200.0) -> pd.DataFrame:
    """Exact special points (restitution.analysis.special_points) covering alpha up to
    ``alpha_max``.

    Cached; the table is computed in steps of 50 windows (about 0.3 s per 50 on first use).
    """
    n_max = 50
    while True:
        pts = _exact_points_cached(n_max)
        if pts["alpha_star"].iloc[-1] > alpha_max:
            return pts
        n_max += 50


def _windows(alpha, star):
    """Contact count n (1-based) of the window [alpha*_{n-1}, alpha*_n) holding each alpha."""
    n = np.searchsorted(star, alpha, side="right") + 1
    if np.any(n > star.size):
        raise ValueError(
            f"alpha up to {np.max(alpha):g} exceeds the last tabulated minimum "
            f"alpha*_{star.size} = {star[-1]:g}; pass a longer points table"
        )
    return n


# ---------------------------------------------------------------------------------------------
# The paper's model, Eqs. 20-21
# ---------------------------------------------------------------------------------------------
def eq21_cor(alpha, alpha_star, alpha_unity, gamma_star, eta1=2.0, eta2=2.0):
    """Eqs. 20-21 for given points: arrays indexed by n - 1 (``alpha_unity[0]`` = 0).

    ``gamma_star`` is a scalar (the paper: alpha*_1) or one value per minimum. The first window
    [0, alpha*_1) uses the falling branch only (alpha#_1 = 0), as Eq. 21 does for n = 1.
    """
    a = np.asarray(alpha, dtype=float)
    star = np.asarray(alpha_star, dtype=float)
    unity = np.asarray(alpha_unity, dtype=float)
    gs = np.broadcast_to(np.asarray(gamma_star, dtype=float), star.shape)
    n = _windows(a, star)
    hi, h = star[n - 1], unity[n - 1]
    lo = np.where(n > 1, star[np.maximum(n - 2, 0)], 0.0)
    g_lo = gs[np.maximum(n - 2, 0)]
    rising = a < h
    with np.errstate(divide="ignore", invalid="ignore"):
        x1 = np.clip((h - a) / (h - lo), 0.0, 1.0)
        x2 = np.clip((a - h) / (hi - h), 0.0, 1.0)
    gamma = np.where(rising, g_lo * x1**eta1, gs[n - 1] * x2**eta2)
    return 1.0 - 2.0 * gamma / (1.0 + a)


def paper_cor(
    alpha, p=0.8, q=0.21, c=None, eta1=2.0, eta2=2.0, alpha_star_1=0.6971, exact_first=False
):
    """Approximate COR of the paper: points from Eqs. 19 and 22, gamma* = alpha*_1, Eqs. 20-21.

    With ``c`` given, gamma* = (1 + c)/2 instead (the minima law e* = (alpha* - c)/(1 + alpha*));
    c = 2 alpha*_1 - 1 reproduces the default. Eq. 21 read literally gives
    gamma = alpha*_1 (alpha/alpha*_1)**eta2 below alpha*_1; ``exact_first`` uses the exact
    single-contact branch (1 - alpha)/(1 + alpha) there instead (Eq. 1).

    >>> round(float(paper_cor(1.0)), 12)  # alpha#_2 = 1 from Eq. 19
    1.0
    """
    a = np.asarray(alpha, dtype=float)
    top = max(float(np.max(a, initial=1.0)), 1.0)
    n_max = int(np.ceil(1.0 + top**p)) + 3
    pts = law_points(n_max, p, q, alpha_star_1)
    gamma = alpha_star_1 if c is None else 0.5 * (1.0 + c)
    e = eq21_cor(a, pts["alpha_star"], pts["alpha_unity"], gamma, eta1, eta2)
    if exact_first:
        e = np.where(a < pts["alpha_star"].iloc[0], (1.0 - a) / (1.0 + a), e)
    return e


def paper_cor_exact_points(alpha, eta1=2.0, eta2=2.0, points=None, exact_gamma=False):
    """Eqs. 20-21 on the exact special points (isolates the error of the power-law shape)."""
    a = np.asarray(alpha, dtype=float)
    pts = exact_points(float(np.max(a, initial=1.0))) if points is None else points
    gamma = pts["gamma_star"].to_numpy() if exact_gamma else pts["alpha_star"].iloc[0]
    return eq21_cor(a, pts["alpha_star"], pts["alpha_unity"], gamma, eta1, eta2)


# ---------------------------------------------------------------------------------------------
# Improved model: exact points, sqrt-cusp shapes
# ---------------------------------------------------------------------------------------------
def rising_basis(s):
    """Columns (1-s)^2 s^k, k = 0..3: gamma/gamma*_{n-1} = col0 + a1 col1 + a2 col2 + a3 col3."""
    s = np.asarray(s, dtype=float)
    base = (1.0 - s) ** 2
    return np.stack([base, base * s, base * s**2, base * s**3], axis=-1)


def falling_basis(w):
    """Columns w^2 [1, (1-w), (1-w) w, (1-w) w^2]: gamma/gamma*_n = col0 + b0 col1 + ..."""
    w = np.asarray(w, dtype=float)
    w2, r = w**2, 1.0 - w
    return np.stack([w2, w2 * r, w2 * r * w, w2 * r * w**2], axis=-1)


def _branch_samples(points: pd.DataFrame, n: int, m: int = _SAMPLES):
    """Exact gamma ratios on both branches of window n: (s, F(s)), (w, G(w))."""
    star, unity = points["alpha_star"].to_numpy(), points["alpha_unity"].to_numpy()
    gstar = points["gamma_star"].to_numpy()
    lo, h, hi = star[n - 2], unity[n - 1], star[n - 1]
    # Chebyshev-like spacing: dense at both ends, where the shapes are stiffest.
    t = 0.5 - 0.5 * np.cos(np.pi * (np.arange(m) + 0.5) / m)
    a_r = lo + t**2 * (h - lo)  # s = t on the rising branch
    a_f = h + t * (hi - h)
    ref = sp.rigid_reference(np.concatenate([a_r, a_f]))
    gamma = 0.5 * (1.0 + ref["alpha"].to_numpy()) * (1.0 - ref["cor"].to_numpy())
    return t, gamma[:m] / gstar[n - 2], t, gamma[m:] / gstar[n - 1], a_r, a_f


def fit_window_shape(points: pd.DataFrame, n: int) -> np.ndarray:
    """Least-squares shape coefficients (a1, a2, a3, b0, b1, b2) of window n >= 2.

    Linear in the coefficients, so a plain lstsq on samples of the exact COR; residuals are
    weighted by 2 gamma*/(1 + alpha), making them errors in the COR itself.
    """
    s, F, w, G, a_r, a_f = _branch_samples(points, n)
    gstar = points["gamma_star"].to_numpy()
    wr = 2.0 * gstar[n - 2] / (1.0 + a_r)
    wf = 2.0 * gstar[n - 1] / (1.0 + a_f)
    B = rising_basis(s)
    a = np.linalg.lstsq(B[:, 1:] * wr[:, None], (F - B[:, 0]) * wr, rcond=None)[0]
    C = falling_basis(w)
    b = np.linalg.lstsq(C[:, 1:] * wf[:, None], (G - C[:, 0]) * wf, rcond=None)[0]
    return np.concatenate([a, b])


@lru_cache(maxsize=8)
def _shape_table_cached(n_max: int) -> pd.DataFrame:
    pts = _exact_points_cached(n_max)
    rows = [np.full(6, np.nan)] + [fit_window_shape(pts, n) for n in range(2, n_max + 1)]
    coef = pd.DataFrame(np.array(rows), columns=["a1", "a2", "a3", "b0", "b1", "b2"])
    return pd.concat([pts.reset_index(drop=True), coef], axis=1)


def shape_table(alpha_max: float = 200.0) -> pd.DataFrame:
    """Exact special points plus per-window shape coefficients, covering alpha <= alpha_max."""
    n_max = 50
    while _exact_points_cached(n_max)["alpha_star"].iloc[-1] <= alpha_max:
        n_max += 50
    return _shape_table_cached(n_max)


def improved_cor(alpha, table: pd.DataFrame | None = None, shape=None):
    """Improved approximate COR (beta = 0): exact points, sqrt-cusp shapes (module docstring).

    Parameters
    ----------
    alpha : array_like
        Mass ratios (> 0).
    table : DataFrame, optional
        Columns ``alpha_star, alpha_unity, gamma_star`` (and ``a1..b2`` for per-window shapes),
        one row per n = 1..N; default :func:`shape_table` covering ``max(alpha)``.
    shape : sequence of 6 floats, optional
        One set of (a1, a2, a3, b0, b1, b2) for every window (e.g. ``UNIVERSAL_SHAPE``) instead
        of the per-window coefficients of ``table``.

    Returns
    -------
    ndarray
        The approximate COR; exact ``(1 - alpha)/(1 + alpha)`` below alpha*_1, and exact at
        every alpha*_n (value e*_n) and alpha#_n (value 1).

    >>> round(float(improved_cor(1.0)), 12), round(float(improved_cor(0.5)), 12)
    (1.0, 0.333333333333)
    """
    a = np.asarray(alpha, dtype=float)
    tab = shape_table(float(np.max(a, initial=1.0))) if table is None else table
    star = tab["alpha_star"].to_numpy()
    unity = tab["alpha_unity"].to_numpy()
    gstar = tab["gamma_star"].to_numpy()
    n = _windows(a, star)
    i = n - 1
    j = np.maximum(n - 2, 0)
    if shape is None:
        coef = tab[["a1", "a2", "a3", "b0", "b1", "b2"]].to_numpy()[i]
    else:
        coef = np.broadcast_to(np.asarray(shape, dtype=float), (a.size, 6)).reshape(a.shape + (6,))
    lo, h, hi = star[j], unity[i], star[i]
    rising = a < h
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.sqrt(np.clip((a - lo) / (h - lo), 0.0, 1.0))
        w = np.clip((a - h) / (hi - h), 0.0, 1.0)
    a1, a2, a3, b0, b1, b2 = np.moveaxis(coef, -1, 0)
    up = gstar[j] * (1.0 - s) ** 2 * (1.0 + s * (a1 + s * (a2 + s * a3)))
    down = gstar[i] * w**2 * (1.0 + (1.0 - w) * (b0 + w * (b1 + w * b2)))
    gamma = np.where(rising, up, down)
    gamma = np.where(n == 1, a, gamma)  # single contact: e = (1 - alpha)/(1 + alpha) exactly
    return 1.0 - 2.0 * gamma / (1.0 + a)


# ---------------------------------------------------------------------------------------------
# Errors against the exact solution
# ---------------------------------------------------------------------------------------------
def error_grid(alpha_min: float = 0.01, alpha_max: float = 200.0, n_alpha: int = 200_001):
    """Log-spaced alphas plus every special point inside the range (the cusps are the worst)."""
    grid = np.geomspace(alpha_min, alpha_max, n_alpha)
    pts = exact_points(alpha_max)
    extra = np.concatenate([pts["alpha_star"], pts["alpha_unity"][1:]])
    extra = np.concatenate([extra, extra * (1 + 1e-6), extra * (1 - 1e-6)])
    extra = extra[(extra >= alpha_min) & (extra <= alpha_max)]
    return np.unique(np.concatenate([grid, extra]))


def errors(models: dict, alpha, exact=None) -> pd.DataFrame:
    """Max and RMS error (and where the max is) of each model ``name -> f(alpha)``.

    ``exact`` defaults to :func:`restitution.analysis.special_points.rigid_reference`'s COR.
    """
    a = np.asarray(alpha, dtype=float)
    ref = sp.rigid_reference(a)["cor"].to_numpy() if exact is None else np.asarray(exact)
    rows = []
    for name, f in models.items():
        err = f(a) - ref
        k = int(np.argmax(np.abs(err)))
        rows.append(
            dict(
                model=name,
                max_abs_error=float(abs(err[k])),
                alpha_at_max=float(a[k]),
                rms_error=float(np.sqrt(np.mean(err**2))),
            )
        )
    return pd.DataFrame(rows)


__all__ = [
    "PAPER",
    "UNIVERSAL_SHAPE",
    "eq21_cor",
    "error_grid",
    "errors",
    "exact_points",
    "falling_basis",
    "fit_window_shape",
    "improved_cor",
    "law_points",
    "paper_cor",
    "paper_cor_exact_points",
    "rising_basis",
    "shape_table",
]
