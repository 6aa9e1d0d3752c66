"""Exact event-driven solver for any one-dimensional linear chain hitting a wall.

Model (non-dimensional: m1 = 1, V0 = 1, omega = 1 with omega^2 = k_12/m_1 + k_12/m_2; inputs in
other units are rescaled on entry, so every time in and out is omega * t). Masses m_1..m_N
(m_1 touches the wall), a spring k_i and a dashpot c_i >= 0 between m_i and m_{i+1}, and at the
wall either a rigid wall (kc = inf: impulsive, v1 -> -v1), a linear contact spring kc on m_1
while u_1 < 0, or a Kelvin-Voigt contact (kc with a dashpot cc, see below). At t = 0 all
u = 0 and all v = -1.

Closed form per phase
---------------------
Every phase is linear, homogeneous and time invariant, so every quantity is an exponential sum.
*Free phase*: the centre of mass moves as X0 + V t exactly; the relative motion is expanded in
the N - 1 non-rigid modes of (K, M). For N = 2 it is the scalar oscillator
r'' + 2 xi r' + r = 0 (r = u2 - u1, xi = c_12 / (2 k_12)), and the next contact is found by the
rigid-wall kernel's closed-form walk over the critical points of the gap
(restitution.kernels.rigid2: every two-mass flight starts with m1 leaving the wall).
*Contact phase*: the full N-DOF system with kc added at m_1 (no rigid mode).
*Sticking phase* (rigid wall only, see below): m_1 held at the wall, m_2..m_N a chain fixed to
it through k_12 and c_12.
Undamped phases use real modes (eigh of M^-1/2 K M^-1/2, mass-normalised Phi). Damped phases use
the complex eigen-decomposition of the modal state matrix [[0, I], [-Omega^2, -Phi^T C Phi]]
with the full (non-proportional) damping matrix C = sum_i c_i d_i d_i^T, one term per conjugate
pair (see _real_modes). The condition number of that basis (1-norm) is checked: above COND_MAX
the scene is flagged STATUS_ILL_CONDITIONED.

Events are located rigorously by restitution.kernels.locator (no sampling of sign changes, a
touch within round-off is not a contact, every sequence ends by proof that no further contact
can come). Dissipation is integrated per dashpot in closed form (a sum over pairs of modes of
(e^{(lam_p + lam_q) T} - 1) / (lam_p + lam_q) terms, restitution.kernels.locator._diss_modal),
from the modal amplitudes alone: it never uses the propagated state, so the energy account is an
independent check. Where those terms would cancel, Gauss-Legendre (round-off exact) is used.

Kelvin-Voigt contact
--------------------
A contact dashpot cc in parallel with kc (solve_chain_kv; F = max(0, kc x + cc x'), x = -u_1,
restitution.model.laws) keeps every phase linear. *Contact phase*: the chain with kc and cc from
m_1 to the ground (_modal_model(..., kc, cc)); it ends where the force returns to 0,
kc x + cc x' = 0, an exponential sum with the penetration's modal coefficients times
(kc + cc lam), located by the same locator (from cc x' > 0 at a contact from the wall); x > 0
there in general. *Free stretch*: m_1 then flies free inside the penetration (the free phase's
modes, for two masses too): until the force rises through 0 again while x > 0 (a new contact,
counted, starting inside; its v1_in is then > 0) or x falls to 0 (the free flight from the
wall), whichever the locator finds first. Energy: the contact dashpot's work is integrated in
closed form with the link dashpots (it is link 0 from the ground to m_1 in _diss_links), the
spring's kc x^2 / 2 left at a force-zero end is booked as dissipated (the massless surface
relaxes) and that of a contact starting inside is taken back, so the account is the contact's
work on m_1 and closes to round-off. The replicas move cc like kc (relative). A scene of one
mass (solve_mass_kv, for the closed form of the tests) runs the same loop with no free modes.
No rigid-limit policy applies (the laws' ranges keep kc finite). An exactly critically damped
contact mode (one mass at zeta = 1) has a defective eigenbasis: STATUS_ILL_CONDITIONED.

Chatter and sticking
--------------------
A rigid wall with a dashpot can make m_1 chatter: approach speeds decay like 1/k, the contact
count grows without bound (a Zeno sequence) while the chain presses m_1 on the wall. The limit
of that sequence is sticking: m_1 at rest on the wall while the force of link 1 on it,
F = k_12 (u2 - u1) + c_12 (v2 - v1), is compressive (F < 0); m_2..m_N then move as their own
clamped linear chain (closed form), and m_1 lifts off at the first time F turns tensile, an
event of the same exponential-sum form located by the same rigorous locator. The kernel switches
to sticking when, after at least STICK_AFTER contacts (shorter chatters are finished exactly), a
contact has approach speed v below V_STICK_CHAIN under a compressive force. The dropped kinetic
energy m_1 v^2 / 2 (< 5e-6) is booked as dissipated, OUT_ERR is raised to v^2 and bit
FLAG_STICKING of OUT_FLAGS is set. The COR error of the cut-off shrinks like v^2: against cut-off
1e-4 (N = 2, 3; alpha 20..50, xi 1..2) cut-offs 1e-1, 1e-2, 1e-3 moved the COR by 1e-5, 4e-8 and
8e-10, i.e. <= 1e-3 v^2, so v^2 is a bound with a safety factor of ~1000 (V_STICK_CHAIN = 3e-3:
measured <= 1.1e-9, bound 1e-5). The chatter speeds decay only like 1/k (k = contact index): 3e-3
is reached after ~1e3..3e4 contacts on the grid alpha 5..200, xi 0.05..3, N = 2..5, 1e-4 only
after ~1e5 or more (kernels/constants.py: why the two-mass walk rigid2 cuts at 1e-3 instead).
A sticking phase is one contact interval in the history (H_VOUT = 0).

Budgets
-------
Every scene has an event budget (max_events, STATUS_EVENT_BUDGET) and a work budget counted in
operations (modal term evaluations in the locator and in the quadratures, WORK_MAX, raised in
proportion by a max_events above WORK_EVENTS; STATUS_WORK_BUDGET), never wall time, so results are
identical for any thread count. A contact that never ends (a damped contact or a sticking phase
that decays to rest on the wall) is proven and reported as STATUS_PERMANENT_CONTACT with cor = 0,
omega_t_col = inf, all energy dissipated.
The hardest chatter of the grid alpha 5..200, xi 0.05..3, N = 2..5 (N = 5, alpha = 200,
xi = 0.1: 33,267 contacts) needs 9e6 operations; the N = 128, alpha = 10, xi = 1 chatter 1.8e7
(2,001 contacts, then sticking: ok). WORK_MAX = 2e7 bounds a scene to a few seconds.

Extremes
--------
Invalid input (lengths, non-positive or non-finite masses and springs, negative dashpots, NaN)
gives STATUS_INVALID with a NaN row, never an exception; an eigen-solver failure gives
STATUS_ILL_CONDITIONED. A contact spring so stiff that beta = k_12/kc < BETA_RIGID is solved as
the rigid limit (see the constants below for the policy and its error bound). Every status
other than STATUS_OK and STATUS_PERMANENT_CONTACT comes with a NaN cor from solve_chain.
"""

import math

import numpy as np

from restitution.jit import njit
from restitution.kernels.constants import (
    ENERGY_TOL,
    EPS,
    MAX_EVENTS_DEFAULT,
    ROUNDOFF_ULPS,
    STICK_AFTER,
    V_STICK_CHAIN,
    V_STICK_RIGID2,
)
from restitution.kernels.copies import put_row, put_rows
from restitution.kernels.lapack import eig_real
from restitution.kernels.layout import (
    FLAG_EXTRAPOLATED,
    FLAG_NEAR_DEFECTIVE,
    FLAG_RIGID_LIMIT,
    FLAG_STICKING,
    FLAG_UNCHECKED,
    H_IMPULSE,
    H_TEND,
    H_TSTART,
    H_VIN,
    H_VOUT,
    H_XMAX,
    N_HIST,
    N_OUT,
    OUT_COR,
    OUT_EDISS,
    OUT_ERR,
    OUT_ETRANS,
    OUT_EVIB,
    OUT_FLAGS,
    OUT_NCOL,
    OUT_NEVENTS,
    OUT_STATUS,
    OUT_TCOL,
    STATUS_ENERGY,
    STATUS_EVENT_BUDGET,
    STATUS_ILL_CONDITIONED,
    STATUS_INVALID,
    STATUS_NONCONVERGED,
    STATUS_NOT_RUN,
    STATUS_OK,
    STATUS_PERMANENT_CONTACT,
    STATUS_WORK_BUDGET,
)
from restitution.kernels.locator import (
    BAND_HIGH,
    BAND_LOW,
    CANCEL_MAX,
    LOC_BUDGET,
    LOC_EVENT,
    LOC_NEVER,
    LOC_PERMANENT,
    MAX_STEPS,
    N_INFO,
    N_RES,
    PASS_DEPTH,
    _diss_modal_inf,
    _diss_pairs,
    _diss_scalar,
    _locate,
    _modal_state,
    _pair_integrals,
    _scalar_advance,
    _scalar_state,
    _xmax,
)
from restitution.kernels.parallel import over_threads
from restitution.kernels.quadratic_refine import refine_pairs
from restitution.kernels.replica import (
    JITTER,
    PURE_SAFETY,
    REPLICA_SAFETY,
    REPLICA_SEED,
    REPLICAS,
    STICK_BUDGET,
    STICK_BUDGET_RIGID2,
    STICK_SAFETY,
    combine,
    finished,
    stick_check,
    weyl,
)
from restitution.kernels.rigid2 import XI_NEGLIGIBLE, _next_contact0, _next_contact_d, _rigid2
from restitution.kernels.roots import threshold_bisection

COND_MAX = 1e8  # eigenvector condition number above which a closed form is not trusted
# A phase whose eigenbasis has a condition number above COND_DEFECT with two eigenvalues within
# DEFECT_REL of each other (relative) is flagged FLAG_NEAR_DEFECTIVE: a mode next to critical
# damping, where the basis degenerates (cond ~ 1e-3 / |xi - xi_crit| on the paper chain at
# alpha = 1e8, xi = 1: 8e7, an estimate of 9e-6 for a COR right to 1e-14, or ill_conditioned).
# The exact runners then solve the scene with its dashpots scaled off that point
# (solvers.exact.bracketed), where the basis is sound.
COND_DEFECT = 1e4
DEFECT_REL = 1e-3
# Rounding of one phase's closed-form dissipation, relative to the initial energy, below which
# its cancellation does not matter (1e5 phases stay 100 times inside ENERGY_TOL); above it a
# cancelling phase is integrated by Gauss-Legendre, at a cost growing with its length.
DISS_FLOOR = 1e-16
WORK_MAX = 2e7  # operations (modal term evaluations) per scene before STATUS_WORK_BUDGET
# A max_events above WORK_EVENTS (the API's default) raises the work budget in proportion: the
# one knob a user has for how long a scene may run. Long chains need it: every locator step costs
# a term per mode, so 512 masses at the rigid wall stop after about 150 contacts within WORK_MAX.
WORK_EVENTS = MAX_EVENTS_DEFAULT
# Very stiff contact springs (beta = k_12 / kc -> 0). The COR approaches the rigid wall's like
# sqrt(beta): |COR(beta) - COR(0)| <= RIGID_LIMIT_C sqrt(beta), measured max 6.5 sqrt(beta) over
# 125 random paper scenes (N = 2..5, alpha 0.1..100, xi 0..2) at beta = 1e-10..1e-6 (same count).
# The finite-stiffness closed form loses digits as beta -> 0 (the contact phase's eigenbasis
# condition grows like 1/beta; its backward error is eps * kc on the soft links), which the
# replica check measures (restitution.kernels.replica). So: below BETA_RIGID the rigid limit is
# always used; below BETA_FALLBACK (the top of the range where the sqrt bound was measured) it
# replaces a finite-stiffness result that failed or whose measured error estimate exceeds the
# limit's bound: the switch is decided by the measured error, not by a threshold in beta.
# Either way OUT_ERR >= RIGID_LIMIT_C sqrt(beta) and FLAG_RIGID_LIMIT is set.
BETA_RIGID = 1e-20
BETA_FALLBACK = 1e-6
RIGID_LIMIT_C = 10.0
# Below EXTRAP_BELOW a finite run whose estimate exceeds EXTRAP_WORTH (since the damped basis is
# consistent, _consistent_vectors, a few long sequences and the undamped runs below ~1e-21) is
# compared with the rigid limit corrected by the expansion
# COR(beta) = COR(0) + a1 sqrt(beta) + a2 beta + ..., its coefficients from finite runs at
# EXTRAP_BETA and 4 EXTRAP_BETA (where the closed form is accurate): the row with the smaller
# estimate stands (_extrapolated; FLAG_EXTRAPOLATED). Measured against the 40-digit reference on
# damped paper chains N = 2..4 at beta = 1e-14..1e-20: errors <= 5e-14 (the rigid limit alone:
# 1e-11..5e-9).
EXTRAP_BETA = 1e-10
EXTRAP_BELOW = 1e-10
EXTRAP_WORTH = 1e-12
# A passed dip that may lie closer than this to gap 0 (in bands, the locator's closest pass: -1
# at the band's edge, 0 at gap 0) is re-run as a contact (_checked_units): a computed gap is
# within ~0.2 bands of the exact one (locator.BAND_ULPS), so this keeps a margin of 5 times it.
PASS_NEAR = 1.0

