"""Minimum-COR design of mass-spring chains: which masses (and springs) rebound the least.

The paper's two-mass optimum alpha*_1 = 0.6971..., COR e*_1 = 0.178... is a *cusp*: the COR is
smallest exactly where one more contact grazes the wall, and rises like the square root of the
distance on one side. This module asks the same of an N-mass chain.

Method
------
1. **Global search**: scipy's ``differential_evolution`` over the logarithms of the ratios
   m_i/m_1 (i = 2..N; optionally also k_i/k_12, i = 2..N-1) within user bounds, seeded, one worker
   and ``updating="deferred"``, so the result is identical for any thread count. Its population
   is solved unchecked (the kernel's first run alone, without the replica check that a reported
   result gets: ``solve_scaled_arrays(check=False)``), 3-8 times faster; the polish and the
   reported design are solved checked.
2. **Polish on the grazing manifold**: the optimum sits where some contact grazes, i.e. on the
   zero set of a smooth grazing condition G (``restitution.analysis.cormap``: the first gap minimum
   after
   the n-th separation, or the first compression minimum of the n-th contact). The polish does not
   poke at the cusp: it solves G = 0 for the coordinate G depends on most (Brent's method) and, for
   more than one free parameter, minimises the COR over the remaining coordinates on that manifold
   (Nelder-Mead, where the COR is smooth). The COR is read on the side of the manifold where the
   grazing contact is absent (there it varies linearly, not like a square root).
3. **Robust variant**: the worst COR over independent mass errors of +-``tolerance`` (each mass
   on its own), searched by an inner optimiser (the worst case near a cusp need not be a corner of
   the error box), is minimised instead.
4. **Bounds**: a ratio on or within 1 % of its bound is tested by relaxing the bound: the
   objective 1e-6 past it (the other ratios kept) and after a short local re-optimisation (the
   polish, or Powell for robust designs) with the bound moved out by 1 %; the bound is *active*
   (``Design.bound_active``) when either falls: the design is then the bound's, not a free
   optimum (a cusp optimum whose grazing manifold meets a bound falls only along the manifold).
   ``Design.active`` lists every active constraint (active bounds, the grazing condition of a
   cusp optimum). Tapered chains bound their step ratio, not their end mass (which only has to
   stay within the solvers' ratio range), so a long chain may taper as fast as a short one.

``warm_starts`` puts given chains (e.g. the optimum of a family this one contains) into the
search's first population. Every design's COR is re-checked by a fresh solver call
(``cor_check``).

Units: ratios to m_1 and k_12; the chain is scaled to omega = 1 (omega^2 = k_12/m_1 + k_12/m_2)
for the solver, so beta = k_12/k_contact as in the paper.
"""

from __future__ import annotations

import functools
import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq, differential_evolution, minimize, root_scalar

from restitution.analysis.scaled import solve_scaled, solve_scaled_arrays
from restitution.kernels.constants import MAX_EVENTS_DEFAULT
from restitution.model.chain import RATIOS, check
from restitution.model.ranges import SceneError, _real, _show

log = logging.getLogger(__name__)

DEFAULT_BOUNDS = (0.01, 100.0)
MAX_MASSES = 16
RELAX = 1e-6  # log step past a bound of the activity test (``_relaxed``)
RELAX_BOX = 0.01  # a bound moved out by this (log: 1 %) for the local re-optimisation there
# Seconds between the progress lines of a stage with no step of its own to report (the polish,
# the bound test, the worst-case search), e.g. "masses N=4 polish: 12799 solves, ... grazing
# evaluations so far (120 s)".
HEARTBEAT = 30.0
_BAD = 10.0  # objective of a scene the solver could not finish (never a minimum: COR <= 1)


def scaled_chain(mass_ratios, spring_ratios, beta: float):
    """(masses, springs, k_contact) in solver units from ratios to m_1 and k_12 and beta."""
    m = np.asarray(mass_ratios, dtype=float)
    kr = np.asarray(spring_ratios, dtype=float)
    k12 = 1.0 / (1.0 / m[0] + 1.0 / m[1])  # omega = 1 with m_1 = 1
    k = kr * k12
    return m, k, (math.inf if beta == 0.0 else k[0] / beta)


def _scaled_chains(masses, spring_ratios, beta: float):
    """``scaled_chain`` of every row of masses (S, N) and spring ratios (S, N - 1), as arrays
    (the same operations, bit for bit): (masses, springs, k_contact) for solve_scaled_arrays."""
    m = masses / masses[:, :1]
    k12 = 1.0 / (1.0 / m[:, 0] + 1.0 / m[:, 1])
    k = spring_ratios * k12[:, None]
    return m, k, (np.full(m.shape[0], math.inf) if beta == 0.0 else k[:, 0] / beta)


