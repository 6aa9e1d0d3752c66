"""Exact impulsive solver: two masses, rigid wall (beta = 0), optional dashpot between them.

Units (docs/physics.md): m1 = 1, V0 = 1, omega = 1, alpha = m2/m1, mu = alpha/(1 + alpha).
Between contacts the centre of mass X moves at constant V and the relative coordinate
r = u2 - u1 obeys r'' + 2 xi r' + r = 0; m1 sits at u1 = X - mu r. Each contact reverses m1's
velocity (paper Eq. 13) and leaves m2's untouched. Time is measured from the previous contact
(local time s), where the gap is exactly g(0) = u1 = 0, so

    g(s) = V s - mu (r(s) - r0)         (V, r0 = r(0), w0 = r'(0) just after the contact).

Finding the next contact never samples g:

* xi = 0: the critical points of g are closed-form, its minima are 2 pi apart and their values
  change by 2 pi V per period. The first negative minimum is reached directly (a ceil when
  V < 0), the root is bracketed between it and the preceding maximum (g is monotone there) and
  polished with a safeguarded Newton. V >= 0 and a non-negative next minimum prove that no
  contact follows (the minima never decrease).
* xi > 0: g'' = mu (r + 2 xi r') solves the same damped equation, so its zeros are closed-form;
  g' is monotone between them (its zeros, the critical points of g, are bracketed), and g is
  monotone between its critical points (roots are bracketed). The walk stops when a decreasing
  piece of g ends below zero (a contact), when g is increasing for ever (no more zeros of g''
  and V >= 0), or when the envelope bound |r(s)| <= e^(-lam s) (|r0| + |b| s) proves that
  V s + mu r0 - mu |r(s)| stays positive (V >= 0).

Contact rule (touching). A local minimum of g is a contact when g_min < -tol with
tol = 16 eps ((|V| + mu |w0|) s + mu (|r0| + |r(s)|)), i.e. the gap is negative by more than a
few ulps of the terms it is computed from (velocity errors grow with s). Minima within
round-off of zero (exact grazing, the values alpha*_n where the contact count steps) are not
contacts. This keeps the COR continuous across alpha*_n: a contact that just qualifies has
approach speed ~sqrt(2 g'' tol) ~ 1e-7, hence an impulse ~1e-7.

Energies are fractions of the initial kinetic energy (1 + alpha)/2, taken at the final
separation: e_translational = cor^2, e_vibrational = relative kinetic + spring energy just after
the last contact (with a dashpot it will be dissipated later), e_dissipated = integral of
c r'^2 from the first to the last contact, by Gauss-Legendre quadrature of the closed-form r'
(independent of the other two, so the sum-to-one is a real check; STATUS_ENERGY if it fails).

Chatter and sticking (damped, large alpha; e.g. alpha = 200, xi = 3). After a few contacts the
spring and dashpot press m1 against the wall. In this perfectly elastic impulsive model m1 then
chatters: bounce speeds decay only like 1/k (k = contact index), so the contact count grows
exponentially with the pressed time (~1e39 contacts for alpha = 200, xi = 3); no event budget
can finish it. Its limit is sticking: m1 at rest on the wall while the force on it,
k2 (r + 2 xi r'), is compressive; m2 then moves on the spring and dashpot alone (closed form,
frequency 1/sqrt(1 + alpha)) and m1 lifts off at the first zero of that force (closed form).
The kernel switches to sticking when, after at least STICK_AFTER = 2000 contacts (shorter
chatters are finished exactly), a contact has approach speed v1 below V_STICK_RIGID2 = 1e-3 under
a compressive force (the dropped 0.5 v1^2, < 5e-7, is booked as dissipated), records the
sticking phase as one contact interval (H_TEND = lift-off, H_VOUT = 0) and sets OUT_ERR to
v1^2. The COR error of the cut-off shrinks like its square: cut-offs 1e-1, 1e-2, 1e-3 move the
COR by 1e-5, 4e-8, 8e-10 against 1e-4 (alpha = 30, xi = 1), <= 1e-3 v1^2, so v1^2 bounds it
with a safety factor of ~1000. (The cut-off was 1e-4 before; chatter speeds decay only like 1/k,
so alpha = 150 and 200 at xi = 0.5 needed more than 100,000 contacts to get there.) Where the
pure chatter finishes (alpha = 200, xi = 0.3: 35,808 contacts) the two agree to ~1e-7 in the
COR. Without a compressive force there is no chatter and the method stays exact (OUT_ERR = 0).
xi = 0 never sticks.
"""