# Phase kinds recorded for sampling.
PH_FREE = 0
PH_CONTACT = 1
PH_STICK = 2


# ----------------------------------------------------------------------------------------------
# System and modal models
# ----------------------------------------------------------------------------------------------


@njit(cache=True)
def _chain_matrix(n, links, ground):
    """Tridiagonal chain matrix with one coefficient per link, plus ``ground`` at mass 0."""
    A = np.zeros((n, n))
    for i in range(n - 1):
        a = links[i]
        A[i, i] += a
        A[i + 1, i + 1] += a
        A[i, i + 1] -= a
        A[i + 1, i] -= a
    A[0, 0] += ground
    return A


@njit(cache=True)
def _count_below(m, k, kg, w2):
    """Number of eigenvalues of K x = w2 M x below w2 (K: the chain's springs k plus kg from
    mass 0 to the ground), from the inertia of K - w2 M = L D L^T with the pivots in the
    differential form e_i = d_i - k_i = k_{i-1} e_{i-1} / d_{i-1} - w2 m_i (no k_{i-1} + k_i,
    whose rounding would cost the small eigenvalues of a stiff chain their relative accuracy)."""
    n = m.size
    count = 0
    e = kg - w2 * m[0]
    for i in range(n - 1):
        d = e + k[i]
        if d == 0.0:
            d = -EPS * k[i]  # a pivot exactly zero: perturbed as in LAPACK's dstebz
        if d < 0.0:
            count += 1
        e = k[i] * (e / d) - w2 * m[i + 1]
    if e < 0.0:
        count += 1
    return count


@njit(cache=True)
def _above(w2, m, k, kg, q):
    """True if eigenvalue q (0-based) of K x = w2 M x is below w2."""
    return _count_below(m, k, kg, w2) > q


_bisect_w2 = threshold_bisection(_above)


@njit(cache=True)
def _refine_w2(m, k, kg, q, lo, hi):
    """Eigenvalue q (0-based, ascending) of K x = w2 M x to a few ulps by bisection of
    _count_below in [lo, hi] (widened to every eigenvalue if it does not hold q)."""
    if not (_count_below(m, k, kg, lo) <= q < _count_below(m, k, kg, hi)):
        lo = 0.0
        hi = 1.0
        while _count_below(m, k, kg, hi) <= q:
            hi *= 4.0
    return _bisect_w2(lo, hi, (m, k, kg, q))  # geometric midpoints: the spectrum spans decades


# A mode far above or below the band of the chain's other masses (a stiff contact's mode on a
# long chain) decays by a large factor per mass away from its peak, so the recurrences of
# _shape, which run towards the peak, grow by it: 500x per mass overflowed after 114 masses
# (N = 128, beta = 1e-3: NaN modes, the locator then spent its whole budget on NaN). Past
# SHAPE_BIG the values computed so far are scaled by 1/SHAPE_BIG, a power of two: exact, so a
# mode that does not overflow keeps its bits, and the far end's amplitudes fall to their true,
# negligible size.
SHAPE_BIG = 2.0**200


@njit(cache=True, refcount=False)
def _rescale(x, ext, lo, hi, f):
    """x[lo..hi], ext[lo..hi-1] and the link force f scaled by 1/SHAPE_BIG (returns f)."""
    for j in range(lo, hi + 1):
        x[j] /= SHAPE_BIG
    for j in range(lo, hi):
        ext[j] /= SHAPE_BIG
    return f / SHAPE_BIG


@njit(cache=True)
def _shape(m, k, kg, w2, r, x, ext):
    """Mode shape x (x_r scaled to 1 first, then M-normalised) of eigenvalue w2 and its link
    extensions ext_i = x_{i+1} - x_i, from the link forces f_i = k_i ext_i: f_i = f_{i-1} -
    w2 m_i x_i from mass 0 down to r, and from the free end up to r, joined at r (the mode's
    peak, so both recurrences run where the mode grows: stable). Every extension is a force
    over a stiffness, so a nearly rigid slow mode keeps its small extensions to full relative
    accuracy (differences of its displacements would not)."""
    n = m.size
    x[0] = 1.0
    f = kg
    for i in range(r):
        f -= w2 * m[i] * x[i]
        ext[i] = f / k[i]
        x[i + 1] = x[i] + ext[i]
        if abs(x[i + 1]) > SHAPE_BIG:
            f = _rescale(x, ext, 0, i + 1, f)
    xr = x[r]
    f = 0.0
    xs = np.empty(n)
    xs[n - 1] = 1.0
    for i in range(n - 1, r, -1):
        f += w2 * m[i] * xs[i]
        ext[i - 1] = f / k[i - 1]
        xs[i - 1] = xs[i] - ext[i - 1]
        if abs(xs[i - 1]) > SHAPE_BIG:
            f = _rescale(xs, ext, i - 1, n - 1, f)
    xb = xs[r]
    sc = xr / xb
    for i in range(r + 1, n):
        x[i] = xs[i] * sc
    for i in range(r, n - 1):
        ext[i] *= sc
    nrm = 0.0
    for i in range(n):
        nrm += m[i] * x[i] * x[i]
    nrm = math.sqrt(nrm)
    for i in range(n):
        x[i] /= nrm
    for i in range(n - 1):
        ext[i] /= nrm


@njit(cache=True)
def _modal_model(m, k, c, kg, cg, drop_rigid):
    """Exponential-sum model of one phase of the chain (m, k, c) with a spring kg and a dashpot
    cg from mass 0 to the ground (the contact spring, or link 1 of a clamped chain).

    Returns ``lam`` (K,), ``U`` (n, K) and ``P`` (K, 2n), complex, such that for a start state
    y0 = (u0, v0) (relative to the centre of mass if ``drop_rigid``) z = P @ y0 and
    u(t) = Re U @ (z e^{lam t}), v(t) = Re U @ (lam z e^{lam t}); plus the eigenvector condition
    number (1 when undamped).
    """
    n = m.size
    K = _chain_matrix(n, k, kg)
    sm = np.sqrt(m)
    Kt = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            Kt[i, j] = K[i, j] / (sm[i] * sm[j])
    w2, psi = np.linalg.eigh(Kt)
    s = 1 if drop_rigid else 0  # eigh sorts ascending: the rigid mode (omega = 0) comes first
    nm = n - s
    phi = np.empty((n, nm))
    ext = np.empty((n - 1, nm))  # link extensions phi[i + 1, q] - phi[i, q]
    om = np.empty(nm)
    # eigh's eigenvalues are good to eps * max(w2) absolutely: a mode far below the fastest
    # (a soft part of a stiff chain) can lose most of its digits (2.7e-6 relative at a 1e10
    # spread: contact ends off by 0.03 and COR by 2e-7). Every mode is refined by bisection on
    # the chain's own pivots from eigh's bracket (a few steps where the spread is small) and its
    # shape rebuilt from the link forces. (Refining only modes whose bound exceeded 1e-12 of
    # themselves left a 16-mass chain 2 contacts off, COR by 1e-3, under an estimate of 2e-8.)
    delta = 8.0 * n * EPS * max(abs(w2[n - 1]), 1e-300)
    xbuf = np.empty(n)
    ebuf = np.empty(max(n - 1, 1))
    for q in range(nm):
        w2q = max(w2[q + s], 0.0)
        if w2q < math.inf:  # (NaN from extreme input: kept, for _safe_model to refuse)
            w2q = _refine_w2(m, k, kg, q + s, max(w2q - delta, 0.0), w2q + delta)
            r = 0
            for i in range(n):
                if abs(psi[i, q + s]) / sm[i] > abs(psi[r, q + s]) / sm[r]:
                    r = i
            _shape(m, k, kg, w2q, r, xbuf, ebuf)
            sign = 1.0 if xbuf[r] * psi[r, q + s] >= 0.0 else -1.0
            for i in range(n):
                phi[i, q] = sign * xbuf[i]
            for i in range(n - 1):
                ext[i, q] = sign * ebuf[i]
        else:
            for i in range(n):
                phi[i, q] = psi[i, q + s] / sm[i]
            for i in range(n - 1):
                ext[i, q] = phi[i + 1, q] - phi[i, q]
        om[q] = math.sqrt(w2q)
    damped = cg > 0.0
    for i in range(c.size):
        if c[i] > 0.0:
            damped = True
    if not damped:
        lam = np.empty(nm, np.complex128)
        U = np.empty((n, nm), np.complex128)
        P = np.zeros((nm, 2 * n), np.complex128)
        for q in range(nm):
            lam[q] = 1j * om[q]
            for i in range(n):
                U[i, q] = phi[i, q]
                P[q, i] = phi[i, q] * m[i]
                P[q, n + i] = -1j * phi[i, q] * m[i] / om[q]
        return lam, U, P, 1.0
    # Modal damping D = Phi^T C Phi, C = sum_i c_i d_i d_i^T (+ cg at mass 0): full in general.
    D = np.zeros((nm, nm))
    for i in range(c.size):
        ci = c[i]
        if ci == 0.0:
            continue
        for q in range(nm):
            dq = ext[i, q]
            for p in range(nm):
                D[q, p] += ci * dq * ext[i, p]
    if cg > 0.0:
        for q in range(nm):
            for p in range(nm):
                D[q, p] += cg * phi[0, q] * phi[0, p]
    # The state matrix of (om q, q'), not of (q, q'): there every mode's eigenvector has parts of
    # like size, while in (q, q') they differ by |lam| (a stiff contact's 2e4 against a slow
    # mode's 0.1), so V^-1 reconstructed the state to eps * 3e4 (the other masses' velocities
    # 1e-11 off after a beta = 1e-8 contact phase: COR errors of 3e-10 on a chain that round-off
    # of its inputs moves by 2e-14).
    sc = np.empty(nm)
    for q in range(nm):
        sc[q] = om[q] if om[q] > 0.0 else 1.0
    S = np.zeros((2 * nm, 2 * nm))
    for q in range(nm):
        S[q, nm + q] = sc[q]
        S[nm + q, q] = -om[q] * (om[q] / sc[q])
        for p in range(nm):
            S[nm + q, nm + p] = -D[q, p]
    lamk, Vk, Wk, cond = _real_modes(S, sc, om, D)
    for q in range(nm):  # back to (q, q')
        for j in range(lamk.size):
            Vk[q, j] /= sc[q]
            Wk[j, q] *= sc[q]
    phic = phi.astype(np.complex128)
    U = phic @ np.ascontiguousarray(Vk[:nm, :])
    PhiTM = np.empty((nm, n), np.complex128)
    for q in range(nm):
        for i in range(n):
            PhiTM[q, i] = phi[i, q] * m[i]
    P = np.empty((lamk.size, 2 * n), np.complex128)
    Pu = np.ascontiguousarray(Wk[:, :nm]) @ PhiTM
    Pv = np.ascontiguousarray(Wk[:, nm:]) @ PhiTM
    for q in range(lamk.size):  # (a loop: kernels/copies.py)
        for i in range(n):
            P[q, i] = Pu[q, i]
            P[q, n + i] = Pv[q, i]
    return lamk, U, P, cond