# ---------------------------------------------------------------------------------------------
# Results.
# ---------------------------------------------------------------------------------------------
@dataclass
class Design:
    """An optimised chain.

    Attributes
    ----------
    masses, springs : numpy arrays
        Ratios m_i/m_1 (masses[0] = 1) and k_i/k_12 (springs[0] = 1).
    cor : float
        COR of the design (the robust objective's nominal COR for ``robust`` designs).
    n_collisions : int
        Contacts of the design (on the side of the cusp where the grazing contact is absent).
    worst_cor : float
        Worst COR over the mass errors (nan unless ``tolerance`` > 0).
    cor_check : float
        COR re-solved by a fresh ``restitution.solve`` call.
    error_estimate : float
        The solver's estimate of the COR's error (``Result.error_estimate`` of the design's
        checked solve): on a grazing cusp, where the replica runs straddle the cusp, about 1e-6.
    bounds_hit : list of str
        Parameters on or within 1 % of a bound, each with the COR just past the bound
        (e.g. ``["m_3/m_1 = 0.01 at lower bound 0.01 (active: COR 0.0987 past it)"]``).
    bound_active : bool
        Some bound is active: the COR falls when that bound is relaxed (by 1e-6), so the design
        depends on the bound (a free optimum would lie beyond it).
    active : list of str
        Every constraint active at the design: the active bounds and the grazing condition the
        optimum sits on (``"grazing new n=2"``); empty for a smooth interior minimum.
    warm_starts : int
        Points put into the search's first population (``x0``), e.g. a smaller family's optimum.
    grazing : tuple or None
        (n, kind) of the grazing condition the polish solved, or None.
    method : str
        How the optimum was found.
    evaluations : int
        Solver calls.
    """

    family: str
    n_masses: int
    beta: float
    masses: np.ndarray
    springs: np.ndarray
    cor: float
    n_collisions: int
    worst_cor: float = math.nan
    tolerance: float = 0.0
    cor_check: float = math.nan
    error_estimate: float = math.nan
    bounds_hit: list = field(default_factory=list)
    grazing: tuple | None = None
    method: str = ""
    evaluations: int = 0
    parameter: float = math.nan  # the family's one parameter (uniform: alpha; tapered: ratio)
    bound_active: bool = False
    active: list = field(default_factory=list)
    warm_starts: int = 0

    def row(self) -> dict:
        """One table row (lists for the chain)."""
        return dict(
            family=self.family,
            n_masses=self.n_masses,
            beta=self.beta,
            tolerance=self.tolerance,
            cor=self.cor,
            cor_check=self.cor_check,
            error_estimate=self.error_estimate,
            worst_cor=self.worst_cor,
            n_collisions=self.n_collisions,
            parameter=self.parameter,
            masses=[float(x) for x in self.masses],
            springs=[float(x) for x in self.springs],
            bounds_hit="; ".join(self.bounds_hit),
            bound_active=bool(self.bound_active),
            active="; ".join(self.active) or "none (smooth interior minimum)",
            warm_starts=int(self.warm_starts),
            grazing="" if self.grazing is None else f"{self.grazing[1]} n={self.grazing[0]}",
            method=self.method,
            evaluations=self.evaluations,
        )


# ---------------------------------------------------------------------------------------------
# Parametrisations: log-parameters -> (mass ratios, spring ratios).
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Family:
    """A family of chains: ``chain(x)`` maps log-parameters x to (mass ratios, spring ratios)."""

    name: str
    n_masses: int
    dim: int
    names: tuple

    def coords(self, masses, springs=None):
        """Log-parameters x of the chain (mass ratios, spring ratios): the inverse of
        :meth:`chain` on the family (a chain outside it: its nearest reading, e.g. m_2/m_1 for
        ``uniform`` and ``tapered``)."""
        m = np.asarray(masses, dtype=float)
        m = m / m[0]
        if m.size != self.n_masses:
            raise ValueError(f"a warm start of {m.size} masses for a family of {self.n_masses}")
        if self.name in ("uniform", "tapered"):
            return np.array([math.log(m[1])])
        x = np.log(m[1:])
        if self.name == "masses+springs":
            k = np.ones(self.n_masses - 1) if springs is None else np.asarray(springs, float)
            x = np.r_[x, np.log(k[1:] / k[0])]
        return x

    def chain(self, x):
        """(mass ratios, spring ratios) of the log-parameters x."""
        m, k = self.chains(np.asarray(x, dtype=float)[:, None])
        return m[0], k[0]

    def chains(self, X):
        """``chain`` of every column of X (dim, S), as arrays (S, N) and (S, N - 1)."""
        n, s = self.n_masses, X.shape[1]
        m = np.ones((s, n))
        k = np.ones((s, n - 1))
        if self.name == "uniform":
            m[:, 1:] = np.array([math.exp(v) for v in X[0]])[:, None]  # (libm's, as before)
        elif self.name == "tapered":
            m = np.exp(X[0][:, None] * np.arange(n))
        else:
            m[:, 1:] = np.exp(X[: n - 1].T)
            if self.name == "masses+springs":
                k[:, 1:] = np.exp(X[n - 1 :].T)
        return m, k


def family(name: str, n_masses: int) -> Family:
    if name in ("uniform", "tapered"):
        label = "m_2/m_1 (all)" if name == "uniform" else "m_(i+1)/m_i"
        return Family(name, n_masses, 1, (label,))
    masses = tuple(f"m_{i}/m_1" for i in range(2, n_masses + 1))
    if name == "masses":
        return Family(name, n_masses, n_masses - 1, masses)
    if name == "masses+springs":
        springs = tuple(f"k_{i}/k_12" for i in range(2, n_masses))
        return Family(name, n_masses, n_masses - 1 + len(springs), masses + springs)
    raise ValueError(
        f"family={name!r}: must be one of 'masses', 'masses+springs', 'uniform', 'tapered'"
    )


