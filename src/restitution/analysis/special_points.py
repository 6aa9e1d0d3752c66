"""Exact special points of the two-mass COR curve: minima alpha*_n, e*_n and unity points alpha#_n.

For a rigid wall (beta = 0) every point is the root of a smooth defining condition, solved with
Brent's method to round-off (no grid scan decides a value):

- ``alpha*_n`` (grazing, paper Eqs. 17-18): after the n-th contact the gap between m1 and the wall
  has its next minimum exactly at zero, so the (n+1)-th contact is tangent. The condition is the
  value of that minimum, :func:`grazing_gap`, which is a smooth function of alpha with a simple
  root (the first n contacts are transversal there). ``e*_n`` is the COR at ``alpha*_n``.
- ``alpha#_n`` (unity COR): the vibration has no energy after n contacts. ``1 - cor`` has a
  *double* root there, so we solve a signed condition instead: the spring extension at the n-th
  contact, :func:`signed_vibration`. In each window ``(alpha*_{n-1}, alpha*_n)`` the post-contact
  vibration state moves along an almost straight line through the origin, so this component changes
  sign exactly once, where the whole state vanishes (checked: the other component is returned).

The motion between contacts is closed form (units m1 = V0 = omega = 1, alpha = m2/m1): centre of
mass velocity V, spring extension r = u2 - u1 with r'' = -r, and m1's gap to the wall

    g(s) = c r (1 - cos s) + V s - c r' sin s,    c = alpha / (1 + alpha),

s being the time since the contact. Its local minima are explicit, so "is there another contact"
and the grazing condition need no sampling; the contact time is a safeguarded Newton root on the
one monotone piece of g that brackets it. This module is an independent reference for the
project's kernels (docs/physics.md) and is used by the tests to check them.

Finite beta (contact spring k1 = k2/beta): the same points are where the contact count changes;
:func:`count_changes` finds them by bracketing and bisecting the count returned by any solver,
normally :func:`restitution.solve_many`.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from numba import prange
from scipy.optimize import brentq

from restitution.analysis.sweeps import interior_minima
from restitution.jit import njit
from restitution.kernels.constants import MAX_EVENTS_DEFAULT
from restitution.kernels.parallel import row_blocks

TWO_PI = 2.0 * math.pi
_NEWTON_ITERS = 100


@njit(cache=True)
def _gap(s, V, a, b):
    return a * (1.0 - math.cos(s)) + V * s - b * math.sin(s)


@njit(cache=True)
def _first_min(V, a, b):
    """(s_min, width): g's first local minimum after s = 0 and its distance to the maximum before.

    g'(s) = V + R sin(s - phi) with R = hypot(a, b); minima where sin(s - phi) = -V/R, cos >= 0.
    Returns s_min = -1 when g has no minimum (R <= |V|: g is monotonic).
    """
    R = math.hypot(a, b)
    if R <= abs(V):
        return -1.0, 0.0
    th = math.asin(-V / R)
    s = (math.atan2(b, a) + th) % TWO_PI
    if s <= 0.0:
        s += TWO_PI
    return s, math.pi + 2.0 * th


@njit(cache=True)
def _root(lo, hi, V, a, b):
    """The root of g on [lo, hi] where g decreases from > 0 to < 0 (safeguarded Newton)."""
    s = 0.5 * (lo + hi)
    for _ in range(_NEWTON_ITERS):
        gs = _gap(s, V, a, b)
        if gs > 0.0:
            lo = s
        elif gs < 0.0:
            hi = s
        else:
            return s
        d = a * math.sin(s) + V - b * math.cos(s)
        step_ok = False
        if d < 0.0:
            t = s - gs / d
            if lo < t < hi:
                step_ok = abs(t - s) < 0.5 * (hi - lo) or hi - lo < 1e-300
                s_new = t
        if not step_ok:
            s_new = 0.5 * (lo + hi)
        if abs(s_new - s) <= 2.2e-16 * abs(s_new) or hi - lo <= 4.4e-16 * abs(hi):
            return s_new
        s = s_new
    return s


@njit(cache=True)
def _next_contact(V, a, b):
    """Time from a contact to the next one, or -1 if m1 never comes back to the wall."""
    smin, width = _first_min(V, a, b)
    if smin < 0.0:
        return -1.0  # monotonic gap: after a genuine contact (g'(0) > 0) it only grows
    gmin = _gap(smin, V, a, b)
    if not gmin < 0.0:
        if V >= 0.0:
            return -1.0
        # Later minima are lower by 2 pi |V| each: jump to the first negative one.
        smin += TWO_PI * (math.floor(gmin / (TWO_PI * -V)) + 1.0)
    lo = max(smin - width, 0.0)
    if not _gap(lo, V, a, b) > 0.0:
        return -1.0  # degenerate: m1 left the previous contact with zero velocity (round-off)
    return _root(lo, smin, V, a, b)


@njit(cache=True)
def _run(alpha, n_max):
    """Follow at most n_max contacts; return (contacts, V, r, r', omega t of the last contact)."""
    c = alpha / (1.0 + alpha)
    # First contact at t = 0: m1's velocity -1 -> +1, m2 keeps -1.
    V = (1.0 - alpha) / (1.0 + alpha)
    r = 0.0
    rp = -2.0
    t = 0.0
    n = 1
    while n < n_max:
        s = _next_contact(V, c * r, c * rp)
        if s < 0.0:
            break
        cs, sn = math.cos(s), math.sin(s)
        r, rp = r * cs + rp * sn, rp * cs - r * sn
        v1 = V - c * rp  # m1's velocity before the contact (< 0)
        V -= 2.0 * v1 / (1.0 + alpha)
        rp += 2.0 * v1  # m1 reverses, m2 keeps its velocity: r' = v2 - v1 grows by 2 v1
        t += s
        n += 1
    return n, V, r, rp, t


@njit(cache=True, parallel=True)
def _run_many(alpha, n_max):
    out = np.empty((alpha.size, 5))
    nb, size, p = row_blocks(alpha.size)  # rows spread over the threads (kernels.parallel)
    for j in prange(nb):
        b = (j * p) % nb
        for i in range(b * size, min(alpha.size, b * size + size)):
            n, V, r, rp, t = _run(alpha[i], n_max)
            out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4] = n, V, r, rp, t
    return out