@njit(cache=True)
def _cond1(V, W):
    """Condition number of the eigenvector matrix V in the 1-norm, ||V||_1 ||V^-1||_1, from the
    inverse W the model needs anyway: within a factor 2n of the 2-norm one (an SVD, which cost
    more than half the set-up of a damped two-mass contact phase) and as good a trust test."""
    nv = 0.0
    nw = 0.0
    for j in range(V.shape[1]):
        sv = 0.0
        sw = 0.0
        for i in range(V.shape[0]):
            sv += abs(V[i, j])
            sw += abs(W[i, j])
        nv = max(nv, sv)
        nw = max(nw, sw)
    return nv * nw


@njit(cache=True)
def _consistent_vectors(wr, wi, Vr, sc):
    """Make each eigenvector (x, y) of the modal state matrix of (sc q, q') obey y_i = lam x_i /
    sc_i exactly, taking each component from the larger of its two parts.

    The kernels rebuild velocities as lam times the displacement part. dgeev gives both parts to
    eps of the vector, so a slow mode's share of the fast (contact) mode's displacement, small
    there, came back multiplied by |lam_fast| / om_slow (2e5 at beta = 1e-8): the other masses'
    velocities were 1e-11 off after a stiff damped contact phase, against 1e-15 from the velocity
    part itself."""
    nm = sc.size
    K = wr.size
    j = 0
    while j < K:
        lam = complex(wr[j], wi[j])
        pair = wi[j] != 0.0 and j + 1 < K
        for i in range(nm):
            x = complex(Vr[i, j], Vr[i, j + 1] if pair else 0.0)
            y = complex(Vr[nm + i, j], Vr[nm + i, j + 1] if pair else 0.0)
            if abs(lam) >= sc[i]:
                x = y * sc[i] / lam
            else:
                y = lam * x / sc[i]
            Vr[i, j] = x.real
            Vr[nm + i, j] = y.real
            if pair:
                Vr[i, j + 1] = x.imag
                Vr[nm + i, j + 1] = y.imag
        j += 2 if pair else 1


@njit(cache=True)
def _real_modes(S, sc, om, D):
    """Modal basis of the real state matrix S, one term per conjugate pair of eigenvalues.

    An eigenvalue lam with Im > 0 has the partner conj(lam), and the two terms of a real motion
    are conjugate: their sum is Re(v z e^{lam t}) with one complex amplitude z. The initial state
    is expanded in LAPACK's real eigenbasis (dgeev, restitution.kernels.lapack: [Re v, Im v] for
    each pair, the real eigenvector of each real eigenvalue), y = Re v a + Im v b + ..., by a
    real inverse; then z = a - i b. This halves the terms every gap evaluation, state and
    dissipation integral of an underdamped phase sums over, and reconstructs y to eps * cond
    (doubling one member of each pair of a complex inverse instead left 5e-10 at a near-critical
    pair, whose two projectors are large and cancel only to round-off).

    S is the modal state matrix of (sc q, q') (see _modal_model) of the modal frequencies om
    and damping D; the eigenpairs dgeev resolves poorly against ||S|| (heavy damping) are
    refined on the quadratic eigenproblem (restitution.kernels.quadratic_refine) and every
    eigenvector is made consistent (_consistent_vectors) before the inverse.

    Returns (lam, V, W, cond): the K kept eigenvalues, V (2nm, K) and W (K, 2nm) complex with
    y(t) = Re V (e^{lam t} * (W y0)), and the real basis's condition number (1-norm). Raises
    LinAlgError if LAPACK fails (_safe_model turns that into STATUS_ILL_CONDITIONED).
    """
    wr, wi, vr, info = eig_real(S)
    if info != 0:
        raise np.linalg.LinAlgError("dgeev did not converge")
    K = wr.size
    Vr = np.empty((K, K))
    for j in range(K):
        for i in range(K):
            Vr[i, j] = vr[j, i]
    refine_pairs(wr, wi, Vr, S, om, D, sc)
    _consistent_vectors(wr, wi, Vr, sc)
    nkeep = 0
    for j in range(K):
        if wi[j] >= 0.0:
            nkeep += 1
    Wr = np.linalg.inv(Vr)
    lam = np.empty(nkeep, np.complex128)
    Vk = np.empty((K, nkeep), np.complex128)
    Wk = np.empty((nkeep, K), np.complex128)
    k = 0
    for j in range(K):
        if wi[j] < 0.0:  # the second member of a pair
            continue
        # round-off can leave +1e-17 real parts on undamped-looking modes
        lam[k] = complex(min(wr[j], 0.0), wi[j])
        for i in range(K):
            if wi[j] > 0.0:
                Vk[i, k] = complex(Vr[i, j], Vr[i, j + 1])
                Wk[k, i] = complex(Wr[j, i], -Wr[j + 1, i])
            else:
                Vk[i, k] = Vr[i, j]
                Wk[k, i] = Wr[j, i]
        k += 1
    return lam, Vk, Wk, _cond1(Vr, Wr)


@njit(cache=True)
def _project(P, y, buf):
    """Modal amplitudes z = P @ y of a real state y, written into buf[:rows of P] and returned
    (a plain loop into a buffer the caller keeps: for the small matrices of a phase a BLAS call,
    or even an allocation, costs more than the product)."""
    z = buf[: P.shape[0]]
    for q in range(P.shape[0]):
        acc = 0.0j
        for j in range(y.size):
            acc += P[q, j] * y[j]
        z[q] = acc
    return z


@njit(cache=True)
def _total(m):
    """Total mass, compensated (Neumaier) so that it is rounded once; a uniform tail
    m_2 = ... = m_N gives m_1 + (N - 1) m_2 exactly as rounded before (dashpot chatter is so
    sensitive that 1 ulp of the total mass moves the COR by ~1e-11 after 900 contacts)."""
    n = m.size
    if n == 1:
        return m[0]
    uniform = True
    for i in range(2, n):
        if m[i] != m[1]:
            uniform = False
    if uniform:
        return m[0] + (n - 1) * m[1]
    s = 0.0
    comp = 0.0
    for i in range(n):
        t = s + m[i]
        if abs(s) >= abs(m[i]):
            comp += (s - t) + m[i]
        else:
            comp += (m[i] - t) + s
        s = t
    return s + comp


@njit(cache=True)
def _near_defective(lam, cond):
    """FLAG_NEAR_DEFECTIVE if a phase's basis (its kept eigenvalues lam: one per conjugate pair)
    has cond > COND_DEFECT and two eigenvalues within DEFECT_REL of each other (a complex one
    and its conjugate included), or could not be formed at all (cond = inf: at a defective
    point the eigenvector matrix can be singular), else 0."""
    if cond == math.inf:
        return FLAG_NEAR_DEFECTIVE
    if not cond > COND_DEFECT:
        return 0
    K = lam.size
    for p in range(K):
        a = abs(lam[p])
        if a > 0.0 and 2.0 * abs(lam[p].imag) <= DEFECT_REL * a and lam[p].imag != 0.0:
            return FLAG_NEAR_DEFECTIVE
        for q in range(p + 1, K):
            b = max(a, abs(lam[q]))
            if b > 0.0 and abs(lam[q] - lam[p]) <= DEFECT_REL * b:
                return FLAG_NEAR_DEFECTIVE
    return 0


# Not inlined: _run calls it three times, and every inlined copy (with its exception handling)
# was typed and optimised again inside _run; a kernel of its own is compiled once (the paper
# chain's first call 33-34 s -> 28.5 s, the same bits; 2026-11-28).
@njit(cache=True)
def _safe_model(m, k, c, kg, cg, drop_rigid):
    """_modal_model, or (empty model, inf) if the eigen-solver fails or returns non-finite
    values (extreme parameters): the caller reports STATUS_ILL_CONDITIONED, never raises."""
    try:
        lam, U, P, cond = _modal_model(m, k, c, kg, cg, drop_rigid)
    except Exception:  # LinAlgError: the eigen-solver did not converge
        lam, U, P = _empty_model(m.size)
        return lam, U, P, math.inf
    # (the shapes too: a NaN amplitude would send the locator through its whole budget)
    ok = math.isfinite(cond) and _finite(lam) and _finite(U) and _finite(P)
    if not ok:
        return lam, U, P, math.inf
    return lam, U, P, cond


@njit(cache=True)
def _finite(a):
    """Every entry of the complex array ``a`` (any shape) finite."""
    return bool(np.isfinite(a).all())


@njit(cache=True)
def _diss_cost(T, lam, c):
    """Operations of one _diss_links call by Gauss-Legendre (sub-intervals x nodes x terms x
    dashpots): what _diss_phase's fallback costs, charged only when it is taken."""
    lmax = 0.0
    for q in range(lam.size):
        lmax = max(lmax, abs(lam[q]))
    nd = 0
    for i in range(c.size):
        if c[i] > 0.0:
            nd += 1
    return (T * lmax / 12.0 + 1.0) * 32.0 * lam.size * nd


@njit(cache=True)
def _vib_energy(m, k, u, v):
    """Relative kinetic + structural spring energy."""
    n = m.size
    mt = 0.0
    p = 0.0
    for i in range(n):
        mt += m[i]
        p += m[i] * v[i]
    V = p / mt
    e = 0.0
    for i in range(n):
        e += 0.5 * m[i] * (v[i] - V) ** 2
    for i in range(n - 1):
        e += 0.5 * k[i] * (u[i + 1] - u[i]) ** 2
    return e


@njit(cache=True)
def _diss_links(T, z, lam, U, c, off):
    """Dashpot work over [0, T] of a modal phase, integrated per dashpot: sum over links i with
    c_i > 0 of c_i (v_{i+1} - v_i)^2. U's rows are masses off..n-1 (masses below are at rest).
    T = inf: to infinite time (a permanent contact), in closed form."""
    acc = 0.0
    if T <= 0.0 or not _any_positive(c):
        return acc
    K = z.size
    g = np.empty(K, np.complex128)
    J1 = np.empty((0, 0), np.complex128)
    J2 = np.empty((0, 0), np.complex128)
    for i in range(c.size):
        if c[i] == 0.0:
            continue
        if J1.shape[0] == 0 and T < math.inf:  # the pair integrals depend on the phase only
            J1, J2 = _pair_integrals(T, lam)
        ra = i - off
        rb = i + 1 - off
        for q in range(K):
            ua = U[ra, q] if ra >= 0 else 0.0
            g[q] = (U[rb, q] - ua) * lam[q] * z[q]
        if T == math.inf:
            acc += _diss_modal_inf(g, lam, c[i])
        else:
            acc += _diss_pairs(T, g, lam, c[i], J1, J2)
    return acc


@njit(cache=True)
def _diss_matrices(U, lam, c, off):
    """Per-model constants of the dashpot work of a phase, summed over the dashpots: with
    a_ip = (U[i + 1 - off, p] - U[i - off, p]) lam_p (link i's relative velocity per unit modal
    amplitude; rows below ``off`` are at rest), A1 = sum_i c_i a_ip a_iq, A2 = sum_i c_i a_ip
    conj(a_iq), and B = sum_i c_i |a_ip| |a_iq|, the scale of their rounding. Empty (0 x 0) when
    there is no dashpot."""
    K = lam.size
    nd = 0
    for i in range(c.size):
        if c[i] > 0.0:
            nd += 1
    if nd == 0:
        K = 0
    A1 = np.zeros((K, K), np.complex128)
    A2 = np.zeros((K, K), np.complex128)
    B = np.zeros((K, K))
    a = np.empty(K, np.complex128)
    for i in range(c.size):
        if c[i] == 0.0 or K == 0:
            continue
        ra = i - off
        rb = i + 1 - off
        for q in range(K):
            ua = U[ra, q] if ra >= 0 else 0.0
            a[q] = (U[rb, q] - ua) * lam[q]
        for p in range(K):
            for q in range(p, K):
                A1[p, q] += c[i] * (a[p] * a[q])
                A2[p, q] += c[i] * (a[p] * a[q].conjugate())
                B[p, q] += c[i] * (abs(a[p]) * abs(a[q]))
    return A1, A2, B