# ---------------------------------------------------------------------------------------------
# Objective.
# ---------------------------------------------------------------------------------------------
class _Objective:
    """COR (or worst COR over mass errors) of a family member, counting solver calls."""

    def __init__(self, fam: Family, beta: float, tolerance: float, max_events: int,
                 progress=None):  # fmt: skip
        self.fam, self.beta, self.tol, self.max_events = fam, beta, tolerance, max_events
        self.calls = 0
        self.grazings = 0  # evaluations of a grazing condition (the polish's manifold search)
        self.samples = 16  # Sobol points of the robust objective's error box
        # Work of the polish: solves and grazing evaluations, stopped past ``limit``.
        self.spent, self.limit = 0, math.inf
        # Progress: ``report`` lines, and a heartbeat every HEARTBEAT s within a ``stage``.
        self.progress, self.stage = progress, None
        self._beat = self._stage_start = time.monotonic()

    def report(self, text: str) -> None:
        """One progress line (none without ``progress``); restarts the heartbeat's clock."""
        if self.progress:
            self.progress(text)
        self._beat = time.monotonic()

    def begin(self, stage: str | None) -> None:
        """Enter a stage of the run: its heartbeat lines are named after it (None: no lines)."""
        self.stage = stage
        self._beat = self._stage_start = time.monotonic()

    def tick(self) -> None:
        """A heartbeat line if HEARTBEAT s passed since the last line (cheap: one clock read)."""
        if self.progress and self.stage and time.monotonic() - self._beat >= HEARTBEAT:
            elapsed = time.monotonic() - self._stage_start
            work = f"{self.calls} solves"
            if self.grazings:
                work += f", {self.grazings} grazing evaluations"
            self.report(
                f"{self.fam.name} N={self.fam.n_masses} {self.stage}: {work} so far "
                f"({elapsed:.0f} s)"
            )

    def spend(self) -> None:
        """Count one evaluation of the polish; _Spent once its budget is used up."""
        self.tick()
        self.spent += 1
        if self.spent > self.limit:
            raise _Spent

    def solve(self, m, k):
        self.spend()
        self.calls += 1
        masses, springs, kc = scaled_chain(m / m[0], k, self.beta)
        return solve_scaled(masses, springs, kc, max_events=self.max_events)

    def cor(self, x) -> float:
        m, k = self.fam.chain(x)
        r = self.solve(m, k)
        return r.cor if r.success else _BAD

    def _box(self, n):
        """Error vectors of the robust objective: centre, corners (<= 64), a Sobol sample."""
        corners = np.array(np.meshgrid(*[[-1.0, 1.0]] * n)).reshape(n, -1).T
        if corners.shape[0] > 64:
            corners = corners[np.random.default_rng(0).choice(corners.shape[0], 64, replace=False)]
        return np.vstack([np.zeros(n), corners, 2.0 * _sobol(n, self.samples) - 1.0]) * self.tol

    def batch(self, X) -> np.ndarray:
        """Objective of a whole population X (dim, S) in one ``solve_many`` call.

        Robust: the worst over the batch of error vectors of :meth:`_box` (the reported design's
        worst case is then searched properly by :meth:`worst`).
        """
        X = np.atleast_2d(X)
        n = self.fam.n_masses
        errs = self._box(n) if self.tol > 0.0 else np.zeros((1, n))
        m, k = self.fam.chains(X)  # every (member, error vector) pair, member by member:
        masses = (m[:, None, :] * (1.0 + errs)).reshape(-1, n)
        springs = np.repeat(k, errs.shape[0], axis=0)
        chains = _scaled_chains(masses, springs, self.beta)
        self.calls += chains[0].shape[0]
        self.tick()
        # Unchecked runs (no replicas: a third of the work or less): the search needs the COR
        # only, and every design it finds is solved again, checked (``_optimise``).
        cor, ok = solve_scaled_arrays(*chains, self.max_events, check=False)
        return np.where(ok, cor, _BAD).reshape(X.shape[1], errs.shape[0]).max(axis=1)

    def worst(self, x) -> float:
        """Worst COR over independent mass errors |d_i| <= tol (inner search, see module doc)."""
        m, k = self.fam.chain(x)
        n = m.size

        def chain(d):
            return scaled_chain(m * (1.0 + np.asarray(d)) / (m[0] * (1.0 + d[0])), k, self.beta)

        # One batch over the error box (its corners, a scrambled Sobol sample, the centre), then a
        # bounded local climb from the worst: near a cusp the worst case may be interior.
        pts = self._box(n)
        self.calls += pts.shape[0]
        cor, ok = solve_scaled_arrays(
            *_scaled_chains(m * (1.0 + pts), np.broadcast_to(k, (pts.shape[0], n - 1)), self.beta),
            self.max_events,
        )
        cor = np.where(ok, cor, _BAD)
        i = int(np.argmax(cor))

        def neg(d):
            self.calls += 1
            self.tick()
            r = solve_scaled(*chain(d), max_events=self.max_events)
            return -(r.cor if r.success else _BAD)

        res = minimize(
            neg,
            pts[i],
            method="Powell",
            bounds=[(-self.tol, self.tol)] * n,
            options={"xtol": 1e-3 * self.tol, "ftol": 1e-12, "maxfev": 20 * n},
        )
        return max(float(cor[i]), -float(res.fun))

    def __call__(self, x) -> float:
        return self.worst(x) if self.tol > 0.0 else self.cor(x)


