"""Nonlinear scene kernels: DOP853 with guaranteed events, or the paper's velocity Verlet.

``solve_scene`` / ``solve_scene_batch``: any chain (masses m[n], a link law and a dashpot per
neighbouring pair, any contact law of ``restitution.model.laws``); two masses are the chain
n = 2, there is no separate two-mass stack. The state is y = [u_1..u_n, v_1..v_n, W, D] and the
contact memory mem as in integrators.py. The kernels count their work in right-hand-side
evaluations (STATUS_WORK_BUDGET, the same on every machine and thread count), return a NaN COR
for any unfinished sequence, and never raise for finite input (compiled with
``error_model="numpy"``); batch rows start as NaN with STATUS_NOT_RUN.

Adaptive method: the contact phases are integrated by DOP853 (integrators.py; the ends of a
power-law contact in sigma = sqrt(x)). Free flight is integrated too, with
the same guaranteed event location, and ends by the proof of ``integrators.no_contact_possible``
-- except for two masses joined by a linear link (the paper's Sections 3.1 and 3.4), whose free
flight is closed form (``free_flight_linear``, unless ``free_closed`` is False): the centre of
mass X moves at constant V and r = u2 - u1 solves r'' + 2 xi w r' + w**2 r = 0, so the gap
g = u1 + xp = X + xp - mu r has |g''| <= G = mu w**2 sqrt(1 + 4 xi**2) sqrt(r0**2 + (r0'/w)**2)
(the oscillator's energy never grows). The next contact is found by a scan whose intervals are
skipped only when min(g(a), g(b)) - G h**2/8 > 0 (the linear interpolation error bound): no
sampling gamble, shallow dips are subdivided until resolved. On such a link without a dashpot,
the plastic law's elastic line (unloading and reloading below xmax) is closed form as well
(``kernels/elastic2.py``): only the power-law loading is integrated.

Contact phases are two-branch machines whose switches are all linear events (integrators.py):
plastic: loading --(x' = 0)--> elastic --(x = xmax)--> loading, elastic --(x = xp)--> separated;
linear: rising --(x' = 0)--> falling --(x' = 0)--> rising, falling --(x = 0)--> separated.
Kelvin-Voigt (F = k x + c x'): as linear, but falling --(k x + c x' = 0)--> separated at x > 0,
then a free stretch inside the penetration --(k x + c x' rises to 0)--> falling (a new contact)
or --(x = 0)--> the free flight. Hunt-Crossley: as Hertz (its range keeps 1 + lam x' > 0).
Each switch projects the state exactly onto the event surface (error O(tolerance)).
History x_max is exact for linear contacts and for plastic contacts that reach the power law; a
plastic contact that stays on the elastic line (no reload) records its entry penetration (the
dent), a lower bound: its turn is not an event since the force law does not change there.

Verlet: the paper's fixed step, step_frac * 2 pi / w with w the highest frequency of the chain
with the contact's slope scale engaged: exact for two masses (the paper's step), the Gershgorin
bound for longer chains.

Energy account (fractions of E0 = M v0**2/2, at the final separation): e_trans = cor**2,
e_vib = relative kinetic + link energy, e_diss = W + D (contact + dashpot, integrated as
extra ODE components, independent of the other two). |sum - 1| > etol -> STATUS_ENERGY, and so
does a negative net contact work (a passive contact cannot create energy; see solve_scene).
"""

import math

import numpy as np

from restitution.jit import njit
from restitution.kernels.constants import EPS
from restitution.kernels.copies import copy_into
from restitution.kernels.elastic2 import EL_FAIL, EL_INTEGRATE, elastic_at, elastic_phase
from restitution.kernels.integrators import (
    EV_FAIL,
    EV_STOP,
    M_BRANCH,
    M_FMAX,
    M_PHASE,
    M_XMAX,
    M_XP,
    N_MEM,
    SIG_DONE,
    SIG_FAIL,
    STOP_NEVER,
    STOP_NO_CONTACT,
    STOP_SAMPLES,
    accel_verlet,
    dent,
    no_contact_possible,
    phase_space,
    rhs,
    rk_phase,
    rk_phase_sampled,
    sample_here,
    sigma_phase,
    sigma_phase_sampled,
    verlet_step,
)
from restitution.kernels.layout import (
    H_IMPULSE,
    H_TEND,
    H_TSTART,
    H_VIN,
    H_VOUT,
    H_XMAX,
    N_OUT,
    OUT_COR,
    OUT_EDISS,
    OUT_ERR,
    OUT_ETRANS,
    OUT_EVIB,
    OUT_NCOL,
    OUT_NEVENTS,
    OUT_STATUS,
    OUT_TCOL,
    STATUS_ENERGY,
    STATUS_EVENT_BUDGET,
    STATUS_INVALID,
    STATUS_NONCONVERGED,
    STATUS_NOT_RUN,
    STATUS_OK,
    STATUS_WORK_BUDGET,
)
from restitution.kernels.parallel import over_threads
from restitution.kernels.roots import newton_bisection
from restitution.model.laws import (
    C_HERTZ,
    C_HUNT_CROSSLEY,
    C_KELVIN_VOIGT,
    C_PLASTIC,
    C_RIGID,
    S_LINEAR,
    SP_K2,
    SP_KIND,
    contact_elastic,
    contact_params_ok,
    contact_viscous,
    structure_energy,
)

N_ACCT = 5  # kinetic, elastic, dissipated in contact, dissipated in dashpot, residual
METHOD_ADAPTIVE = 0
METHOD_VERLET = 1
# Right-hand-side evaluations per scene (about a second for N = 8): a scene that needs more ends
# with STATUS_WORK_BUDGET.
MAX_WORK_DEFAULT = 4_000_000


# ------------------------------------------------- closed-form free flight of two masses --
@njit(cache=True, error_model="numpy", refcount=False)
def _basis(x, xi):
    """C(x), S(x): the solutions of r'' + 2 xi r' + r = 0 with C(0) = 1, C'(0) = -xi and
    S(0) = 0, S'(0) = 1 (all damping regimes, overflow-free).

    Next to critical damping (xi = 1 + d) the rates are formed without cancellation: wd or wh
    from (1 - xi)(1 + xi), exact in its first factor (1 - xi**2 rounds to eps, 10 % of 2 d at
    d = 1e-15), and S = e^{-xi x} sinh(wh x) / wh while wh x <= 1 (the difference of the two
    exponentials lost all but wh x of its digits: flights of a critically damped link came out
    1e-9 off)."""
    if xi < 1.0:
        wd = math.sqrt((1.0 - xi) * (1.0 + xi))
        e = math.exp(-xi * x)
        return e * math.cos(wd * x), e * (math.sin(wd * x) / wd if wd * x > 1e-300 else x)
    if xi == 1.0:
        e = math.exp(-x)
        return e, e * x
    wh = math.sqrt((xi - 1.0) * (xi + 1.0))
    ep = math.exp(-x / (wh + xi))  # e^{(wh - xi) x}, its rate without cancellation
    em = math.exp(-(wh + xi) * x)
    if wh * x <= 1.0:
        return 0.5 * (ep + em), math.exp(-xi * x) * (math.sinh(wh * x) / wh)
    return 0.5 * (ep + em), 0.5 * (ep - em) / wh


# Below this |x| (1 + xi) the increments of the basis are summed as Taylor series (terms fall
# at least like 0.5**n / n!; 24 of them leave < 1e-25 of the leading term).
SERIES_X = 0.5


@njit(cache=True, error_model="numpy", refcount=False)
def _increments(x, xi):
    """E = C(x) - 1 + xi x and F = S(x) - x (``_basis``), both O(x**2), without the
    cancellation of forming them from C and S where x is small: there by their Taylor series
    (coefficients a_{n+2} = -(2 xi (n + 1) a_{n+1} + a_n) / ((n + 1)(n + 2)))."""
    if abs(x) * (1.0 + xi) > SERIES_X:
        cx, sx = _basis(x, xi)
        return cx - 1.0 + xi * x, sx - x
    c0, c1, s0, s1 = 1.0, -xi, 0.0, 1.0
    e = 0.0
    f = 0.0
    p = x
    for n in range(24):
        d = (n + 1.0) * (n + 2.0)
        c2 = -(2.0 * xi * (n + 1.0) * c1 + c0) / d
        s2 = -(2.0 * xi * (n + 1.0) * s1 + s0) / d
        p *= x
        e += c2 * p
        f += s2 * p
        c0, c1, s0, s1 = c1, c2, s1, s2
    return e, f


