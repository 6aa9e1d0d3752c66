"""Integrators written once for any chain and any force law: velocity Verlet and DOP853, the
8th-order Runge-Kutta method of Dormand and Prince with its 7th-order dense output.

A chain is its masses ``m[n]`` (m[0] at the wall), one link law per neighbouring pair (rows of
``lk``, each a ``structure_params`` array), dashpots ``c[n-1]``, the contact law ``cp`` and its
mutable memory ``mem``. The force laws enter only through these packed parameters: ``rhs`` /
``accel_verlet`` below dispatch on the law codes of ``restitution.model.laws``, so any law added
there is integrated by the same code. (Passing the law as a numba function argument would defeat
numba's on-disk cache: a minute of compilation per process.) Two masses are the chain n = 2;
there is no separate two-mass stack.

State y = [u_1..u_n, v_1..v_n, W, D] (length 2n + 2): lab-frame displacements and velocities,
W = integral of the contact force times d(penetration) (work done on the contact), D = dashpot
loss. mem = [phase, branch, xmax, fmax, xp, spare...]: phase 1 = in contact, branch 1 =
loading/rising, xmax/fmax the largest penetration and force so far (plastic), xp the residual
dent (m1 touches iff x = -u1 > xp).

Step control (``dp_step``): Hairer's error estimator, the 5th-order difference corrected by the
3rd-order one, per component against atol + rtol |y_i|, the largest component (not the RMS).

Event location. Every event of these scenes is a *linear* functional g(y) = w.y + b of the
state (a penetration, a velocity), so on an accepted step g along the dense output is a
polynomial of degree 7 in theta in [0, 1]. Its first root is found with certainty by Bernstein
bounds (convex-hull property: all Bernstein coefficients > 0 => no root) and left-first
subdivision, not by endpoint signs: a shallow contact or a reload past the previous maximum that
enters and leaves within one step is found. An event that starts the phase at g = 0 (leaving the
surface) is handled exactly by dividing out the zero leading coefficients (theta**k): the linear
coefficient is h w.f(y0) itself. The state at the event is then computed by a step of its own
to the root, with one Newton correction of the time (g / g') on that state, so it carries the
step's 8th order, not the interpolant's 7th (a Newton step below 1e-6 of the step is applied by
the state's Taylor series instead of a second step). A step on which no event can trigger skips
the dense output (its three extra stages) and the search: every g_k positive at both ends by
more than 2 h times the largest |g_k'| over the step's 13 stages (``events_excluded``; the ends
of a held scissor branch likewise, ``branches_excluded``).

Non-smooth points. A contact on the power law F = kappa x**eta from x = 0 (Hertz's x**1.5 at
both ends of every contact; the plastic law's first loading) makes y(t) a series in powers
t**(eta + 2), ... that no step across t = 0 resolves at its order. Those stretches are integrated
in sigma = sqrt(x) instead (``rhs_sigma``, ``sigma_phase``), where x = sigma**2 exactly and the
motion is smooth for half-integer eta (for other eta the force sigma**(2 eta) is smoother than in
t but not smooth: the step that starts or ends at sigma = 0 is then sized by its singular term,
``sigma_end_zone``): the exit ends exactly at sigma = 0, so the separation needs no event
location at all.
"""

from __future__ import annotations

import math

import numpy as np

from restitution.jit import njit
from restitution.kernels import dop853_tableau as T
from restitution.kernels.copies import copy_into, copy_row, fill_2d
from restitution.kernels.dop853_sums import dense_rows, solution, stage_state
from restitution.kernels.roots import first_root
from restitution.model.laws import (
    C_PLASTIC,
    C_RIGID,
    S_LINEAR,
    S_SCISSOR,
    SP_K2,
    SP_KIND,
    contact_force,
    contact_hysteretic,
    scissor_branch,
    scissor_force_on,
    scissor_point,
    structure_energy,
    structure_extent,
    structure_force,
)