@njit(cache=True)
def _diss_phase(T, z, lam, A1, A2, B, U, c, off, budget, floor):
    """Dashpot work over [0, T] (T finite) of a modal phase with amplitudes z, all dashpots at
    once: 1/2 sum over pairs p <= q of Re[z_p z_q A1_pq J1_pq + z_p conj(z_q) A2_pq J2_pq]
    (see locator._diss_modal), so its cost does not grow with the number of dashpots or with
    T. Where the terms' rounding scale (B) exceeds CANCEL_MAX times the result, and their
    rounding exceeds ``floor`` (an absolute energy: below it the energy account cannot see it),
    each dashpot is integrated by Gauss-Legendre instead (_diss_links' fallback), whose cost
    grows with T times the fastest rate: if that exceeds ``budget`` operations it is not run
    (NaN).

    Returns (work, operations charged)."""
    K = A1.shape[0]
    if T <= 0.0 or K == 0:
        return 0.0, 0.0
    J1, J2 = _pair_integrals(T, lam)
    acc = 0.0
    mag = 0.0
    for p in range(K):
        zp = z[p]
        if zp == 0.0:
            continue
        azp = abs(zp)
        for q in range(p, K):
            zq = z[q]
            if zq == 0.0:
                continue
            w = 1.0 if q == p else 2.0  # (p, q) and (q, p) give the same real part
            t1 = (zp * zq) * A1[p, q] * J1[p, q]
            t2 = (zp * zq.conjugate()) * A2[p, q] * J2[p, q]
            acc += w * (t1.real + t2.real)
            mag += w * azp * abs(zq) * B[p, q] * (abs(J1[p, q]) + abs(J2[p, q]))
    cost = 0.5 * K * (K + 1.0)
    if not (mag <= CANCEL_MAX * abs(acc) or EPS * mag <= floor):
        cost += _diss_cost(T, lam, c)
        if cost > budget:
            return math.nan, cost
        return _diss_links(T, z, lam, U, c, off), cost
    return 0.5 * acc, cost


@njit(cache=True)
def _any_positive(c):
    for i in range(c.size):
        if c[i] > 0.0:
            return True
    return False


@njit(cache=True)
def _empty_model(n):
    return (
        np.zeros(0, np.complex128),
        np.zeros((n, 0), np.complex128),
        np.zeros((0, 2 * n), np.complex128),
    )


# ----------------------------------------------------------------------------------------------
# The event-driven solver
# ----------------------------------------------------------------------------------------------


@njit(cache=True)
def _fail(out, status):
    for j in range(N_OUT):
        out[j] = math.nan
    out[OUT_STATUS] = status
    out[OUT_FLAGS] = 0.0
    return out


@njit(cache=True, error_model="numpy", refcount=False)
def _record_state(rec, r, u, v, first):
    """rec[r, 3 + i] = u[i], rec[r, 3 + n + i] = v[i] for i >= first: a record's state (a loop,
    as kernels/copies.py)."""
    n = u.shape[0]
    for i in range(first, n):
        rec[r, 3 + i] = u[i]
        rec[r, 3 + n + i] = v[i]