@njit(cache=True, error_model="numpy", refcount=False)
def _osc_change(x, xi, r0, w0):
    """(r(x) - r0 - w0 x, r'(x) - w0) for r'' + 2 xi r' + r = 0 from r(0) = r0, r'(0) = w0 (r
    = r0 C + (w0 + xi r0) S): the change of the link's motion over x, accurate relative to
    itself where x is small (``_increments``)."""
    e, f = _increments(x, xi)
    return r0 * e + (w0 + xi * r0) * f, w0 * e - (r0 + xi * w0) * f - (r0 + 2.0 * xi * w0) * x


@njit(cache=True, error_model="numpy", refcount=False)
def _gap(s, g0, v1, mu, xi, w, r0, w0):
    """m1's gap at lab time s: g0 + v1 s - mu (r - r0 - w0 w s). Formed from its own start and
    speed, not as the centre of mass minus mu r: those are O(1) where the gap and its slope are
    tiny (a chatter), and their difference had put a root 5e-9 (relative) off."""
    dr, _ = _osc_change(w * s, xi, r0, w0)
    return g0 + v1 * s - mu * dr


@njit(cache=True, error_model="numpy", refcount=False)
def _gap_slope(s, g0, v1, mu, xi, w, r0, w0):
    """``_gap`` and its derivative in s."""
    dr, dw = _osc_change(w * s, xi, r0, w0)
    return g0 + v1 * s - mu * dr, v1 - mu * w * dw


_polish_gap = newton_bisection(_gap_slope, refcount=False)

# A closed-form flight rounds the state once (a few operations per speed). Its momentum error,
# at most FLIGHT_ROUNDING eps (m1 |v1| + m2 |v2|), enters the sum of local errors that floors
# the adaptive estimate: without it a run solved in closed form throughout (two masses at a
# rigid wall: impulsive contacts and these flights) had the estimate 0, its two settings giving
# one result.
FLIGHT_ROUNDING = 4.0


@njit(cache=True, error_model="numpy", inline="always")
def _flight_rounding(y, m, err_acc):
    err_acc[0] += FLIGHT_ROUNDING * EPS * (m[0] * abs(y[2]) + m[1] * abs(y[3]))


@njit(cache=True, error_model="numpy", refcount=False)
def free_flight_linear(y, xp, m1, m2, k, c):
    """Advance two masses joined by a linear link (k, dashpot c; no contact) to the next contact;
    return its local time or -1 (m1 never reaches the contact surface u1 = -xp again).

    y = [u1, u2, v1, v2, W, D]. On a contact, y is the state there with u1 = -xp exactly, and
    y[5] gains the dashpot loss.
    """
    m = m1 + m2
    mu = m2 / m
    inv = 1.0 / m1 + 1.0 / m2
    w = math.sqrt(k * inv)  # the link's angular frequency; times below are lab times
    xi = c * inv / (2.0 * w)
    x0 = (m1 * y[0] + m2 * y[1]) / m + xp
    v = (m1 * y[2] + m2 * y[3]) / m
    r0 = y[1] - y[0]
    w0 = (y[3] - y[2]) / w  # dr/d(w t)
    amp = math.sqrt(r0 * r0 + w0 * w0)
    gbound = mu * w * w * math.sqrt(1.0 + 4.0 * xi * xi) * amp
    # the gap u1 + xp and its slope v1 from m1's own state (``_gap``)
    g0 = y[0] + xp
    dg0 = y[2]
    s = 0.0
    if g0 <= 0.0:
        g0 = 0.0
    if g0 == 0.0:
        if dg0 <= 0.0:
            return 0.0  # leaving along the surface: touching again at once
        s = dg0 / gbound if gbound > 0.0 else 1.0 / w
    gs = _gap(s, g0, dg0, mu, xi, w, r0, w0)
    h = 0.25 / w
    hit = -1.0
    for _ in range(100_000_000):
        if v > 0.0 and x0 + v * s - mu * amp > 0.0:
            break  # the gap can never close again
        if v <= 0.0 and w * s > 1e9:
            break
        gb = _gap(s + h, g0, dg0, mu, xi, w, r0, w0)
        if gb <= 0.0:
            hit = _polish_gap(s, s + h, (g0, dg0, mu, xi, w, r0, w0))[1]
            break
        if min(gs, gb) - gbound * h * h / 8.0 > 0.0 or w * h < 1e-12 * max(1.0, w * s):
            s += h
            gs = gb
            h *= 2.0  # the bound test itself limits h where the gap is small
        else:
            h *= 0.5
    if hit < 0.0:
        return -1.0
    x = w * hit
    dr, dw = _osc_change(x, xi, r0, w0)
    r = r0 + w0 * x + dr
    wr = w0 + dw
    e_before = 0.5 * mu * m1 * w * w * (r0 * r0 + w0 * w0)  # (reduced mass m1 mu)
    e_after = 0.5 * mu * m1 * w * w * (r * r + wr * wr)
    y[0] = -xp
    y[1] = -xp + r
    y[2] = dg0 - mu * w * dw  # (m1's speed from its own, as the gap)
    y[3] = v + (m1 / m) * w * wr
    y[5] += e_before - e_after
    return hit


# ------------------------------------------------------------------------------ the scene --
ENTER = 0  # the branch starts at the contact surface (or at t = 0)
AFTER_TURN = 1  # the branch starts at a turn: v1 = 0 projected, x at a local maximum
AFTER_RISE = 2  # the branch starts at a reload (plastic, x = xmax) or a rise (linear, v1 = 0)
MID = 3  # the branch goes on from inside (after a stretch in sigma): no event starts on its surface

# Zeno guard of the non-plastic contacts. m1 at rest in a contact (a slow creep out of a linear
# contact after a long press) has v1 = 0 to within the integration error: at a loose rtol each
# turn (v1 rising through 0) was followed at once by a rise (v1 falling through 0) and so on,
# every event a millionth of a step after the last, until the work budget ran out (a 4-mass
# scissor chain, 7 contacts: rtol 1e-4..1e-6 exhausted its budget in 1.5 s, 1e-8 finished in
# 7 ms). After ZENO_FLIPS turns and rises in a row, each within ZENO_QUICK of the next step after
# the last event, the contact goes on unloading and a rise needs v1 <= -ZENO_BAND * atol (until
# it separates). The branches of these laws exert the same force (only the events and the
# recorded maximum depth differ), so the band moves no force; a scene without such a run of
# events computes exactly as before. A contact that ends while the band is on, with m1 moving
# into the wall within it, lets m1 leave at rest if the links pull it off (``_leave_at_rest``):
# a two-mass scissor scene touched again at once and chattered 12,366 times until its budget ran
# out (docs/solvers.md, "m1 leaving a guarded contact at rest").
ZENO_QUICK = 1e-3
ZENO_FLIPS = 8
ZENO_BAND = 100.0

# The ends of a power-law contact are integrated in sigma = sqrt(x) (integrators.sigma_phase) over
# x <= SIGMA_ZONE * (the contact's depth scale), where the force has done little work and x'
# stays near its value at the surface.
SIGMA_ZONE = 0.3
# The largest step of an integrated free flight, in units of 1/w_free (w_free: the chain's
# highest free frequency): a sixth of its shortest period. The error control sizes the steps; the
# cap keeps the 7th-order dense output on which events and scissor branch points are located as
# accurate as the steps. At 0.5 (DP5's cap, kept with DOP853) a slow free flight took 12 steps a
# period. At 1 the benchmark's scissor scene kept its errors at rtol 1e-4..1e-12 and ran
# 1.5-1.65x faster; the three-mass Hertz chain's errors grew up to 4x at rtol 1e-9..1e-7 (still
# 36x or more below their estimates), none from 3e-10 on. At 2 the scissor scene's error at rtol
# 1e-12 grew from 3e-16 to 5e-14 (2026-11-27).
# w_free takes every link at its stiffest slope, the scissor's cap k2, though that scene's flight
# runs on its soft bars. A local cap was tried (each step capped at HMAX_FREE over the Gershgorin
# bound with each scissor link's slope bounded over the extensions its potential allows at the
# state's internal energy, which a free flight never raises: w 0.21 there instead of 1): the
# flight took 240-573 right-hand sides instead of 669-684 at rtol 1e-4..1e-12, but its steps were
# then the error control's, and the COR errors grew 16-150x at rtol 1e-8..1e-12 (7.4e-12 ->
# 1.2e-10, 6.5e-14 -> 9.9e-12, 3.3e-16 -> 4.7e-14; still 12x or more below the estimates). The
# cap's smaller errors there are the flight's own truncation error, not the dense output's (the
# old cap kept only around the two lock crossings restored none of them), so the cap stays
# global (docs/accuracy.md, "The scissor spring").
HMAX_FREE = 1.0