import math

import numpy as np
from numba import prange

from restitution.jit import njit
from restitution.kernels.constants import (
    ENERGY_TOL,
    EPS,
    ROUNDOFF_ULPS,
    STICK_AFTER,
    V_STICK_RIGID2,
)
from restitution.kernels.copies import put_row
from restitution.kernels.layout import (
    FLAG_STICKING,
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
    STATUS_NONCONVERGED,
    STATUS_OK,
)
from restitution.kernels.parallel import row_blocks
from restitution.kernels.replica import (
    JITTER,
    PURE_SAFETY,
    REPLICA_SEED,
    REPLICAS,
    STICK_BUDGET_RIGID2,
    STICK_SAFETY,
    combine,
    finished,
    stick_check,
    weyl,
)
from restitution.kernels.roots import (
    expansion,
    halley_bracketed,
    hermite_cubic_root,
    newton_bracketed,
    newton_descent,
)

# A damping ratio below the smallest normal float moves the COR by O(xi), far below an ulp, but
# subnormal arithmetic in the damped closed-form walk fails (event_not_converged): it is 0.
XI_NEGLIGIBLE = 2.2250738585072014e-308
_TOUCH = 16.0  # contact if g_min < -_TOUCH * eps * (scale of the terms of g)
_MAX_WALK = 1_000_000  # zeros of g'' visited in one contact search before giving up
_TWO_PI = 2.0 * math.pi

# 20-point Gauss-Legendre on [-1, 1]: exact to round-off for e^(c s) pieces with |c h| <= 4.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(20)


# ---------------------------------------------------------------------------------------------
# Shared helpers
# ---------------------------------------------------------------------------------------------
@njit(cache=True)
def _tol(V, mu, r0, w0, rs, s):
    """Round-off scale of g(s): below -tol a minimum is a contact.

    The velocities V and w0 carry absolute errors of a few ulps of |V| + mu |w0|, which grow
    linearly in s in the gap; positions those of mu (|r0| + |r(s)|).
    """
    return _TOUCH * EPS * ((abs(V) + mu * abs(w0)) * s + mu * (abs(r0) + abs(rs)) + 1e-300)


@njit(cache=True)
def _s_minus_sin(s):
    """s - sin(s) without cancellation (series below 1)."""
    if s >= 1.0:
        return s - math.sin(s)
    s2 = s * s
    term = s * s2 / 6.0
    acc = term
    k = 3.0
    while abs(term) > 1e-18 * abs(acc):
        term *= -s2 / ((k + 1.0) * (k + 2.0))
        acc += term
        k += 2.0
    return acc


# ---------------------------------------------------------------------------------------------
# xi = 0: closed-form motion and critical points
# ---------------------------------------------------------------------------------------------
@njit(cache=True)
def _gap0(s, V, mu, r0, w0):
    """g(s), g'(s), g''(s) for xi = 0 (r = r0 cos s + w0 sin s), written without cancellation."""
    sh = math.sin(0.5 * s)
    ch = math.cos(0.5 * s)
    sn = 2.0 * sh * ch
    sh2 = sh * sh
    v = V - mu * w0  # m1's speed leaving the wall
    if s < 1.0:  # near the contact g ~ v s: keep v explicit so small v stays accurate
        g = v * s + mu * w0 * _s_minus_sin(s) + 2.0 * mu * r0 * sh2
    else:
        g = V * s + 2.0 * mu * r0 * sh2 - mu * w0 * sn
    gp = v + 2.0 * mu * w0 * sh2 + mu * r0 * sn
    gpp = mu * (r0 * (1.0 - 2.0 * sh2) + w0 * sn)  # = mu r(s)
    return g, gp, gpp


_halley_gap0 = halley_bracketed(_gap0)  # (lo, hi, x, (V, mu, r0, w0))