# DOP853 (kernels/dop853_tableau.py): 12 stages, the 13th is f at the new point (FSAL), 3 more
# for the dense output; its weighted stage sums written out in kernels/dop853_sums.py.
DP_C = T.C
DP_E3 = T.E3
DP_E5 = T.E5
N_ST = T.N_STAGES  # 12
N_EXT = T.N_STAGES_EXTENDED  # 16
N_DENSE = T.INTERPOLATOR_POWER  # 7 = the dense output's degree in theta
# The dense output is y0 + sum_k F_k b_k(theta) with the basis of
# (scipy's Dop853DenseOutput): b_k = theta**(k//2 + 1) (1 - theta)**((k + 1)//2);
# DENSE_MONO[k, j] is the coefficient of theta**j in b_k.
DENSE_MONO = np.zeros((N_DENSE, N_DENSE + 1))
for _k in range(N_DENSE):
    _p = np.zeros(N_DENSE + 1)
    _p[_k // 2 + 1] = 1.0
    for _ in range((_k + 1) // 2):
        _p[1:] = _p[1:] - _p[:-1]
    DENSE_MONO[_k] = _p
del _k, _p

M_PHASE, M_BRANCH, M_XMAX, M_FMAX, M_XP = 0, 1, 2, 3, 4
N_MEM = 8


@njit(cache=True, error_model="numpy", refcount=False)
def dent(cp, mem):
    if cp[0] == C_PLASTIC and mem[M_FMAX] > 0.0:
        return mem[M_XMAX] - mem[M_FMAX] / cp[1]
    return 0.0


# rk_phase return codes
EV_STOP = -1  # the stop test passed (e.g. no further contact possible)
EV_FAIL = -2  # step size underflow or step budget exhausted
# rk_phase stop tests
STOP_NEVER = 0
STOP_NO_CONTACT = 1


@njit(cache=True, error_model="numpy", refcount=False)
def dense_from_stages(y0, ynew, K, h, F):
    """F of the dense output from a step's 16 stages K (in time or in sigma)."""
    n = y0.shape[0]
    for i in range(n):
        dy = ynew[i] - y0[i]
        F[0, i] = dy
        F[1, i] = h * K[0, i] - dy
        F[2, i] = 2.0 * dy - h * (K[N_ST, i] + K[0, i])
    dense_rows(K, h, F)


@njit(cache=True, error_model="numpy", refcount=False)
def dense_coeffs(y0, ynew, K, h, m, lk, c, cp, mem, F, tmp):
    """The 7th-order dense output of an accepted step (scipy's DOP853._dense_output_impl): the
    three extra stages into K[13:16], then F (7 x len(y)) with y(theta) = y0 + sum_k F_k b_k."""
    n = y0.shape[0]
    for s in range(N_ST + 1, N_EXT):
        stage_state(y0, K, h, s, tmp)
        rhs(tmp, m, lk, c, cp, mem, F[0])  # F[0] as scratch (a row view once per stage)
        for i in range(n):
            K[s, i] = F[0, i]
    dense_from_stages(y0, ynew, K, h, F)


@njit(cache=True, error_model="numpy", refcount=False)
def event_poly(F, K, h, y0, W, e, b, coef):
    """Monomial coefficients (degree 7 in theta) of w.y(theta) + b along the dense output, w the
    event's row e of W (an index, not a row view: kernels/copies.py). The linear one is
    h w.f(y0) directly (not F_0 + F_1 after rounding), so an event that starts on its own surface
    with zero slope has an exactly zero coefficient there."""
    n = y0.shape[0]
    g0 = b
    for i in range(n):
        g0 += W[e, i] * y0[i]
    for j in range(N_DENSE + 1):
        coef[j] = 0.0
    coef[0] = g0
    for k in range(N_DENSE):
        gk = 0.0
        for i in range(n):
            gk += W[e, i] * F[k, i]
        for j in range(2, N_DENSE + 1):
            coef[j] += DENSE_MONO[k, j] * gk
    slope = 0.0
    for i in range(n):
        slope += W[e, i] * K[0, i]
    coef[1] = h * slope


# An accepted step skips its dense output and root search when no event can trigger on it: every
# g_k positive at both ends with min(g_0, g_1) > EXCLUDE_MARGIN * h * (the largest |g_k'| over
# the step's 13 stages). g stays positive over the step if its true largest rate R is below
# (g_0 + g_1) / h, i.e. within 2 * EXCLUDE_MARGIN = 4 times the sampled one: the stages sample
# [0, h] at gaps of at most 0.27 h, on a step accurate to rtol.
EXCLUDE_MARGIN = 2.0


@njit(cache=True, error_model="numpy", refcount=False)
def events_excluded(K, h, y, ynew, W, B, nev):
    """True when no event g_k = W[k].y + B[k] (k < nev) can trigger on the accepted step from y
    to ynew (stages K[0:13]): see EXCLUDE_MARGIN. False for NaN and for an event on its surface."""
    n = y.shape[0]
    for k in range(nev):
        g0 = B[k]
        g1 = B[k]
        for i in range(n):
            g0 += W[k, i] * y[i]
            g1 += W[k, i] * ynew[i]
        if not (g0 > 0.0 and g1 > 0.0):
            return False
        rate = 0.0
        for s in range(N_ST + 1):
            r = 0.0
            for i in range(n):
                r += W[k, i] * K[s, i]
            rate = max(rate, abs(r))
        if not (min(g0, g1) > EXCLUDE_MARGIN * abs(h) * rate):
            return False
    return True


@njit(cache=True, error_model="numpy", refcount=False)
def dense_state(y0, F, theta, out):
    """y(theta) on the dense output (scipy's Dop853DenseOutput: nested theta, 1 - theta)."""
    n = y0.shape[0]
    for i in range(n):
        acc = 0.0
        for k in range(N_DENSE - 1, -1, -1):
            acc += F[k, i]
            acc *= theta if k % 2 == 0 else 1.0 - theta
        out[i] = y0[i] + acc


@njit(cache=True, error_model="numpy", refcount=False)
def link_force(sp, x, mem, i):
    """Force of the nonlinear link i: on the branch that ``rk_phase`` holds it on
    (mem[N_MEM + i], see "Link branch points" below), else on the branch x is on."""
    if mem.shape[0] > N_MEM:
        return scissor_force_on(sp, x, int(mem[N_MEM + i]))
    return structure_force(sp, x)


@njit(cache=True, error_model="numpy", refcount=False)
def rhs(y, m, lk, c, cp, mem, dy):
    """Equations of motion of the chain with the current contact branch."""
    n = m.shape[0]
    for i in range(n):
        dy[i] = y[n + i]
        dy[n + i] = 0.0
    fc = 0.0
    if mem[M_PHASE] == 1.0:
        fc = contact_force(cp, int(mem[M_BRANCH]), mem[M_XMAX], mem[M_FMAX], -y[0], -y[n])
    dy[n] = fc
    d = 0.0
    for i in range(n - 1):
        x = y[i + 1] - y[i]
        # a linear link inline: the row view lk[i] costs a reference count (half of rhs's time)
        f = lk[i, SP_K2] * x if lk[i, SP_KIND] == S_LINEAR else link_force(lk[i], x, mem, i)
        dv = y[n + i + 1] - y[n + i]
        fd = c[i] * dv
        dy[n + i] += f + fd
        dy[n + i + 1] -= f + fd
        d += fd * dv
    for i in range(n):
        dy[n + i] /= m[i]
    dy[2 * n] = -fc * y[n]
    dy[2 * n + 1] = d


@njit(cache=True, error_model="numpy", refcount=False)
def rhs_sigma(sg, z, m, lk, c, cp, mem, dz):
    """Equations of motion over sigma = sqrt(x) (x = -u1 the penetration) instead of time, for
    the ends of a power-law contact: z = [y, t], dz = dz/dsigma = f(y) dt/dsigma with
    dt/dsigma = 2 sigma / x'. Near x = 0 the force k x**eta makes y(t) a series in powers
    t**(eta + 2), t**(2 eta + 2), ... (Hertz: t**3.5), which no Runge-Kutta step across it
    resolves at its order; in sigma, x = sigma**2 exactly, the Hertz force is k sigma**3 and the
    motion is smooth (for any half-integer eta). z[0] is set to -sigma**2 (u1 is not integrated,
    its rate -2 sigma is exact); valid while x' stays away from zero (``sigma_phase`` checks)."""
    nm = m.shape[0]
    ny = 2 * nm + 2
    z[0] = -sg * sg
    rhs(z, m, lk, c, cp, mem, dz)
    dtds = 2.0 * sg / (-z[nm])
    for i in range(ny):
        dz[i] *= dtds
    dz[0] = -2.0 * sg
    dz[ny] = dtds


@njit(cache=True, error_model="numpy", refcount=False)
def dp_step(y, f0, h, rtol, atol, m, lk, c, cp, mem, K, ynew, tmp, sig=False, s0=0.0):
    """One DOP853 step from y (with f0 = f(y)); fills K[0:13] (K[12] = f(ynew)) and ynew;
    returns the error norm of Hairer's estimator (the 5th-order difference, corrected by the
    3rd-order one to the size of the 8th-order error: err5**2 / sqrt(err5**2 + 0.01 err3**2)),
    the largest over the components.
    ``sig``: the state is [y, t] over the independent variable sigma = sqrt(x) from s0
    (``rhs_sigma``)."""
    n = y.shape[0]
    for i in range(n):
        K[0, i] = f0[i]
    for s in range(1, N_ST):
        stage_state(y, K, h, s, tmp)
        # into ynew (free until the end) and copied: a row view K[s] costs a reference count
        if sig:
            rhs_sigma(s0 + DP_C[s] * h, tmp, m, lk, c, cp, mem, ynew)
        else:
            rhs(tmp, m, lk, c, cp, mem, ynew)
        for i in range(n):
            K[s, i] = ynew[i]
    solution(y, K, h, ynew)
    if sig:
        rhs_sigma(s0 + h, ynew, m, lk, c, cp, mem, tmp)
    else:
        rhs(ynew, m, lk, c, cp, mem, tmp)
    for i in range(n):
        K[N_ST, i] = tmp[i]
    # Per component, the largest, not Hairer's RMS over all of them: with the energy and time
    # components (errors ~0) in the mean, the velocities were allowed sqrt(n) times their share
    # (single Hertz contacts 10-100 rtol off; with the largest, below rtol).
    # A NaN or infinite component is a failed step (NaN), not a skipped one: a scissor link held
    # on its bars' formula far past the tension cap (where that formula ends at the flat bars)
    # overflows, and a NaN skipped here had been accepted as an exact step.
    worst = 0.0
    finite = True
    for i in range(n):
        a5 = 0.0
        a3 = 0.0
        for j in range(N_ST + 1):
            a5 += DP_E5[j] * K[j, i]
            a3 += DP_E3[j] * K[j, i]
        sc = atol + rtol * max(abs(y[i]), abs(ynew[i]))
        q5 = (a5 / sc) ** 2
        q3 = (a3 / sc) ** 2
        if q5 > 0.0 and q5 < math.inf:
            worst = max(worst, q5 / math.sqrt(q5 + 0.01 * q3))
        elif not q5 == 0.0:
            finite = False
    return abs(h) * worst if finite else math.nan


@njit(cache=True, error_model="numpy", refcount=False)
def _momentum_error(K, h, m):
    """Hairer's corrected local error estimate of the total momentum over the step."""
    nm = m.shape[0]
    a5 = 0.0
    a3 = 0.0
    for j in range(N_ST + 1):
        mom = 0.0
        for i in range(nm):
            mom += m[i] * K[j, nm + i]
        a5 += DP_E5[j] * mom
        a3 += DP_E3[j] * mom
    if a5 == 0.0:
        return 0.0
    return abs(h) * a5 * a5 / math.sqrt(a5 * a5 + 0.01 * a3 * a3)


@njit(cache=True, error_model="numpy", refcount=False)
def internal_energy(y, m, lk):
    """Energy of the motion relative to the centre of mass: relative kinetic + link potentials."""
    n = m.shape[0]
    mt = 0.0
    p = 0.0
    ek = 0.0
    for i in range(n):
        mt += m[i]
        p += m[i] * y[n + i]
        ek += 0.5 * m[i] * y[n + i] * y[n + i]
    e = ek - 0.5 * p * p / mt
    for i in range(n - 1):
        e += structure_energy(lk[i], y[i + 1] - y[i])
    return max(e, 0.0)


# no_contact_possible's extents: found for 1 + 1e-4 times the energy, kept while the energy is
# within 1e-3 below that (the free flight's energy moves by the integration error, or falls
# through the dashpots); a bound up to about 5e-4 wider than the exact one.
EXTENT_PAD = 1.0 + 1e-4
EXTENT_REUSE = 1.0 - 1e-3


@njit(cache=True, error_model="numpy", refcount=False)
def no_contact_possible(y, m, lk, xp, ext):
    """True when m1 provably never reaches the contact surface u1 = -xp again (free flight).

    The centre of mass X moves at the constant V (no wall force). m1 trails it by
    X - u1 = sum_i mu_i r_i (r_i = u_{i+1} - u_i, mu_i = mass beyond link i / total mass), and the
    internal energy E (relative kinetic + link potentials) never grows in free flight (dashpots
    only dissipate), so every r_i stays within U_i(r_i) <= E. Linear links together: by
    Cauchy-Schwarz sum mu_i r_i <= sqrt(2 E sum mu_i**2/k_i); any other link: mu_i times its
    extent at energy E. With V > 0, X + xp - that bound > 0 now stays > 0 for ever.

    ``ext`` (n - 1 x 2, first column < 0 on entry to a phase) keeps each nonlinear link's extent
    between calls: a bisection of about 50 evaluations of its energy, a third of a scissor
    scene's time when made after every step. It is found for the energy EXTENT_PAD above E and
    reused while E stays within EXTENT_REUSE below that: the extent grows with the energy, so the
    bound stays an upper bound (the proof may come a step later, never wrongly).
    """
    n = m.shape[0]
    mt = 0.0
    p = 0.0
    q = 0.0
    for i in range(n):
        mt += m[i]
        p += m[i] * y[n + i]
        q += m[i] * y[i]
    if p <= 0.0:
        return False
    e = internal_energy(y, m, lk)
    beyond = mt
    lin = 0.0
    bound = 0.0
    for i in range(n - 1):
        beyond -= m[i]
        mu = beyond / mt
        if lk[i, 0] == 0.0:  # S_LINEAR
            lin += mu * mu / lk[i, 1]
        else:
            if not (e <= ext[i, 0] and e >= EXTENT_REUSE * ext[i, 0]):
                ext[i, 0] = e * EXTENT_PAD
                ext[i, 1] = structure_extent(lk[i], ext[i, 0], 1.0)
            bound += mu * ext[i, 1]
    bound += math.sqrt(2.0 * e * lin)
    return q / mt + xp - bound > 0.0


# ------------------------------------------------------------------------ link branch points --
# The scissor law is C1 but not C2 where its branches meet (laws.SB_*: the pads' cap, the lock,
# the tension cap): a step across such a point loses its order, and the step control paid for it
# with rejected, shrinking steps. ``rk_phase`` therefore holds every scissor link on one branch's
# formula for whole steps (mem extended by one entry per link, read by ``link_force``; each
# formula is analytic across its ends), finds on each accepted step the first theta where a link
# reaches an end of its branch (x_i(theta) on the dense output, the same certified root finder as
# the contact events), steps to it as to an event and goes on from there on the next branch. The
# sigma stretches at a power-law contact's ends (``sigma_phase``) do the same on their dense output
# in sigma (a point there had been stepped across). The callers see none of it; a scene without
# scissor links runs the same arithmetic as before.


@njit(cache=True, error_model="numpy")
def branch_mem(y, m, lk, mem, bstrip):
    """mem extended by the branch of every scissor link (-1 for the others), or mem itself when
    there is none. A link exactly on a point takes the branch its x moves into; bstrip[i, 0] /
    bstrip[i, 1] = 1 marks a link that starts on its branch's lower / upper end (its event's
    leading zero is exact, as ``rk_phase``'s ``strip``)."""
    nm = m.shape[0]
    mb = np.empty(N_MEM + nm - 1)
    return mb if branch_mem_into(y, m, lk, mem, bstrip, mb) else mem


@njit(cache=True, error_model="numpy", refcount=False)
def branch_mem_into(y, m, lk, mem, bstrip, mb):
    """``branch_mem`` into the given mb (N_MEM + N - 1 entries); returns whether a link is a
    scissor (else mb is left alone and the caller uses mem itself)."""
    nm = m.shape[0]
    held = False
    for i in range(nm - 1):
        held = held or lk[i, SP_KIND] == S_SCISSOR
    if not held:
        return False
    for i in range(mb.shape[0]):
        mb[i] = mem[i] if i < N_MEM else -1.0
    for i in range(nm - 1):
        bstrip[i, 0] = 0
        bstrip[i, 1] = 0
        if lk[i, SP_KIND] != S_SCISSOR:
            continue
        x = y[i + 1] - y[i]
        br = scissor_branch(lk[i], x)
        if x == scissor_point(lk[i], br - 1) and y[nm + i + 1] - y[nm + i] < 0.0:
            br -= 1
        mb[N_MEM + i] = br
        bstrip[i, 0] = 1 if x == scissor_point(lk[i], br - 1) else 0
        bstrip[i, 1] = 1 if x == scissor_point(lk[i], br) else 0
    return True


@njit(cache=True, error_model="numpy", refcount=False)
def link_poly(F, K, h, y, i, coef):
    """``event_poly`` of the extension x_i = y[i + 1] - y[i] (linear coefficient h x_i')."""
    for j in range(N_DENSE + 1):
        coef[j] = 0.0
    coef[0] = y[i + 1] - y[i]
    for k in range(N_DENSE):
        gk = F[k, i + 1] - F[k, i]
        for j in range(2, N_DENSE + 1):
            coef[j] += DENSE_MONO[k, j] * gk
    coef[1] = h * (K[0, i + 1] - K[0, i])


@njit(cache=True, error_model="numpy", refcount=False)
def first_branch_root(F, K, h, y, m, lk, mb, bstrip, coef, g, rs):
    """First theta in [0, 1] of the step where a scissor link reaches an end of the branch it is
    held on: (theta, link, +1 up / -1 down); theta = -1 when none."""
    nm = m.shape[0]
    best = 2.0
    link = -1
    side = 0
    for i in range(nm - 1):
        if lk[i, SP_KIND] != S_SCISSOR:
            continue
        br = int(mb[N_MEM + i])
        link_poly(F, K, h, y, i, coef)
        for e in range(2):
            p = scissor_point(lk[i], br - 1 + e)
            if not abs(p) < math.inf:
                continue
            sg = 1.0 - 2.0 * e  # lower end: x - p falls to 0; upper end: p - x does
            for j in range(N_DENSE + 1):
                g[j] = sg * coef[j]
            g[0] -= sg * p
            s = 0
            if bstrip[i, e] > 0:
                g[0] = 0.0
                s = 1
                while s < N_DENSE and g[s] == 0.0:
                    s += 1
            th = first_root(g, N_DENSE, s, rs)
            if th >= 0.0 and th < best:
                best, link, side = th, i, 2 * e - 1
    return (best if link >= 0 else -1.0), link, side


@njit(cache=True, error_model="numpy", refcount=False)
def branches_excluded(K, h, y, ynew, m, lk, mb):
    """True when no scissor link can reach an end of the branch it is held on during the
    accepted step from y to ynew: ``events_excluded``'s rate test on each extension against
    each finite end of its branch (False for a link on an end)."""
    nm = m.shape[0]
    for i in range(nm - 1):
        if lk[i, SP_KIND] != S_SCISSOR:
            continue
        x0 = y[i + 1] - y[i]
        x1 = ynew[i + 1] - ynew[i]
        rate = 0.0
        for s in range(N_ST + 1):
            rate = max(rate, abs(K[s, i + 1] - K[s, i]))
        margin = EXCLUDE_MARGIN * abs(h) * rate
        br = int(mb[N_MEM + i])
        lo = scissor_point(lk[i], br - 1)
        hi = scissor_point(lk[i], br)
        if abs(lo) < math.inf and not (min(x0, x1) - lo > margin):
            return False
        if abs(hi) < math.inf and not (hi - max(x0, x1) > margin):
            return False
    return True


@njit(cache=True, error_model="numpy", refcount=False)
def step_to_point(y, f0, dt, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp, i, p, work, sig=False,
                  s0=0.0):  # fmt: skip
    """``rk_phase``'s step to an event, for link i reaching x_i = p: a step of its own and one
    Newton correction of its length on that state; ynew is the state there. Returns the length.
    ``sig``: a step in sigma from s0 (``sigma_phase``; dt < 0 at a contact's exit)."""
    for it in range(2):
        work[0] -= 12.0
        dp_step(y, f0, dt, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp, sig, s0)
        if it == 1:
            break
        step = -(ynew[i + 1] - ynew[i] - p) / (K[N_ST, i + 1] - K[N_ST, i])
        if not (abs(step) < 0.01 * abs(dt) and abs(step) > 1e-15 * abs(dt)):
            break
        dt += step
    return dt


@njit(cache=True, error_model="numpy", refcount=False)
def branch_switch(mb, bstrip, i, side):
    """Link i goes on to the branch beyond the end it reached (side +1 up, -1 down), starting on
    that branch's lower / upper end; no other link starts on a point."""
    for k in range(bstrip.shape[0]):
        bstrip[k, 0] = 0
        bstrip[k, 1] = 0
    mb[N_MEM + i] += side
    bstrip[i, 0 if side > 0 else 1] = 1


# A Newton correction of an event time below NEWTON_TAYLOR of the step is applied to the state by
# its Taylor series to second order (y'' from the step's end slopes) instead of a second step:
# the neglected terms, ~ step**2 dt |y(3)| / 2, are below 1e-12 dt**3 |y(3)| there.
NEWTON_TAYLOR = 1e-6


@njit(cache=True, error_model="numpy", inline="always")
def event_state(y, f0, dt, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp, W, e, b, work):
    """ynew = the state at the event g = w.y + b = 0 (w: row e of W) located at dt on the dense
    output: by a DOP853 step of its own and one Newton correction of the time (g / g') on that
    state, so the state carries the step's 8th order, not the dense output's 7th (the
    interpolant of a long step put event times off by ~1e-10 relative). Returns the corrected
    dt."""
    n = y.shape[0]
    work[0] -= 12.0
    dp_step(y, f0, dt, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp)
    g = b
    gd = 0.0
    for i in range(n):
        g += W[e, i] * ynew[i]
        gd += W[e, i] * K[N_ST, i]
    step = -g / gd
    if not (abs(step) < 0.01 * dt and abs(step) > 1e-15 * dt):
        return dt
    if abs(step) <= NEWTON_TAYLOR * dt:
        for i in range(n):
            acc = (K[N_ST, i] - K[0, i]) / dt
            ynew[i] += step * (K[N_ST, i] + 0.5 * step * acc)
        return dt + step
    dt += step
    work[0] -= 12.0
    dp_step(y, f0, dt, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp)
    return dt


@njit(cache=True, error_model="numpy")
def phase_space(n, nm):
    """The work arrays of ``rk_phase`` for a state of n entries and nm masses, allocated once per
    scene: (K, F, ynew, tmp, f0, coef, gb, rs, ext, bstrip, mb)."""
    return (
        np.empty((N_EXT, n)),
        np.empty((N_DENSE, n)),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(N_DENSE + 1),
        np.empty(N_DENSE + 1),
        np.empty(N_DENSE + 1),
        np.empty((max(nm - 1, 0), 2)),
        np.zeros((max(nm - 1, 0), 2), dtype=np.int64),
        np.empty(N_MEM + nm - 1),
    )


@njit(cache=True, error_model="numpy", refcount=False)
def rk_phase(
    y, t, h, hmax, rtol, atol, m, lk, c, cp, mem, W, B, strip, nev, stop, work, err_acc, ws
):  # fmt: skip
    """Integrate with DOP853 until the first event (or ``stop``); y is updated in place.

    W[k], B[k], strip[k] (k < nev) define the events g_k = W[k].y + B[k] (trigger: > 0 -> <= 0);
    ``strip`` applies to the first step only (leading zeros of an event that starts on its own
    surface). Returns (code, t, h_next) with code = event index, EV_STOP or EV_FAIL.
    stop = STOP_NO_CONTACT ends the phase when ``no_contact_possible`` after an accepted step.
    ``work[0]`` counts right-hand-side evaluations left for the whole scene (a budget in
    operations: results do not depend on the machine or thread count); EV_FAIL when it runs
    out or the step underflows.
    ``err_acc[0]`` accumulates the local error estimates of the total momentum.
    Scissor links stop at their branch points inside the phase ("Link branch points" above).
    ``ws``: the work arrays (``phase_space``), allocated once per scene, so that the phase
    allocates nothing and compiles without reference counts (each phase allocated 10 arrays
    and counted references to its array arguments: ~5 % of a plastic scene's run).
    """
    K, F, ynew, tmp, f0, coef, gb, rs, ext, bstrip, mbs = ws
    fill_2d(ext, -1.0)  # no_contact_possible's
    fill_2d(bstrip, 0)
    held = branch_mem_into(y, m, lk, mem, bstrip, mbs)
    mb = mbs if held else mem  # mem itself without scissor links
    still = 0  # branch switches in a row without a step (a guard against a link at rest on one)
    rhs(y, m, lk, c, cp, mb, f0)
    first = True
    while work[0] > 0.0:
        work[0] -= 12.0
        h = min(h, hmax)
        if not (h >= 1e-14 * max(1.0, abs(t)) and h < math.inf):  # also catches NaN
            return EV_FAIL, t, h
        err = dp_step(y, f0, h, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp)
        if not err <= 1.0:  # also catches NaN
            fac = 0.2 if not err == err else max(0.2, 0.9 * err**-0.125)
            h *= fac
            continue
        best = 2.0
        which = -1
        search = not events_excluded(K, h, y, ynew, W, B, nev) or (
            held and not branches_excluded(K, h, y, ynew, m, lk, mb)
        )
        if search:
            work[0] -= 3.0
            dense_coeffs(y, ynew, K, h, m, lk, c, cp, mb, F, tmp)
            for k in range(nev):
                event_poly(F, K, h, y, W, k, B[k], coef)
                s = 0
                if first and strip[k] > 0:
                    coef[0] = 0.0
                    s = strip[k]
                    while s < N_DENSE and coef[s] == 0.0:
                        s += 1
                th = first_root(coef, N_DENSE, s, rs)
                if th >= 0.0 and th < best:
                    best, which = th, k
        err_acc[0] += _momentum_error(K, h, m)
        hn = h * min(10.0, max(0.2, 0.9 * max(err, 1e-10) ** -0.125))
        if held and still < 2 and search:
            bt, bi, bs = first_branch_root(F, K, h, y, m, lk, mb, bstrip, coef, gb, rs)
            if bt >= 0.0 and bt < best:  # a branch point first: step to it, go on past it
                dt = bt * h
                p = scissor_point(lk[bi], int(mb[N_MEM + bi]) + (0 if bs > 0 else -1))
                if dt > 0.0:
                    dt = step_to_point(
                        y, f0, dt, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp, bi, p, work
                    )  # fmt: skip
                    copy_into(y, ynew)
                    t += dt
                    first = False
                    still = 0
                else:
                    still += 1
                branch_switch(mb, bstrip, bi, bs)
                rhs(y, m, lk, c, cp, mb, f0)
                h = hn
                continue
        if which >= 0:
            dt = best * h
            if dt > 0.0:
                dt = event_state(y, f0, dt, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp,
                                 W, which, B[which], work)  # fmt: skip
                copy_into(y, ynew)
            return which, t + dt, hn
        copy_into(y, ynew)
        copy_row(f0, K, N_ST)
        t += h
        h = hn
        first = False
        still = 0
        fill_2d(bstrip, 0)
        if stop == STOP_NO_CONTACT and no_contact_possible(y, m, lk, mem[M_XP], ext):
            return EV_STOP, t, h
    return EV_FAIL, t, h


# sigma_phase return codes
SIG_DONE = 0  # reached the target sigma
SIG_LEFT = 1  # x' fell below half its start value: the caller goes on in time
SIG_FAIL = 2  # step underflow or work budget


@njit(cache=True, error_model="numpy", refcount=False)
def sigma_end_zone(span, rtol, eta):
    """The length next to sigma = 0 that one step spans where the power law's force
    sigma**(2 eta) is not smooth there (2 eta not an integer), else 0.

    The motion then has a term in sigma**(2 eta + 2), and a DOP853 step that starts or ends at
    sigma = 0 has an error of the order of its length**(2 eta + 2) (relative to the stretch's
    change) that its own estimate does not see. So that step is |span| rtol**(1/(2 eta + 2))
    long: its error about rtol. The steps away from sigma = 0 are the controller's (the
    motion is analytic on each; the singular point off the step only makes the controller grade
    them). Until 2026-11-28 the first step was sized as in a smooth stretch (capped at 0.9 of
    the span): a run and its check at rtol/100 took nearly the same first step and shared its
    error (plastic, eta = 0.69, m2/m1 = 4e-4: 3.8e-7 off at rtol 1e-6, 1.06 times the estimate
    of the setting rtol 1e-4; 2.4e-10 with a first step of 0.01 of the span)."""
    if 2.0 * eta == math.floor(2.0 * eta):
        return 0.0
    return abs(span) * rtol ** (1.0 / (2.0 * eta + 2.0))


@njit(cache=True, error_model="numpy", refcount=False)
def sigma_first_step(span, rtol, eta, s0):
    """The first step of a sigma stretch from s0: span * min(0.25, 0.13 (rtol/1e-12)**(1/8)),
    and at most ``sigma_end_zone`` from a non-smooth sigma = 0. At a quarter of the span the
    first step's error norm was ~100 at rtol 1e-12 (Hertz contacts: a rejected step per
    stretch); DOP853's error grows like h**8, so this size lands near 0.5."""
    h = span * min(0.25, 0.13 * (rtol / 1e-12) ** 0.125)
    zone = sigma_end_zone(span, rtol, eta) if s0 == 0.0 else 0.0
    if zone > 0.0 and abs(h) > zone:
        h = math.copysign(zone, span)
    return h


@njit(cache=True, error_model="numpy", inline="always")
def sigma_last_step(h, s, s_b, zone):
    """(h, last): the step from s towards s_b, landing on s_b if it reaches it; towards a
    non-smooth s_b = 0 (``zone`` > 0) the step that would land there from farther than
    1.25 zone stops zone short of it, so the last step is zone long."""
    rest = s_b - s
    if abs(h) < abs(rest):
        return h, False
    if zone > 0.0 and abs(rest) > 1.25 * zone:
        return rest - math.copysign(zone, rest), False
    return rest, True


@njit(cache=True, error_model="numpy")
def sigma_phase(y, t, s_b, rtol, atol, m, lk, c, cp, mem, work, err_acc):
    """Integrate from the current penetration x = -y[0] > = 0 to x = s_b**2 in sigma = sqrt(x)
    (``rhs_sigma``) by DOP853, the last step landing on s_b exactly: the entry into a power-law
    contact (x = 0 -> s_b**2) or its exit (-> 0, the separation itself, no event to locate).
    Stops early (SIG_LEFT) when |x'| falls below half its start value, where dt/dsigma would
    grow without bound. y is updated in place; returns (code, t).
    Scissor links stop at their branch points inside the stretch as in ``rk_phase`` ("Link
    branch points" above), located on the dense output in sigma (``sigma_to_branch_point``)."""
    nm = m.shape[0]
    ny = y.shape[0]
    nz = ny + 1
    z = np.empty(nz)
    copy_into(z, y)
    z[ny] = 0.0
    s0 = math.sqrt(max(-y[0], 0.0))
    xd0 = -y[nm]
    if not (xd0 != 0.0 and s_b != s0):
        return SIG_LEFT, t
    K = np.empty((N_EXT, nz))
    F = np.empty((N_DENSE, nz))
    znew = np.empty(nz)
    tmp = np.empty(nz)
    f0 = np.empty(nz)
    coef = np.empty(N_DENSE + 1)
    gb = np.empty(N_DENSE + 1)
    rs = np.empty(N_DENSE + 1)  # first_root's scratch
    bstrip = np.zeros((max(nm - 1, 0), 2), dtype=np.int64)
    mb = branch_mem(z, m, lk, mem, bstrip)  # mem itself without scissor links
    held = mb.shape[0] > N_MEM
    still = 0  # branch switches in a row without a step (a guard against a link at rest on one)
    rhs_sigma(s0, z, m, lk, c, cp, mb, f0)
    span = s_b - s0
    h = sigma_first_step(span, rtol, cp[3], s0)  # (cp[3]: the power law's exponent)
    zone = sigma_end_zone(span, rtol, cp[3]) if s_b == 0.0 else 0.0
    s = s0
    code = SIG_FAIL
    while work[0] > 0.0:
        work[0] -= 12.0
        h, last = sigma_last_step(h, s, s_b, zone)
        if not (abs(h) >= 1e-14 * abs(span)):  # also catches NaN
            break
        err = dp_step(z, f0, h, rtol, atol, m, lk, c, cp, mb, K, znew, tmp, True, s)
        if not err <= 1.0:
            h *= 0.2 if not err == err else max(0.2, 0.9 * err**-0.125)
            continue
        err_acc[0] += _momentum_error(K, h, m)
        if held and still < 2 and not branches_excluded(K, h, z, znew, m, lk, mb):
            work[0] -= 3.0
            dense_coeffs_sigma(z, znew, K, h, s, m, lk, c, cp, mb, F, tmp)
            bt, bi, bs = first_branch_root(F, K, h, z, m, lk, mb, bstrip, coef, gb, rs)
            if bt >= 0.0:  # a branch point on this step: step to it, go on past it
                ds = sigma_to_branch_point(z, f0, bt * h, s, rtol, atol, m, lk, c, cp, mb, K,
                                           znew, tmp, bi, bs, work)  # fmt: skip
                still = 0 if ds != 0.0 else still + 1
                s = sigma_switch_branch(z, znew, f0, s, ds, m, lk, c, cp, mb, bstrip, bi, bs)
                h *= min(10.0, max(0.2, 0.9 * max(err, 1e-10) ** -0.125))
                continue
        copy_into(z, znew)
        copy_row(f0, K, N_ST)
        s = s_b if last else s + h
        if last:
            code = SIG_DONE
            break
        if not (-z[nm] * xd0 > 0.5 * xd0 * xd0):
            code = SIG_LEFT
            break
        h *= min(10.0, max(0.2, 0.9 * max(err, 1e-10) ** -0.125))
        still = 0
        fill_2d(bstrip, 0)
    if code != SIG_FAIL:
        copy_into(y, z)
        y[0] = -s * s
        t += z[ny]
    return code, t


@njit(cache=True, error_model="numpy", inline="always")
def sigma_to_branch_point(z, f0, ds, s, rtol, atol, m, lk, c, cp, mb, K, znew, tmp, i, side,
                          work):  # fmt: skip
    """znew = the state in sigma where link i reaches the end of its held branch (side +1 up,
    -1 down), ds along the accepted step from s (``step_to_point`` in sigma: a step of its own
    and a Newton correction). Returns the corrected ds (0 when the link starts on the point)."""
    if ds == 0.0:
        return 0.0
    p = scissor_point(lk[i], int(mb[N_MEM + i]) + (0 if side > 0 else -1))
    return step_to_point(z, f0, ds, rtol, atol, m, lk, c, cp, mb, K, znew, tmp, i, p, work, True,
                         s)  # fmt: skip


@njit(cache=True, error_model="numpy", inline="always")
def sigma_switch_branch(z, znew, f0, s, ds, m, lk, c, cp, mb, bstrip, i, side):
    """Go on from the branch point (znew at s + ds, or z itself when ds = 0) on link i's next
    branch; returns the new sigma."""
    if ds != 0.0:
        for k in range(z.shape[0]):  # not z[:] = znew: an array assignment needs numba's NRT
            z[k] = znew[k]
        s += ds
    branch_switch(mb, bstrip, i, side)
    rhs_sigma(s, z, m, lk, c, cp, mb, f0)
    return s


@njit(cache=True, error_model="numpy", refcount=False)
def accel_verlet(y, m, lk, c, cp, mem, acc):
    """Accelerations (acc[:n]) for Verlet with the path-following contact law; returns
    (contact force, dashpot power)."""
    n = m.shape[0]
    fc = 0.0
    if cp[0] != C_RIGID:
        fc, xm, fm = contact_hysteretic(cp, mem[M_XMAX], mem[M_FMAX], -y[0], -y[n])
        mem[M_XMAX], mem[M_FMAX] = xm, fm
    for i in range(n):
        acc[i] = 0.0
    acc[0] = fc
    pw = 0.0
    for i in range(n - 1):
        x = y[i + 1] - y[i]
        # a linear link inline: the row view lk[i] costs a reference count (half of rhs's time)
        f = lk[i, SP_K2] * x if lk[i, SP_KIND] == S_LINEAR else structure_force(lk[i], x)
        dv = y[n + i + 1] - y[n + i]
        fd = c[i] * dv
        acc[i] += f + fd
        acc[i + 1] -= f + fd
        pw += fd * dv
    for i in range(n):
        acc[i] /= m[i]
    return fc, pw


@njit(cache=True, error_model="numpy")
def verlet_step(y, acc, h, m, lk, c, cp, mem, damped):
    """One velocity-Verlet step; acc has n + 2 entries (accelerations, contact force, dashpot
    power) and enters with a(y), leaves with a(y_new). With a dashpot (``damped``) the new
    acceleration depends on the new velocity: it is evaluated at the predictor v + h*a, then once
    more at the corrected velocity (a fixed-point pass, which keeps the scheme second order).
    W (contact work) and D (dashpot loss) use the trapezoidal rule."""
    n = m.shape[0]
    x_old = -y[0]
    f_old = acc[n]
    p_old = acc[n + 1]
    for i in range(n):
        vh = y[n + i] + 0.5 * h * acc[i]
        y[i] += h * vh
        y[n + i] = vh
    vhalf = y[n : 2 * n].copy()
    for i in range(n):
        y[n + i] = vhalf[i] + 0.5 * h * acc[i]
    fc, pw = accel_verlet(y, m, lk, c, cp, mem, acc)
    for i in range(n):
        y[n + i] = vhalf[i] + 0.5 * h * acc[i]
    if damped:
        fc, pw = accel_verlet(y, m, lk, c, cp, mem, acc)
        for i in range(n):
            y[n + i] = vhalf[i] + 0.5 * h * acc[i]
    y[2 * n] += 0.5 * (f_old + fc) * (-y[0] - x_old)
    y[2 * n + 1] += 0.5 * h * (p_old + pw)
    acc[n] = fc
    acc[n + 1] = pw


# ------------------------------------------------------------------------ sampled variants --
# The trajectory sampler (``stepping.sample_scene``) runs the same steps as ``rk_phase`` and
# ``sigma_phase`` and also evaluates the state at requested times: copies of the two loops with
# the sampling added, so that the solver's own path is left exactly as it is (``solve`` results
# bit-identical, its compile unchanged). Samples are sorted times ts, a cursor si[0] (the next
# one to fill), the states Ys[i] and the contact forces Fs[i].
STOP_SAMPLES = 2  # rk_phase_sampled: end once every sample is filled (no events)


@njit(cache=True, error_model="numpy", refcount=False)
def sample_force(cp, mem, x, xdot):
    """The contact law's force on m1 at penetration x and its rate xdot with the current branch
    (0 off contact or at a rigid wall; the smooth continuation past the surface clipped at 0)."""
    if mem[M_PHASE] != 1.0 or cp[0] == C_RIGID:
        return 0.0
    return max(contact_force(cp, int(mem[M_BRANCH]), mem[M_XMAX], mem[M_FMAX], x, xdot), 0.0)


@njit(cache=True, error_model="numpy", refcount=False)
def sample_here(y, t, cp, mem, ts, si, Ys, Fs):
    """Fill the samples at times <= t with the state y (at time t)."""
    n = y.shape[0]
    nm = (Ys.shape[1] - 2) // 2  # the state is [u, v, energies]: v1 = y[nm]
    while si[0] < ts.shape[0] and ts[si[0]] <= t:
        k = si[0]
        for i in range(n):
            Ys[k, i] = y[i]
        Fs[k] = sample_force(cp, mem, -y[0], -y[nm])
        si[0] += 1


@njit(cache=True, error_model="numpy", refcount=False)
def sample_dense(y0, F, t0, h, t_hi, closed, cp, mem, ts, si, Ys, Fs):
    """Fill the samples in (t0, t_hi] (``closed``) or (t0, t_hi) from the dense output (y0, F)
    of a step of length h from t0."""
    while si[0] < ts.shape[0]:
        k = si[0]
        tk = ts[k]
        if tk > t_hi or (tk == t_hi and not closed):
            break
        dense_state(y0, F, (tk - t0) / h, Ys[k])
        nm = (Ys.shape[1] - 2) // 2
        Fs[k] = sample_force(cp, mem, -Ys[k, 0], -Ys[k, nm])
        si[0] += 1


@njit(cache=True, error_model="numpy")
def rk_phase_sampled(
    y, t, h, hmax, rtol, atol, m, lk, c, cp, mem, W, B, strip, nev, stop, work, err_acc,
    ts, si, Ys, Fs,
):  # fmt: skip
    """``rk_phase`` (the same steps, the same arithmetic) that also fills the samples up to the
    phase's end from the dense output of each accepted step: those in (t, t + h] of a step, those
    before the event of the step that ends the phase. ``stop`` = STOP_SAMPLES ends the phase
    (EV_STOP) once every sample is filled."""
    n = y.shape[0]
    K = np.empty((N_EXT, n))
    F = np.empty((N_DENSE, n))
    ynew = np.empty(n)
    tmp = np.empty(n)
    f0 = np.empty(n)
    coef = np.empty(N_DENSE + 1)
    gb = np.empty(N_DENSE + 1)
    rs = np.empty(N_DENSE + 1)  # first_root's scratch
    ext = np.full((max(m.shape[0] - 1, 0), 2), -1.0)  # no_contact_possible's
    sample_here(y, t, cp, mem, ts, si, Ys, Fs)
    if stop == STOP_SAMPLES and si[0] >= ts.shape[0]:
        return EV_STOP, t, h
    bstrip = np.zeros((max(m.shape[0] - 1, 0), 2), dtype=np.int64)
    mb = branch_mem(y, m, lk, mem, bstrip)
    held = mb.shape[0] > N_MEM
    still = 0
    rhs(y, m, lk, c, cp, mb, f0)
    first = True
    while work[0] > 0.0:
        work[0] -= 12.0
        h = min(h, hmax)
        if not (h >= 1e-14 * max(1.0, abs(t)) and h < math.inf):  # also catches NaN
            return EV_FAIL, t, h
        err = dp_step(y, f0, h, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp)
        if not err <= 1.0:  # also catches NaN
            fac = 0.2 if not err == err else max(0.2, 0.9 * err**-0.125)
            h *= fac
            continue
        best = 2.0
        which = -1
        search = not events_excluded(K, h, y, ynew, W, B, nev) or (
            held and not branches_excluded(K, h, y, ynew, m, lk, mb)
        )
        if search:  # the work rk_phase counts (the samples need the dense output anyway)
            work[0] -= 3.0
        dense_coeffs(y, ynew, K, h, m, lk, c, cp, mb, F, tmp)
        for k in range(nev if search else 0):
            event_poly(F, K, h, y, W, k, B[k], coef)
            s = 0
            if first and strip[k] > 0:
                coef[0] = 0.0
                s = strip[k]
                while s < N_DENSE and coef[s] == 0.0:
                    s += 1
            th = first_root(coef, N_DENSE, s, rs)
            if th >= 0.0 and th < best:
                best, which = th, k
        err_acc[0] += _momentum_error(K, h, m)
        hn = h * min(10.0, max(0.2, 0.9 * max(err, 1e-10) ** -0.125))
        if held and still < 2 and search:
            bt, bi, bs = first_branch_root(F, K, h, y, m, lk, mb, bstrip, coef, gb, rs)
            if bt >= 0.0 and bt < best:
                dt = bt * h
                p = scissor_point(lk[bi], int(mb[N_MEM + bi]) + (0 if bs > 0 else -1))
                if dt > 0.0:
                    dt = step_to_point(
                        y, f0, dt, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp, bi, p, work
                    )  # fmt: skip
                    # F is still the dense output of the whole step from y
                    sample_dense(y, F, t, h, t + dt, True, cp, mem, ts, si, Ys, Fs)
                    copy_into(y, ynew)
                    t += dt
                    first = False
                    still = 0
                else:
                    still += 1
                branch_switch(mb, bstrip, bi, bs)
                rhs(y, m, lk, c, cp, mb, f0)
                h = hn
                if stop == STOP_SAMPLES and si[0] >= ts.shape[0]:
                    return EV_STOP, t, h
                continue
        if which >= 0:
            dt = best * h
            if dt > 0.0:
                dt = event_state(y, f0, dt, rtol, atol, m, lk, c, cp, mb, K, ynew, tmp,
                                 W, which, B[which], work)  # fmt: skip
                # F is still the dense output of the whole step from y (dp_step leaves it)
                sample_dense(y, F, t, h, t + dt, False, cp, mem, ts, si, Ys, Fs)
                copy_into(y, ynew)
            return which, t + dt, hn
        sample_dense(y, F, t, h, t + h, True, cp, mem, ts, si, Ys, Fs)
        copy_into(y, ynew)
        copy_row(f0, K, N_ST)
        t += h
        h = hn
        first = False
        still = 0
        fill_2d(bstrip, 0)
        if stop == STOP_NO_CONTACT and no_contact_possible(y, m, lk, mem[M_XP], ext):
            return EV_STOP, t, h
        if stop == STOP_SAMPLES and si[0] >= ts.shape[0]:
            return EV_STOP, t, h
    return EV_FAIL, t, h


@njit(cache=True, error_model="numpy", refcount=False)
def dense_coeffs_sigma(z0, znew, K, h, s0, m, lk, c, cp, mem, F, tmp):
    """``dense_coeffs`` of a step in sigma from s0 (``rhs_sigma``; z = [y, t])."""
    n = z0.shape[0]
    for s in range(N_ST + 1, N_EXT):
        stage_state(z0, K, h, s, tmp)
        rhs_sigma(s0 + DP_C[s] * h, tmp, m, lk, c, cp, mem, F[0])
        for i in range(n):
            K[s, i] = F[0, i]
    dense_from_stages(z0, znew, K, h, F)


@njit(cache=True, error_model="numpy", refcount=False)
def _dense_component(z0, F, theta, i):
    acc = 0.0
    for k in range(N_DENSE - 1, -1, -1):
        acc += F[k, i]
        acc *= theta if k % 2 == 0 else 1.0 - theta
    return z0[i] + acc


@njit(cache=True, error_model="numpy", refcount=False)
def sample_sigma(z0, F, s0, h, t0, t_hi, closed, cp, mem, ts, si, Ys, Fs, tmp):
    """Fill the samples in (t0 + z0[t], t_hi] (``closed``) or (.., t_hi) of a step in sigma from
    s0: the time is the state's last component, monotonic over the step (x' keeps its sign in a
    sigma stretch), so the sample's theta is found by bisection on the dense output's time, and
    the state there is the dense output with u1 = -sigma**2 exactly."""
    ny = Ys.shape[1]
    while si[0] < ts.shape[0]:
        k = si[0]
        tk = ts[k]
        if tk > t_hi or (tk == t_hi and not closed):
            break
        target = tk - t0
        lo, hi = 0.0, 1.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            if _dense_component(z0, F, mid, ny) < target:
                lo = mid
            else:
                hi = mid
        th = 0.5 * (lo + hi)
        dense_state(z0, F, th, tmp)
        sg = s0 + th * h
        for i in range(ny):
            Ys[k, i] = tmp[i]
        Ys[k, 0] = -sg * sg
        Fs[k] = sample_force(cp, mem, sg * sg, -Ys[k, (Ys.shape[1] - 2) // 2])
        si[0] += 1


@njit(cache=True, error_model="numpy")
def sigma_phase_sampled(y, t, s_b, rtol, atol, m, lk, c, cp, mem, work, err_acc, ts, si, Ys, Fs):
    """``sigma_phase`` (the same steps, the same arithmetic) that also fills the samples up to
    its end (``sample_sigma``)."""
    nm = m.shape[0]
    ny = y.shape[0]
    nz = ny + 1
    sample_here(y, t, cp, mem, ts, si, Ys, Fs)
    z = np.empty(nz)
    copy_into(z, y)
    z[ny] = 0.0
    s0 = math.sqrt(max(-y[0], 0.0))
    xd0 = -y[nm]
    if not (xd0 != 0.0 and s_b != s0):
        return SIG_LEFT, t
    K = np.empty((N_EXT, nz))
    F = np.empty((N_DENSE, nz))
    znew = np.empty(nz)
    tmp = np.empty(nz)
    tmp2 = np.empty(nz)
    f0 = np.empty(nz)
    coef = np.empty(N_DENSE + 1)
    gb = np.empty(N_DENSE + 1)
    rs = np.empty(N_DENSE + 1)  # first_root's scratch
    bstrip = np.zeros((max(nm - 1, 0), 2), dtype=np.int64)
    mb = branch_mem(z, m, lk, mem, bstrip)
    held = mb.shape[0] > N_MEM
    still = 0
    rhs_sigma(s0, z, m, lk, c, cp, mb, f0)
    span = s_b - s0
    h = sigma_first_step(span, rtol, cp[3], s0)  # (cp[3]: the power law's exponent)
    zone = sigma_end_zone(span, rtol, cp[3]) if s_b == 0.0 else 0.0
    s = s0
    code = SIG_FAIL
    while work[0] > 0.0:
        work[0] -= 12.0
        h, last = sigma_last_step(h, s, s_b, zone)
        if not (abs(h) >= 1e-14 * abs(span)):  # also catches NaN
            break
        err = dp_step(z, f0, h, rtol, atol, m, lk, c, cp, mb, K, znew, tmp, True, s)
        if not err <= 1.0:
            h *= 0.2 if not err == err else max(0.2, 0.9 * err**-0.125)
            continue
        err_acc[0] += _momentum_error(K, h, m)
        t_hi = t + znew[ny]
        if held and still < 2 and not branches_excluded(K, h, z, znew, m, lk, mb):
            work[0] -= 3.0  # the work sigma_phase counts
            dense_coeffs_sigma(z, znew, K, h, s, m, lk, c, cp, mb, F, tmp2)
            bt, bi, bs = first_branch_root(F, K, h, z, m, lk, mb, bstrip, coef, gb, rs)
            if bt >= 0.0:
                ds = sigma_to_branch_point(z, f0, bt * h, s, rtol, atol, m, lk, c, cp, mb, K,
                                           znew, tmp, bi, bs, work)  # fmt: skip
                if ds != 0.0:  # F is still the dense output of the whole step from z
                    sample_sigma(z, F, s, h, t, t + znew[ny], True, cp, mem, ts, si, Ys, Fs, tmp2)
                still = 0 if ds != 0.0 else still + 1
                s = sigma_switch_branch(z, znew, f0, s, ds, m, lk, c, cp, mb, bstrip, bi, bs)
                h *= min(10.0, max(0.2, 0.9 * max(err, 1e-10) ** -0.125))
                continue
            if si[0] < ts.shape[0] and ts[si[0]] <= t_hi:
                sample_sigma(z, F, s, h, t, t_hi, not last, cp, mem, ts, si, Ys, Fs, tmp2)
        elif si[0] < ts.shape[0] and ts[si[0]] <= t_hi:
            dense_coeffs_sigma(z, znew, K, h, s, m, lk, c, cp, mb, F, tmp2)
            sample_sigma(z, F, s, h, t, t_hi, not last, cp, mem, ts, si, Ys, Fs, tmp2)
        copy_into(z, znew)
        copy_row(f0, K, N_ST)
        s = s_b if last else s + h
        if last:
            code = SIG_DONE
            break
        if not (-z[nm] * xd0 > 0.5 * xd0 * xd0):
            code = SIG_LEFT
            break
        h *= min(10.0, max(0.2, 0.9 * max(err, 1e-10) ** -0.125))
        still = 0
        fill_2d(bstrip, 0)
    if code != SIG_FAIL:
        copy_into(y, z)
        y[0] = -s * s
        t += z[ny]
    return code, t
