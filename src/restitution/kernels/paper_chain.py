"""The paper's piecewise-linear scenes (any N >= 2, beta >= 0, xi >= 0) as presets of the general
chain kernel restitution.kernels.exact_chain: one kernel, this module only builds the chain.

Model (non-dimensional, docs/physics.md): m1 = 1, m2..mN = alpha, springs k2 = alpha/(1+alpha)
between neighbours, contact spring k1 = k2/beta on m1 while u1 < 0 (beta = 0: rigid wall,
v1 -> -v1), dashpot c = 2 xi k2 between m1 and m2 only. At t = 0 all u = 0, all v = -1.

Closed form per phase
---------------------
Both phases are linear, homogeneous and time invariant, so every quantity is an exponential sum.
*Free phase*: the centre of mass moves as X0 + V t exactly; the relative motion is expanded in the
N-1 non-rigid modes of (K, M). For N = 2 it is the scalar oscillator r'' + 2 xi r' + r = 0
(r = u2 - u1) written with C(t) = e^{-xi t} cos / cosh and S(t) = e^{-xi t} sin(wt)/w / sinh(gt)/g,
switched to their power series when |(1 - xi^2) t^2| < 1/2, so xi = 1 and xi -> 1 lose nothing.
Early in a flight (t (1 + 2 xi) < 1/2) the gap is u1(0) + v1 t - mu (O(t^2) series terms), with
v1 m1's own stored velocity, and velocities advance by increments: the shallow flights of
rigid-wall dashpot chatter (gaps ~1e-8) keep full relative accuracy.
*Contact phase*: the full N-DOF system with k1 added at m1 (all modes elastic, no rigid mode).
Undamped phases use real modes (lambda = i omega, eigh of M^-1/2 K M^-1/2); damped phases use the
complex eigen-decomposition of the modal state matrix [[0, I], [-Omega^2, -D]] (D = c d d^T, the
dashpot is rank one). Its eigenvector condition number is checked: above COND_MAX the scene is
flagged STATUS_ILL_CONDITIONED (the closed form would lose more than ~8 digits). Decompositions are
done once per scene.

Event location (rigorous)
-------------------------
In every phase the monitored gap is f(t) = c0 + c1 t + Re sum_k b_k (e^{lambda_k t} - 1),
Re lambda <= 0 (free: f = u1; contact: f = -u1; c0 = its exact start value, 0 after an event).
Hence for s >= t and m >= 2, |f^(m)(s)| <= B_m(t) = sum_k |b_k| |lambda_k|^m e^{Re lambda_k t},
and the oscillating part is bounded by B_0 (for the scalar N = 2 oscillator the same role
is played by the non-increasing energies r^(m)^2 + r^(m+1)^2). From a point with f >= -tol we step
by the largest h for which the cubic lower bound f + f' h + f'' h^2/2 - B3 h^3/6 stays >= -tol, so
no step can cross a point where f < -tol; such steps converge quadratically to a transversal root
and superlinearly (order 3/2) to a tangency. A crossing is *certified* when the quadratic upper
bound f + f' h + B2 h^2/2 dips below -tol; f is then strictly decreasing on [t, t + |f'|/B2], so
its unique root there is the event, found by bracketed, safeguarded Newton to machine precision.

Touching rule: a contact (or a separation) happens iff the gap goes below -tol, with
tol = 8 eps * scale (locator.BAND_ULPS) and scale = the round-off scale of f at that moment: the
magnitudes of the terms that cancel in it, |c0| + |c1 t| + |w0| + sum_k |b_k e^{lambda_k t}|
(1 + |lambda_k| t). A gap minimum within that band is a graze and changes nothing (its impulse
would be O(sqrt(tol))), which keeps the COR continuous across the grazing points alpha*_n. The
decision is certified: the replica check's two runs use bands of 0.25 and 2 times tol, so a
touch within round-off of the band's edge shows up as their spread in the error estimate.

The band never shrinks below its value at the phase start (the constant w0 carries the rounding
of the start state's modal projection for ever), so exponentially small lobes of a decaying
approach are grazes, not contacts.

Termination by proof: in free flight with V >= 0, once X(t) - B0(t) > -tol0/2 the gap can never
go below the band again (X never decreases, B0 never grows), so the sequence is finished. In a
damped contact whose slowest term is real, if that term outweighs the sum of all others (or if the
whole motion has decayed into the band without separating) the contact can never end
(``permanent contact``: the system comes to rest against the wall, COR = 0, omega_t_col = inf,
all energy dissipated: STATUS_PERMANENT_CONTACT). Every phase has a step budget
(STATUS_NONCONVERGED) and every scene an event budget (STATUS_EVENT_BUDGET) and a work budget
(STATUS_WORK_BUDGET), so nothing hangs.

Rigid wall + dashpot: m1 chatters against the wall with velocities decaying like 1/n. After
STICK_AFTER contacts, a contact slower than V_STICK_CHAIN (two masses: V_STICK_RIGID2) under a
compressive force continues with the sticking limit (see restitution.kernels.exact_chain and
kernels/constants.py): OUT_ERR is then at least v^2 (v: the speed where the chatter was cut) and
OUT_FLAGS has FLAG_STICKING set.

Energies (fractions of the initial kinetic energy Mtot/2) are evaluated at the final separation:
translational cor^2, vibrational (relative kinetic + structural springs), dissipated = integral
of c (v2 - v1)^2 per phase in closed form from the modal amplitudes (a sum over pairs of modes;
32-point Gauss-Legendre, round-off exact, where that sum would cancel), never from the propagated
state; a permanent contact's to infinite time, in closed form. Their sum is checked, for
permanent contacts too (STATUS_ENERGY if off by more than 1e-9, or NaN).
"""