@njit(cache=True)
def _next_contact0(V, mu, r0, w0):
    """Local time of the next contact for xi = 0, or -1.0 if there is none; flag for failure.

    Minima of g are at s_k = phi - asin(V/A) + 2 pi k (A = mu R), preceded by maxima at
    s_k - pi + 2 asin(V/A); g(s_{k+1}) = g(s_k) + 2 pi V exactly.
    """
    R = math.hypot(r0, w0)
    A = mu * R
    if V >= A:  # g' >= 0 for ever
        return -1.0, True
    if V <= -A:  # g' <= 0 for ever: degenerate (cannot follow a genuine contact)
        return 0.0, False
    phi = math.atan2(w0, r0)
    asn = math.asin(V / A)
    smin = phi - asn
    while smin <= 0.0:
        smin += _TWO_PI
    while smin - _TWO_PI > 0.0:
        smin -= _TWO_PI
    gmin = _gap0(smin, V, mu, r0, w0)[0]
    tol = _tol(V, mu, r0, w0, R, smin)
    if gmin >= -tol:
        if V >= 0.0:  # minima never decrease: proof that no contact follows
            return -1.0, True
        # Minima fall by 2 pi |V| per period: jump straight to the first negative one.
        j = math.floor((gmin + tol) / (-_TWO_PI * V)) + 1.0
        smin += _TWO_PI * j
        gmin = _gap0(smin, V, mu, r0, w0)[0]
        while gmin >= -_tol(V, mu, r0, w0, R, smin):  # round-off in the jump
            smin += _TWO_PI
            gmin = _gap0(smin, V, mu, r0, w0)[0]
        # The jump may overshoot by one period when the extrapolation rounded the other way.
        prev = smin - _TWO_PI
        if prev > 0.0:
            gprev = _gap0(prev, V, mu, r0, w0)[0]
            if gprev < -_tol(V, mu, r0, w0, R, prev):
                smin = prev
    lo = max(smin - math.pi + 2.0 * asn, 0.0)
    # Start from a half cosine through (lo, g(lo)) and (smin, gmin): exact for V = 0, close
    # otherwise, so the safeguarded Halley iteration needs two or three steps.
    # g at the maximum in closed form (only a starting guess needs it): cos(s - phi) = -c.
    glo = V * lo + mu * r0 + A * math.sqrt((1.0 - V / A) * (1.0 + V / A)) if lo > 0.0 else 0.0
    c = -(glo + gmin) / (glo - gmin)
    x = lo + (smin - lo) * math.acos(max(-1.0, min(1.0, c))) / math.pi
    if not (lo < x < smin):
        x = 0.5 * (lo + smin)
    return _halley_gap0(lo, smin, x, (V, mu, r0, w0))


# ---------------------------------------------------------------------------------------------
# xi > 0: numerically stable basis of the damped relative motion
# ---------------------------------------------------------------------------------------------
@njit(cache=True)
def _basis(s, xi, q, w):
    """(E C, E S, E C - 1) at s, with E = e^(-xi s), C = cos/cosh(w s), S = sin/sinh(w s)/w.

    q = 1 - xi^2 (sign selects the regime), w = sqrt(|q|). Any solution of
    y'' + 2 xi y' + y = 0 is y(s) = y0 E C + (y0' + xi y0) E S. The forms avoid 0/0 and
    overflow: the overdamped pair uses expm1, so nothing degrades as xi -> 1 from either side.
    """
    if q > 0.0:
        e = math.exp(-xi * s)
        c = math.cos(w * s)
        sh = math.sin(0.5 * w * s)
        return e * c, e * math.sin(w * s) / w, math.expm1(-xi * s) * c - 2.0 * sh * sh
    if q == 0.0:
        e = math.exp(-s)
        return e, s * e, math.expm1(-s)
    l1 = 1.0 / (xi + w)  # = xi - w without cancellation
    e1 = math.exp(-l1 * s)
    z = math.expm1(-2.0 * w * s)
    ecm1 = 0.5 * (math.expm1(-l1 * s) + math.expm1(-(xi + w) * s))  # no cancellation: both < 0
    return e1 * (1.0 + 0.5 * z), -e1 * z / (2.0 * w), ecm1


# 1 / ((n + 2)(n + 1)) of the Taylor recurrences below: a multiply, not a divide, in the loop's
# dependency chain (the series runs in every gap evaluation of a short damped flight).
_INV_N2N1 = 1.0 / ((np.arange(60) + 2.0) * (np.arange(60) + 1.0))