def rigid_reference(alpha, max_events: int = MAX_EVENTS_DEFAULT) -> pd.DataFrame:
    """Exact beta = 0 two-mass solution (independent of the kernels), vectorised over alpha.

    Returns a DataFrame with ``alpha, cor, n_collisions, omega_t_col`` and ``finished`` (False when
    ``max_events`` contacts were reached and another one would follow).
    """
    a = np.atleast_1d(np.asarray(alpha, dtype=np.float64)).ravel()
    out = _run_many(a, int(max_events))
    n = out[:, 0].astype(np.int64)
    finished = n < max_events
    if not finished.all():
        # n == max_events: finished only if no further contact would follow.
        for i in np.flatnonzero(~finished):
            finished[i] = grazing_gap(a[i], int(max_events)) >= 0.0
    return pd.DataFrame(
        {
            "alpha": a,
            "cor": out[:, 1],
            "n_collisions": n,
            "omega_t_col": out[:, 4],
            "finished": finished,
        }
    )


def state_after(alpha: float, n: int):
    """(contacts made, V, r, r', omega t) after the first ``min(n, total)`` contacts."""
    return _run(float(alpha), int(n))


def grazing_gap(alpha: float, n: int) -> float:
    """Value of the gap's first minimum after the n-th contact (< 0: an (n+1)-th contact follows).

    Its root in alpha is ``alpha*_n``. Defined wherever the first n contacts exist; raises
    ValueError otherwise.
    """
    made, V, r, rp, _ = _run(float(alpha), int(n))
    if made < n:
        raise ValueError(f"alpha={alpha!r} has only {made} contacts, fewer than n={n}")
    c = alpha / (1.0 + alpha)
    smin, _ = _first_min(V, c * r, c * rp)
    if smin < 0.0:
        return math.inf if V >= 0.0 else -math.inf
    return float(_gap(smin, V, c * r, c * rp))