class _Spent(Exception):
    """The polish used up its budget (``_Objective.limit``)."""


@functools.lru_cache(maxsize=16)
def _sobol(dim: int, n: int) -> np.ndarray:
    from scipy.stats import qmc

    return qmc.Sobol(dim, scramble=True, seed=0).random(n)


# ---------------------------------------------------------------------------------------------
# Polish on the grazing manifold.
# ---------------------------------------------------------------------------------------------
def _grazing_value(fam: Family, beta: float, x, n: int, kind: str, objective=None) -> float:
    from restitution.analysis.cormap import grazing  # cormap imports nothing of this module

    if objective is not None:
        objective.spend()
        objective.grazings += 1
    m, k = fam.chain(x)
    masses, springs, kc = scaled_chain(m, k, beta)
    try:
        # Unchecked runs, as the search's (``_Objective.batch``): the polish needs G only, and
        # the design it finds is solved again, checked (``_optimise``).
        return grazing(masses, springs, kc, n, kind, check=False).value
    except SceneError:
        # The manifold search's unbounded steps (Nelder-Mead, secant) can leave the ratios the
        # solvers handle (a mass ratio of 6e-9 in Fig. 8(b)'s polish): no manifold point there.
        return math.nan


# The root finders' tolerance on G = 0. G, the grazing contact's gap, carries round-off of about
# 1e-12 (its sign flips several times within +-8 ulps of a root: design polish of free masses and
# springs N = 7, 2026-11-28), so a root is defined to about that and the finders stop there. At
# 1e-15 the secant chased that noise to its iteration limit in a quarter of the polish's solves.
ROOT_XTOL = 1e-12


def _solve_on_manifold(fam, beta, x, j, n, kind, span=0.05, objective=None):
    """x with coordinate j moved so that G(n, kind) = 0 (nearest root within +-span), or None."""

    @functools.lru_cache(maxsize=8)  # the secant starts where f0 was taken
    def f(t):
        y = np.array(x, dtype=float)
        y[j] = t
        return _grazing_value(fam, beta, y, n, kind, objective)

    f0 = f(x[j])
    if not math.isfinite(f0):
        return None
    # Fast path (the manifold search calls this often from points near the manifold): secant.
    try:
        sec = root_scalar(f, x0=x[j], x1=x[j] + 1e-7, method="secant", xtol=ROOT_XTOL, maxiter=30)
        if sec.converged and abs(sec.root - x[j]) <= span:
            y = _to_safe_side(f, sec.root, x, j)
            if y is not None:
                return y
    except (ValueError, OverflowError, ZeroDivisionError):
        pass
    step = span / 64
    while step <= span:
        for s in (1.0, -1.0):
            f1 = f(x[j] + s * step)
            if math.isfinite(f1) and f1 * f0 <= 0.0:
                lo, hi = sorted((x[j], x[j] + s * step))
                try:
                    t = brentq(f, lo, hi, xtol=ROOT_XTOL, maxiter=200)
                except ValueError:  # G is NaN inside the bracket (a scene the solver refused)
                    return None
                return _to_safe_side(f, t, x, j)
        step *= 2.0
    return None


def _to_safe_side(f, t, x, j):
    """Step a root t of f by ulps onto the side without the grazing contact (f >= 0).

    There the COR is linear in the distance, so round-off in the root costs round-off in the COR
    (on the other side it rises like the square root)."""
    g = f(t)
    if not math.isfinite(g) or abs(g) > 1e-9:
        return None
    direction = 1.0 if f(t + 1e-9) >= g else -1.0
    # Steps of 1, 2, 4, ... ulps: the root is known to ROOT_XTOL, so the safe side can be
    # thousands of ulps away; the step ends at most twice as far in as the first safe point.
    step = max(float(np.spacing(abs(t))), 1e-18)  # (a root at 0: no climb from 5e-324)
    while g < 0.0 and step <= 1e-9:
        t += direction * step
        g, step = f(t), 2.0 * step
    if not g >= 0.0:
        return None
    y = np.array(x, dtype=float)
    y[j] = t
    return y


def _candidates(n_col: int, beta: float):
    """Grazing conditions that can bound a cusp next to a scene with n_col contacts."""
    out = [(n, "new") for n in (n_col - 1, n_col) if n >= 1]
    if beta > 0.0:
        out += [(n, "split") for n in range(1, n_col + 1)]
    return out


def _polish(fam, beta, x0, objective: _Objective, progress, box):
    """Polish the global search's best point on the grazing manifold; (x, grazing, finished):
    the best point found, its grazing condition or None, and False when the polish stopped at
    its budget (``objective.limit``: then the best point so far)."""
    m, k = fam.chain(x0)
    n_col = objective.solve(m, k).n_collisions
    best = [np.asarray(x0, float), objective.cor(x0), None]
    try:
        _polish_steps(fam, beta, x0, objective, progress, box, n_col, best)
    except _Spent:
        if progress:
            progress(f"polish: stopped at its budget of {objective.limit} evaluations")
        return best[0], best[2], False
    return best[0], best[2], True