@njit(cache=True)
def _small_d(s, xi):
    """D1 = E S - s and D2 = E C - 1 + xi E S (both O(s^2)) by Taylor series, for small s."""
    # Taylor coefficients of the impulse response h (h0=0, h1=1) and of c (c0=1, c1=0).
    h0, h1, c0, c1 = 0.0, 1.0, 1.0, 0.0
    d1 = 0.0
    d2 = 0.0
    sp = s
    x2 = 2.0 * xi
    for n in range(0, 60):
        inv = _INV_N2N1[n]
        kn = x2 * (n + 1)
        h2 = -(kn * h1 + h0) * inv
        c2 = -(kn * c1 + c0) * inv
        sp *= s
        t1 = h2 * sp
        t2 = c2 * sp
        d1 += t1
        d2 += t2
        if abs(t1) <= 1e-18 * abs(d1) and abs(t2) <= 1e-18 * abs(d2) and n > 2:
            break
        h0, h1, c0, c1 = h1, h2, c1, c2
    return d1, d2


@njit(cache=True)
def _gapd(s, V, mu, xi, q, w, r0, w0):
    """g(s), g'(s), g''(s) and r(s) for xi > 0."""
    ec, es, ecm1 = _basis(s, xi, q, w)
    b = w0 + xi * r0
    v = V - mu * w0
    if s * (1.0 + 2.0 * xi) < 0.5:  # near the contact: g = v s - mu (w0 D1 + r0 D2)
        d1, d2 = _small_d(s, xi)
        g = v * s - mu * (w0 * d1 + r0 * d2)
    else:
        g = V * s - mu * (r0 * ecm1 + b * es)
    rp = w0 * ec - (r0 + xi * w0) * es
    if s < 1.0:  # g' = v - mu (r'(s) - w0), accurate for small v near the contact
        gp = v - mu * (w0 * ecm1 - (r0 + xi * w0) * es)
    else:  # r' has decayed: keep its small value exact
        gp = V - mu * rp
    rs = r0 * ec + b * es
    gpp = mu * (rs + 2.0 * xi * rp)
    return g, gp, gpp, rs


@njit(cache=True)
def _g(s, V, mu, xi, q, w, r0, w0):
    """(g, g') at s for xi > 0."""
    g, gp, _, _ = _gapd(s, V, mu, xi, q, w, r0, w0)
    return g, gp


@njit(cache=True)
def _dg(s, V, mu, xi, q, w, r0, w0):
    """(g', g'') at s for xi > 0."""
    _, gp, gpp, _ = _gapd(s, V, mu, xi, q, w, r0, w0)
    return gp, gpp


_newton_g = newton_bracketed(_g)
_newton_dg = newton_bracketed(_dg)
_expand_g = expansion(_g)
_expand_dg = expansion(_dg)
_newton_concave = newton_descent(_g)  # (x, args): g concave and decreasing left of x


@njit(cache=True)
def _newton_d(lo, hi, which, V, mu, xi, q, w, r0, w0):
    """Root of g (which=0) or g' (which=1) on [lo, hi], f monotone, f(lo), f(hi) of opposite
    sign (or zero): bracketed Newton with bisection safeguard (roots.newton_bracketed)."""
    args = (V, mu, xi, q, w, r0, w0)
    if which == 0:
        return _newton_g(lo, hi, args)
    return _newton_dg(lo, hi, args)


@njit(cache=True)
def _next_zero(a, d, s_after, xi, q, w):
    """First zero > s_after of y = a E C + (d + xi a) E S (y(0) = a, y'(0) = d); inf if none."""
    bb = d + xi * a
    if q > 0.0:  # zeros at (x0 + k pi)/w with tan(x0) = -a w / bb
        if a == 0.0 and bb == 0.0:
            return math.inf
        x0 = math.atan2(a * w, -bb)
        if x0 <= 0.0:
            x0 += math.pi
        k = math.floor((w * s_after - x0) / math.pi) + 1.0
        if k < 0.0:
            k = 0.0
        s = (x0 + k * math.pi) / w
        while s <= s_after:
            k += 1.0
            s = (x0 + k * math.pi) / w
        return s
    if q == 0.0:  # y = e^(-s) (a + bb s)
        if bb == 0.0:
            return math.inf
        s = -a / bb
        return s if s > s_after else math.inf
    den = bb - a * w  # overdamped: z = e^(-2 w s) = (a w + bb) / (bb - a w)
    if den == 0.0:
        return math.inf
    zm1 = 2.0 * a * w / den
    if not (-1.0 < zm1 < 0.0):
        return math.inf
    s = -math.log1p(zm1) / (2.0 * w)
    return s if s > s_after else math.inf