@njit(cache=True, error_model="numpy", refcount=False)
def _setup_contact_events(cp, mem, W, B, strip, how, nm=2, band=0.0):
    """Event rows of the current contact branch; returns their number.

    ``strip`` counts the leading zeros of an event that starts on its own surface (exactly, since
    the state is projected there): the separation when entering, the reload (double zero: x at
    its maximum with v1 = 0) or the rise (v1 = 0) after a turn, the turn after a linear rise.
    ``nm`` is the number of masses (v1 is y[nm]); W has as many columns as the state.
    ``band`` > 0 (the Zeno guard, ``_contact_event``): an elastic rise needs v1 <= -band.
    """
    for k in range(2):
        for i in range(W.shape[1]):
            W[k, i] = 0.0
        B[k] = 0.0
        strip[k] = 0
    plastic = cp[0] == C_PLASTIC
    if mem[M_BRANCH] == 1.0:
        # turn: x' = -v1 falls to 0
        W[0, nm] = -1.0
        strip[0] = 1 if (how == AFTER_RISE and not plastic) else 0
        return 1
    # separation: x - xp = -u1 - xp falls to 0
    W[0, 0] = -1.0
    B[0] = -mem[M_XP]
    strip[0] = 1 if how == ENTER else 0
    if cp[0] == C_KELVIN_VOIGT:
        # the force k x + c x' = -k u1 - c v1 falls to 0 (at x > 0); ENTER here is a contact
        # that started inside the penetration, where that force rose through 0
        W[0, 0] = -cp[2]
        W[0, nm] = -cp[3]
    if plastic:
        # reload past the maximum: xmax - x = xmax + u1 falls to 0
        W[1, 0] = 1.0
        B[1] = mem[M_XMAX]
        strip[1] = 2 if how == AFTER_TURN else 0
    else:
        # elastic contact, x rising again: v1 falls to 0 (to -band)
        W[1, nm] = 1.0
        B[1] = band
        strip[1] = 1 if (how == AFTER_TURN and band == 0.0) else 0
    return 2


@njit(cache=True, error_model="numpy", inline="always")
def _contact_switch(code, y, iv, kind, cp, mem, how, xmax_c):
    """The law's switch at an event of a contact phase, the same for two masses and for chains:
    y[0] = u1, y[iv] = v1. At the deepest point the loading branch turns (the plastic law
    records its largest force and its dent); a reload past xmax (plastic) or a rise again
    (elastic) returns to loading; else m1 separates at the dent. Returns (how, xmax_c,
    separated)."""
    if mem[M_BRANCH] == 1.0:  # turn at the deepest point
        y[iv] = 0.0
        x = -y[0]
        xmax_c = max(xmax_c, x)
        mem[M_BRANCH] = 0.0
        if kind == C_PLASTIC and x >= mem[M_XMAX]:
            mem[M_XMAX] = x
            mem[M_FMAX] = cp[2] * x ** cp[3]
            mem[M_XP] = dent(cp, mem)
        return AFTER_TURN, xmax_c, False
    if code == 1:  # reload past xmax (plastic) / rising again (elastic)
        if kind == C_PLASTIC:
            y[0] = -mem[M_XMAX]
        else:
            y[iv] = 0.0
        mem[M_BRANCH] = 1.0
        return AFTER_RISE, xmax_c, False
    if kind == C_KELVIN_VOIGT:
        y[0] = -cp[3] * y[iv] / cp[2]  # on k x + c x' = 0: the force-zero end, x >= 0
    else:
        y[0] = -mem[M_XP]  # separation
    mem[M_PHASE] = 0.0
    return how, xmax_c, True


@njit(cache=True, error_model="numpy", inline="always")
def _contact_event(code, y, iv, kind, cp, mem, how, xmax_c, dt, h, atol, guard):
    """``_contact_switch`` with the Zeno guard (ZENO_FLIPS above): ``dt`` the time since the
    last event, ``h`` the next step, ``guard`` = [quick turns and rises in a row, band] (zeroed
    at a separation). Returns (how, xmax_c, separated)."""
    flip = kind != C_PLASTIC and not (mem[M_BRANCH] == 0.0 and code == 0)  # a turn or a rise
    v1 = y[iv]
    how, xmax_c, separated = _contact_switch(code, y, iv, kind, cp, mem, how, xmax_c)
    if separated:
        guard[0] = 0.0
        guard[1] = 0.0
        return how, xmax_c, True
    if not flip:
        return how, xmax_c, False
    if guard[1] > 0.0:  # the band is on: the event is at v1 = 0 or -band, kept (no projection)
        y[iv] = v1
        return MID, xmax_c, False
    guard[0] = guard[0] + 1.0 if dt <= ZENO_QUICK * h else 0.0
    if guard[0] >= ZENO_FLIPS:
        guard[1] = ZENO_BAND * atol
        mem[M_BRANCH] = 0.0
        return MID, xmax_c, False
    return how, xmax_c, False


@njit(cache=True, error_model="numpy", inline="always")
def _leave_at_rest(code, y, m, lk, c, cp, mem, guard):
    """The Zeno guard at a separation (``code`` 0 on the unloading branch) while its band is on:
    m1 at rest in the contact reaches the surface with v1 in (-band, 0), moving into the wall
    within the band (a separation needs x' <= 0, i.e. v1 >= 0). If the links pull m1 off the
    wall at rest there (its acceleration without the contact force > 0), it leaves at rest:
    v1 = 0. Else (pushed in: no separation at rest) the state is kept as it was."""
    n = m.shape[0]
    if not (guard[1] > 0.0 and code == 0 and mem[M_BRANCH] == 0.0):
        return
    if not (-guard[1] < y[n] < 0.0):
        return
    ys = y.copy()
    ys[0] = -mem[M_XP]
    ys[n] = 0.0
    free = mem.copy()
    free[M_PHASE] = 0.0
    dy = np.empty(y.shape[0])
    rhs(ys, m, lk, c, cp, free, dy)
    if dy[n] > 0.0:
        y[n] = 0.0


@njit(cache=True, error_model="numpy", refcount=False)
def _record(hist, n, col, value):
    if n < hist.shape[0]:
        hist[n, col] = value


@njit(cache=True, error_model="numpy", refcount=False)
def chain_frequency_bound(m, lk, kc):
    """Gershgorin bound on the highest angular frequency (links at their largest slope, SP_K2;
    a contact slope kc on m1)."""
    n = m.shape[0]
    lam = 0.0
    for i in range(n):
        row = 0.0
        if i > 0:
            row += 2.0 * lk[i - 1, SP_K2]
        if i < n - 1:
            row += 2.0 * lk[i, SP_K2]
        if i == 0:
            row += kc
        lam = max(lam, row / m[i])
    return math.sqrt(lam)


@njit(cache=True, error_model="numpy", refcount=False)
def verlet_frequency(m, lk, kc):
    """The highest angular frequency that sets Verlet's step: exact for two masses (the largest
    eigenvalue of the 2 x 2 problem with the contact slope kc on m1 and the link at its largest
    slope, as the paper's step), ``chain_frequency_bound`` for longer chains."""
    if m.shape[0] != 2:
        return chain_frequency_bound(m, lk, kc)
    k = lk[0, SP_K2]
    tr = (kc + k) / m[0] + k / m[1]
    det = kc * k / (m[0] * m[1])
    lam = 0.5 * tr + math.sqrt(max(0.25 * tr * tr - det, 0.0))
    return math.sqrt(lam)


@njit(cache=True, error_model="numpy", refcount=False)
def _momentum(y, m):
    n = m.shape[0]
    p = 0.0
    for i in range(n):
        p += m[i] * y[n + i]
    return p