def signed_vibration(alpha: float, n: int) -> float:
    """Spring extension r = u2 - u1 at the n-th contact: changes sign once at ``alpha#_n``."""
    made, V, r, rp, _ = _run(float(alpha), int(n))
    if made == n - 1 and n > 1:
        # At (or a round-off below) alpha*_{n-1} the n-th contact is the tangent one at the gap's
        # first minimum: continue r there so the function is defined on the closed window.
        c = alpha / (1.0 + alpha)
        smin, _ = _first_min(V, c * r, c * rp)
        if smin >= 0.0 and abs(_gap(smin, V, c * r, c * rp)) < 1e-9:
            return float(r * math.cos(smin) + rp * math.sin(smin))
    if made < n:
        raise ValueError(f"alpha={alpha!r} has only {made} contacts, fewer than n={n}")
    return float(r)


def alpha_star_1_closed_form() -> float:
    """alpha*_1 = 1 / (1 - 2 cos x1), x1 the first positive root of tan x = x (paper Eqs. 10-11)."""
    x1 = brentq(lambda x: math.sin(x) - x * math.cos(x), math.pi, 1.5 * math.pi, xtol=1e-16)
    return 1.0 / (1.0 - 2.0 * math.cos(x1))


def _brent(f, lo, hi):
    return brentq(f, lo, hi, xtol=1e-15, rtol=4.0 * np.finfo(float).eps, maxiter=200)


def alpha_star(n: int, lo: float, step: float) -> float:
    """Root of :func:`grazing_gap` (alpha, n) above ``lo`` (> alpha*_{n-1}), bracketed by steps."""
    f_lo = grazing_gap(lo, n)
    if not f_lo > 0.0:
        raise ValueError(f"grazing gap of n={n} is not positive at alpha={lo!r}")
    for _ in range(10_000):
        hi = lo + step
        f_hi = grazing_gap(hi, n)
        if f_hi < 0.0:
            return _brent(lambda a: grazing_gap(a, n), lo, hi)
        lo = hi
    raise RuntimeError(f"no grazing point found for n={n}")


def alpha_unity(n: int, lo: float, hi: float) -> float:
    """Root of :func:`signed_vibration` (alpha, n) in the n-contact window (lo, hi)."""
    return _brent(lambda a: signed_vibration(a, n), lo, hi)


def special_points(n_max: int = 30) -> pd.DataFrame:
    """alpha*_n, e*_n, alpha#_n for n = 1..n_max (beta = 0), with residuals of their conditions.

    Columns: ``n, alpha_star, e_star, omega_t_star`` (duration at alpha*_n), ``alpha_unity``
    (alpha#_n; 0 for n = 1, the limit alpha -> 0), ``gamma_star = (1 + alpha*)(1 - e*)/2`` (the
    paper's gamma at the minimum, Eq. 20), ``grazing_residual`` (gap minimum at alpha*_n),
    ``unity_residual`` (1 - cor at alpha#_n) and ``vibration_residual`` (|r'| there).
    """
    rows = []
    prev = 0.0
    spacing = 0.7
    for n in range(1, n_max + 1):
        # Step well below the spacing of the minima (which grows slowly, ~1.25 n**0.25).
        a_star = alpha_star(n, prev + 1e-9 * max(1.0, prev), 0.1 * spacing)
        _, e_star, _, _, t_star = _run(a_star, n)
        if n == 1:
            a_unity, unity_res, vib_res = 0.0, 0.0, 0.0
        else:
            a_unity = alpha_unity(n, prev, a_star)
            _, v_u, _, rp_u, _ = _run(a_unity, n)
            unity_res, vib_res = 1.0 - v_u, abs(rp_u)
        rows.append(
            dict(
                n=n,
                alpha_star=a_star,
                e_star=e_star,
                omega_t_star=t_star,
                alpha_unity=a_unity,
                gamma_star=0.5 * (1.0 + a_star) * (1.0 - e_star),
                grazing_residual=grazing_gap(a_star, n),
                unity_residual=unity_res,
                vibration_residual=vib_res,
            )
        )
        spacing = a_star - prev if n > 1 else spacing
        prev = a_star
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------------------------
# Finite beta: where the contact count changes (bisection on the count of any solver).
# ---------------------------------------------------------------------------------------------
def count_changes(
    solver, alpha_min: float, alpha_max: float, n_grid: int = 400, steps: int = 60
) -> pd.DataFrame:
    """Every alpha in [alpha_min, alpha_max] where the contact count changes, by bisection.

    ``solver(alphas) -> (cor, n_collisions)`` arrays. A log grid brackets the changes; each bracket
    is bisected ``steps`` times on the count in log alpha (a change of the count is a discontinuity,
    so the count itself is the defining condition). Returns ``alpha_change`` (midpoint of the final
    bracket), ``bracket`` (its width), ``n_below``, ``n_above`` and ``cor_below``, ``cor_above``
    (the COR at the bracket's ends; at a cusp minimum both tend to the minimum COR).
    """
    grid = np.geomspace(alpha_min, alpha_max, n_grid)
    cor, cnt = solver(grid)
    idx = np.flatnonzero(np.diff(cnt) != 0)
    lo, hi = grid[idx].copy(), grid[idx + 1].copy()
    n_lo, n_hi = cnt[idx].copy(), cnt[idx + 1].copy()
    c_lo, c_hi = cor[idx].copy(), cor[idx + 1].copy()
    for _ in range(steps):
        if lo.size == 0:
            break
        mid = np.sqrt(lo * hi)
        c_mid, n_mid = solver(mid)
        left = n_mid == n_lo  # the change is above mid
        lo = np.where(left, mid, lo)
        c_lo = np.where(left, c_mid, c_lo)
        hi = np.where(left, hi, mid)
        c_hi = np.where(left, c_hi, c_mid)
        n_hi = np.where(left, n_hi, n_mid)
    return pd.DataFrame(
        {
            "alpha_change": 0.5 * (lo + hi),
            "bracket": hi - lo,
            "n_below": n_lo,
            "n_above": n_hi,
            "cor_below": c_lo,
            "cor_above": c_hi,
        }
    )