@njit(cache=True)
def _env_proof(s, V, mu, xi, q, w, r0, w0):
    """True if V s' + mu r0 - mu |r(s')| >= -tol for every s' >= s (no contact after s)."""
    if V < 0.0:
        return False
    b = abs(w0 + xi * r0)
    p = abs(r0)
    lam = xi if q >= 0.0 else 1.0 / (xi + w)
    # |r| <= e^(-lam s)(p + b s): its maximum on [s, inf) is at max(s, 1/lam - p/b).
    sm = s
    if b > 0.0:
        sm = max(s, 1.0 / lam - p / b)
    m = math.exp(-lam * sm) * (p + b * sm)
    if q > 0.0:  # also |sin(w s)/w| <= 1/w
        m = min(m, math.exp(-lam * s) * (p + b / w))
    elif q < 0.0:  # and sinh-part <= e^(-lam s)/(2 w)
        m = min(m, math.exp(-lam * s) * (p + b / (2.0 * w)))
    return V * s + mu * r0 - mu * m >= -_tol(V, mu, r0, w0, m, s)


@njit(cache=True)
def _expand(lo, which, sgn, V, mu, xi, q, w, r0, w0, thresh):
    """On a monotone tail, double the step until sgn f(hi) < thresh (f = g or g';
    roots.expansion)."""
    args = (V, mu, xi, q, w, r0, w0)
    if which == 0:
        return _expand_g(lo, sgn, thresh, args)
    return _expand_dg(lo, sgn, thresh, args)


@njit(cache=True)
def _next_contact_d(V, mu, xi, q, w, r0, w0):
    """Local time of the next contact for xi > 0, or -1.0 if there is none; flag for failure.

    Walks the intervals between closed-form zeros of g''; g' is monotone on each, so every
    critical point of g is bracketed, and g is monotone between critical points.
    """
    ay = r0 + 2.0 * xi * w0  # y = g''/mu = r + 2 xi r', which solves the same equation
    dy = w0 - 2.0 * xi * (r0 + 2.0 * xi * w0)
    sa = 0.0
    ga = 0.0  # g and g' at s = 0, as _gapd gives them there (exactly)
    gpa = V - mu * w0
    top = 0.0  # start of the current decreasing piece of g (a maximum, or 0)
    for _ in range(_MAX_WALK):
        sb = _next_zero(ay, dy, sa, xi, q, w)
        if sb < math.inf:
            gb, gpb, _, rsb = _gapd(sb, V, mu, xi, q, w, r0, w0)
        else:
            gb, rsb = -math.inf, 0.0  # (unused)
            gpb = V  # r' -> 0
        if sb == math.inf and V == 0.0 and gpa < 0.0:  # g falls for ever towards mu r0
            if mu * r0 >= -_tol(V, mu, r0, w0, 0.0, sa):
                return -1.0, True
            hi = _expand(sa, 0, 1.0, V, mu, xi, q, w, r0, w0, 0.5 * mu * r0)
            return _newton_d(top, hi, 0, V, mu, xi, q, w, r0, w0)
        if gpa >= 0.0 and gpb < 0.0:  # a maximum of g inside [sa, sb]
            if sb < math.inf and gb < -_tol(V, mu, r0, w0, rsb, sb):
                # g is concave on [sa, sb] and crosses zero after its maximum: Newton from the
                # right of the crossing converges to it monotonically, never past it, so the
                # maximum itself is not needed. Its start: one Newton step from the root of
                # the Hermite cubic of g on [sa, sb] (any Newton step from where g falls lands
                # right of the crossing, g being concave), else sb itself.
                x = sb
                xg = hermite_cubic_root(sa, ga, gpa, sb, gb, gpb)
                if sa < xg < sb:
                    g1, gp1, _, _ = _gapd(xg, V, mu, xi, q, w, r0, w0)
                    if gp1 < 0.0:
                        x = min(xg - g1 / gp1, sb)
                return _newton_concave(x, (V, mu, xi, q, w, r0, w0))
            hi = sb if sb < math.inf else _expand(sa, 1, 1.0, V, mu, xi, q, w, r0, w0, 0.0)
            if hi == math.inf:
                return 0.0, False
            top, ok = _newton_d(sa, hi, 1, V, mu, xi, q, w, r0, w0)
            if not ok:
                return 0.0, False
        elif gpa < 0.0 and gpb >= 0.0:  # a minimum inside: contact if it is below zero
            hi = sb if sb < math.inf else _expand(sa, 1, -1.0, V, mu, xi, q, w, r0, w0, 0.0)
            if hi == math.inf:
                return 0.0, False
            c, ok = _newton_d(sa, hi, 1, V, mu, xi, q, w, r0, w0)
            if not ok:
                return 0.0, False
            g, _, _, rs = _gapd(c, V, mu, xi, q, w, r0, w0)
            if g < -_tol(V, mu, r0, w0, rs, c):
                return _newton_d(top, c, 0, V, mu, xi, q, w, r0, w0)
        if gpb < 0.0:  # g decreasing at sb, monotone on [top, sb]: has it crossed zero?
            if sb == math.inf:  # decreasing for ever (V < 0): a contact
                base = max(sa, top)
                g, _, _, rs = _gapd(base, V, mu, xi, q, w, r0, w0)
                hi = base
                thresh = -_tol(V, mu, r0, w0, rs, base)
                if g >= thresh:
                    hi = _expand(base, 0, 1.0, V, mu, xi, q, w, r0, w0, thresh)
                if hi == math.inf:
                    return 0.0, False
                return _newton_d(top, hi, 0, V, mu, xi, q, w, r0, w0)
            if gb < -_tol(V, mu, r0, w0, rsb, sb):
                return _newton_d(top, sb, 0, V, mu, xi, q, w, r0, w0)
        if sb == math.inf:  # increasing for ever from a non-negative minimum
            return -1.0, True
        if gpb >= 0.0 and _env_proof(sb, V, mu, xi, q, w, r0, w0):
            return -1.0, True
        sa = sb
        ga = gb
        gpa = gpb
    return 0.0, False