@njit(cache=True, error_model="numpy", refcount=False)
def _energies(y, m, lk, v0, out, acct, y0=None):
    """The result's COR and energy fractions at the final separation ``y``. From a given
    initial state ``y0`` (solve_scene) the COR is the centre of mass's velocity over its approach
    speed before and the fractions are of the initial kinetic + link energy."""
    n = m.shape[0]
    mt = 0.0
    ek = 0.0
    for i in range(n):
        mt += m[i]
        ek += 0.5 * m[i] * y[n + i] * y[n + i]
    e0 = 0.5 * mt * v0 * v0
    vc = _momentum(y, m) / mt
    eel = 0.0
    for i in range(n - 1):
        eel += structure_energy(lk[i], y[i + 1] - y[i])
    erel = ek - 0.5 * mt * vc * vc
    out[OUT_COR] = vc / v0
    out[OUT_ETRANS] = vc * vc / (v0 * v0)
    if y0 is not None:
        e0, p0 = initial_energy(y0, m, lk)
        out[OUT_COR] = vc * mt / -p0
        out[OUT_ETRANS] = 0.5 * mt * vc * vc / e0
    out[OUT_EVIB] = (erel + eel) / e0
    out[OUT_EDISS] = (y[2 * n] + y[2 * n + 1]) / e0
    acct[0] = ek / e0
    acct[1] = eel / e0
    acct[2] = y[2 * n] / e0
    acct[3] = y[2 * n + 1] / e0
    acct[4] = out[OUT_ETRANS] + out[OUT_EVIB] + out[OUT_EDISS] - 1.0


@njit(cache=True, error_model="numpy", refcount=False)
def initial_energy(y0, m, lk):
    """(kinetic + link energy, momentum) of the initial state y0 = [u(n), v(n)]."""
    n = m.shape[0]
    e = 0.0
    for i in range(n):
        e += 0.5 * m[i] * y0[n + i] * y0[n + i]
    for i in range(n - 1):
        e += structure_energy(lk[i], y0[i + 1] - y0[i])
    return e, _momentum(y0, m)


@njit(cache=True, error_model="numpy", refcount=False)
def state_ok(y0, m):
    """The kernel's guard of a given initial state (named by the Python layer first): 2 n
    finite numbers, m1 on the wall (u1 = 0) and moving (v1 != 0), the centre of mass
    approaching the wall."""
    n = m.shape[0]
    if y0.shape[0] != 2 * n or y0[0] != 0.0 or y0[n] == 0.0:
        return False
    for i in range(2 * n):
        if not math.isfinite(y0[i]):
            return False
    return _momentum(y0, m) < 0.0


@njit(cache=True, error_model="numpy", refcount=False)
def input_ok(m, lk, c, cp, v0):
    """The kernel's own guard (the Python entry checks and names every parameter first)."""
    n = m.shape[0]
    if n < 1 or lk.shape[0] < n - 1 or c.shape[0] < n - 1:
        return False
    if not (v0 > 0.0 and v0 < math.inf):
        return False
    for i in range(n):
        if not (m[i] > 0.0 and m[i] < math.inf):
            return False
    for i in range(n - 1):
        if not (lk[i, SP_K2] > 0.0 and lk[i, SP_K2] < math.inf):
            return False
        if not (c[i] >= 0.0 and c[i] < math.inf):
            return False
    return contact_params_ok(cp)


@njit(cache=True, error_model="numpy")
def solve_scene(
    m, lk, c, cp, v0, method, rtol, step_frac, etol, max_events, max_work, hist, acct,
    free_closed=True, y0=None, cap=HMAX_FREE,
):  # fmt: skip
    """COR of one chain with any contact and link laws; ``out`` as kernels/layout.py.

    m[n] (m[0] = 1 in kernel units), lk[n-1] link laws, c[n-1] dashpots, cp the contact law; all
    masses start at -v0 with m1 on the wall surface. method 0 = adaptive DOP853 (rtol, atol =
    rtol*v0), 1 = velocity Verlet (step = step_frac * 2 pi / ``verlet_frequency``).
    ``max_work`` bounds the right-hand-side evaluations (STATUS_WORK_BUDGET); ``acct`` receives
    the energy account (N_ACCT entries); ``free_closed`` = False integrates the free flight of
    two masses with a linear link too (checks of the integrated free flight). Never raises for
    finite input: a failure is a NaN COR with its status.

    ``y0`` (None: the uniform approach above) is a given initial state [u(n), v(n)] in kernel
    units (u1 = 0: m1 on the wall; v0 is then the centre of mass's approach speed, the scale of
    atol): the scene starts with a contact if v1 < 0, in free flight if v1 > 0; the COR is the
    centre of mass's velocity after over before, the energies fractions of the initial
    kinetic + link energy (``_energies``).

    ``cap``: the adaptive method's largest step of an integrated free flight, in units of
    1/w_free (HMAX_FREE; the check run of ``restitution.solvers.numerical`` takes a larger one).
    """
    out = np.full(N_OUT, np.nan)
    out[OUT_STATUS] = STATUS_INVALID
    out[OUT_NCOL] = 0.0
    out[OUT_NEVENTS] = 0.0
    for i in range(acct.shape[0]):
        acct[i] = np.nan
    if not input_ok(m, lk, c, cp, v0):
        return out
    n = m.shape[0]
    y = np.zeros(2 * n + 2)
    for i in range(n):
        y[n + i] = -v0
    free0 = False  # m1 leaving the wall at t = 0: a free flight first
    p_scale = 0.0  # the approach momentum, the unit of the momentum error
    if y0 is not None:
        if not state_ok(y0, m):
            return out
        for i in range(2 * n):
            y[i] = y0[i]
        free0 = y[n] > 0.0
        p_scale = -_momentum(y0, m)
    mem = np.zeros(N_MEM)
    ysep = y.copy()
    work = np.zeros(1)
    work[0] = max_work
    mt = 0.0
    for i in range(n):
        mt += m[i]
    if method == METHOD_VERLET:
        status, ncol, tcol = _verlet(
            y, ysep, m, lk, c, cp, mem, step_frac, max_events, work, hist, v0, free0
        )
        err = 0.0
    else:
        status, ncol, tcol, err = _adaptive(
            y, ysep, m, lk, c, cp, mem, rtol, max_events, work, hist, v0, free_closed, free0, cap
        )
    out[OUT_NCOL] = ncol
    out[OUT_NEVENTS] = ncol
    out[OUT_TCOL] = tcol
    _energies(ysep, m, lk, v0, out, acct, y0)
    out[OUT_ERR] = err / (mt * v0)
    if y0 is not None:
        out[OUT_ERR] = err / p_scale
    if status == STATUS_OK and not abs(acct[4]) <= etol:
        status = STATUS_ENERGY
    if status == STATUS_OK and acct[2] < -etol:
        status = STATUS_ENERGY  # net contact work < 0: the law created energy (see solve_scene)
    if status == STATUS_OK and not (
        math.isfinite(out[OUT_COR]) and math.isfinite(out[OUT_TCOL]) and math.isfinite(out[OUT_ERR])
    ):
        status = STATUS_NONCONVERGED  # never a non-finite number marked ok
    if status != STATUS_OK and status != STATUS_ENERGY:
        out[OUT_COR] = np.nan  # an unfinished sequence has no COR
    out[OUT_STATUS] = status
    return out


@njit(cache=True, error_model="numpy")
def _sigma_room(y, m, lk, c, cp, mem, x_sw):
    """Largest x_sw' <= x_sw over which x' changes by at most a quarter at m1's present
    acceleration: x'**2 >= 4 |x''| x_sw' (0 when x' = 0)."""
    n = m.shape[0]
    dy = np.empty(y.shape[0])
    rhs(y, m, lk, c, cp, mem, dy)
    a = abs(dy[n])
    xd2 = y[n] * y[n]
    if a > 0.0:
        x_sw = min(x_sw, 0.25 * xd2 / a)
    return x_sw if xd2 > 0.0 else 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _sigma_entry(y, t, m, lk, c, cp, mem, rtol, atol, work, err_acc):
    """The entry stretch of a contact on the power law F = kappa x**eta from x = 0, in sigma:
    up to SIGMA_ZONE x the depth at which m1 alone would stop, limited by ``_sigma_room``.
    Returns (code, t): SIG_DONE or SIG_LEFT (both go on in time), SIG_FAIL."""
    n = m.shape[0]
    xd = -y[n]
    eta = cp[3]
    depth = ((eta + 1.0) * m[0] * xd * xd / (2.0 * cp[2])) ** (1.0 / (eta + 1.0))
    x_sw = _sigma_room(y, m, lk, c, cp, mem, SIGMA_ZONE * depth)
    if not x_sw > 0.0:
        return SIG_DONE, t
    return sigma_phase(y, t, math.sqrt(x_sw), rtol, atol, m, lk, c, cp, mem, work, err_acc)