def _polish_steps(fam, beta, x0, objective, progress, box, n_col, best):
    """The steps of _polish, improving ``best`` = [x, COR, grazing] in place."""
    best_x, best_f, best_g = best
    for n, kind in _candidates(n_col, beta):
        # Solve G = 0 for the coordinate it depends on most.
        grads = []
        for j in range(fam.dim):
            e = np.zeros(fam.dim)
            e[j] = 1e-6
            gp = _grazing_value(fam, beta, x0 + e, n, kind, objective)
            gm = _grazing_value(fam, beta, x0 - e, n, kind, objective)
            grads.append(abs(gp - gm) if math.isfinite(gp - gm) else 0.0)
        if not any(grads):
            continue
        j = int(np.argmax(grads))
        y = _solve_on_manifold(fam, beta, x0, j, n, kind, objective=objective)
        if y is None or not _inside(y, box):
            continue
        if fam.dim > 1:
            y = _minimise_on_manifold(fam, beta, y, j, n, kind, objective)
            if not _inside(y, box):
                continue
        fy = objective.cor(y)
        if progress:
            progress(f"polish: grazing {kind} n={n}: COR {fy:.15g} (search: {best_f:.15g})")
        if fy <= best_f + 1e-12:
            best_x, best_f, best_g = y, fy, (n, kind)
            best[:] = best_x, best_f, best_g
    # At beta > 0 the COR may also have a smooth minimum next to the cusp (the new contact's
    # impulse then grows smoothly, not like a square root): a tight local search finds it.
    loc = minimize(
        objective.cor,
        x0,
        method="Nelder-Mead",
        bounds=box,
        options={
            "xatol": 1e-13,
            "fatol": 1e-16,
            "maxfev": 400 * fam.dim,
            "initial_simplex": np.vstack([x0, x0 + 1e-4 * np.eye(fam.dim)]),
        },
    )
    if loc.fun < best_f - 1e-12:  # more than round-off below the grazing point
        if progress:
            progress(f"polish: smooth minimum: COR {loc.fun:.15g}")
        best[:] = loc.x, loc.fun, None


def _inside(x, box) -> bool:
    return all(lo <= xi <= hi for xi, (lo, hi) in zip(x, box, strict=True))


def _minimise_on_manifold(fam, beta, y0, j, n, kind, objective):
    """Minimise the COR over the other coordinates, coordinate j solved from G = 0 each time."""
    free = [i for i in range(fam.dim) if i != j]
    state = {"y": np.array(y0)}

    def f(z):
        x = np.array(state["y"])
        x[free] = z
        y = _solve_on_manifold(fam, beta, x, j, n, kind, objective=objective)
        if y is None:
            return _BAD
        state["y"] = y
        return objective.cor(y)

    res = minimize(
        f,
        np.asarray(y0)[free],
        method="Nelder-Mead",
        options={"xatol": 1e-9, "fatol": 1e-14, "maxfev": 60 * len(free)},
    )
    x = np.array(state["y"])
    x[free] = res.x
    y = _solve_on_manifold(fam, beta, x, j, n, kind, objective=objective)
    return y0 if y is None or objective.cor(y) > objective.cor(y0) else y


# ---------------------------------------------------------------------------------------------
# Public entry points.
# ---------------------------------------------------------------------------------------------
def _int_in(name: str, value, low: int, high: int) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise SceneError(f"{name} must be an integer in [{low}, {high}]; got {_show(value)}")
    if not low <= value <= high:
        raise SceneError(f"{name} must be an integer in [{low}, {high}]; got {_show(value)}")
    return int(value)


def _check(n_masses, beta, bounds, tolerance, vary, seed=1, popsize=15, maxiter=200,
           max_events=MAX_EVENTS_DEFAULT, polish=True, progress=None):  # fmt: skip
    """Every argument of the design entry points, before any work (SceneError, a ValueError,
    naming the argument and its range)."""
    _int_in("n_masses", n_masses, 2, MAX_MASSES)
    b = _real(beta)
    if b is None or not (math.isfinite(b) and 0.0 <= b <= 1e6):
        raise SceneError(f"beta must be a number in [0, 1e6] (0: rigid wall); got {_show(beta)}")
    lo_r, hi_r = RATIOS["masses[i]/masses[0]"]
    what = f"bounds must be (low, high) with {lo_r:g} <= low < high <= {hi_r:g}"
    try:
        lo, hi = (_real(v) for v in bounds)
    except (TypeError, ValueError):
        raise SceneError(f"{what}; got {_show(bounds)}") from None
    if lo is None or hi is None or not lo_r <= lo < hi <= hi_r:
        raise SceneError(f"{what} (the ratios the solvers handle); got {_show(bounds)}")
    t = _real(tolerance)
    if t is None or not (math.isfinite(t) and 0.0 <= t < 0.5):
        raise SceneError(f"tolerance must be a number in [0, 0.5); got {_show(tolerance)}")
    if not isinstance(vary, str) or vary not in ("masses", "masses+springs"):
        raise SceneError(f"vary must be 'masses' or 'masses+springs'; got {_show(vary)}")
    if seed is not None:
        _int_in("seed", seed, 0, 2**32 - 1)
    _int_in("popsize", popsize, 1, 10_000)
    _int_in("maxiter", maxiter, 1, 1_000_000)
    check("max_events", max_events)
    if not isinstance(polish, (bool, np.bool_)):
        raise SceneError(f"polish must be True or False; got {_show(polish)}")
    if progress is not None and not callable(progress):
        raise SceneError(f"progress must be a callable (e.g. print) or None; got {_show(progress)}")