@njit(cache=True)
def _dissipated(L, xi, q, w, r0, w0):
    """Integral of r'(s)^2 over [0, L] by composite 20-point Gauss-Legendre (exact to round-off:
    each piece has |rate x length| <= 4)."""
    fast = 2.0 * (xi + w) if q < 0.0 else 2.0  # fastest exponential rate in r'^2
    h_fast = min(1.0, 4.0 / fast)
    t_fast = min(L, 40.0 / fast) if q < 0.0 else 0.0  # beyond, the fast mode is < 1e-17
    acc = 0.0
    a = 0.0
    while a < L:
        h = h_fast if a < t_fast else 1.0
        b = min(a + h, L)
        half = 0.5 * (b - a)
        mid = 0.5 * (a + b)
        part = 0.0
        for i in range(_GL_X.shape[0]):
            ec, es, _ = _basis(mid + half * _GL_X[i], xi, q, w)
            rp = w0 * ec - (r0 + xi * w0) * es
            part += _GL_W[i] * rp * rp
        acc += half * part
        a = b
    return acc


@njit(cache=True)
def _advance(s, xi, q, w, r0, w0):
    """r and r' at local time s."""
    if xi == 0.0:
        c = math.cos(s)
        sn = math.sin(s)
        return r0 * c + w0 * sn, -r0 * sn + w0 * c
    ec, es, _ = _basis(s, xi, q, w)
    return r0 * ec + (w0 + xi * r0) * es, w0 * ec - (r0 + xi * w0) * es


# ---------------------------------------------------------------------------------------------
# Public kernels
# ---------------------------------------------------------------------------------------------
@njit(cache=True)
def _stick(alpha, xi, r0, v2):
    """Sticking phase: m1 rests on the wall, m2 moves on the spring and dashpot.

    With tau = s / sqrt(1 + alpha), r = u2 obeys r_tt + 2 xi2 r_t + r = 0, xi2 = xi/sqrt(1 + a).
    m1 lifts off when the spring + dashpot force on it, k2 (r + 2 xi r'), turns tensile: the
    first zero of a solution of the same equation, closed-form.

    Returns
    -------
    s_lift, r, r' at lift-off (s_lift = inf: m1 never lifts off), integral of r'^2 ds.
    """
    sq = math.sqrt(1.0 + alpha)
    xi2 = xi / sq
    q2 = (1.0 - xi2) * (1.0 + xi2)
    w2 = math.sqrt(abs(q2))
    rt = v2 * sq  # dr/dtau
    ay = r0 + 2.0 * xi2 * rt
    dy = rt - 2.0 * xi2 * (r0 + 2.0 * xi2 * rt)
    tau = _next_zero(ay, dy, 0.0, xi2, q2, w2)
    if tau == math.inf:
        return math.inf, 0.0, 0.0, 0.0
    r, rtl = _advance(tau, xi2, q2, w2, r0, rt)
    return tau * sq, r, rtl / sq, _dissipated(tau, xi2, q2, w2, r0, rt) / sq