import math

import numpy as np

from restitution.jit import njit
from restitution.kernels.copies import put_row
from restitution.kernels.exact_chain import BETA_RIGID, WORK_MAX, _solve_stiff
from restitution.kernels.exact_chain import _modal_model as _chain_modal_model
from restitution.kernels.exact_chain import _sample as _chain_sample
from restitution.kernels.layout import N_HIST, N_OUT
from restitution.kernels.locator import (  # noqa: F401  (re-exported for tests and tools)
    LOC_BUDGET,
    LOC_EVENT,
    LOC_NEVER,
    LOC_PERMANENT,
    _locate,
)
from restitution.kernels.parallel import over_threads


@njit(cache=True)
def _masses(alpha, n):
    m = np.full(n, alpha)
    m[0] = 1.0
    return m


@njit(cache=True)
def _paper_chain(alpha, beta, xi, n):
    """The paper's scene as a chain: m = [1, alpha, ...], k = alpha/(1+alpha) on every link,
    c = 2 xi k on the first link only, kc = k/beta (beta = 0: rigid wall)."""
    m = _masses(alpha, n)
    k2 = alpha / (1.0 + alpha)
    k = np.full(n - 1, k2)
    c = np.zeros(n - 1)
    c[0] = 2.0 * xi * k2
    kc = k2 / beta if beta > 0.0 else math.inf
    return m, k, c, kc


@njit(cache=True)
def _modal_model(m, k2, kc, c, drop_rigid):
    """Uniform chain (every spring k2), dashpot c on the first link, contact spring kc: see
    restitution.kernels.exact_chain._modal_model."""
    n = m.size
    cc = np.zeros(n - 1)
    cc[0] = c
    return _chain_modal_model(m, np.full(n - 1, k2), cc, kc, 0.0, drop_rigid)


@njit(cache=True)
def solve_linear(alpha, beta, xi, n_masses, max_events, hist):
    """Exact event-driven solution of one piecewise-linear scene.

    Parameters
    ----------
    alpha, beta, xi : float
        Mass ratio, stiffness ratio k2/k1 (0 = rigid wall), damping ratio of the m1-m2 dashpot.
    n_masses : int
        Number of masses N >= 2.
    max_events : int
        Contact budget; exceeding it gives STATUS_EVENT_BUDGET.
    hist : ndarray, shape (rows, N_HIST)
        One row per contact is written while rows last.

    Returns
    -------
    out : ndarray, shape (N_OUT,)
        See ``restitution.kernels.layout``.
    """
    m, k, c, kc = _paper_chain(alpha, beta, xi, n_masses)
    # beta < BETA_FALLBACK may be solved as the rigid limit (FLAG_RIGID_LIMIT, see kernels.chain)
    return _solve_stiff(m, k, c, kc, max_events, hist, WORK_MAX, False)


@njit(cache=True, nogil=True)
def _linear_rows(alpha, beta, xi, n_masses, max_events, out, order, start, stop):
    """``solve_linear`` of the rows order[start:stop] into ``out`` (kernels.parallel)."""
    hist = np.zeros((0, N_HIST))
    for j in range(start, stop):
        i = order[j]
        put_row(out, i, solve_linear(alpha[i], beta[i], xi[i], int(n_masses[i]), max_events, hist))


def solve_linear_batch(alpha, beta, xi, n_masses, max_events):
    """``solve_linear`` over arrays of scenes (one row each) on numba's threads; scenes are
    independent, so the result is bit-identical for any thread count."""
    alpha, beta, xi = (np.ascontiguousarray(a, dtype=np.float64) for a in (alpha, beta, xi))
    n_masses = np.ascontiguousarray(n_masses, dtype=np.int64)
    out = np.empty((alpha.size, N_OUT))
    over_threads(_linear_rows, alpha.size, alpha, beta, xi, n_masses, int(max_events), out)
    return out


@njit(cache=True)
def _sample(alpha, beta, xi, n, times, max_events):
    m, k, c, kc = _paper_chain(alpha, beta, xi, n)
    if beta < BETA_RIGID:
        kc = math.inf
    U, V, _f, _imp = _chain_sample(m, k, c, kc, times, max_events)
    return U, V


def sample_linear(alpha, beta, xi, n_masses, times, max_events=10_000):
    """Positions and velocities (len(times), N) at the given times, from the closed form of the
    phase that contains each time (the event history is recomputed once)."""
    times = np.ascontiguousarray(times, dtype=np.float64)
    return _sample(float(alpha), float(beta), float(xi), int(n_masses), times, int(max_events))