def _box_of(fam: Family, bounds):
    """(lower, upper) log-bounds of the family's parameters.

    Every ratio (m_i/m_1, k_i/k_12; uniform: alpha) within ``bounds``. Tapered chains: the step
    ratio r = m_(i+1)/m_i within ``bounds`` and the end mass r**(N-1) within the ratios the solvers
    handle (``chain.RATIOS``, 1e-8..1e8), not within ``bounds``: bounding the end mass by
    ``bounds`` would cut a long chain off from the tapers a short one reaches (at N = 7 the
    decreasing chain could not taper faster than r = 0.464, issue 26)."""
    lo, hi = math.log(bounds[0]), math.log(bounds[1])
    if fam.name != "tapered":
        return [lo] * fam.dim, [hi] * fam.dim
    r_lo, r_hi = RATIOS["masses[i]/masses[0]"]
    steps = fam.n_masses - 1
    return [max(lo, math.log(r_lo) / steps)], [min(hi, math.log(r_hi) / steps)]


def _first_population(fam, lb, ub, popsize, seed, starts):
    """The search's first population: a scrambled Sobol sample of the box with the warm starts
    (clipped into the box) in its first rows."""
    import warnings

    from scipy.stats import qmc

    size = max(5, popsize * fam.dim)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # Sobol's balance warning for sizes not a power of 2
        unit = qmc.Sobol(fam.dim, scramble=True, seed=seed).random(size)
    pop = np.asarray(lb) + unit * (np.asarray(ub) - np.asarray(lb))
    for i, x in enumerate(starts[: size - 1]):
        pop[i] = np.clip(x, lb, ub)
    return pop


def _relaxed(objective, fam, x, lb, ub, f_x, local=None):
    """Bounds the design sits on or near (within 1 % in the ratio), each tested by relaxing it.

    Two tests; the bound is active (a free optimum lies beyond it) when either lowers the
    objective by more than 1e-12: (1) the objective ``RELAX`` (relative 1e-6) past the bound,
    the other ratios kept (small, so that the first-order change decides); (2) ``local(x, box)``,
    a local re-optimisation from the design in the box with this bound moved out by
    ``RELAX_BOX`` (1 %), started from the design pushed onto the relaxed bound: an optimum on a
    grazing manifold that meets the bound is only lowered by moving along the manifold, i.e. by
    changing the other ratios too. [(text, active)]."""
    out = []
    r_lo, r_hi = (math.log(v) for v in RATIOS["masses[i]/masses[0]"])
    for j, (name, xi, low, up) in enumerate(zip(fam.names, x, lb, ub, strict=True)):
        for edge, which, sign in ((low, "lower", -1.0), (up, "upper", 1.0)):
            gap = abs(xi - edge)
            if gap >= 0.01:
                continue
            word = "at" if gap < 1e-6 else f"within {100 * (math.exp(gap) - 1):.2g} % of"
            text = f"{name} = {math.exp(xi):.4g} {word} {which} bound {math.exp(edge):.4g}"
            y = np.array(x, dtype=float)
            y[j] = edge + sign * RELAX_BOX
            m, _ = fam.chain(y)
            lm = np.log(m / m[0])
            if lm.min() < r_lo or lm.max() > r_hi:
                out.append((f"{text} (the solvers' ratio range: not relaxed)", True))
                continue
            y[j] = edge + sign * RELAX
            step = objective(y) - f_x
            moved = math.nan
            if local is not None:
                box = [list(b) for b in zip(lb, ub, strict=True)]
                box[j][0 if sign < 0 else 1] = edge + sign * RELAX_BOX
                pushed = np.array(x, dtype=float)
                pushed[j] = edge + sign * RELAX_BOX  # onto the relaxed bound, then re-optimised
                moved = min(local(pushed, [tuple(b) for b in box]), f_x) - f_x
            active = step < -1e-12 or moved < -1e-12
            words = f"COR {step:+.2g} just past it"
            if math.isfinite(moved):
                words += f", {moved:+.2g} re-optimised with the bound 1 % out"
            out.append((f"{text} ({'active' if active else 'not active'}: {words})", active))
    return out