def smooth_minima(solver, alpha_min: float, alpha_max: float, n_grid: int = 400) -> pd.DataFrame:
    """Local COR minima that are *not* at a change of the contact count (e.g. beta = 1).

    A grid local minimum whose two neighbours share its contact count is refined with bounded
    Brent minimisation in log alpha (accuracy ~sqrt(eps) in alpha, ample for a smooth minimum).
    Returns ``alpha_min, cor_min, n_collisions``.
    """
    from scipy.optimize import minimize_scalar

    grid = np.geomspace(alpha_min, alpha_max, n_grid)
    cor, cnt = solver(grid)
    inner = interior_minima(cor)
    rows = []
    for i in inner:
        if not cnt[i - 1] == cnt[i] == cnt[i + 1]:
            continue  # a cusp: count_changes finds it

        def f(x):
            return float(solver(np.array([math.exp(x)]))[0][0])

        res = minimize_scalar(
            f, bounds=(math.log(grid[i - 1]), math.log(grid[i + 1])), method="bounded",
            options={"xatol": 1e-10},
        )  # fmt: skip
        rows.append(dict(alpha_min=math.exp(res.x), cor_min=res.fun, n_collisions=int(cnt[i])))
    return pd.DataFrame(rows, columns=["alpha_min", "cor_min", "n_collisions"])


def rigid_solver(alphas):
    """``count_changes`` adapter for :func:`rigid_reference`."""
    ref = rigid_reference(alphas)
    return ref["cor"].to_numpy(), ref["n_collisions"].to_numpy()


def kernel_solver(beta: float, max_events: int = MAX_EVENTS_DEFAULT):
    """``count_changes`` adapter for :func:`restitution.solve_many` at stiffness ratio ``beta``."""

    def solve(alphas):
        from restitution.api import solve_many

        res = solve_many(pd.DataFrame({"alpha": alphas, "beta": beta}), max_events=max_events)
        return res["cor"].to_numpy(), res["n_collisions"].to_numpy()

    return solve


__all__ = [
    "alpha_star",
    "alpha_star_1_closed_form",
    "alpha_unity",
    "count_changes",
    "grazing_gap",
    "kernel_solver",
    "rigid_reference",
    "rigid_solver",
    "signed_vibration",
    "smooth_minima",
    "special_points",
    "state_after",
]