@njit(cache=True)
def _run(
    m,
    k,
    c,
    kc,
    max_events,
    hist,
    rec,
    work_max,
    v_stick=V_STICK_CHAIN,
    stick_after=STICK_AFTER,
    jitter=0.0,
    seed=0,
    band=1.0,
    force_free=-1,
    force_t=0.0,
    force_v=0.0,
    y0=None,
    cc=0.0,
):
    """Solve one scene in normalised units (m[0] = 1, omega = 1); fill ``hist`` and, if rec has
    rows, record every phase start as [t0, kind (PH_*), duration, u(n), v(n)]. ``jitter`` > 0
    perturbs the state by that much (relative) at every phase start, along the Weyl sequence
    from index ``seed`` (the replica check, restitution.kernels.replica); ``band`` scales the
    touching band of its free flights (the replicas' BAND_LOW and BAND_HIGH). Free flight
    number ``force_free`` (from 0; -1: none) ends in a contact at ``force_t`` with approach
    speed ``force_v`` (_checked_units' pass replica: its passed dip taken as a contact).
    ``y0`` (None: every mass at -1, every spring unstretched) is the state [u(n), v(n)] at
    t = 0 with u[0] = 0: m1 touches the wall; it hits it at t = 0 if v[0] < 0, and the scene
    starts in free flight if v[0] > 0 (v[0] = 0 is refused by the Python layer). The COR is then
    the centre of mass's velocity after over its approach speed before, and the energies are
    fractions of the initial kinetic + spring energy.

    ``cc`` > 0 (with a finite kc): a Kelvin-Voigt contact, the dashpot cc in parallel with kc,
    whose contact ends where the force -(kc u1 + cc v1) returns to 0 while u1 < 0; m1 then flies
    free inside the penetration until that force rises through 0 again (a new contact there) or
    u1 rises through 0 (the free flight). See the module docstring, "Kelvin-Voigt contact".
    A chain of one mass (n = 1) is taken with a Kelvin-Voigt contact (no free modes).

    Returns (out, n_records, closest pass) with the closest pass (band units, free flight
    index, time, approach speed of a contact at the band's depth there; see _checked_units).
    """
    out = np.zeros(N_OUT)
    closest = np.array([math.inf, -1.0, 0.0, 0.0])
    n = m.size
    work_max *= max(1.0, max_events / WORK_EVENTS)  # (see WORK_EVENTS)
    rigid = kc == math.inf
    mt = _total(m)
    floor = DISS_FLOOR * 0.5 * mt  # of a phase's dissipation: see _diss_phase
    kv = cc > 0.0 and not rigid  # a Kelvin-Voigt contact (its dashpot cc on m1)
    mu = m[1] / (m[0] + m[1]) if n > 1 else 0.0
    xi = c[0] / (2.0 * k[0]) if n > 1 else 0.0  # of the scalar two-mass oscillator (omega = 1)
    if xi < XI_NEGLIGIBLE:
        xi = 0.0  # subnormal: undamped to within any float (see kernels.rigid2)
    q2 = (1.0 - xi) * (1.0 + xi)  # its 1 - xi^2 and frequency, as restitution.kernels.rigid2
    w2 = math.sqrt(abs(q2))
    status = STATUS_OK
    flags = 0
    cond = 1.0
    if n > 2 or kv:  # (two masses: the closed-form walk, except inside a KV penetration)
        lamF, UF, PF, condF = _safe_model(m, k, c, 0.0, 0.0, True)
        cond = max(cond, condF)
        flags |= _near_defective(lamF, condF)
    else:
        lamF, UF, PF = _empty_model(n)
    A1F, A2F, BF = _diss_matrices(UF, lamF, c, 0)
    # The contact phase's dashpots: the links' (offset 0), or with a Kelvin-Voigt contact its
    # dashpot cc as a link 0 from the ground to m1 followed by the links (offset 1, so that
    # link i >= 1 joins masses i - 1 and i; _diss_links).
    cC = np.empty(n if kv else n - 1)
    offC = 1 if kv else 0
    if kv:
        cC[0] = cc
    for i in range(n - 1):  # (a loop: kernels/copies.py)
        cC[offC + i] = c[i]
    if not rigid:
        lamC, UC, PC, condC = _safe_model(m, k, c, kc, cc if kv else 0.0, False)
        cond = max(cond, condC)
        flags |= _near_defective(lamC, condC)
    else:
        lamC, UC, PC = _empty_model(n)
    A1C, A2C, BC = _diss_matrices(UC, lamC, cC, offC)
    lamS, US, PS = _empty_model(n - 1)  # clamped chain m_2..m_N, built on first sticking
    A1S, A2S, BS = _diss_matrices(US, lamS, c, 1)
    have_stick = False
    if cond > COND_MAX:
        status = STATUS_ILL_CONDITIONED
        if cond == math.inf:  # no model at all: nothing to run
            out[OUT_STATUS] = status
            out[OUT_FLAGS] = flags
            out[OUT_COR] = math.nan
            out[OUT_ERR] = math.inf
            return out, 0, closest

    u = np.zeros(n)
    v = -np.ones(n)
    if y0 is not None:
        for i in range(n):
            u[i] = y0[i]
            v[i] = y0[n + i]
    y = np.empty(2 * n)
    ys = np.empty(2 * n - 2)
    info = np.zeros(N_INFO)
    nfree = -1  # index of the current free flight
    # Scratch for every phase (modal amplitudes, gap coefficients, the locator's evaluations):
    # one allocation per scene instead of three or four per contact.
    zbuf = np.empty(2 * n, np.complex128)
    bbuf = np.empty(2 * n, np.complex128)
    xbuf = np.empty(2 * n if kv else 0, np.complex128)  # a KV phase's penetration
    res = np.empty(N_RES)
    inside = False  # (KV) m1 free inside the penetration: the phase after a force-zero end
    recontact = False  # (KV) the contact starts inside the penetration, where the force rose
    t = 0.0
    t_last = 0.0
    ncol = 1
    ediss = 0.0
    lost = 0.0
    err = 0.0
    work = 0.0
    nrec = 0
    nh = hist.shape[0]
    in_contact = not rigid
    permanent = False
    jc = seed  # index into the jitter's Weyl sequence
    if y0 is not None:
        if v[0] > 0.0:  # m1 leaves the wall at t = 0: no contact yet, a free flight first
            ncol = 0
            in_contact = False
        elif nh > 0:
            hist[0, H_TSTART] = 0.0
            hist[0, H_VIN] = v[0]
        if rigid and ncol == 1:  # the impact at t = 0
            vin = v[0]
            v[0] = -vin
            if nh > 0:
                hist[0, H_TEND] = 0.0
                hist[0, H_VOUT] = -vin
                hist[0, H_XMAX] = 0.0
                hist[0, H_IMPULSE] = -2.0 * vin * m[0]
    elif nh > 0:
        hist[0, H_TSTART] = 0.0
        hist[0, H_VIN] = -1.0
    if rigid and y0 is None:
        v[0] = 1.0
        if nh > 0:
            hist[0, H_TEND] = 0.0
            hist[0, H_VOUT] = 1.0
            hist[0, H_XMAX] = 0.0
            hist[0, H_IMPULSE] = 2.0
    while True:
        if work > work_max:
            status = STATUS_WORK_BUDGET
            break
        if jitter > 0.0:
            for i in range(n):
                u[i] *= 1.0 + jitter * weyl(jc)
                v[i] *= 1.0 + jitter * weyl(jc + 1)
                jc += 2
        if nrec < rec.shape[0]:
            rec[nrec, 0] = t
            rec[nrec, 1] = PH_CONTACT if in_contact else PH_FREE
            rec[nrec, 2] = math.inf
            _record_state(rec, nrec, u, v, 0)
        nrec += 1
        if in_contact:
            p_in = 0.0
            for i in range(n):
                y[i] = u[i]
                y[n + i] = v[i]
                p_in += m[i] * v[i]
            z = _project(PC, y, zbuf)
            bgap = bbuf[: z.size]
            g0 = 0.0  # the end event's function at the start: the penetration, 0 at the wall
            if kv:
                # The force kc x + cc x' = -(kc u1 + cc v1): its modal coefficients are the
                # penetration's times (kc + cc lam); it is cc x' > 0 at a contact from the
                # wall, 0 at one from inside the penetration (started by that very event).
                bx = xbuf[: z.size]
                for q in range(z.size):
                    bx[q] = -UC[0, q] * z[q]
                    bgap[q] = -(kc + cc * lamC[q]) * UC[0, q] * z[q]
                if not recontact:
                    g0 = -(kc * u[0] + cc * v[0])
                x0 = -u[0]
                ediss -= 0.5 * kc * x0 * x0  # the contact spring is loaded again (W = F x')
            else:
                for q in range(z.size):
                    bgap[q] = -UC[0, q] * z[q]
            code = _locate(
                g0,
                0.0,
                bgap,
                lamC,
                True,
                info,
                _steps_left(work_max - work, z.size),
                res,
            )
            work += (info[3] + 1.0) * z.size
            if code == LOC_BUDGET:
                status = STATUS_WORK_BUDGET if work >= work_max else STATUS_NONCONVERGED
                break
            if code == LOC_PERMANENT or code == LOC_NEVER:
                permanent = True
                # Dissipation to infinite time, in closed form (the slowest decay can be 1e10
                # times slower than the fastest mode: no quadrature reaches it in bounded work).
                slow = _slowest(bgap, lamC)
                ediss += _diss_links(math.inf, z, lamC, UC, cC, offC)
                if ncol - 1 < nh:
                    hist[ncol - 1, H_TEND] = math.inf
                    hist[ncol - 1, H_VOUT] = 0.0
                    if kv:
                        xm = _xmax(0.0, 80.0 / slow, -u[0], 0.0, xbuf[: z.size], lamC)
                    else:
                        xm = _xmax(info[2], 80.0 / slow, 0.0, 0.0, bgap, lamC)
                    hist[ncol - 1, H_XMAX] = xm
                    hist[ncol - 1, H_IMPULSE] = -p_in
                break
            te = info[0]
            dw, cost = _diss_phase(te, z, lamC, A1C, A2C, BC, UC, cC, offC, work_max - work, floor)
            work += cost
            if work > work_max:
                status = STATUS_WORK_BUDGET
                break
            ediss += dw
            x0 = -u[0]
            _modal_state(te, z, lamC, UC, 0.0, 0.0, u, v)
            inside = False
            if not kv:
                u[0] = 0.0  # separation: exactly at the wall
            elif u[0] < 0.0:
                # The force is 0 with m1 inside the penetration: the spring's energy there is
                # lost (the massless surface relaxes), and m1 flies free inside.
                ediss += 0.5 * kc * u[0] * u[0]
                inside = True
            else:
                u[0] = 0.0  # (the force-zero end at the wall itself)
            t += te
            t_last = t
            if nrec - 1 < rec.shape[0]:
                rec[nrec - 1, 2] = te
            if ncol - 1 < nh:
                p_out = 0.0
                for i in range(n):
                    p_out += m[i] * v[i]
                hist[ncol - 1, H_TEND] = t
                hist[ncol - 1, H_VOUT] = v[0]
                if kv:
                    xm = _xmax(0.0, te, x0, 0.0, xbuf[: z.size], lamC)
                else:
                    xm = _xmax(info[2], te, 0.0, 0.0, bgap, lamC)
                hist[ncol - 1, H_XMAX] = xm
                hist[ncol - 1, H_IMPULSE] = p_out - p_in
            in_contact = False
            continue
        if inside:
            # (KV) Free inside the penetration (x = -u1 > 0, force 0): until the force
            # -(kc u1 + cc v1) rises through 0 (a new contact, from inside) or x falls to 0 (on
            # to the free flight). Both are exponential sums of the free modes plus the centre
            # of mass's X0 + V t, located by the same locator.
            X0 = 0.0
            V = 0.0
            for i in range(n):
                X0 += m[i] * u[i]
                V += m[i] * v[i]
            X0 /= mt
            V /= mt
            for i in range(n):
                y[i] = u[i] - X0
                y[n + i] = v[i] - V
            z = _project(PF, y, zbuf)
            bx = xbuf[: z.size]
            bgap = bbuf[: z.size]
            for q in range(z.size):
                bx[q] = -UF[0, q] * z[q]
                bgap[q] = (kc + cc * lamF[q]) * UF[0, q] * z[q]
            code_x = _locate(
                -u[0], -V, bx, lamF, False, info, _steps_left(work_max - work, z.size), res, band
            )
            work += (info[3] + 1.0) * (z.size + 1)
            tx = info[0]
            code = _locate(
                0.0,  # the force-zero end itself
                kc * V,
                bgap,
                lamF,
                False,
                info,
                _steps_left(work_max - work, z.size),
                res,
                band,
            )
            work += (info[3] + 1.0) * (z.size + 1)
            tg = info[0]
            if code_x == LOC_BUDGET or code == LOC_BUDGET:
                status = STATUS_WORK_BUDGET if work >= work_max else STATUS_NONCONVERGED
                break
            if code_x != LOC_EVENT and code != LOC_EVENT:
                status = STATUS_NONCONVERGED  # (m1 inside for ever: not a motion of the model)
                break
            out_first = code_x == LOC_EVENT and (code != LOC_EVENT or tx <= tg)
            te = tx if out_first else tg
            dw, cost = _diss_phase(te, z, lamF, A1F, A2F, BF, UF, c, 0, work_max - work, floor)
            work += cost
            if work > work_max:
                status = STATUS_WORK_BUDGET
                break
            ediss += dw
            _modal_state(te, z, lamF, UF, X0, V, u, v)
            t += te
            if nrec - 1 < rec.shape[0]:
                rec[nrec - 1, 2] = te
            inside = False
            if out_first:
                u[0] = 0.0  # m1 leaves the penetration: the free flight from the wall
                continue
            if ncol >= max_events:
                status = STATUS_EVENT_BUDGET
                break
            ncol += 1
            if ncol - 1 < nh:
                hist[ncol - 1, H_TSTART] = t
                hist[ncol - 1, H_VIN] = v[0]
            in_contact = True
            recontact = True
            continue
        # Free flight.
        nfree += 1
        X0 = 0.0
        V = 0.0
        for i in range(n):
            X0 += m[i] * u[i]
            V += m[i] * v[i]
        X0 /= mt
        V /= mt
        if n == 2:
            r0 = u[1] - u[0]
            rd0 = v[1] - v[0]
            # Every free flight of two masses starts with m1 exactly at the wall, leaving it:
            # the rigid-wall kernel's closed-form walk over the critical points of the gap
            # finds the next contact (or proves there is none) in a few closed-form steps.
            if xi == 0.0:
                s_next, found = _next_contact0(V, mu, r0, rd0)
            else:
                s_next, found = _next_contact_d(V, mu, xi, q2, w2, r0, rd0)
            work += 2.0
            if not found:
                code = LOC_BUDGET
            elif s_next < 0.0:
                code = LOC_NEVER
            else:
                code = LOC_EVENT
                info[0] = s_next
            z = zbuf[:0]
        else:
            r0 = 0.0
            rd0 = 0.0
            for i in range(n):
                y[i] = u[i] - X0
                y[n + i] = v[i] - V
            z = _project(PF, y, zbuf)
            bgap = bbuf[: z.size]
            for q in range(z.size):
                bgap[q] = UF[0, q] * z[q]
            code = _locate(
                u[0],
                V,
                bgap,
                lamF,
                False,
                info,
                _steps_left(work_max - work, z.size),
                res,
                band,
            )
            work += (info[3] + 1.0) * z.size
            if info[4] < closest[0]:
                closest[0] = info[4]
                closest[1] = nfree
                closest[2] = info[5]
                closest[3] = info[6]
            if nfree == force_free and code != LOC_BUDGET:
                code = LOC_EVENT
                info[0] = force_t
        if code == LOC_NEVER:
            break
        if code != LOC_EVENT:
            status = STATUS_WORK_BUDGET if work >= work_max else STATUS_NONCONVERGED
            break
        te = info[0]
        if n == 2:
            work += (te * max(1.0, 2.0 * xi) / 12.0 + 1.0) * 32.0  # _diss_scalar's nodes
            if work > work_max:
                status = STATUS_WORK_BUDGET
                break
            ediss += _diss_scalar(te, xi, r0, rd0, c[0])
            _scalar_advance(te, xi, r0, rd0, mu, u, v)
        else:
            dw, cost = _diss_phase(te, z, lamF, A1F, A2F, BF, UF, c, 0, work_max - work, floor)
            work += cost
            if work > work_max:
                status = STATUS_WORK_BUDGET
                break
            ediss += dw
            _modal_state(te, z, lamF, UF, X0, V, u, v)
        u[0] = 0.0  # contact starts exactly at the wall
        if nfree == force_free:
            v[0] = -force_v  # the passed dip as a contact at the band's depth
        t += te
        if nrec - 1 < rec.shape[0]:
            rec[nrec - 1, 2] = te
        if ncol >= max_events:
            status = STATUS_EVENT_BUDGET
            break
        ncol += 1
        if ncol - 1 < nh:
            hist[ncol - 1, H_TSTART] = t
            hist[ncol - 1, H_VIN] = v[0]
        if not rigid:
            in_contact = True
            recontact = False
            continue
        vin = v[0]
        force = k[0] * u[1] + c[0] * v[1]  # of link 1 on m1 held at the wall (< 0: compressive)
        if c[0] > 0.0 and ncol > stick_after and -vin < v_stick and force < 0.0:
            # Chatter under a compressive force: continue with its limit, sticking.
            if not have_stick:
                lamS, US, PS, condS = _safe_model(m[1:], k[1:], c[1:], k[0], c[0], False)
                A1S, A2S, BS = _diss_matrices(US, lamS, c, 1)
                have_stick = True
                cond = max(cond, condS)
                flags |= _near_defective(lamS, condS)
                if condS > COND_MAX:
                    status = STATUS_ILL_CONDITIONED
                    break
            flags |= FLAG_STICKING
            err = max(err, vin * vin)  # measured COR error of the cut-off: <= 1e-3 v^2
            lost += 0.5 * m[0] * vin * vin
            p_in = 0.0
            for i in range(n):
                p_in += m[i] * v[i]
            if nrec < rec.shape[0]:
                rec[nrec, 0] = t
                rec[nrec, 1] = PH_STICK
                rec[nrec, 2] = math.inf
                rec[nrec, 3] = 0.0
                rec[nrec, 3 + n] = 0.0
                _record_state(rec, nrec, u, v, 1)
            nrec += 1
            for i in range(n - 1):
                ys[i] = u[i + 1]
                ys[n - 1 + i] = v[i + 1]
            zs = _project(PS, ys, zbuf)
            # f = -F (>= 0 while compressive) = -(k12 u2 + c12 v2): lift-off when f < 0.
            bs = bbuf[: zs.size]
            for q in range(zs.size):
                bs[q] = -(k[0] + c[0] * lamS[q]) * US[0, q] * zs[q]
            code = _locate(
                -force,
                0.0,
                bs,
                lamS,
                True,
                info,
                _steps_left(work_max - work, zs.size),
                res,
            )
            work += (info[3] + 1.0) * zs.size
            if code == LOC_BUDGET:
                status = STATUS_WORK_BUDGET if work >= work_max else STATUS_NONCONVERGED
                break
            if code == LOC_PERMANENT or code == LOC_NEVER:
                permanent = True
                ediss += _diss_links(math.inf, zs, lamS, US, c, 1)
                if ncol - 1 < nh:
                    hist[ncol - 1, H_TEND] = math.inf
                    hist[ncol - 1, H_VOUT] = 0.0
                    hist[ncol - 1, H_XMAX] = 0.0
                    hist[ncol - 1, H_IMPULSE] = -p_in
                break
            te = info[0]
            dw, cost = _diss_phase(te, zs, lamS, A1S, A2S, BS, US, c, 1, work_max - work, floor)
            work += cost
            if work > work_max:
                status = STATUS_WORK_BUDGET
                break
            ediss += dw
            u1 = np.empty(n - 1)
            v1 = np.empty(n - 1)
            _modal_state(te, zs, lamS, US, 0.0, 0.0, u1, v1)
            u[0] = 0.0
            v[0] = 0.0
            for i in range(n - 1):
                u[1 + i] = u1[i]
                v[1 + i] = v1[i]
            t += te
            t_last = t
            if nrec - 1 < rec.shape[0]:
                rec[nrec - 1, 2] = te
            if ncol - 1 < nh:
                p_out = 0.0
                for i in range(n):
                    p_out += m[i] * v[i]
                hist[ncol - 1, H_TEND] = t
                hist[ncol - 1, H_VOUT] = 0.0
                hist[ncol - 1, H_XMAX] = 0.0
                hist[ncol - 1, H_IMPULSE] = p_out - p_in
            continue
        v[0] = -vin
        t_last = t
        if ncol - 1 < nh:
            hist[ncol - 1, H_TEND] = t
            hist[ncol - 1, H_VOUT] = -vin
            hist[ncol - 1, H_XMAX] = 0.0
            hist[ncol - 1, H_IMPULSE] = -2.0 * vin * m[0]

    e0 = 0.5 * mt
    p0 = -mt  # the momentum before (towards the wall)
    if y0 is not None:
        e0, p0 = _initial_energy(m, k, y0)
    if permanent:
        # Everything comes to rest against the wall: all energy not yet dissipated is.
        cor = 0.0
        evib = 0.0
        t_last = math.inf
        if status == STATUS_OK:
            status = STATUS_PERMANENT_CONTACT
    else:
        p = 0.0
        for i in range(n):
            p += m[i] * v[i]
        cor = p / mt
        if y0 is not None:
            cor = p / -p0
        evib = _vib_energy(m, k, u, v) / e0
    out[OUT_COR] = cor
    out[OUT_NCOL] = ncol
    out[OUT_TCOL] = t_last
    out[OUT_ETRANS] = cor * cor
    if y0 is not None:  # the centre of mass's kinetic energy after, over the initial energy
        out[OUT_ETRANS] = 0.5 * cor * cor * p0 * p0 / mt / e0
    out[OUT_EVIB] = evib
    out[OUT_EDISS] = (ediss + lost) / e0
    out[OUT_NEVENTS] = ncol
    err = max(ROUNDOFF_ULPS * EPS * ncol * cond, err)
    out[OUT_FLAGS] = flags
    # A permanent contact is a finished result too: its account (all energy dissipated) is
    # checked like any other. It must close to ENERGY_TOL, or to the run's own error bound
    # where that is larger (thousands of contacts, a conditioned eigenbasis: a row that claims
    # 1e-6 cannot be held to 1e-9 in its energies); the estimate then covers the account's gap.
    gap = abs(out[OUT_ETRANS] + evib + out[OUT_EDISS] - 1.0)
    finished = status == STATUS_OK or status == STATUS_PERMANENT_CONTACT
    if finished and not gap <= max(ENERGY_TOL, err):
        status = STATUS_ENERGY
    out[OUT_ERR] = max(err, gap) if gap == gap else err
    out[OUT_STATUS] = status
    return out, nrec, closest