def _optimise(fam, beta, bounds, tolerance, seed, popsize, maxiter, max_events, progress, polish,
              starts=()):  # fmt: skip
    objective = _Objective(fam, beta, tolerance, max_events, progress)
    lb, ub = _box_of(fam, bounds)
    starts = [np.asarray(fam.coords(*s), dtype=float) for s in starts]
    gen = [0]

    def callback(intermediate_result):
        gen[0] += 1
        objective.report(
            f"{fam.name} N={fam.n_masses} generation {gen[0]}: best "
            f"{intermediate_result.fun:.10g} ({objective.calls} solves)"
        )

    objective.begin("search")

    res = differential_evolution(
        objective.batch,
        list(zip(lb, ub, strict=True)),
        seed=seed,
        popsize=popsize,
        maxiter=maxiter,
        # The search only has to find the cusp's basin: the polish resolves the cusp itself.
        tol=1e-7,
        workers=1,
        updating="deferred",
        polish=False,
        callback=callback,
        init=_first_population(fam, lb, ub, popsize, seed, starts) if starts else "sobol",
        vectorized=True,
    )
    x, graz = res.x, None
    method = "differential_evolution"
    if polish and tolerance == 0.0:
        # The polish's budget is the global search's: its population times (maxiter + 1)
        # evaluations (solves and grazing evaluations), so popsize and maxiter bound the
        # whole run (the polish alone ran 450 s for N = 16, popsize 4, maxiter 3).
        objective.spent = 0
        objective.limit = max(5, popsize * fam.dim) * (maxiter + 1)
        box = list(zip(lb, ub, strict=True))
        objective.begin("polish")
        x, graz, finished = _polish(fam, beta, res.x, objective, progress, box)
        objective.limit = math.inf
        method += " + grazing-manifold polish" if graz else " + local polish (smooth minimum)"
        if not finished:
            method += f" (stopped at its budget of {max(5, popsize * fam.dim) * (maxiter + 1)})"
    elif tolerance > 0.0:
        # Robust objective is not a cusp of one condition: refine it where it is (bounded Powell).
        objective.begin("local search (Powell)")
        loc = minimize(
            lambda z: float(objective.batch(np.asarray(z)[:, None])[0]),
            res.x,
            method="Powell",
            bounds=list(zip(lb, ub, strict=True)),
            options={"xtol": 1e-8, "ftol": 1e-12, "maxfev": 50 * fam.dim},
        )
        if loc.fun <= res.fun:
            x = loc.x
        method += " + Powell; worst case: batch over the error box, then an inner Powell climb"
    m, k = fam.chain(x)
    r = objective.solve(m, k)
    masses, springs, kc = scaled_chain(m, k, beta)
    check = solve_scaled(masses, springs, kc, max_events=max_events)
    # "near": within 1 % of a bound, where the local polish may stop short of it while the COR
    # still falls towards it; the bound is active when the COR falls just past it (RELAX).
    f_x = objective(x)

    def local(x0, box):
        """The objective after a short local search from x0 in ``box`` (the activity test)."""
        if tolerance == 0.0:
            objective.spent, objective.limit = 0, 1000 * fam.dim + 2000
            y, _, _ = _polish(fam, beta, x0, objective, None, box)
            objective.limit = math.inf
            return objective.cor(y)
        res = minimize(lambda z: float(objective.batch(np.asarray(z)[:, None])[0]), x0,
                       method="Powell", bounds=box,
                       options={"xtol": 1e-8, "ftol": 1e-12, "maxfev": 20 * fam.dim})  # fmt: skip
        # Powell ran on the batch objective (the error box's sample); compare like with like:
        # the worst case of its result searched as the design's was (``worst``).
        return objective(res.x)

    objective.begin("bound test")
    hits = _relaxed(objective, fam, x, lb, ub, f_x, local if polish or tolerance > 0 else None)
    objective.begin("worst case")
    active = [text for text, on in hits if on]
    if graz is not None:
        active.append(f"grazing {graz[1]} n={graz[0]}")
    return Design(
        family=fam.name,
        n_masses=fam.n_masses,
        beta=beta,
        masses=m,
        springs=k,
        cor=r.cor,
        n_collisions=r.n_collisions,
        worst_cor=objective.worst(x) if tolerance > 0.0 else math.nan,
        tolerance=tolerance,
        cor_check=check.cor,
        error_estimate=r.error_estimate,
        bounds_hit=[text for text, _ in hits],
        bound_active=any(on for _, on in hits),
        active=active,
        warm_starts=len(starts),
        grazing=graz,
        method=method,
        evaluations=objective.calls,
        parameter=math.exp(x[0]) if fam.dim == 1 else math.nan,
    )


def _starts(warm_starts, n_masses: int) -> list:
    """Warm starts as [(masses, springs)], each checked (SceneError naming ``warm_starts``)."""
    out = []
    try:
        items = list(warm_starts)
    except TypeError:
        raise SceneError(
            f"warm_starts must be a sequence of Design or (masses, springs); got "
            f"{_show(warm_starts)}"
        ) from None
    for item in items:
        m, k = (item.masses, item.springs) if isinstance(item, Design) else item
        m = np.asarray(m, dtype=float)
        k = np.ones(n_masses - 1) if k is None else np.asarray(k, dtype=float)
        if m.shape != (n_masses,) or k.shape != (n_masses - 1,):
            raise SceneError(
                f"warm_starts must hold chains of n_masses = {n_masses} masses and "
                f"{n_masses - 1} springs; got {m.size} masses, {k.size} springs"
            )
        if not (np.all(np.isfinite(m)) and np.all(m > 0) and np.all(np.isfinite(k))
                and np.all(k > 0)):  # fmt: skip
            raise SceneError("warm_starts must hold finite positive masses and springs")
        out.append((m, k))
    return out