@njit(cache=True, error_model="numpy", refcount=False)
def contact_first_step(w_cont, rtol):
    """First step of a contact phase in time: min(0.5, 0.11 (rtol/1e-12)**(1/8)) / w_cont. The
    fixed 0.05 / w_cont before was about a quarter of the step the error control then took at
    rtol 1e-12 (a first error norm of 1.6e-5 on Hertz contacts); this size is about 0.6 of it
    (DOP853's error grows like h**8)."""
    return min(0.5, 0.11 * (rtol / 1e-12) ** 0.125) / w_cont


@njit(cache=True, error_model="numpy", inline="always")
def _adaptive(
    y, ysep, m, lk, c, cp, mem, rtol, max_events, work, hist, v0, free_closed, free0=False,
    cap=HMAX_FREE,
):  # fmt: skip
    """The adaptive run from y (a contact at t = 0, or with ``free0`` a free flight first)."""
    n = m.shape[0]
    closed = free_closed and n == 2 and lk[0, SP_KIND] == S_LINEAR
    # the plastic law's elastic line in closed form too (kernels/elastic2.py): undamped link
    elastic_closed = closed and cp[0] == C_PLASTIC and c[0] == 0.0
    ny = 2 * n + 2
    atol = rtol * v0
    kind = int(cp[0])
    W = np.zeros((2, ny))
    B = np.zeros(2)
    strip = np.zeros(2, dtype=np.int64)
    err_acc = np.zeros(1)
    ws = phase_space(ny, n)  # rk_phase's work arrays
    guard = np.zeros(2)  # the Zeno guard's state (_contact_event)
    t_event = 0.0
    t = 0.0
    tcol = 0.0
    ncol = 1
    # step scales from the highest frequency, free and with the contact's slope scale cp[1]
    w_cont = chain_frequency_bound(m, lk, cp[1] if kind != C_RIGID else 0.0)
    w_free = chain_frequency_bound(m, lk, 0.0)
    if not w_free > 0.0:  # a single mass: no free-flight scale, take the contact's
        w_free = w_cont if w_cont > 0.0 else 1.0
    if not w_cont > 0.0:
        w_cont = w_free
    hc = contact_first_step(w_cont, rtol)
    hf = 0.05 / w_free
    hmax_free = cap / w_free
    h = hc
    p_in = _momentum(y, m)
    xmax_c = 0.0
    if free0:  # no contact yet: on to the free flight below (the 'else' branch of the loop)
        ncol = 0
        h = hf
        mem[M_PHASE] = 0.0
    elif kind == C_RIGID:
        _record(hist, 0, H_TSTART, 0.0)
        _record(hist, 0, H_VIN, y[n] / v0)
        y[n] = -y[n]
        copy_into(ysep, y)
        _record(hist, 0, H_TEND, 0.0)
        _record(hist, 0, H_VOUT, y[n] / v0)
        _record(hist, 0, H_IMPULSE, (_momentum(y, m) - p_in) / v0)
        mem[M_PHASE] = 0.0
    else:
        _record(hist, 0, H_TSTART, 0.0)
        _record(hist, 0, H_VIN, y[n] / v0)
        mem[M_PHASE] = 1.0
        mem[M_BRANCH] = 1.0
    entering = True
    how = ENTER
    sigma_exit = True
    while True:
        # a contact starting on the power law at x = 0 (Hertz; plastic before any dent)
        power_entry = (
            kind == C_HERTZ or kind == C_HUNT_CROSSLEY or (kind == C_PLASTIC and mem[M_FMAX] == 0.0)
        )
        if mem[M_PHASE] == 1.0:
            if how == ENTER and mem[M_BRANCH] == 1.0 and power_entry:
                scode, t = _sigma_entry(y, t, m, lk, c, cp, mem, rtol, atol, work, err_acc)
                if scode == SIG_FAIL:
                    return _fail(work), ncol, tcol, err_acc[0]
                how = MID
            nev = _setup_contact_events(cp, mem, W, B, strip, how, n, guard[1])
            x_sw = 0.0
            power_exit = kind == C_HERTZ or kind == C_HUNT_CROSSLEY
            if power_exit and mem[M_BRANCH] == 0.0 and sigma_exit:
                # separation replaced by x = x_sw, from where sigma runs to x = 0 (only if the
                # branch starts deeper: a turn inside the zone has x' = 0 there)
                x_sw = SIGMA_ZONE * xmax_c
                if -y[0] > x_sw:
                    B[0] -= x_sw
                else:
                    x_sw = 0.0
            code = EL_INTEGRATE
            if elastic_closed and mem[M_BRANCH] == 0.0:
                code, s, err = elastic_phase(
                    y, mem[M_XP], mem[M_XMAX], m[0], m[1], lk[0, SP_K2], cp[1], work
                )  # fmt: skip
                if code == EL_FAIL:
                    return _fail(work), ncol, tcol, err_acc[0]
                if code != EL_INTEGRATE:
                    t += s
                    err_acc[0] += err
                    h = hc
            if code == EL_INTEGRATE:
                code, t, h = rk_phase(
                    y, t, h, 1e300, rtol, atol, m, lk, c, cp, mem, W, B, strip, nev,
                    STOP_NEVER, work, err_acc, ws,
                )  # fmt: skip
            if code == EV_FAIL or code == EV_STOP:
                return _fail(work), ncol, tcol, err_acc[0]
            if code == 0 and x_sw > 0.0:
                y[0] = -x_sw
                scode = SIG_FAIL + 1  # not tried
                if _sigma_room(y, m, lk, c, cp, mem, x_sw) == x_sw:
                    scode, t = sigma_phase(
                        y, t, 0.0, rtol, atol, m, lk, c, cp, mem, work, err_acc
                    )  # fmt: skip
                if scode == SIG_FAIL:
                    return _fail(work), ncol, tcol, err_acc[0]
                if scode != SIG_DONE:  # x' too small here: on in time to the surface itself
                    sigma_exit = False
                    how = MID
                    continue
            sigma_exit = True
            _leave_at_rest(code, y, m, lk, c, cp, mem, guard)
            how, xmax_c, separated = _contact_event(
                code, y, n, kind, cp, mem, how, xmax_c, t - t_event, h, atol, guard
            )
            t_event = t
            if separated:
                tcol = t
                copy_into(ysep, y)
                k = ncol - 1
                _record(hist, k, H_TEND, t)
                _record(hist, k, H_VOUT, y[n] / v0)
                _record(hist, k, H_XMAX, xmax_c)
                _record(hist, k, H_IMPULSE, (_momentum(y, m) - p_in) / v0)
                entering = True
                h = hf
        else:
            inside = kind == C_KELVIN_VOIGT and -y[0] > 0.0
            if inside:
                # m1 left the force-zero end inside the penetration (x > 0, F = 0): free until
                # the force k x + c x' rises through 0 again (a new contact there) or x falls
                # to 0 (on to the free flight below)
                W[0, :] = 0.0
                W[1, :] = 0.0
                W[0, 0] = cp[2]
                W[0, n] = cp[3]
                B[0] = 0.0
                B[1] = 0.0
                W[1, 0] = -1.0
                strip[0] = 1
                strip[1] = 0
                code, t, h = rk_phase(
                    y, t, h, hmax_free, rtol, atol, m, lk, c, cp, mem, W, B, strip, 2,
                    STOP_NEVER, work, err_acc, ws,
                )  # fmt: skip
                if code == EV_FAIL or code == EV_STOP:
                    return _fail(work), ncol, tcol, err_acc[0]
                if code == 1:
                    y[0] = 0.0
                    inside = False
                else:
                    y[0] = -cp[3] * y[n] / cp[2]
                entering = True
            if not inside:
                if closed:
                    s = free_flight_linear(y, mem[M_XP], m[0], m[1], lk[0, SP_K2], c[0])
                    if s < 0.0:
                        return STATUS_OK, ncol, tcol, err_acc[0]
                    _flight_rounding(y, m, err_acc)
                    t += s
                    work[0] -= 100.0  # a closed-form free flight: about 100 gap evaluations
                    if work[0] <= 0.0:
                        return STATUS_WORK_BUDGET, ncol, tcol, err_acc[0]
                else:
                    W[0, :] = 0.0
                    W[0, 0] = 1.0
                    B[0] = mem[M_XP]
                    strip[0] = 1 if entering else 0
                    code, t, h = rk_phase(
                        y, t, h, hmax_free, rtol, atol, m, lk, c, cp, mem, W, B, strip, 1,
                        STOP_NO_CONTACT, work, err_acc, ws,
                    )  # fmt: skip
                    if code == EV_STOP:
                        return STATUS_OK, ncol, tcol, err_acc[0]
                    if code == EV_FAIL:
                        return _fail(work), ncol, tcol, err_acc[0]
                    y[0] = -mem[M_XP]
            h = hc
            # a new contact starts
            if ncol >= max_events:
                return STATUS_EVENT_BUDGET, ncol, tcol, err_acc[0]
            k = ncol
            ncol += 1
            xmax_c = -y[0]
            p_in = _momentum(y, m)
            _record(hist, k, H_TSTART, t)
            _record(hist, k, H_VIN, y[n] / v0)
            if kind == C_RIGID:
                y[n] = -y[n]
                tcol = t
                copy_into(ysep, y)
                _record(hist, k, H_TEND, t)
                _record(hist, k, H_VOUT, y[n] / v0)
                _record(hist, k, H_IMPULSE, (_momentum(y, m) - p_in) / v0)
                entering = True
                h = hf
            else:
                mem[M_PHASE] = 1.0
                if inside:  # the force rose through 0 at x > 0 while x' < 0: x still falls
                    mem[M_BRANCH] = 0.0
                elif contact_elastic(cp) or mem[M_FMAX] == 0.0:
                    mem[M_BRANCH] = 1.0
                else:
                    mem[M_BRANCH] = 0.0
                how = ENTER