@njit(cache=True)
def _initial_energy(m, k, y0):
    """(kinetic + spring energy, momentum) of the state y0 = [u(n), v(n)]."""
    n = m.size
    e = 0.0
    p = 0.0
    for i in range(n):
        e += 0.5 * m[i] * y0[n + i] * y0[n + i]
        p += m[i] * y0[n + i]
    for i in range(n - 1):
        e += 0.5 * k[i] * (y0[i + 1] - y0[i]) ** 2
    return e, p


@njit(cache=True)
def _steps_left(work, terms):
    """Locator steps the remaining work budget allows (at least 1, at most MAX_STEPS)."""
    return int(min(max(work / max(terms, 1), 1.0), MAX_STEPS))


@njit(cache=True)
def _slowest(b, lam):
    """Decay rate of the slowest term present (for the length of a permanent contact)."""
    slow = 0.0
    for q in range(b.size):
        if abs(b[q]) > 0.0 and (slow == 0.0 or -lam[q].real < slow):
            slow = -lam[q].real
    return max(slow, 1e-300)


# ----------------------------------------------------------------------------------------------
# Entry points
# ----------------------------------------------------------------------------------------------


@njit(cache=True)
def _valid(m, k, c, kc, max_events):
    """True if the scene is one the kernel handles (checked before any work; the Python layer
    gives the user a message naming the parameter, the kernel only refuses)."""
    n = m.size
    if n < 2 or k.size != n - 1 or c.size != n - 1 or max_events < 1:
        return False
    for i in range(n):
        if not (0.0 < m[i] < math.inf):
            return False
    for i in range(n - 1):
        if not (0.0 < k[i] < math.inf) or not (0.0 <= c[i] < math.inf):
            return False
    return kc > 0.0  # NaN fails too; inf is the rigid wall


@njit(cache=True)
def _normalise(m, k, c, kc):
    """(m, k, c, kc) in the kernel's units m[0] = 1, omega = 1 (unchanged, bit for bit, when
    they already are)."""
    w2 = k[0] / m[0] + k[0] / m[1] if m.size > 1 else kc / m[0]  # (one mass: its contact)
    if m[0] == 1.0 and abs(w2 - 1.0) <= 4.0 * EPS:
        return m.copy(), k.copy(), c.copy(), kc
    m0 = m[0]
    w = math.sqrt(w2)
    return m / m0, k / (m0 * w2), c / (m0 * w), kc / (m0 * w2)


@njit(cache=True)
def _scale_dashpot(m, k, kc, cc):
    """A contact dashpot cc of the scene (m, k, kc) in the units _normalise gives (as c)."""
    w2 = k[0] / m[0] + k[0] / m[1] if m.size > 1 else kc / m[0]
    if m[0] == 1.0 and abs(w2 - 1.0) <= 4.0 * EPS:
        return cc
    return cc / (m[0] * math.sqrt(w2))


@njit(cache=True, inline="always")
def _walks_rigid2(ms, kcs, use_rigid2, y0):
    """Whether _solve_units runs the two-mass walk (kernels.rigid2): two masses at a rigid wall
    from the uniform approach (the walk starts from it only)."""
    return use_rigid2 and ms.size == 2 and kcs == math.inf and y0 is None


@njit(cache=True, inline="always")
def _solve_units(
    ms,
    ks,
    cs,
    kcs,
    max_events,
    hist,
    work_max,
    use_rigid2,
    jitter,
    seed,
    band=1.0,
    force_free=-1,
    force_t=0.0,
    force_v=0.0,
    stick=1.0,
    y0=None,
    ccs=0.0,
):
    """(out, closest pass) of one run (_run's; the closest pass is none for two masses at a rigid
    wall, whose kernel walks the gap's critical points in closed form). ``stick`` scales the
    sticking limit's cut-off speed (the half-speed check of _checked_units)."""
    if _walks_rigid2(ms, kcs, use_rigid2, y0):
        # Two masses at a rigid wall: the dedicated closed-form kernel (alpha, xi) is faster.
        xi = cs[0] / (2.0 * ks[0])
        out = _rigid2(ms[1], xi, max_events, hist, stick * V_STICK_RIGID2, jitter, seed)
        return out, np.array([math.inf, -1.0, 0.0, 0.0])
    rec = np.zeros((0, 3 + 2 * ms.size))
    out, _, closest = _run(
        ms,
        ks,
        cs,
        kcs,
        max_events,
        hist,
        rec,
        work_max,
        stick * V_STICK_CHAIN,
        STICK_AFTER,
        jitter,
        seed,
        band,
        force_free,
        force_t,
        force_v,
        y0,
        ccs,
    )
    return out, closest


@njit(cache=True)
def _replica_scene(m, k, c, kc, seed):
    """The replica's scene: (m, k, c, kc) perturbed as the eigen-solvers' round-off perturbs the
    phase matrices. Masses and springs move by JITTER relative: _modal_model refines every
    undamped mode on the chain's own pivots, to an error relative to each mass and spring.
    (They moved by JITTER * ||A|| in every entry of A = M^-1/2 K M^-1/2 while eigh's absolute
    error set the modes: on 150 random chains over ratios 1e-4..1e4 that made 56 rows
    ill-conditioned; relative, 27, with no finished row outside its estimate against the
    reference.) Dashpots move on the scale sqrt(||A||), as the damped decomposition (dgeev on
    the companion form) is accurate relative to the norm; zero dashpots stay zero."""
    n = m.size
    anorm = 0.0
    for i in range(n):
        d = 0.0
        if i > 0:
            d += k[i - 1]
        if i < n - 1:
            d += k[i]
        anorm = max(anorm, d / m[i])
    mr = m.copy()
    for i in range(n):
        mr[i] *= 1.0 + JITTER * weyl(seed + i)
    kr = k.copy()
    cr = c.copy()
    for i in range(n - 1):
        s = math.sqrt(m[i] * m[i + 1])
        kr[i] *= 1.0 + JITTER * weyl(seed + n + i)
        if c[i] > 0.0:
            cr[i] += JITTER * weyl(seed + 2 * n + i) * (c[i] + math.sqrt(anorm) * s)
    # The contact spring moves relative to itself: the contact phase's own backward error on the
    # soft links (eps kc) acts only for the contact's duration, and emulating it on the links
    # would move every free flight by as much (estimates 1e8 times the measured errors at
    # beta = 1e-8, and needless switches to the rigid limit).
    kcr = kc * (1.0 + JITTER * weyl(seed + 3 * n))
    return mr, kr, cr, kcr


@njit(cache=True)
def _checked_units(
    ms, ks, cs, kcs, max_events, hist, work_max, use_rigid2, y0=None, ccs=0.0, check=True
):
    """_solve_units with the replica check (restitution.kernels.replica): a finished row's
    error estimate covers the round-off its replica reveals, or the row is ill-conditioned.

    The replicas also certify the touching rule: they locate contacts with touching bands of
    BAND_LOW and BAND_HIGH times the kernel's (locator.BAND_ULPS ulps of the gap's scale), so
    a free-flight dip whose depth lies within round-off of the band's edge is counted by one run
    and passed by another; the COR's jump across that cusp is then their spread, and enters
    the error estimate (or makes the row ill-conditioned), as at the paper's grazing points.

    After a long sequence round-off moves the state by far more than the band, so a dip the
    run passes well above the band can be a contact of the exact motion that no replica
    happens to flip (tests/test_shallow.py, seed 7 at the kernel's own 58 -> 59 step: the
    closest pass 23 bands above gap 0, the replicas' 11 and 64, all three passing it, the COR
    2.9e-8 from the reference under an estimate of 8e-13). The replicas' spread of the closest
    pass (times REPLICA_SAFETY) is how far the exact dip may lie from the computed one; if that
    reaches within PASS_NEAR bands of gap 0, a third replica, the run itself with that dip
    taken as a contact as deep as it may be (plus locator.PASS_DEPTH bands), measures the
    jump a passed dip can cause, and its spread enters the estimate.

    ``y0`` (an initial state, _run) is shared by the replicas as given: a replica scene that
    _normalise rescales moves it by JITTER-sized amounts, one more perturbation of the
    round-off size the replicas emulate. ``ccs``: a Kelvin-Voigt contact's dashpot (_run),
    moved by JITTER relative to itself in the replicas, as the contact spring.

    ``check`` False: the first run alone, flagged FLAG_UNCHECKED (a search's row, no result)."""
    out, near = _solve_units(
        ms, ks, cs, kcs, max_events, hist, work_max, use_rigid2, 0.0, 0, y0=y0, ccs=ccs
    )
    if not check:
        out[OUT_FLAGS] = int(out[OUT_FLAGS]) | FLAG_UNCHECKED
        return out
    if not finished(out[OUT_STATUS]):
        return out
    nohist = np.zeros((0, N_HIST))
    reps = np.empty((REPLICAS + 1, N_OUT))
    dev = 0.0  # the replicas' largest deviation of the closest pass (bands)
    for r in range(REPLICAS):
        seed = r * REPLICA_SEED
        mr0, kr0, cr0, kcr0 = _replica_scene(ms, ks, cs, kcs, seed)
        ccr = 0.0
        if ccs > 0.0:
            ccr = _scale_dashpot(
                mr0, kr0, kcr0, ccs * (1.0 + JITTER * weyl(seed + 3 * ms.size + 1))
            )
        mr, kr, cr, kcr = _normalise(mr0, kr0, cr0, kcr0)
        band = BAND_LOW if r == 0 else BAND_HIGH
        row, rnear = _solve_units(
            mr,
            kr,
            cr,
            kcr,
            max_events,
            nohist,
            work_max,
            use_rigid2,
            JITTER,
            seed,
            band,
            y0=y0,
            ccs=ccr,
        )
        put_row(reps, r, row)
        if finished(reps[r, OUT_STATUS]) and near[0] < math.inf:
            dev = max(dev, abs(rnear[0] - near[0]))
    reach = REPLICA_SAFETY * dev  # how far the exact closest pass may be from the computed one
    extra = 1 if near[0] - reach < PASS_NEAR else 0
    if extra:
        depth = max(reach - near[0], 0.0) + PASS_DEPTH  # bands below gap 0, at most
        row = _solve_units(
            ms,
            ks,
            cs,
            kcs,
            max_events,
            nohist,
            work_max,
            use_rigid2,
            0.0,
            0,
            1.0,
            int(near[1]),
            near[2],
            near[3] * math.sqrt(depth / PASS_DEPTH),
            y0=y0,
            ccs=ccs,
        )[0]
        put_row(reps, REPLICAS, row)
    out = combine(out, reps[: REPLICAS + extra])
    if int(out[OUT_FLAGS]) & FLAG_STICKING:  # the cut-off, measured (replica.stick_check)
        factor = STICK_BUDGET_RIGID2 if _walks_rigid2(ms, kcs, use_rigid2, y0) else STICK_BUDGET
        budget = min(max_events, int(factor * out[OUT_NCOL]) + 100)
        pure = _solve_units(
            ms, ks, cs, kcs, budget, nohist, work_max, use_rigid2, 0.0, 0, stick=0.0, y0=y0
        )[0]
        if finished(pure[OUT_STATUS]):
            return stick_check(out, pure, PURE_SAFETY)
        half = _solve_units(
            ms, ks, cs, kcs, max_events, nohist, work_max, use_rigid2, 0.0, 0, stick=0.5, y0=y0
        )[0]
        out = stick_check(out, half, STICK_SAFETY)
    return out