@njit(cache=True)
def _record(hist, n, t0, t1, vin, vout, impulse):
    if n < hist.shape[0]:
        hist[n, H_TSTART] = t0
        hist[n, H_TEND] = t1
        hist[n, H_VIN] = vin
        hist[n, H_VOUT] = vout
        hist[n, H_XMAX] = 0.0
        hist[n, H_IMPULSE] = impulse


@njit(cache=True)
def _rigid2(alpha, xi, max_events, hist, v_stick, jitter=0.0, seed=0):
    """rigid2 with an explicit sticking threshold (v_stick = 0: never stick, pure chatter) and
    no replica check; ``jitter`` > 0 perturbs the state (V, r, r') by that much (relative) at
    every contact, along the Weyl sequence from ``seed`` (restitution.kernels.replica)."""
    out = np.zeros(N_OUT)
    if xi < XI_NEGLIGIBLE:
        xi = 0.0
    mu = alpha / (1.0 + alpha)
    q = (1.0 - xi) * (1.0 + xi)  # 1 - xi^2 without cancellation near xi = 1
    w = math.sqrt(abs(q))
    status = STATUS_OK
    V = -1.0  # state just before the first contact (t = 0)
    r0 = 0.0
    rp = 0.0
    t = 0.0  # time of the contact being processed
    t_sep = 0.0  # time of the last separation
    n = 0
    diss = 0.0  # integral of r'^2 (dashpot work / c)
    lost = 0.0  # m1's kinetic energy dropped on entering a sticking phase
    err = 0.0
    jc = seed  # index into the jitter's Weyl sequence
    while True:
        if n >= max_events:
            status = STATUS_EVENT_BUDGET
            break
        if jitter > 0.0:
            V *= 1.0 + jitter * weyl(jc)
            r0 *= 1.0 + jitter * weyl(jc + 1)
            rp *= 1.0 + jitter * weyl(jc + 2)
            jc += 3
        v1 = min(V - mu * rp, 0.0)  # m1's approach speed (<= 0)
        if xi > 0.0 and n >= STICK_AFTER and -v1 < v_stick and r0 + 2.0 * xi * rp < 0.0:
            # Chatter under a compressive force: its limit is sticking (see module docstring).
            v2 = V + (1.0 - mu) * rp
            s_l, r_l, rp_l, d = _stick(alpha, xi, r0, v2)
            lost += 0.5 * v1 * v1
            err = max(err, v1 * v1)  # bound of the cut-off's COR error (docstring)
            if s_l == math.inf:  # pressed for ever: everything comes to rest on the wall
                _record(hist, n, t, math.inf, v1, 0.0, (1.0 + alpha) * (0.0 - V))
                n += 1
                lost += 0.5 * alpha * v2 * v2 + 0.5 * mu * r0 * r0
                V, r0, rp, t_sep = 0.0, 0.0, 0.0, math.inf
                break
            _record(hist, n, t, t + s_l, v1, 0.0, (1.0 + alpha) * (mu * rp_l - V))
            n += 1
            diss += d
            t += s_l
            V = mu * rp_l  # m1 at rest: V = alpha v2/(1 + alpha), r' = v2
            r0 = r_l
            w0 = rp_l
        else:
            _record(hist, n, t, t, v1, -v1, -2.0 * v1)
            n += 1
            V -= 2.0 * v1 / (1.0 + alpha)  # the wall's impulse -2 v1 acts on m1 only
            w0 = rp + 2.0 * v1
        t_sep = t
        if xi == 0.0:
            s, ok = _next_contact0(V, mu, r0, w0)
        else:
            s, ok = _next_contact_d(V, mu, xi, q, w, r0, w0)
        rp = w0
        if not ok:
            status = STATUS_NONCONVERGED
            break
        if s < 0.0:  # no further contact, proven
            break
        if n >= max_events:  # a further contact exists but is over budget: state at t_sep
            status = STATUS_EVENT_BUDGET
            break
        if xi > 0.0:
            diss += _dissipated(s, xi, q, w, r0, w0)
        r0, rp = _advance(s, xi, q, w, r0, w0)
        t += s
    e_kin0 = 0.5 * (1.0 + alpha)
    out[OUT_COR] = V
    out[OUT_NCOL] = n
    out[OUT_TCOL] = t_sep
    out[OUT_ETRANS] = V * V
    out[OUT_EVIB] = 0.5 * mu * (rp * rp + r0 * r0) / e_kin0
    out[OUT_EDISS] = (2.0 * xi * mu * diss + lost) / e_kin0
    out[OUT_NEVENTS] = n
    out[OUT_ERR] = max(err, ROUNDOFF_ULPS * EPS * max(n, 1))  # round-off floor per contact
    out[OUT_FLAGS] = FLAG_STICKING if lost > 0.0 else 0
    total = out[OUT_ETRANS] + out[OUT_EVIB] + out[OUT_EDISS]
    if status == STATUS_OK and abs(total - 1.0) > ENERGY_TOL:
        status = STATUS_ENERGY
    out[OUT_STATUS] = status
    return out