@njit(cache=True, error_model="numpy", refcount=False)
def _fail(work):
    """Status of a failed phase: the work budget if it ran out, else a step-size underflow."""
    return STATUS_WORK_BUDGET if work[0] <= 0.0 else STATUS_NONCONVERGED


@njit(cache=True, error_model="numpy", inline="always")
def _verlet(y, ysep, m, lk, c, cp, mem, step_frac, max_events, work, hist, v0, free0=False):
    """The paper's scheme: one fixed step for the whole scene, step_frac * 2 pi / w with w the
    highest frequency with the contact's slope scale cp[1] engaged (``verlet_frequency``; k1
    also bounds the plastic unloading and the scissor's capped slope). Switching steps at
    state-dependent times would add its own O(h) jitter."""
    n = m.shape[0]
    h = step_frac * 2.0 * math.pi / verlet_frequency(m, lk, cp[1])
    damped = contact_viscous(cp)  # a force that depends on the velocity: the corrected pass
    for i in range(n - 1):
        damped = damped or c[i] != 0.0
    acc = np.zeros(n + 2)
    ext = np.full((max(n - 1, 0), 2), -1.0)  # no_contact_possible's
    fc, pw = accel_verlet(y, m, lk, c, cp, mem, acc)
    acc[n], acc[n + 1] = fc, pw
    t = 0.0
    ncol = 1
    tcol = 0.0
    in_contact = True
    xmax_c = 0.0
    p_in = _momentum(y, m)
    if free0:  # m1 leaves the wall at t = 0: the first contact comes later
        ncol = 0
        in_contact = False
    else:
        _record(hist, 0, H_TSTART, 0.0)
        _record(hist, 0, H_VIN, y[n] / v0)
    it = 0
    while work[0] > 0.0:
        work[0] -= 2.0 if damped else 1.0
        it += 1
        verlet_step(y, acc, h, m, lk, c, cp, mem, damped)
        t += h
        now = acc[n] > 0.0
        if now and not in_contact:
            if ncol >= max_events:
                return STATUS_EVENT_BUDGET, ncol, tcol
            _record(hist, ncol, H_TSTART, t)
            _record(hist, ncol, H_VIN, y[n] / v0)
            p_in = _momentum(y, m)
            xmax_c = 0.0
            ncol += 1
        if now:
            xmax_c = max(xmax_c, -y[0])
        if in_contact and not now:
            tcol = t
            copy_into(ysep, y)
            k = ncol - 1
            _record(hist, k, H_TEND, t)
            _record(hist, k, H_VOUT, y[n] / v0)
            _record(hist, k, H_XMAX, xmax_c)
            _record(hist, k, H_IMPULSE, (_momentum(y, m) - p_in) / v0)
        in_contact = now
        if not now:
            mem[M_XP] = dent(cp, mem)
            if (it & 7) == 0 and no_contact_possible(y, m, lk, mem[M_XP], ext):
                return STATUS_OK, ncol, tcol
    return STATUS_WORK_BUDGET, ncol, tcol


@njit(cache=True, nogil=True, error_model="numpy")
def _scene_rows(m, lk, c, n, cp, v0, method, rtol, step_frac, etol, max_events, max_work, cap,
                out, order, start, stop):  # fmt: skip
    """``solve_scene`` of the padded rows order[start:stop] into ``out`` (kernels.parallel)."""
    hist = np.zeros((0, 6))
    for j in range(start, stop):
        i = order[j]
        k = n[i]
        if k < 2 or k > m.shape[1]:
            out[i, OUT_STATUS] = STATUS_INVALID
            continue
        acct = np.zeros(N_ACCT)
        out[i] = solve_scene(
            m[i, :k], lk[i, : k - 1], c[i, : k - 1], cp[i], v0[i], method, rtol, step_frac,
            etol, max_events, max_work, hist, acct, True, None, cap,
        )  # fmt: skip


def solve_scene_batch(
    m, lk, c, n, cp, v0, method, rtol, step_frac, etol, max_events, max_work, cap=HMAX_FREE
):
    """``solve_scene`` over padded rows: m (rows, nmax), lk (rows, nmax-1, N_SP),
    c (rows, nmax-1), n (rows,) int64 masses per row, cp (rows, N_CP), v0 (rows,), on numba's
    threads (kernels.parallel).

    Every row starts as NaN with STATUS_NOT_RUN before any work, so a row the kernel did not
    finish can never pass as a result. Rows are independent: bit-identical for any thread count.
    """
    m, lk, c, cp, v0 = (np.ascontiguousarray(a, dtype=np.float64) for a in (m, lk, c, cp, v0))
    n = np.ascontiguousarray(n, dtype=np.int64)
    out = np.full((n.size, N_OUT), np.nan)
    out[:, OUT_STATUS] = STATUS_NOT_RUN
    over_threads(
        _scene_rows, n.size, m, lk, c, n, cp, v0, int(method), float(rtol), float(step_frac),
        float(etol), int(max_events), float(max_work), float(cap), out,
    )  # fmt: skip
    return out


# --------------------------------------------------------------------- the trajectory sampler --
# ``sample_scene`` runs ``_adaptive``'s contact sequence again (a copy of its loop on the sampled
# phases of integrators.py: the same steps, the same events, the same arithmetic, so its
# result row is ``solve_scene``'s bit for bit) and evaluates the state at requested times:
# from each step's 7th-order dense output in time, from the dense output in sigma at the ends of
# power-law contacts (the sample's sigma found on the step's time component), in closed form in
# the free flight of two masses with a linear link. It records the time of every contact start
# and end (EV_START, EV_END) and of every impact at a rigid wall (EV_IMPACT).
EV_START = 0
EV_END = 1
EV_IMPACT = 2


@njit(cache=True, error_model="numpy", refcount=False)
def _free_linear_at(y0, m1, m2, k, c, s, out):
    """The state at local time s of the closed-form free flight of ``free_flight_linear`` from
    y0 (the same formulas; D gains the dashpot's loss)."""
    m = m1 + m2
    mu = m2 / m
    inv = 1.0 / m1 + 1.0 / m2
    w = math.sqrt(k * inv)
    xi = c * inv / (2.0 * w)
    v = (m1 * y0[2] + m2 * y0[3]) / m
    r0 = y0[1] - y0[0]
    w0 = (y0[3] - y0[2]) / w
    x = w * s
    dr, dw = _osc_change(x, xi, r0, w0)
    r = r0 + w0 * x + dr
    wr = w0 + dw
    e_before = 0.5 * mu * m1 * w * w * (r0 * r0 + w0 * w0)
    e_after = 0.5 * mu * m1 * w * w * (r * r + wr * wr)
    out[0] = y0[0] + y0[2] * s - mu * dr
    out[1] = out[0] + r
    out[2] = y0[2] - mu * w * dw
    out[3] = v + (m1 / m) * w * wr
    out[4] = y0[4]
    out[5] = y0[5] + e_before - e_after