@njit(cache=True, inline="always")
def _extrapolated(ms, ks, cs, beta, lim, max_events, work_max, use_rigid2, y0=None, check=True):
    """The rigid wall's row ``lim`` (its own estimate) corrected to the stiffness ratio ``beta``
    by extrapolation in s = sqrt(beta): the quadratic through the limit (s = 0) and the
    finite-stiffness runs at EXTRAP_BETA and 4 EXTRAP_BETA (where the closed form is accurate),
    evaluated at s (see EXTRAP_BELOW). A row flagged FLAG_EXTRAPOLATED, or ``lim`` itself where
    the three runs do not share one contact sequence (a graze between them: no smooth
    expansion)."""
    nohist = np.zeros((0, N_HIST))
    s = math.sqrt(beta)
    s1 = math.sqrt(EXTRAP_BETA)
    s2 = 2.0 * s1
    r1 = _checked_units(
        ms, ks, cs, ks[0] / EXTRAP_BETA, max_events, nohist, work_max, use_rigid2, y0,
        check=check,
    )  # fmt: skip
    r2 = _checked_units(
        ms, ks, cs, ks[0] / (4.0 * EXTRAP_BETA), max_events, nohist, work_max, use_rigid2, y0,
        check=check,
    )  # fmt: skip
    st = lim[OUT_STATUS]
    if not (
        r1[OUT_STATUS] == st
        and r2[OUT_STATUS] == st
        and r1[OUT_NCOL] == lim[OUT_NCOL]
        and r2[OUT_NCOL] == lim[OUT_NCOL]
    ):
        return lim
    # Lagrange weights of the nodes 0, s1, s2 at s
    w0 = (s - s1) * (s - s2) / (s1 * s2)
    w1 = s * (s - s2) / (s1 * (s1 - s2))
    w2 = s * (s - s1) / (s2 * (s2 - s1))
    out = lim.copy()
    for col in (OUT_COR, OUT_TCOL, OUT_EVIB, OUT_EDISS):
        out[col] = w0 * lim[col] + w1 * r1[col] + w2 * r2[col]
    out[OUT_ETRANS] = out[OUT_COR] * out[OUT_COR]
    if y0 is not None:  # (not cor**2 from a general initial state: extrapolated as the rest)
        out[OUT_ETRANS] = w0 * lim[OUT_ETRANS] + w1 * r1[OUT_ETRANS] + w2 * r2[OUT_ETRANS]
    # The quadratic's own truncation is bounded by its distance to the line through the first
    # two nodes (that distance is the s**2 term, times s1 / s larger than the dropped s**3 term);
    # the runs' estimates enter with their weights.
    line = lim[OUT_COR] + (r1[OUT_COR] - lim[OUT_COR]) * (s / s1)
    own = abs(w0) * lim[OUT_ERR] + abs(w1) * r1[OUT_ERR] + abs(w2) * r2[OUT_ERR]
    gap = abs(out[OUT_ETRANS] + out[OUT_EVIB] + out[OUT_EDISS] - 1.0)
    out[OUT_ERR] = max(abs(out[OUT_COR] - line) + own, gap)
    out[OUT_FLAGS] = (int(lim[OUT_FLAGS]) & ~FLAG_RIGID_LIMIT) | FLAG_EXTRAPOLATED
    return out


@njit(cache=True, inline="always")
def _solve_stiff(ms, ks, cs, kcs, max_events, hist, work_max, use_rigid2, y0=None, check=True):
    """Normalised scene, with the rigid-limit policy for very stiff contact springs (see
    BETA_RIGID): returns the raw kernel row (no NaN applied). ``check``: _checked_units'."""
    beta = ks[0] / kcs
    limit = 0.0 < beta < BETA_RIGID
    extrapolate = 0.0 < beta < EXTRAP_BELOW
    compare = False
    out = np.empty(0)
    if not limit:
        out = _checked_units(
            ms, ks, cs, kcs, max_events, hist, work_max, use_rigid2, y0, check=check
        )
        st = out[OUT_STATUS]
        failed = st != STATUS_OK and st != STATUS_PERMANENT_CONTACT
        limit = 0.0 < beta < BETA_FALLBACK and (
            failed or out[OUT_ERR] > RIGID_LIMIT_C * math.sqrt(beta)
        )
        extrapolate = extrapolate and (failed or out[OUT_ERR] > EXTRAP_WORTH)
        # A finite-stiffness run that reached the end (ill-conditioned or not) is a check
        # on the limit: a graze that the stiff contact makes and the rigid wall misses changes
        # the contact count, and the limit's COR jumps by far more than C sqrt(beta).
        compare = finished(st) or st == STATUS_ILL_CONDITIONED
    if limit or extrapolate:
        kept = hist.copy() if compare else hist[:0]
        lim = _checked_units(
            ms, ks, cs, math.inf, max_events, hist, work_max, use_rigid2, y0, check=check
        )
        ext = lim
        bound = RIGID_LIMIT_C * math.sqrt(beta)
        if extrapolate and finished(lim[OUT_STATUS]) and bound > lim[OUT_ERR]:
            ext = _extrapolated(ms, ks, cs, beta, lim, max_events, work_max, use_rigid2, y0, check)
        lim[OUT_ERR] = max(lim[OUT_ERR], bound)
        lim[OUT_FLAGS] = int(lim[OUT_FLAGS]) | FLAG_RIGID_LIMIT
        if ext[OUT_ERR] < lim[OUT_ERR]:
            lim = ext
        if not limit and not lim[OUT_ERR] < out[OUT_ERR]:
            put_rows(hist, kept)  # the finite run's own estimate is the better one: it stands
            return out
        if compare and not (
            lim[OUT_NCOL] == out[OUT_NCOL]
            and abs(lim[OUT_COR] - out[OUT_COR]) <= out[OUT_ERR] + lim[OUT_ERR]
        ):
            put_rows(hist, kept)  # the limit disagrees: the finite run stands, with its own status
            return out
        return lim
    return out


@njit(cache=True)
def _solve(m, k, c, kc, max_events, hist, work_max, y0=None, cc=0.0, check=True):
    """One scene from the user's (m, k, c, kc): normalised, solved, an unfinished row's COR
    voided. ``check`` False: the search rows of solve_chain_batch (_checked_units)."""
    out = np.empty(N_OUT)
    if not _valid(m, k, c, kc, max_events):
        return _fail(out, STATUS_INVALID)
    if cc > 0.0:  # Kelvin-Voigt (checked by the caller: kc finite, cc finite)
        return _solve_kv(m, k, c, kc, cc, max_events, hist, work_max, y0, check)
    ms, ks, cs, kcs = _normalise(m, k, c, kc)
    if y0 is None:
        out = _solve_stiff(ms, ks, cs, kcs, max_events, hist, work_max, True, check=check)
    else:
        ys = _normalise_state(m, k, y0)
        out = _solve_stiff(ms, ks, cs, kcs, max_events, hist, work_max, True, ys, check)
    st = out[OUT_STATUS]
    if st != STATUS_OK and st != STATUS_PERMANENT_CONTACT:
        out[OUT_COR] = math.nan  # an unfinished sequence has no COR
        out[OUT_ETRANS] = math.nan
    return out


@njit(cache=True, inline="always")
def _solve_kv(m, k, c, kc, cc, max_events, hist, work_max, y0=None, check=True):
    """A Kelvin-Voigt contact (kc, cc): the checked run (no rigid-limit policy: the contact's
    dashpot has no rigid limit of the chain's, and the laws' ranges keep kc finite)."""
    ms, ks, cs, kcs = _normalise(m, k, c, kc)
    ccs = _scale_dashpot(m, k, kc, cc)
    if y0 is None:
        out = _checked_units(ms, ks, cs, kcs, max_events, hist, work_max, True, None, ccs, check)
    else:
        ys = _normalise_state(m, k, y0)
        out = _checked_units(ms, ks, cs, kcs, max_events, hist, work_max, True, ys, ccs, check)
    st = out[OUT_STATUS]
    if st != STATUS_OK and st != STATUS_PERMANENT_CONTACT:
        out[OUT_COR] = math.nan
        out[OUT_ETRANS] = math.nan
    return out


@njit(cache=True)
def _valid_kv(kc, cc):
    return 0.0 < kc < math.inf and 0.0 <= cc < math.inf


@njit(cache=True)
def solve_chain_kv(m, k, c, kc, cc, max_events, hist):
    """``solve_chain`` with a Kelvin-Voigt contact: the contact spring kc (finite) with the
    dashpot cc >= 0 in parallel (units of c; cc = 0 is the linear contact, solve_chain's row
    bit for bit). Invalid kc or cc give STATUS_INVALID."""
    if not _valid_kv(kc, cc):
        return _fail(np.empty(N_OUT), STATUS_INVALID)
    return _solve(m, k, c, kc, max_events, hist, WORK_MAX, None, cc)


@njit(cache=True)
def solve_chain_kv_state(m, k, c, kc, cc, y0, max_events, hist):
    """``solve_chain_state`` with a Kelvin-Voigt contact (as ``solve_chain_kv``)."""
    if not _valid_kv(kc, cc) or not _valid_state(m, y0):
        return _fail(np.empty(N_OUT), STATUS_INVALID)
    return _solve(m, k, c, kc, max_events, hist, WORK_MAX, y0, cc)