@njit(cache=True)
def rigid2(alpha, xi, max_events, hist):
    """Two masses against a rigid wall (beta = 0), with a dashpot of damping ratio xi.

    Parameters
    ----------
    alpha : float
        Mass ratio m2/m1 > 0.
    xi : float
        Damping ratio of the dashpot between m1 and m2 (>= 0; 0 = undamped).
    max_events : int
        Contact budget; STATUS_EVENT_BUDGET if the sequence needs more (the outputs then
        describe the state after the last processed contact).
    hist : ndarray, shape (rows, N_HIST)
        Filled with one row per contact while rows remain (pass shape (0, N_HIST) for none).

    Returns
    -------
    out : ndarray, shape (N_OUT,)
        Layout of restitution.kernels.layout. OUT_ERR is the round-off bound: ROUNDOFF_ULPS ulps
        per contact, or what the replica check reveals (restitution.kernels.replica; a scene
        whose replica moves the COR by more than ILL_TOL is STATUS_ILL_CONDITIONED); where a
        sticking phase replaced a chatter, at least the square of the speed at which chatter
        was cut and 4 times the COR's change when it is cut at half that speed
        (``replica.stick_check``).

    Examples
    --------
    >>> out = rigid2(1.0, 0.0, 100, np.zeros((0, N_HIST)))
    >>> round(float(out[OUT_COR]), 12), int(out[OUT_NCOL])
    (1.0, 2)
    """
    out = _rigid2(alpha, xi, max_events, hist, V_STICK_RIGID2, 0.0)
    if not finished(out[OUT_STATUS]):
        return out
    reps = np.empty((REPLICAS, N_OUT))
    for r in range(REPLICAS):
        seed = r * REPLICA_SEED
        a = alpha * (1.0 + JITTER * weyl(seed))
        x = xi * (1.0 + JITTER * weyl(seed + 1))
        reps[r] = _rigid2(a, x, max_events, np.zeros((0, N_HIST)), V_STICK_RIGID2, JITTER, seed + 2)
    out = combine(out, reps)
    if int(out[OUT_FLAGS]) & FLAG_STICKING:  # the cut-off, measured (replica.stick_check)
        nohist = np.zeros((0, N_HIST))
        budget = min(max_events, int(STICK_BUDGET_RIGID2 * out[OUT_NCOL]) + 100)
        pure = _rigid2(alpha, xi, budget, nohist, 0.0, 0.0)
        if finished(pure[OUT_STATUS]):
            return stick_check(out, pure, PURE_SAFETY)
        half = _rigid2(alpha, xi, max_events, nohist, 0.5 * V_STICK_RIGID2, 0.0)
        out = stick_check(out, half, STICK_SAFETY)
    return out


@njit(parallel=True, cache=True)
def rigid2_batch(alpha, xi, max_events):
    """rigid2 over arrays alpha, xi (same length); rows independent, so any thread count gives
    bit-identical results.

    Returns
    -------
    out : ndarray, shape (n, N_OUT)
    """
    n = alpha.shape[0]
    out = np.empty((n, N_OUT))
    nb, size, p = row_blocks(n)  # rows spread over the threads (kernels.parallel)
    for j in prange(nb):
        b = (j * p) % nb
        for i in range(b * size, min(n, b * size + size)):
            put_row(out, i, rigid2(alpha[i], xi[i], max_events, np.zeros((0, N_HIST))))
    return out
