"""The (alpha, beta) plane of the two-mass model: the curves where the contact count steps.

The count of contacts changes across curves in the plane. Each is the zero set of a smooth
*grazing condition* G, evaluated from the exact solver's contact history:

``new`` (index n)
    After the n-th separation, m1 flies free; G is the value of the first local minimum of its gap
    to the wall. G > 0: no (n+1)-th contact there; G < 0: one follows. At beta = 0 its roots are
    the paper's alpha*_n (``restitution.analysis.special_points``).
``split`` (index n)
    During the n-th contact (beta > 0), the contact spring's compression x = -u1 may dip; G is the
    first local minimum of x under the *contact* equations of motion continued past any separation.
    G > 0: the contact holds; G < 0: it splits in two (x = 0 is reached before the dip's bottom).

Both are smooth functions of (alpha, beta) wherever the first n contacts are transversal, because
the event times of those contacts are smooth and the state is propagated between them in closed
form (undamped normal modes; :func:`chain_states`). The contact times come from the exact kernel
(``Result.history``); nothing here samples a trajectory to decide a contact: the extrema are roots
of the velocity, bracketed on a step far below the fastest period and solved by Brent's method.

Curves are traced by pseudo-arclength continuation in the plane (x, y) = (ln alpha, sqrt(beta))
(sqrt: contact durations grow like sqrt(beta), so curves leave beta = 0 with finite slope there),
predictor along the secant, corrector a scalar root solve of G along the normal. A curve ends where
its contact structure does (fewer than n contacts) or at the box; a ``new`` curve whose grazing
instant reaches its separation turns into the ``split`` curve of the same contact.

Units: m1 = 1, V0 = 1, omega = 1 with omega^2 = k2/m1 + k2/m2 (README, "Physics conventions").
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.linalg import eigh
from scipy.optimize import brentq

from restitution.kernels.modal_scan import first_rise

log = logging.getLogger(__name__)

KINDS = ("new", "split")
_SCAN_PER_PERIOD = 24
_ROOT_TOL = 1e-10  # |G| accepted at a root (G is O(1); roots reach ~1e-15)
# One-sided y step at beta = 0 (the closed-form modes lose accuracy below beta ~ 1e-10).
_Y_EDGE = 1e-3  # scan steps per period of the fastest mode when bracketing an extremum


# ---------------------------------------------------------------------------------------------
# Closed-form propagation of an undamped chain between the kernel's contact times.
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Modes:
    """Mass-normalised modes of M u'' + K u = 0: u = phi q, q_j'' = -w2_j q_j."""

    w2: np.ndarray
    phi: np.ndarray
    m: np.ndarray

    @classmethod
    def of(cls, m: np.ndarray, K: np.ndarray) -> Modes:
        w2, phi = eigh(K, np.diag(m))
        w2 = np.where(w2 < 1e-12 * max(1.0, float(w2.max())), 0.0, w2)  # the rigid-body mode
        return cls(w2, phi, m)

    def coords(self, u, v):
        return self.phi.T @ (self.m * u), self.phi.T @ (self.m * v)

    def _q(self, q0, p0, t):
        w = np.sqrt(self.w2)
        tt = np.atleast_1d(np.asarray(t, dtype=float))[:, None]
        rigid = w == 0.0
        ws = np.where(rigid, 1.0, w)
        sn, cs = np.sin(tt * ws), np.cos(tt * ws)
        q = np.where(rigid, q0 + p0 * tt, q0 * cs + p0 / ws * sn)
        p = np.where(rigid, p0, p0 * cs - q0 * ws * sn)
        return q, p

    def advance(self, u, v, t):
        """State (u, v) after time t (scalar)."""
        q0, p0 = self.coords(u, v)
        q, p = self._q(q0, p0, t)
        return self.phi @ q[0], self.phi @ p[0]

    def first(self, u, v, t):
        """(u_1, v_1, a_1) of the first mass at times t (array) from state (u, v) at t = 0."""
        q0, p0 = self.coords(u, v)
        q, p = self._q(q0, p0, t)
        row = self.phi[0]
        return q @ row, p @ row, -(q * self.w2) @ row

    def first_velocity(self, u, v, t):
        """v_1 of the first mass at times t (array), bit for bit ``first(u, v, t)[1]``.

        Brent's solve in :func:`first_minimum` needs the velocity alone: no positions, no
        accelerations, and no sines of the rigid-body mode (its velocity is constant)."""
        return self.velocity_from(*self.coords(u, v))(t)

    def velocity_from(self, q0, p0):
        """``t -> first_velocity`` of the modal state (q0, p0), with everything that does not
        depend on t done once (Brent's solve calls it ~10 times per minimum)."""
        w = np.sqrt(self.w2)
        moving = w != 0.0
        still = ~moving
        rest, wm, p0m = p0[still], w[moving], p0[moving]
        qw = q0[moving] * wm
        row = self.phi[0]

        def at(t):
            tt = np.atleast_1d(np.asarray(t, dtype=float))[:, None]
            p = np.empty((tt.shape[0], w.size))
            p[:, still] = rest
            # The same operations, in the same order, as _q on the moving modes.
            sn, cs = np.sin(tt * wm), np.cos(tt * wm)
            p[:, moving] = p0m * cs - qw * sn
            return p @ row

        return at


def stiffness(springs, k_contact: float = 0.0) -> np.ndarray:
    """Chain stiffness matrix (springs between neighbours) plus k_contact on the first mass."""
    k = np.asarray(springs, dtype=float)
    n = k.size + 1
    K = np.zeros((n, n))
    for i, ki in enumerate(k):
        K[i, i] += ki
        K[i + 1, i + 1] += ki
        K[i, i + 1] -= ki
        K[i + 1, i] -= ki
    K[0, 0] += k_contact
    return K


def chain_states(masses, springs, k_contact, history, upto: int, modes=None):
    """States (u, v) at the start and end of contacts 1..upto, propagated between the given times.

    ``history`` has the kernel's ``omega_t_start, omega_t_end`` per contact (scaled units): a
    ``Result.history`` table or the pair of arrays; ``k_contact = inf`` is the rigid wall (m1's
    velocity reverses at each contact instant). ``modes``: the chain's (free, touching) Modes
    when the caller has them (``_modes``). Returns a list of ``(u_start, v_start, u_end,
    v_end)``.
    """
    m = np.asarray(masses, dtype=float)
    free, touch = _modes(m, springs, k_contact) if modes is None else modes
    rigid = math.isinf(k_contact)
    u = np.zeros(m.size)
    v = -np.ones(m.size)
    t = 0.0
    if isinstance(history, tuple):
        ts, te = history
    else:
        ts = history["omega_t_start"].to_numpy()
        te = history["omega_t_end"].to_numpy()
    out = []
    for j in range(upto):
        if ts[j] > t:
            u, v = free.advance(u, v, ts[j] - t)
        u = u.copy()
        u[0] = 0.0  # on the wall at a contact's start (removes round-off of the propagation)
        u_s, v_s = u, v.copy()
        if rigid:
            v = v.copy()
            v[0] = -v[0]
        else:
            u, v = touch.advance(u, v, te[j] - ts[j])
            u = u.copy()
            u[0] = 0.0
        out.append((u_s, v_s, u, v.copy()))
        t = te[j]
    return out


def _modes(m: np.ndarray, springs, k_contact):
    """(free, touching) Modes of a chain: off the wall, and on its contact spring (None at a
    rigid wall)."""
    free = Modes.of(m, stiffness(springs))
    return free, None if math.isinf(k_contact) else Modes.of(m, stiffness(springs, k_contact))


def first_minimum(modes: Modes, u, v, horizon: float, sign: float = 1.0):
    """First local minimum of sign * u_1(t), t in (0, horizon]: (t_min, value) or (nan, nan).

    Bracketed on the velocity sign change from - to + on a scan of ``_SCAN_PER_PERIOD`` steps per
    fastest period (``modal_scan.first_rise``: it stops there), then solved by Brent's method on
    the velocity (an exact root of a closed form).
    """
    wmax = math.sqrt(float(modes.w2.max()))
    h = 2.0 * math.pi / wmax / _SCAN_PER_PERIOD
    n = max(8, int(math.ceil(horizon / h)))
    t = np.linspace(0.0, horizon, n + 1)
    q0, p0 = modes.coords(u, v)
    # the scan stops at the first rise (restitution.kernels.modal_scan; 17x numpy's whole grid)
    i = first_rise(t, q0, p0, np.sqrt(modes.w2), np.ascontiguousarray(modes.phi[0]), sign)
    if i < 0:
        return math.nan, math.nan
    velocity = modes.velocity_from(q0, p0)

    def f(s):
        return sign * float(velocity(np.array([s]))[0])

    s = brentq(f, t[i], t[i + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
    return s, sign * float(modes.first(u, v, np.array([s]))[0][0])


# ---------------------------------------------------------------------------------------------
# Grazing conditions.
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Grazing:
    """Value of a grazing condition and what it was computed from."""

    value: float  # G: nan where undefined (fewer than n contacts)
    t_min: float  # time of the extremum after the separation (new) / contact start (split)
    n_collisions: int  # contacts of the scene
    cor: float


def grazing(
    masses, springs, k_contact, n: int, kind: str, max_events: int = 10_000, check: bool = True
) -> Grazing:
    """Grazing condition G of contact ``n`` of a chain (scaled units, see module docstring).

    ``check=False``: an optimiser's evaluation (the design polish): the contact times of the
    kernel's first run without its replica check (``scaled.contact_times``)."""
    from restitution.analysis.scaled import contact_times  # the one place that calls the solver

    if kind not in KINDS:
        raise ValueError(f"kind={kind!r}: must be one of {KINDS}")
    if kind == "split" and math.isinf(k_contact):
        raise ValueError("kind='split' needs a finite contact stiffness (beta > 0)")
    res, ts, te = contact_times(masses, springs, k_contact, max_events=max_events, check=check)
    if res.n_collisions < n or not res.success:
        return Grazing(math.nan, math.nan, res.n_collisions, res.cor)
    m = np.asarray(masses, dtype=float)
    free, touch = modes = _modes(m, springs, k_contact)
    states = chain_states(masses, springs, k_contact, (ts, te), n, modes)
    slow = math.sqrt(float(free.w2[free.w2 > 0].min()))
    if kind == "new":
        _, _, u, v = states[n - 1]
        # The first minimum of the gap is within one slowest period of the separation.
        s, g = first_minimum(free, u, v, 2.0 * math.pi / slow * 1.05)
        if math.isnan(s):
            # Monotone gap: m1 moves away for good (or comes straight back if V < 0).
            com = float(m @ v) / m.sum()
            g = math.inf if com >= 0.0 else -math.inf
        return Grazing(g, s, res.n_collisions, res.cor)
    u, v, _, _ = states[n - 1]
    dur = te[n - 1] - ts[n - 1]
    if n < res.n_collisions:
        dur = max(dur, te[n] - ts[n - 1])
    # Compression x = -u1: its first local minimum under the contact equations of motion.
    s, x = first_minimum(touch, u, v, 1.2 * dur, sign=-1.0)
    if math.isnan(s):
        return Grazing(-math.inf, s, res.n_collisions, res.cor)  # no dip before the contact ends
    return Grazing(x, s, res.n_collisions, res.cor)


def paper_chain(alpha: float, beta: float):
    """(masses, springs, k_contact) of the two-mass scene (alpha, beta) in scaled units."""
    k2 = alpha / (1.0 + alpha)
    return [1.0, alpha], [k2], (math.inf if beta == 0.0 else k2 / beta)


def G(alpha: float, beta: float, n: int, kind: str) -> Grazing:
    """Grazing condition of the two-mass scene (alpha, beta) for contact ``n`` (``kind``)."""
    return grazing(*paper_chain(alpha, beta), n, kind)


# ---------------------------------------------------------------------------------------------
# Pseudo-arclength continuation in (x, y) = (ln alpha, sqrt(beta)).
# ---------------------------------------------------------------------------------------------
ALPHA_RANGE = (0.05, 100.0)
BETA_MAX = 1.0


def _to_plane(x: float, y: float):
    return math.exp(x), y * y


def _g(n, kind, x, y) -> Grazing:
    alpha, beta = _to_plane(x, abs(y))
    return G(alpha, beta, n, kind)


@dataclass
class Curve:
    """One traced curve: points (alpha, beta) with G = 0, its kind and contact index."""

    n: int
    kind: str
    alpha: list
    beta: list
    residual: list
    t_min: list
    end: str = ""

    def frame(self, curve_id: int) -> pd.DataFrame:
        return pd.DataFrame(
            {
                "curve": curve_id,
                "n": self.n,
                "kind": self.kind,
                "alpha": self.alpha,
                "beta": self.beta,
                "residual": self.residual,
                "t_min": self.t_min,
                "end": self.end,
            }
        )


def _corrector(n, kind, zp, nrm, h):
    """Solve G(zp + lam * nrm) = 0 for the normal offset lam (|lam| < h): lam or None."""

    def f(lam):
        return _g(n, kind, zp[0] + lam * nrm[0], zp[1] + lam * nrm[1]).value

    f0 = f(0.0)
    if not math.isfinite(f0):
        return None
    # Bracket the root by stepping outward on both sides of the prediction.
    step = 0.05 * h
    for _ in range(6):
        for sgn in (1.0, -1.0):
            f1 = f(sgn * step)
            if math.isfinite(f1) and f1 * f0 <= 0.0:
                lo, hi = sorted((0.0, sgn * step))
                lam = brentq(f, lo, hi, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200)
                # A sign change across a jump of G (an extremum born or dying) is no root.
                return lam if abs(f(lam)) < _ROOT_TOL else None
        step *= 2.0
        if step > h:
            break
    return None


def trace(
    n: int,
    kind: str,
    z0,
    t0,
    h: float = 0.02,
    h_max: float = 0.08,
    h_min: float = 1e-5,
    max_points: int = 2000,
    box=(*ALPHA_RANGE, BETA_MAX),
) -> Curve:
    """Follow the zero set of G(n, kind) from z0 = (ln alpha, sqrt beta) along the tangent t0.

    ``box`` = (alpha_min, alpha_max, beta_max) ends the curve (``end = "box"``)."""
    x_lo, x_hi = math.log(box[0]), math.log(box[1])
    y_hi = math.sqrt(box[2])
    z = np.asarray(z0, dtype=float)
    t = np.asarray(t0, dtype=float) / np.hypot(*t0)
    g0 = _g(n, kind, *z)
    curve = Curve(n, kind, [], [], [], [])

    def add(zz, gg):
        a, b = _to_plane(zz[0], abs(zz[1]))
        curve.alpha.append(a)
        curve.beta.append(b)
        curve.residual.append(gg.value)
        curve.t_min.append(gg.t_min)

    add(z, g0)
    while len(curve.alpha) < max_points:
        zp = z + h * t
        nrm = np.array([-t[1], t[0]])
        lam = _corrector(n, kind, zp, nrm, h)
        if lam is None:
            if h / 2 < h_min:
                # The condition stops being defined (contact n disappears: another curve is met)
                # or stops being smooth (its extremum is born or dies): the curve ends here.
                curve.end = "ends"
                break
            h /= 2
            continue
        z_new = zp + lam * nrm
        step = z_new - z
        t_new = step / np.hypot(*step)
        if t_new @ t < 0.5:  # turned by more than 60 degrees: too long a step
            if h / 2 < h_min:
                curve.end = "turn"
                break
            h /= 2
            continue
        out = z_new[1] < 0.0 or z_new[1] > y_hi or not x_lo <= z_new[0] <= x_hi
        if out:
            curve.end = "box"
            zc = _on_edge(n, kind, z, z_new, x_lo, x_hi, y_hi)
            if zc is not None:
                add(zc, _g(n, kind, *zc))
            break
        g = _g(n, kind, *z_new)
        add(z_new, g)
        z, t = z_new, t_new
        h = min(h * 1.4, h_max) if abs(lam) < 0.1 * h else h
    else:
        curve.end = "max_points"
    return curve


def gradient(n: int, kind: str, z, d: float = 1e-6) -> np.ndarray:
    """Finite-difference gradient of G in (x, y) (one-sided in y at the beta = 0 edge)."""
    x, y = z
    gx = (_g(n, kind, x + d, y).value - _g(n, kind, x - d, y).value) / (2 * d)
    if y < _Y_EDGE:
        gy = (_g(n, kind, x, y + _Y_EDGE).value - _g(n, kind, x, y).value) / _Y_EDGE
    else:
        gy = (_g(n, kind, x, y + d).value - _g(n, kind, x, y - d).value) / (2 * d)
    return np.array([gx, gy])


def tangent(n: int, kind: str, z, hint) -> np.ndarray:
    """Unit tangent of the level set G = 0 at z, oriented along ``hint``."""
    gx, gy = gradient(n, kind, z)
    t = np.array([-gy, gx])
    t /= np.hypot(*t)
    return t if t @ np.asarray(hint, dtype=float) >= 0.0 else -t


def _near(curves, n, kind, z, tol=2e-3) -> bool:
    """Whether z lies within tol of a traced curve of the same condition (polyline distance)."""
    for c in curves:
        if c.n != n or c.kind != kind or len(c.alpha) < 2:
            continue
        p = np.column_stack([np.log(c.alpha), np.sqrt(c.beta)])
        a, b = p[:-1], p[1:]
        ab = b - a
        w = np.clip(
            np.einsum("ij,ij->i", z - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300),
            0,
            1,
        )
        if np.min(np.hypot(*(a + w[:, None] * ab - z).T)) < tol:
            return True
    return False


def _land(n, kind, z):
    """Move z onto G(n, kind) = 0 along the gradient (None if that fails)."""
    gr = gradient(n, kind, z)
    if not np.all(np.isfinite(gr)) or not gr.any():
        return None
    nrm = gr / np.hypot(*gr)
    lam = _corrector(n, kind, np.asarray(z, float), nrm, 0.02)
    return None if lam is None else np.asarray(z, float) + lam * nrm


def trace_all(
    alpha_star, n_max: int | None = None, extra_seeds=(), progress=None, box=None, curves=None
) -> list[Curve]:
    """Trace every count-step curve reachable from the beta = 0 grazing points and extra seeds.

    ``alpha_star``: the exact beta = 0 points alpha*_1.. (``special_points``), seeds of the ``new``
    curves. Where a curve ends inside the box (its contact disappears), the conditions that vanish
    there (|G| small, contact index up to n + 1) are the curves it meets: they are traced in both
    directions from that junction. ``extra_seeds``: (n, kind, alpha, beta) points on other curves
    (e.g. from the grid, for components not connected to beta = 0). Returns the curves in the order
    traced. ``box`` = (alpha_min, alpha_max, beta_max); ``curves``: already traced curves, extended
    in place (their conditions are not traced again).
    """
    box = box or (*ALPHA_RANGE, BETA_MAX)
    curves = [] if curves is None else curves
    queue = []
    for n, a in enumerate(alpha_star[:n_max], start=1):
        z = np.array([math.log(a), 0.0])
        queue.append((n, "new", z, tangent(n, "new", z, (0.0, 1.0))))
    for n, kind, a, b in extra_seeds:
        z = _land(n, kind, (math.log(a), math.sqrt(b)))
        if z is not None:
            t = tangent(n, kind, z, (1.0, 0.0))
            queue += [(n, kind, z, t), (n, kind, z, -t)]
    while queue:
        n, kind, z, t = queue.pop(0)
        if _near(curves, n, kind, z + 0.01 * t):
            continue
        c = trace(n, kind, z, t, box=box)
        curves.append(c)
        if progress:
            progress(f"curve {len(curves)}: {kind} n={n}, {len(c.alpha)} points, end: {c.end}")
        if c.end != "ends":
            continue
        z_end = np.array([math.log(c.alpha[-1]), math.sqrt(c.beta[-1])])
        for k in range(1, n + 2):
            for kd in KINDS:
                if (k, kd) == (n, kind) or (kd == "split" and z_end[1] == 0.0):
                    continue
                g = _g(k, kd, *z_end)
                if not (math.isfinite(g.value) and abs(g.value) < 1e-3):
                    continue
                zj = _land(k, kd, z_end)
                if zj is None:
                    continue
                tj = tangent(k, kd, zj, (1.0, 0.0))
                queue += [(k, kd, zj, tj), (k, kd, zj, -tj)]
    return curves


def _on_edge(n, kind, z, z_new, x_lo, x_hi, y_hi):
    """The root of G on the box edge crossed by the step z -> z_new (None if not found)."""
    frac = _edge_fraction(z, z_new, x_lo, x_hi, y_hi)
    zc = z + frac * (z_new - z)
    d = z_new - z
    # Which coordinate hit its limit: move along the other one.
    hit_x = (
        frac == _edge_fraction(z, z_new, x_lo, x_hi, math.inf)
        and d[0] != 0.0
        and (abs(zc[0] - x_lo) < 1e-12 or abs(zc[0] - x_hi) < 1e-12)
    )
    along = np.array([0.0, 1.0]) if hit_x else np.array([1.0, 0.0])
    lam = _corrector(n, kind, zc, along, np.hypot(*d))
    return None if lam is None else zc + lam * along


def _edge_fraction(z, z_new, x_lo, x_hi, y_hi):
    fr = 1.0
    d = z_new - z
    for lim, k in ((0.0, 1), (y_hi, 1), (x_lo, 0), (x_hi, 0)):
        if d[k] != 0.0:
            f = (lim - z[k]) / d[k]
            if 0.0 <= f < fr:
                fr = f
    return fr


__all__ = [
    "G",
    "Grazing",
    "KINDS",
    "Modes",
    "chain_states",
    "first_minimum",
    "grazing",
    "paper_chain",
    "stiffness",
]