@njit(cache=True)
def solve_mass_kv(kc, cc, max_events, hist):
    """One mass m1 = 1 hitting a Kelvin-Voigt contact (kc, cc) at speed 1: the kernel's run
    (with its replica check) on a chain of one mass, in units m1 = 1, omega = sqrt(kc / m1)
    (times omega * t, lengths V0 / omega). A check of the contact phase, its force-zero end and
    its dissipation against the closed form (tests/test_kelvin_voigt_exact.py)."""
    m = np.ones(1)
    e = np.zeros(0)
    if not (_valid_kv(kc, cc) and cc > 0.0 and max_events >= 1):
        return _fail(np.empty(N_OUT), STATUS_INVALID)
    ms, ks, cs, kcs = _normalise(m, e, e, kc)
    ccs = _scale_dashpot(m, e, kc, cc)
    return _checked_units(ms, ks, cs, kcs, max_events, hist, WORK_MAX, False, None, ccs)


@njit(cache=True)
def _valid_state(m, y0):
    """An initial state the kernel takes: 2 n finite numbers, u[0] = 0, v[0] != 0 and the
    centre of mass approaching the wall (the Python layer names the bad entry)."""
    n = m.size
    if y0.size != 2 * n or y0[0] != 0.0 or y0[n] == 0.0:
        return False
    p = 0.0
    for i in range(2 * n):
        if not math.isfinite(y0[i]):
            return False
    for i in range(n):
        p += m[i] * y0[n + i]
    return p < 0.0


@njit(cache=True)
def _normalise_state(m, k, y0):
    """y0 in the units _normalise gives (m, k): speeds stay, lengths scale with omega, which
    _normalise sets to 1 (a copy either way)."""
    ys = y0.copy()
    w2 = k[0] / m[0] + k[0] / m[1]
    if not (m[0] == 1.0 and abs(w2 - 1.0) <= 4.0 * EPS):
        w = math.sqrt(w2)
        for i in range(m.size):
            ys[i] *= w
    return ys


@njit(cache=True)
def solve_chain_state(m, k, c, kc, y0, max_events, hist):
    """``solve_chain`` from the initial state y0 = [u(n), v(n)] (u in units V0 / omega of the
    given m, k; v in units V0; u[0] = 0, m1 touching the wall; v[0] != 0; the centre of mass
    approaching, sum m v < 0; see _run): COR = centre-of-mass velocity after / its approach
    speed before, energies as fractions of the initial kinetic + spring energy. An invalid
    state gives STATUS_INVALID."""
    if not _valid_state(m, y0):
        return _fail(np.empty(N_OUT), STATUS_INVALID)
    return _solve(m, k, c, kc, max_events, hist, WORK_MAX, y0)


@njit(cache=True)
def solve_chain(m, k, c, kc, max_events, hist, check=True):
    """Exact event-driven solution of one linear chain hitting a wall.

    Parameters
    ----------
    m : ndarray, float64 (n,)
        Masses, n >= 2, m[0] touches the wall (kernel units m[0] = 1; others are rescaled).
    k : ndarray, float64 (n - 1,)
        Spring stiffness of each link (> 0).
    c : ndarray, float64 (n - 1,)
        Dashpot coefficient of each link (>= 0).
    kc : float
        Contact spring stiffness (> 0), or math.inf for a rigid wall.
    max_events : int
        Contact budget; exceeding it gives STATUS_EVENT_BUDGET.
    hist : ndarray, shape (rows, N_HIST)
        One row per contact is written while rows last.
    check : bool
        False: the first run alone, without the replica check, flagged FLAG_UNCHECKED (a
        search's row, as in ``solve_chain_batch``); its history is the checked row's.

    Returns
    -------
    out : ndarray, shape (N_OUT,)
        See ``restitution.kernels.layout``; times are omega * t. Any status other than
        STATUS_OK and STATUS_PERMANENT_CONTACT comes with a NaN cor. Never raises for input of
        the declared types: invalid values give STATUS_INVALID.
    """
    return _solve(m, k, c, kc, max_events, hist, WORK_MAX, check=check)


@njit(cache=True, nogil=True)
def _chain_rows(m, k, c, n, kc, max_events, check, out, order, start, stop):
    """``solve_chain`` of the padded rows order[start:stop] into ``out`` (kernels.parallel);
    ``check`` False: search rows (solve_chain_batch)."""
    hist = np.zeros((0, N_HIST))
    for j in range(start, stop):
        i = order[j]
        ni = n[i]
        if ni < 2 or ni > m.shape[1]:
            put_row(out, i, _fail(np.empty(N_OUT), STATUS_INVALID))
            continue
        row = _solve(
            np.ascontiguousarray(m[i, :ni]),
            np.ascontiguousarray(k[i, : ni - 1]),
            np.ascontiguousarray(c[i, : ni - 1]),
            kc[i],
            max_events,
            hist,
            WORK_MAX,
            check=check,
        )
        put_row(out, i, row)


def solve_chain_batch(m, k, c, n, kc, max_events, check=True):
    """``solve_chain`` over padded arrays: m (rows, nmax), k and c (rows, nmax - 1), n (rows,)
    int64, kc (rows,), on numba's threads. Every row starts as NaN with STATUS_NOT_RUN before
    any work, so no row is ever left uninitialised; rows are independent and their work budgets
    count operations, so the result is bit-identical for any thread count.

    ``check=False`` gives an optimiser's search rows: each scene's first run alone, without the
    replica check (a third of the work or less), flagged FLAG_UNCHECKED. Such a row is no
    result: its OUT_ERR is only the kernel's own bound, not the round-off the replicas measure,
    and an ill-conditioned scene keeps its status. At a rigid wall its COR is the checked row's,
    bit for bit (with a stiff contact the rigid-limit policy reads OUT_ERR and may differ)."""
    m, k, c, kc = (np.ascontiguousarray(a, dtype=np.float64) for a in (m, k, c, kc))
    n = np.ascontiguousarray(n, dtype=np.int64)
    out = np.full((n.size, N_OUT), math.nan)
    out[:, OUT_STATUS] = STATUS_NOT_RUN
    over_threads(_chain_rows, n.size, m, k, c, n, kc, int(max_events), bool(check), out)
    return out


@njit(cache=True)
def _sample(m, k, c, kc, times, max_events, y0=None):
    n = m.size
    nrow = 3 * max_events + 4
    rec = np.zeros((nrow, 3 + 2 * n))
    hist = np.zeros((max_events, N_HIST))
    out, nrec, _ = _run(m, k, c, kc, max_events, hist, rec, WORK_MAX, y0=y0)
    nrec = min(nrec, nrow)
    rigid = kc == math.inf
    mt = _total(m)
    mu = m[1] / (m[0] + m[1])
    xi = c[0] / (2.0 * k[0])
    if xi < XI_NEGLIGIBLE:
        xi = 0.0  # as in _run
    if n > 2:
        lamF, UF, PF, _c = _modal_model(m, k, c, 0.0, 0.0, True)
    else:
        lamF, UF, PF = _empty_model(n)
    if not rigid:
        lamC, UC, PC, _c = _modal_model(m, k, c, kc, 0.0, False)
    else:
        lamC, UC, PC = _empty_model(n)
    lamS, US, PS, _c = _modal_model(m[1:], k[1:], c[1:], k[0], c[0], False)
    U = np.empty((times.size, n))
    Vv = np.empty((times.size, n))
    F = np.zeros(times.size)
    u = np.empty(n)
    v = np.empty(n)
    us = np.empty(n - 1)
    vs = np.empty(n - 1)
    y = np.empty(2 * n)
    ys = np.empty(2 * n - 2)
    zbuf = np.empty(2 * n, np.complex128)
    for j in range(times.size):
        tj = times[j]
        if tj < 0.0:
            U[j, :] = -tj
            Vv[j, :] = -1.0
            if y0 is not None:  # (no motion before t = 0 is defined for a given state)
                U[j, :] = math.nan
                Vv[j, :] = math.nan
            continue
        p = 0
        while p + 1 < nrec and rec[p + 1, 0] <= tj:
            p += 1
        tau = tj - rec[p, 0]
        u0 = rec[p, 3 : 3 + n]
        v0 = rec[p, 3 + n :]
        kind = rec[p, 1]
        if kind == PH_CONTACT:
            for i in range(n):
                y[i] = u0[i]
                y[n + i] = v0[i]
            z = _project(PC, y, zbuf)
            _modal_state(tau, z, lamC, UC, 0.0, 0.0, u, v)
            F[j] = kc * max(-u[0], 0.0)
        elif kind == PH_STICK:
            for i in range(n - 1):
                ys[i] = u0[i + 1]
                ys[n - 1 + i] = v0[i + 1]
            zs = _project(PS, ys, zbuf)
            _modal_state(tau, zs, lamS, US, 0.0, 0.0, us, vs)
            u[0] = 0.0
            v[0] = 0.0
            for i in range(n - 1):
                u[1 + i] = us[i]
                v[1 + i] = vs[i]
            F[j] = max(-(k[0] * us[0] + c[0] * vs[0]), 0.0)
        else:
            X0 = 0.0
            V = 0.0
            for i in range(n):
                X0 += m[i] * u0[i]
                V += m[i] * v0[i]
            X0 /= mt
            V /= mt
            if n == 2:
                _scalar_state(tau, xi, u0[1] - u0[0], v0[1] - v0[0], mu, u0[0], V, u, v)
            else:
                for i in range(n):
                    y[i] = u0[i] - X0
                    y[n + i] = v0[i] - V
                z = _project(PF, y, zbuf)
                _modal_state(tau, z, lamF, UF, X0, V, u, v)
        put_row(U, j, u)
        put_row(Vv, j, v)
    nimp = 0
    if rigid:
        nh = min(int(out[OUT_NEVENTS]), max_events)
        for i in range(nh):
            if hist[i, H_TSTART] == hist[i, H_TEND]:
                nimp += 1
    impacts = np.empty((nimp, 2))
    if rigid:
        j = 0
        for i in range(min(int(out[OUT_NEVENTS]), max_events)):
            if hist[i, H_TSTART] == hist[i, H_TEND]:
                impacts[j, 0] = hist[i, H_TSTART]
                impacts[j, 1] = hist[i, H_IMPULSE]
                j += 1
    return U, Vv, F, impacts


@njit(cache=True)
def sample_chain(m, k, c, kc, times, max_events):
    """Trajectory of a chain at the given times (omega * t).

    Returns
    -------
    u, v : ndarray (len(times), n)
        Positions (V0/omega units) and velocities (V0 units), from the closed form of the phase
        that contains each time (the event history is computed once).
    f : ndarray (len(times),)
        Wall contact force on m1 (m1 V0 omega units): kc * max(-u1, 0) for a contact spring, the
        holding force during a sticking phase, 0 when apart or at an instantaneous impact.
    impacts : ndarray (n_impacts, 2)
        Rows (omega * t, impulse / (m1 V0)) of the rigid wall's impacts (empty otherwise).

    Invalid parameters give NaN arrays and no impacts.
    """
    if not _valid(m, k, c, kc, max_events):
        nan = np.full((times.size, max(m.size, 1)), math.nan)
        return nan, nan.copy(), np.full(times.size, math.nan), np.empty((0, 2))
    ms, ks, cs, kcs = _normalise(m, k, c, kc)
    if ks[0] / kcs < BETA_RIGID:
        kcs = math.inf  # the rigid limit (see BETA_RIGID)
    return _sample(ms, ks, cs, kcs, times, max_events)


@njit(cache=True)
def sample_chain_state(m, k, c, kc, y0, times, max_events):
    """``sample_chain`` from the initial state y0 (as ``solve_chain_state``; times >= 0)."""
    if not _valid(m, k, c, kc, max_events) or not _valid_state(m, y0):
        nan = np.full((times.size, max(m.size, 1)), math.nan)
        return nan, nan.copy(), np.full(times.size, math.nan), np.empty((0, 2))
    ms, ks, cs, kcs = _normalise(m, k, c, kc)
    ys = _normalise_state(m, k, y0)
    if ks[0] / kcs < BETA_RIGID:
        kcs = math.inf  # the rigid limit (see BETA_RIGID)
    return _sample(ms, ks, cs, kcs, times, max_events, ys)