@njit(cache=True, error_model="numpy", refcount=False)
def _sample_free_linear(y0, t0, t_hi, m, lk, c, ts, si, Ys, Fs):
    """Fill the samples in [t0, t_hi) from the closed-form free flight from y0 at t0."""
    while si[0] < ts.shape[0] and ts[si[0]] < t_hi:
        k = si[0]
        _free_linear_at(y0, m[0], m[1], lk[0, SP_K2], c[0], ts[k] - t0, Ys[k])
        Fs[k] = 0.0
        si[0] += 1


@njit(cache=True, error_model="numpy", refcount=False)
def _sample_elastic(y0, t0, t_hi, mem, m, lk, cp, ts, si, Ys, Fs):
    """Fill the samples in [t0, t_hi) from the closed-form elastic phase from y0 at t0."""
    while si[0] < ts.shape[0] and ts[si[0]] < t_hi:
        k = si[0]
        Fs[k] = elastic_at(
            y0, mem[M_XP], m[0], m[1], lk[0, SP_K2], cp[1], ts[k] - t0, Ys[k]
        )  # fmt: skip
        si[0] += 1


@njit(cache=True, error_model="numpy", refcount=False)
def _event(evt, evk, cnt, t, kind):
    j = cnt[0]
    if j < evt.shape[0]:
        evt[j] = t
        evk[j] = kind
        cnt[0] = j + 1


@njit(cache=True, error_model="numpy", inline="always")
def _sigma_entry_sampled(y, t, m, lk, c, cp, mem, rtol, atol, work, err_acc, ts, si, Ys, Fs):
    """``_sigma_entry`` on ``sigma_phase_sampled``."""
    n = m.shape[0]
    xd = -y[n]
    eta = cp[3]
    depth = ((eta + 1.0) * m[0] * xd * xd / (2.0 * cp[2])) ** (1.0 / (eta + 1.0))
    x_sw = _sigma_room(y, m, lk, c, cp, mem, SIGMA_ZONE * depth)
    if not x_sw > 0.0:
        return SIG_DONE, t
    return sigma_phase_sampled(
        y, t, math.sqrt(x_sw), rtol, atol, m, lk, c, cp, mem, work, err_acc, ts, si, Ys, Fs
    )


@njit(cache=True, error_model="numpy", inline="always")
def _adaptive_sampled(
    y, ysep, m, lk, c, cp, mem, rtol, max_events, work, hist, v0, ts, si, Ys, Fs,
    evt, evk, cnt, max_work, free0=False, cap=HMAX_FREE,
):  # fmt: skip
    """``_adaptive`` (free_closed = True) with the samples and the contact events recorded;
    after the last contact the free flight goes on until the last sample (its own work budget
    ``max_work``). ``free0``: a free flight first, as in ``_adaptive``."""
    n = m.shape[0]
    closed = n == 2 and lk[0, SP_KIND] == S_LINEAR
    elastic_closed = closed and cp[0] == C_PLASTIC and c[0] == 0.0
    ny = 2 * n + 2
    atol = rtol * v0
    kind = int(cp[0])
    W = np.zeros((2, ny))
    B = np.zeros(2)
    strip = np.zeros(2, dtype=np.int64)
    err_acc = np.zeros(1)
    guard = np.zeros(2)  # the Zeno guard's state (_contact_event)
    t_event = 0.0
    y0 = np.empty(ny)
    t = 0.0
    tcol = 0.0
    ncol = 1
    w_cont = chain_frequency_bound(m, lk, cp[1] if kind != C_RIGID else 0.0)
    w_free = chain_frequency_bound(m, lk, 0.0)
    if not w_free > 0.0:
        w_free = w_cont if w_cont > 0.0 else 1.0
    if not w_cont > 0.0:
        w_cont = w_free
    hc = contact_first_step(w_cont, rtol)
    hf = 0.05 / w_free
    hmax_free = cap / w_free
    h = hc
    p_in = _momentum(y, m)
    xmax_c = 0.0
    if free0:  # no contact yet: on to the free flight (as in _adaptive)
        ncol = 0
        h = hf
        mem[M_PHASE] = 0.0
    elif kind == C_RIGID:
        _record(hist, 0, H_TSTART, 0.0)
        _record(hist, 0, H_VIN, y[n] / v0)
        y[n] = -y[n]
        copy_into(ysep, y)
        _record(hist, 0, H_TEND, 0.0)
        _record(hist, 0, H_VOUT, y[n] / v0)
        _record(hist, 0, H_IMPULSE, (_momentum(y, m) - p_in) / v0)
        mem[M_PHASE] = 0.0
        _event(evt, evk, cnt, 0.0, EV_IMPACT)
    else:
        _record(hist, 0, H_TSTART, 0.0)
        _record(hist, 0, H_VIN, y[n] / v0)
        mem[M_PHASE] = 1.0
        mem[M_BRANCH] = 1.0
        _event(evt, evk, cnt, 0.0, EV_START)
    entering = True
    how = ENTER
    sigma_exit = True
    while True:
        power_entry = (
            kind == C_HERTZ or kind == C_HUNT_CROSSLEY or (kind == C_PLASTIC and mem[M_FMAX] == 0.0)
        )
        if mem[M_PHASE] == 1.0:
            if how == ENTER and mem[M_BRANCH] == 1.0 and power_entry:
                scode, t = _sigma_entry_sampled(
                    y, t, m, lk, c, cp, mem, rtol, atol, work, err_acc, ts, si, Ys, Fs
                )
                if scode == SIG_FAIL:
                    return _fail(work), ncol, tcol, err_acc[0]
                how = MID
            nev = _setup_contact_events(cp, mem, W, B, strip, how, n, guard[1])
            x_sw = 0.0
            power_exit = kind == C_HERTZ or kind == C_HUNT_CROSSLEY
            if power_exit and mem[M_BRANCH] == 0.0 and sigma_exit:
                x_sw = SIGMA_ZONE * xmax_c
                if -y[0] > x_sw:
                    B[0] -= x_sw
                else:
                    x_sw = 0.0
            code = EL_INTEGRATE
            if elastic_closed and mem[M_BRANCH] == 0.0:
                copy_into(y0, y)
                code, s, err = elastic_phase(
                    y, mem[M_XP], mem[M_XMAX], m[0], m[1], lk[0, SP_K2], cp[1], work
                )  # fmt: skip
                if code == EL_FAIL:
                    return _fail(work), ncol, tcol, err_acc[0]
                if code != EL_INTEGRATE:
                    _sample_elastic(y0, t, t + s, mem, m, lk, cp, ts, si, Ys, Fs)
                    t += s
                    err_acc[0] += err
                    h = hc
            if code == EL_INTEGRATE:
                code, t, h = rk_phase_sampled(
                    y, t, h, 1e300, rtol, atol, m, lk, c, cp, mem, W, B, strip, nev,
                    STOP_NEVER, work, err_acc, ts, si, Ys, Fs,
                )  # fmt: skip
            if code == EV_FAIL or code == EV_STOP:
                return _fail(work), ncol, tcol, err_acc[0]
            if code == 0 and x_sw > 0.0:
                y[0] = -x_sw
                scode = SIG_FAIL + 1
                if _sigma_room(y, m, lk, c, cp, mem, x_sw) == x_sw:
                    scode, t = sigma_phase_sampled(
                        y, t, 0.0, rtol, atol, m, lk, c, cp, mem, work, err_acc, ts, si, Ys, Fs
                    )  # fmt: skip
                if scode == SIG_FAIL:
                    return _fail(work), ncol, tcol, err_acc[0]
                if scode != SIG_DONE:
                    sigma_exit = False
                    how = MID
                    continue
            sigma_exit = True
            _leave_at_rest(code, y, m, lk, c, cp, mem, guard)
            how, xmax_c, separated = _contact_event(
                code, y, n, kind, cp, mem, how, xmax_c, t - t_event, h, atol, guard
            )
            t_event = t
            if separated:
                tcol = t
                copy_into(ysep, y)
                k = ncol - 1
                _record(hist, k, H_TEND, t)
                _record(hist, k, H_VOUT, y[n] / v0)
                _record(hist, k, H_XMAX, xmax_c)
                _record(hist, k, H_IMPULSE, (_momentum(y, m) - p_in) / v0)
                _event(evt, evk, cnt, t, EV_END)
                entering = True
                h = hf
        else:
            inside = kind == C_KELVIN_VOIGT and -y[0] > 0.0
            if inside:  # as in _adaptive: free inside the penetration, F = 0
                W[0, :] = 0.0
                W[1, :] = 0.0
                W[0, 0] = cp[2]
                W[0, n] = cp[3]
                B[0] = 0.0
                B[1] = 0.0
                W[1, 0] = -1.0
                strip[0] = 1
                strip[1] = 0
                code, t, h = rk_phase_sampled(
                    y, t, h, hmax_free, rtol, atol, m, lk, c, cp, mem, W, B, strip, 2,
                    STOP_NEVER, work, err_acc, ts, si, Ys, Fs,
                )  # fmt: skip
                if code == EV_FAIL or code == EV_STOP:
                    return _fail(work), ncol, tcol, err_acc[0]
                if code == 1:
                    y[0] = 0.0
                    inside = False
                else:
                    y[0] = -cp[3] * y[n] / cp[2]
                entering = True
            if inside:
                pass  # the force rose through 0: a contact starts below
            elif closed:
                copy_into(y0, y)
                s = free_flight_linear(y, mem[M_XP], m[0], m[1], lk[0, SP_K2], c[0])
                if s < 0.0:
                    _sample_free_linear(y0, t, math.inf, m, lk, c, ts, si, Ys, Fs)
                    return STATUS_OK, ncol, tcol, err_acc[0]
                _sample_free_linear(y0, t, t + s, m, lk, c, ts, si, Ys, Fs)
                _flight_rounding(y, m, err_acc)
                t += s
                work[0] -= 100.0
                if work[0] <= 0.0:
                    return STATUS_WORK_BUDGET, ncol, tcol, err_acc[0]
            else:
                W[0, :] = 0.0
                W[0, 0] = 1.0
                B[0] = mem[M_XP]
                strip[0] = 1 if entering else 0
                code, t, h = rk_phase_sampled(
                    y, t, h, hmax_free, rtol, atol, m, lk, c, cp, mem, W, B, strip, 1,
                    STOP_NO_CONTACT, work, err_acc, ts, si, Ys, Fs,
                )  # fmt: skip
                if code == EV_STOP:
                    # no contact any more: the free flight on to the last sample
                    more = np.zeros(1)
                    more[0] = max_work
                    rk_phase_sampled(
                        y, t, h, hmax_free, rtol, atol, m, lk, c, cp, mem, W, B, strip, 0,
                        STOP_SAMPLES, more, np.zeros(1), ts, si, Ys, Fs,
                    )  # fmt: skip
                    return STATUS_OK, ncol, tcol, err_acc[0]
                if code == EV_FAIL:
                    return _fail(work), ncol, tcol, err_acc[0]
                y[0] = -mem[M_XP]
            h = hc
            if ncol >= max_events:
                return STATUS_EVENT_BUDGET, ncol, tcol, err_acc[0]
            k = ncol
            ncol += 1
            xmax_c = -y[0]
            p_in = _momentum(y, m)
            _record(hist, k, H_TSTART, t)
            _record(hist, k, H_VIN, y[n] / v0)
            if kind == C_RIGID:
                y[n] = -y[n]
                tcol = t
                copy_into(ysep, y)
                _record(hist, k, H_TEND, t)
                _record(hist, k, H_VOUT, y[n] / v0)
                _record(hist, k, H_IMPULSE, (_momentum(y, m) - p_in) / v0)
                _event(evt, evk, cnt, t, EV_IMPACT)
                entering = True
                h = hf
            else:
                mem[M_PHASE] = 1.0
                if inside:  # the force rose through 0 at x > 0 while x' < 0: x still falls
                    mem[M_BRANCH] = 0.0
                elif contact_elastic(cp) or mem[M_FMAX] == 0.0:
                    mem[M_BRANCH] = 1.0
                else:
                    mem[M_BRANCH] = 0.0
                _event(evt, evk, cnt, t, EV_START)
                how = ENTER