def minimize_cor(
    n_masses: int = 2,
    *,
    beta: float = 0.0,
    bounds=DEFAULT_BOUNDS,
    vary: str = "masses",
    tolerance: float = 0.0,
    seed: int = 1,
    popsize: int = 15,
    maxiter: int = 200,
    max_events: int = MAX_EVENTS_DEFAULT,
    polish: bool = True,
    progress=print,
    warm_starts=(),
) -> Design:
    """Chain of ``n_masses`` masses with the smallest COR (see the module docstring).

    Parameters
    ----------
    n_masses : int
        N in [2, 16].
    beta : float
        k_12/k_contact in [0, 1e6]; 0 is the rigid wall.
    bounds : (low, high)
        Bounds of every ratio m_i/m_1 (and k_i/k_12), 0 < low < high.
    vary : {"masses", "masses+springs"}
        Free parameters: the mass ratios (springs equal), or the springs k_i/k_12 too.
    tolerance : float
        > 0: minimise the worst COR over independent mass errors |dm_i/m_i| <= tolerance (robust).
    seed, popsize, maxiter
        Of ``differential_evolution`` (seeded: the same result on every run and thread count).
    max_events : int
        Contact budget of every solve of the search and of the design's own: a candidate that
        needs more contacts counts as unfinished, never as a minimum. The long sequences near
        the edges of a box (a heavy end mass: 10^4-10^5 contacts, COR near 1) cost 0.03-0.3 s
        each; a budget of 10^4 skips most of that work.
    progress : callable or None
        Called with one line per generation, one per polish step, and every ``HEARTBEAT``
        (30) s of a stage with no step of its own (polish, bound test, worst case: "masses N=4
        polish: 12799 solves, ... grazing evaluations so far (120 s)"); default ``print``, a
        logger's ``info`` works.
        The lines never change the result.
    warm_starts : sequence of Design or of (masses, springs)
        Chains of ``n_masses`` masses put into the search's first population (clipped into the
        bounds), e.g. the optimum of a smaller family: the search then ends at most at their
        COR. The rest of the population is the usual Sobol sample.

    Returns
    -------
    Design

    Examples
    --------
    >>> d = minimize_cor(2, progress=None)
    >>> round(d.masses[1], 6), round(d.cor, 6)
    (0.697123, 0.178465)
    """
    _check(n_masses, beta, bounds, tolerance, vary, seed, popsize, maxiter, max_events, polish,
           progress)  # fmt: skip
    fam = family(vary, n_masses)
    starts = _starts(warm_starts, n_masses)
    bounds = (float(_real(bounds[0])), float(_real(bounds[1])))
    return _optimise(
        fam, float(_real(beta)), bounds, float(_real(tolerance)), seed, popsize, maxiter,
        max_events, progress, polish, starts,
    )  # fmt: skip


def best_uniform(
    n_masses: int,
    *,
    beta: float = 0.0,
    bounds=DEFAULT_BOUNDS,
    seed: int = 1,
    popsize: int = 15,
    maxiter: int = 200,
    max_events: int = MAX_EVENTS_DEFAULT,
    progress=print,
    warm_starts=(),
) -> Design:
    """The paper's uniform chain (Fig. 6: m_2..m_N all alpha m_1, equal springs), best alpha.
    ``max_events`` and ``warm_starts`` as in :func:`minimize_cor` (each start read as its
    m_2/m_1)."""
    _check(n_masses, beta, bounds, 0.0, "masses", seed, popsize, maxiter, max_events, True,
           progress)  # fmt: skip
    starts = _starts(warm_starts, n_masses)
    bounds = (float(_real(bounds[0])), float(_real(bounds[1])))
    return _optimise(
        family("uniform", n_masses),
        float(beta),
        bounds,
        0.0,
        seed,
        popsize,
        maxiter,
        max_events,
        progress,
        True,
        starts,
    )


def best_tapered(
    n_masses: int,
    *,
    direction: str = "decreasing",
    beta: float = 0.0,
    bounds=DEFAULT_BOUNDS,
    seed: int = 1,
    popsize: int = 15,
    maxiter: int = 200,
    max_events: int = MAX_EVENTS_DEFAULT,
    progress=print,
    warm_starts=(),
) -> Design:
    """Geometric chain m_i = r**(i-1) m_1, equal springs, best r < 1 ("decreasing" from the wall)
    or r > 1 ("increasing"); the step ratio r within ``bounds`` and the end mass r**(N-1) within
    the ratios the solvers handle (1e-8..1e8). ``max_events`` and ``warm_starts`` as in
    :func:`minimize_cor` (each start read as its m_2/m_1)."""
    _check(n_masses, beta, bounds, 0.0, "masses", seed, popsize, maxiter, max_events, True,
           progress)  # fmt: skip
    starts = _starts(warm_starts, n_masses)
    bounds = (float(_real(bounds[0])), float(_real(bounds[1])))
    if direction not in ("decreasing", "increasing"):
        raise SceneError(f"direction must be 'decreasing' or 'increasing'; got {_show(direction)}")
    if not (bounds[0] < 1.0 if direction == "decreasing" else bounds[1] > 1.0):
        raise SceneError(
            f"bounds = {_show(bounds)} leave no ratio r of a {direction} chain "
            f"(r {'< 1' if direction == 'decreasing' else '> 1'} within the bounds)"
        )
    b = (bounds[0], 1.0) if direction == "decreasing" else (1.0, bounds[1])
    d = _optimise(
        family("tapered", n_masses),
        float(beta),
        b,
        0.0,
        seed,
        popsize,
        maxiter,
        max_events,
        progress,
        True,
        starts,
    )
    d.family = f"tapered ({direction})"
    return d


__all__ = [
    "DEFAULT_BOUNDS",
    "Design",
    "best_tapered",
    "best_uniform",
    "minimize_cor",
    "scaled_chain",
    "solve_scaled",
]