@njit(cache=True, error_model="numpy")
def sample_scene(
    m, lk, c, cp, v0, rtol, etol, max_events, max_work, ts, hist, y0=None, cap=HMAX_FREE
):
    """The adaptive method's run of one chain (``solve_scene`` with method 0 and
    free_closed = True: the same result row, bit for bit) with its states at the sorted times
    ``ts`` (kernel units, >= 0).

    Returns (out, Ys, Fs, evt, evk): the result row, the states (len(ts), 2n + 2; NaN where
    the run stopped before), the contact law's force at each sample, and the contact events
    (times and kinds EV_START / EV_END / EV_IMPACT; at most 2 max_events of them). A sample at
    an event's time (the same float) is the state there after the event's switch: the start of
    the contact, the separation, the reversal of an impact; so a second run with the event
    times among the samples gives the states at the events. ``y0``: a given initial state, ``cap``
    the free flights' step cap, as in ``solve_scene``.
    """
    n = m.shape[0]
    ny = 2 * n + 2
    ns = ts.shape[0]
    Ys = np.full((ns, ny), np.nan)
    Fs = np.full(ns, np.nan)
    n_ev = 2 * max_events
    evt = np.full(n_ev, np.nan)
    evk = np.zeros(n_ev, dtype=np.int64)
    cnt = np.zeros(1, dtype=np.int64)
    acct = np.zeros(N_ACCT)
    out = np.full(N_OUT, np.nan)
    out[OUT_STATUS] = STATUS_INVALID
    out[OUT_NCOL] = 0.0
    out[OUT_NEVENTS] = 0.0
    if not input_ok(m, lk, c, cp, v0):
        return out, Ys, Fs, evt[:0], evk[:0]
    y = np.zeros(ny)
    for i in range(n):
        y[n + i] = -v0
    free0 = False
    p_scale = 0.0
    if y0 is not None:
        if not state_ok(y0, m):
            return out, Ys, Fs, evt[:0], evk[:0]
        for i in range(2 * n):
            y[i] = y0[i]
        free0 = y[n] > 0.0
        p_scale = -_momentum(y0, m)
    mem = np.zeros(N_MEM)
    ysep = y.copy()
    work = np.zeros(1)
    work[0] = max_work
    mt = 0.0
    for i in range(n):
        mt += m[i]
    si = np.zeros(1, dtype=np.int64)
    # samples at t <= 0 (only t = 0): the state at the first contact (after it, at a rigid wall)
    if cp[0] == C_RIGID and not free0:
        y[n] = -y[n]
        sample_here(y, 0.0, cp, mem, ts, si, Ys, Fs)
        y[n] = -y[n]
    else:
        sample_here(y, 0.0, cp, mem, ts, si, Ys, Fs)
    status, ncol, tcol, err = _adaptive_sampled(
        y, ysep, m, lk, c, cp, mem, rtol, max_events, work, hist, v0, ts, si, Ys, Fs,
        evt, evk, cnt, max_work, free0, cap,
    )  # fmt: skip
    out[OUT_NCOL] = ncol
    out[OUT_NEVENTS] = ncol
    out[OUT_TCOL] = tcol
    _energies(ysep, m, lk, v0, out, acct, y0)
    out[OUT_ERR] = err / (mt * v0)
    if y0 is not None:
        out[OUT_ERR] = err / p_scale
    if status == STATUS_OK and not abs(acct[4]) <= etol:
        status = STATUS_ENERGY
    if status == STATUS_OK and acct[2] < -etol:
        status = STATUS_ENERGY
    if status == STATUS_OK and not (
        math.isfinite(out[OUT_COR]) and math.isfinite(out[OUT_TCOL]) and math.isfinite(out[OUT_ERR])
    ):
        status = STATUS_NONCONVERGED
    if status != STATUS_OK and status != STATUS_ENERGY:
        out[OUT_COR] = np.nan
    out[OUT_STATUS] = status
    k = cnt[0]
    return out, Ys, Fs, evt[:k], evk[:k]
