"""Event toolkit shared by the exact kernels: the scalar damped oscillator, exponential-sum gaps
with derivative bounds, the rigorous event locator, and dissipation integrals in closed form
(Gauss-Legendre where the closed form's terms would cancel).

A gap in any phase of a linear chain is f(t) = c0 + c1 t + Re sum_k b_k (e^{lambda_k t} - 1),
Re lambda <= 0 (the free flight of two masses, the scalar oscillator below, is walked in closed
form by restitution.kernels.rigid2 instead). For s >= t and m >= 2,
|f^(m)(s)| <= B_m(t) = sum_k |b_k| |lambda_k|^m e^{Re lambda_k t}. The locator steps by the
largest h for which the cubic lower bound f + f' h + f'' h^2/2 - B3 h^3/6 stays above the
touching band -tol, so no step can cross a point where f < -tol, and it certifies a crossing
with the quadratic upper bound f + f' h + B2 h^2/2 or the cubic one f + f' h + f'' h^2/2 +
B3 h^3/6 (f strictly decreasing up to the root, then safeguarded Newton). Where the rates
present differ by more than SPLIT_RATIO (a contact spring much stiffer than the chain), it also
steps on the slow part g of f, with the fast modes bounded by their amplitude A (f >= g - A),
and takes the longer of the two safe steps: a long contact ringing at the contact frequency is
crossed in a few steps, not ten per ringing period. See restitution.kernels.exact_chain for the
model
that uses it.
"""

import cmath
import math

import numpy as np

from restitution.jit import njit
from restitution.kernels.constants import EPS
from restitution.kernels.roots import bisection, first_cubic_root, newton_polish

# Touching band, in ulps of the gap's own round-off scale at that moment (_eval_gap's res[7]):
# the computed gap is within ~1.5 of them of its exact value (measured against mpmath on the
# free flights of 16 random chains, N = 8..16, ratios 1e-2..1e4), so a dip deeper than
# BAND_ULPS of them is a contact. (It was 64 ulps of a scale without the phase-rounding term:
# dips 8..64 ulps deep, real contacts, were passed as grazes.)
BAND_ULPS = 8.0
# The replica check certifies the touching decision (kernels.chain._checked_units): its two
# replicas locate contacts with bands of BAND_LOW and BAND_HIGH times the band, so a dip whose
# depth is within round-off of the band's edge is counted by one run and not by another, and
# the spread (the COR's jump across that cusp) enters the error estimate.
BAND_LOW = 0.25
BAND_HIGH = 2.0
# A dip is a pass worth recording once the gap has opened beyond PASS_OPEN bands since the
# phase start (the start itself, a separation at gap 0, is no pass); see _locate.
PASS_OPEN = 4.0
# The pass replica's contact: as deep as the deepest dip the band passes, and round-off.
PASS_DEPTH = 1.25
N_INFO = 7
MAX_STEPS = 400_000  # conservative steps per phase
SPLIT_RATIO = 8.0  # rates this far apart: the locator also steps on the slow part (_split)
N_RES = 14  # entries of _eval_gap's result (with the two-scale split)

# Locator outcomes.
LOC_EVENT = 0
LOC_NEVER = 1
LOC_BUDGET = 2
LOC_PERMANENT = 3


# Gauss-Legendre on [-1, 1]. With 32 nodes on sub-intervals of length GL_H/max|lambda| the
# quadrature error for products of exponentials is ~1e-31 (relative): exact to round-off.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(32)
GL_H = 12.0
ANCHOR = 32  # exponentials advanced by recurrence are re-anchored this often (no error growth)
# A closed-form dissipation integral whose terms sum (in magnitude) to more than this multiple of
# the result would lose more than ~1e-12 of it to cancellation (measured: <= 2e-13 up to 1e3,
# 2e-12 up to 1e4, against Gauss-Legendre, over the phases of 20 damped N = 8 chains): there
# Gauss-Legendre is used instead. (64 sent a third of those phases to the quadrature.)
CANCEL_MAX = 1e3

# ----------------------------------------------------------------------------------------------
# The scalar damped oscillator r'' + 2 xi r' + r = 0 (free phase of two masses)
# ----------------------------------------------------------------------------------------------


@njit(cache=True, refcount=False)
def _cs(xi, t):
    """(e^{-xi t} C(t), e^{-xi t} S(t)) with C = cos(wt)|cosh(gt)|1, S = sin(wt)/w|sinh(gt)/g|t."""
    d = 1.0 - xi * xi
    x = -d * t * t
    if abs(x) < 0.5:
        # Series: C = sum x^j/(2j)!, S = t sum x^j/(2j+1)!; no 0/0 at xi = 1.
        c = 1.0
        s = 1.0
        tc = 1.0
        ts = 1.0
        for j in range(1, 14):
            tc *= x / ((2 * j - 1) * (2 * j))
            ts *= x / ((2 * j) * (2 * j + 1))
            c += tc
            s += ts
        e = math.exp(-xi * t)
        return e * c, e * s * t
    if d > 0.0:
        w = math.sqrt(d)
        e = math.exp(-xi * t)
        return e * math.cos(w * t), e * math.sin(w * t) / w
    g = math.sqrt(-d)
    slow = math.exp(-t / (xi + g))  # e^{(g - xi) t} without cancellation
    fast = math.exp(-(xi + g) * t)
    return 0.5 * (slow + fast), 0.5 * (slow - fast) / g


@njit(cache=True, refcount=False)
def _osc(xi, r0, rd0, t):
    ce, se = _cs(xi, t)
    return r0 * ce + (rd0 + xi * r0) * se, rd0 * ce - (r0 + xi * rd0) * se


# ----------------------------------------------------------------------------------------------
# Gap evaluation with derivative bounds over [t, inf)
# ----------------------------------------------------------------------------------------------


@njit(cache=True, refcount=False)
def _eval_gap(t, c0, c1, b, lam, res, split=math.inf):
    """res = f, f', f'', f''', B0, B2, B3, scale, X at phase time t: B_m bounds |f^(m)| on
    [t, inf) (m = 0: the oscillating part f - X only). ``scale`` is the round-off scale of f at
    t: the magnitudes of the terms that cancel in it, |c0| + |c1 t| + |w0| and each mode's
    |b_k e^{lambda_k t}| (1 + |lambda_k| t) (the exponential's argument lambda_k t is rounded
    to eps |lambda_k t|).

    With a finite ``split`` (res then has 14 entries): also the slow part g (f without
    the modes with |lambda| > split), g', g'', its B3, and A = sum over the fast modes of
    |b_k| e^{Re lambda_k t}, which bounds |f - g| on [t, inf).
    """
    f = c0 + c1 * t
    f1 = c1
    f2 = 0.0
    f3 = 0.0
    b0 = 0.0
    b2 = 0.0
    b3 = 0.0
    # f = c0 + c1 t + (osc(t) - osc(0)), so that f(0) = c0 exactly: the modal reconstruction of
    # u1 at a phase start is only good to eps * |state|, which may exceed the band of f's terms.
    w0 = 0.0
    osc = 0.0
    gosc = 0.0
    g1 = c1
    g2 = 0.0
    g3b = 0.0
    afast = 0.0
    bphase = 0.0
    for k in range(b.size):
        w0 += b[k].real
        lk = lam[k]
        e = b[k] * cmath.exp(lk * t) if t != 0.0 else b[k]  # (every phase starts at t = 0)
        le = lk * e
        l2e = lk * le
        osc += e.real
        f1 += le.real
        f2 += l2e.real
        f3 += (lk * l2e).real
        a = math.sqrt(e.real * e.real + e.imag * e.imag)  # |e| (hypot is 5x slower)
        al = math.sqrt(lk.real * lk.real + lk.imag * lk.imag)
        b0 += a
        bphase += a * al
        b2 += a * al * al
        b3 += a * al * al * al
        if al > split:
            afast += a
        else:
            gosc += e.real
            g1 += le.real
            g2 += l2e.real
            g3b += a * al * al * al
    if split < math.inf:
        res[9] = f + (gosc - w0)
        res[10] = g1
        res[11] = g2
        res[12] = g3b
        res[13] = afast
    res[0] = f + (osc - w0)
    res[1] = f1
    res[2] = f2
    res[3] = f3
    res[4] = b0
    res[5] = b2
    res[6] = b3
    res[7] = abs(c0) + abs(c1 * t) + abs(w0) + b0 + bphase * t
    res[8] = c0 - w0 + c1 * t


@njit(cache=True, refcount=False)
def _eval_f(t, c0, c1, b, lam, res):
    """res[0], res[1] = f, f' at phase time t: _eval_gap's first two entries by the same
    arithmetic (bit for bit), without the derivative bounds the root polish does not use."""
    f1 = c1
    w0 = 0.0
    osc = 0.0
    for k in range(b.size):
        w0 += b[k].real
        lk = lam[k]
        e = b[k] * cmath.exp(lk * t)
        osc += e.real
        f1 += (lk * e).real
    res[0] = c0 + c1 * t + (osc - w0)
    res[1] = f1


@njit(cache=True, refcount=False)
def _f_df(t, c0, c1, b, lam, res):
    """(f, f') at phase time t (``_eval_f``, which leaves them in res[0], res[1])."""
    _eval_f(t, c0, c1, b, lam, res)
    return res[0], res[1]


_polish_gap = newton_polish(_f_df)


@njit(cache=True, refcount=False)
def _refine(lo, hi, c0, c1, b, lam, res, at_lo=False):
    """Root of the gap on [lo, hi], f(lo) > 0 > f(hi) (f strictly decreasing on [lo, hi], or at
    least past its last crossing): safeguarded Newton to machine precision (roots.newton_polish).
    ``at_lo``: res already holds the gap at lo (the locator's last step end), so it is not
    evaluated again."""
    if not at_lo:
        _eval_f(lo, c0, c1, b, lam, res)
    return _polish_gap(lo, hi, res[0], res[1], (c0, c1, b, lam, res))


@njit(cache=True, refcount=False)
def _dominant_real(b, lam):
    """Index of the slowest-decaying term if it is real and decays slower than all others (the
    only case in which a damped contact can last for ever), else -1."""
    kmax = -1
    lr = -math.inf
    for k in range(b.size):
        if b[k] != 0.0 and lam[k].real > lr:
            lr = lam[k].real
            kmax = k
    if kmax < 0 or abs(lam[kmax].imag) > 1e-12 * abs(lam[kmax]):
        return -1
    for k in range(b.size):
        if k != kmax and b[k] != 0.0 and lam[k].real >= lr - 1e-12 * abs(lr):
            return -1
    return kmax


@njit(cache=True, refcount=False)
def _never_ends(t, b, lam, tol, kmax):
    """Proof that a damped contact never ends: the slowest real term (kmax, from
    _dominant_real) outweighs all others now, hence forever (all others decay faster)."""
    dom = (b[kmax] * cmath.exp(lam[kmax] * t)).real
    rest = 0.0
    for k in range(b.size):
        if k != kmax and b[k] != 0.0:
            rest += abs(b[k]) * math.exp(lam[k].real * t)
    return dom - rest > tol


@njit(cache=True, refcount=False)
def _split(b, lam):
    """|lambda| above which _locate bounds a mode by its amplitude alone (inf: no split): the
    geometric mean of the slowest and fastest rates present, where they differ by more than
    SPLIT_RATIO."""
    lo = math.inf
    hi = 0.0
    for k in range(b.size):
        if b[k] != 0.0:
            al = abs(lam[k])
            lo = min(lo, al)
            hi = max(hi, al)
    if not (hi > SPLIT_RATIO * lo):
        return math.inf
    return math.sqrt(lo * hi)


@njit(cache=True, refcount=False)
def _closest_pass(info, low, t, f2, unit):
    """Keep (low / unit, t, v) in info[4:7] if it is the lowest pass so far; v is the approach
    speed of a dip PASS_DEPTH bands deep at the curvature f2 there."""
    r = low / unit
    if r < info[4]:
        info[4] = r
        info[5] = t
        info[6] = math.sqrt(2.0 * max(f2, 0.0) * PASS_DEPTH * unit)


@njit(cache=True)
def _locate(c0, c1, b, lam, check_permanent, info, max_steps=MAX_STEPS, res=None, band=1.0):
    """First time the gap goes below the touching band; see the module docstring.

    Returns a LOC_* code; info = [event time, max gap, time of max gap, steps, closest pass,
    its time, the approach speed of a contact there PASS_DEPTH bands deep] (N_INFO entries).
    The closest pass is the lowest point of the gap the locator stepped over once the gap had
    opened beyond PASS_OPEN bands, in units of the band (band = 1): gap 0 is 0 and the band's
    edge -1 (exact_chain._checked_units re-runs a dip that may be a contact). ``res``: an
    optional scratch array of N_RES entries (a kernel passes one for all its phases).
    ``band``: the band's width in units of BAND_ULPS ulps of the gap's scale (the replica
    check's runs use BAND_LOW and BAND_HIGH, see there).
    """
    if res is None:
        res = np.empty(N_RES)
    t = 0.0
    fmax = -math.inf
    tmax = 0.0
    split = _split(b, lam)
    kdom = _dominant_real(b, lam) if check_permanent else -1
    _eval_gap(t, c0, c1, b, lam, res, split)
    # The band is round-off of the gap's own scale at each moment (res[7]). It never shrinks
    # below its value at the phase start, which binds only where a damped motion decays: the
    # constant w0 = sum Re b_k(0) in f (its asymptote c0 + c1 t - w0) carries the rounding of
    # the modal projection of the start state, ~eps * sum |b_k(0)|, for ever (else
    # exponentially small lobes of a damped approach, e.g. V = 0, would count as contacts).
    # Undamped phases: res[7] never falls below its start value, so the floor never binds.
    ulps = band * BAND_ULPS * EPS
    tol0 = ulps * res[7] + 1e-300
    t_pos = -1.0  # last step end with f > 0 (none yet)
    info[4] = math.inf
    info[5] = -1.0
    info[6] = 0.0
    for it in range(max_steps):
        if it > 0:  # (res holds the gap at t = 0 already)
            _eval_gap(t, c0, c1, b, lam, res, split)
        f = res[0]
        f1 = res[1]
        f2 = res[2]
        b2 = res[5]
        b3 = res[6]
        tol = max(ulps * res[7], tol0)
        info[3] = it
        if f > fmax:
            fmax = f
            tmax = t
        info[1] = fmax
        info[2] = tmax
        # f(s) >= X(t) - B0(t) for all s >= t when V >= 0: never below the band again.
        if c1 >= 0.0 and res[8] - res[4] > -0.5 * tol0:
            return LOC_NEVER
        if kdom >= 0 and _never_ends(t, b, lam, tol + abs(res[8]), kdom):
            return LOC_PERMANENT
        # A step may end just past the root of f (it only keeps f >= -tol): a near-parabolic
        # shallow flight lands it at f ~ -tol. The root is then in [t_pos, t] (t_pos = the last
        # step end with f > 0), not at t: polishing from t itself misplaced dashpot-chatter
        # contacts by tol/|f'| ~ 1e-9 at approach speeds ~1e-5 (COR off by 2e-9 over 1725 contacts).
        lo = t if (f > 0.0 or t_pos < 0.0) else t_pos
        if f < -tol:  # only by round-off at a step end: the crossing is in [lo, t]
            info[0] = _refine(lo, t, c0, c1, b, lam, res) if lo < t else t
            return LOC_EVENT
        if f1 < 0.0:
            if b2 > 0.0:
                reach = -f1 / b2
                dip = f + 0.5 * f1 * reach
            else:
                reach = 2.0 * (f + tol) / -f1
                dip = -math.inf
            if dip >= -tol and b3 > 0.0:
                # The cubic upper bound f + f' s + f'' s^2/2 + B3 s^3/6 (f'' from the Taylor
                # remainder with |f'''| <= B3) is tighter where the curvature is known: its slope
                # f' + f'' s + B3 s^2/2 (an upper bound of f'(t + s), convex in s) stays < 0 up
                # to its root s1, so f decreases strictly on [t, t + s1); a dip below the band
                # there certifies the crossing one step earlier.
                s1 = (-f2 + math.sqrt(f2 * f2 - 2.0 * b3 * f1)) / b3
                dip3 = f + s1 * (f1 + s1 * (0.5 * f2 + s1 * b3 / 6.0))
                if dip3 < -tol:
                    reach = s1
                    dip = dip3
            if dip < -tol:  # f strictly decreasing on [t, t + reach]
                hi = t if lo < t else t + reach  # the root is behind t if f(t) <= 0
                info[0] = _refine(lo, hi, c0, c1, b, lam, res, lo == t)
                return LOC_EVENT
        if f > 0.0:
            t_pos = t
        opened = fmax > PASS_OPEN * tol
        if opened:  # a step end passed (above the band): the closest pass so far?
            _closest_pass(info, f, t, f2, tol / band)
        h = first_cubic_root(f + tol, f1, f2, b3)
        if split < math.inf:
            # Two time scales (a contact spring much stiffer than the chain): the fast modes
            # ring inside the slow motion, and bound the cubic's step to a fraction of their
            # period. f >= g - A on [t, inf) (g: the slow part, A: the fast amplitude now), so
            # a step that keeps g - A above the band is as safe and, deep in a long contact,
            # spans many fast periods.
            gap = res[9] - res[13] + tol
            if gap > 0.0:
                h = max(h, first_cubic_root(gap, res[10], res[11], res[12]))
        if h == math.inf:
            return LOC_NEVER
        if h <= 4.0 * EPS * max(t, 1.0):
            # Stalled on a tangency exactly at the band edge: it is a graze by the rule; pass it.
            h = max(first_cubic_root(f + 2.0 * tol, f1, f2, b3), 4.0 * EPS * max(t, 1.0))
        if opened and f1 < 0.0 and f2 > 0.0 and -f1 <= f2 * h:
            # The step spans the bottom of a dip: its quadratic model's vertex is the pass.
            s = -f1 / f2
            _closest_pass(info, f + 0.5 * f1 * s, t + s, f2, tol / band)
        t += h
    return LOC_BUDGET


@njit(cache=True, refcount=False)
def _slope(t, c0, c1, b, lam, res):
    """f'(t) (``_eval_gap``, which leaves it in res[1])."""
    _eval_gap(t, c0, c1, b, lam, res)
    return res[1]


_bisect_slope = bisection(_slope)


@njit(cache=True)
def _xmax(t0, tend, c0, c1, b, lam):
    """Largest gap on [0, tend] (history only).

    A long damped contact rings with many local maxima, so a Newton climb from the locator's best
    sample (t0, kept as a candidate) can stop on a lower one: that left x_max 2% low for the last
    contact at alpha = 100, beta = 1e-3, xi = 0.3. Instead f' is scanned at 1/16 of the fastest
    ringing period, every + to - sign change is bisected on f' to round-off, and the largest f
    wins; two maxima inside one scan step would need content faster than the fastest mode.
    """
    res = np.empty(9)
    _eval_gap(t0, c0, c1, b, lam, res)
    best = res[0]
    rate = 0.0
    for k in range(lam.size):
        rate = max(rate, abs(lam[k].imag), abs(lam[k].real))
    n = 1 if rate == 0.0 else min(max(int(math.ceil(tend * rate * 8.0 / math.pi)), 1), 4_000_000)
    h = tend / n
    _eval_gap(0.0, c0, c1, b, lam, res)
    best = max(best, res[0])
    slope = res[1]
    for i in range(1, n + 1):
        t = tend if i == n else i * h
        _eval_gap(t, c0, c1, b, lam, res)
        best = max(best, res[0])
        if slope > 0.0 and res[1] <= 0.0:
            lo, hi = _bisect_slope(t - h, t, (c0, c1, b, lam, res))
            _eval_gap(0.5 * (lo + hi), c0, c1, b, lam, res)
            best = max(best, res[0])
            _eval_gap(t, c0, c1, b, lam, res)
        slope = res[1]
    return best


# ----------------------------------------------------------------------------------------------
# State propagation and dissipation
# ----------------------------------------------------------------------------------------------


@njit(cache=True, refcount=False)
def _modal_state(t, z, lam, U, X0, V, u, v):
    """u, v at phase time t from modal coefficients z (plus centre-of-mass motion X0 + V t)."""
    n = U.shape[0]
    for i in range(n):
        u[i] = 0.0
        v[i] = 0.0
    for k in range(z.size):  # (each u[i], v[i] still sums over k in order: no allocation)
        ez = z[k] * cmath.exp(lam[k] * t)
        lz = lam[k] * ez
        for i in range(n):
            u[i] += (U[i, k] * ez).real
            v[i] += (U[i, k] * lz).real
    for i in range(n):
        u[i] = X0 + V * t + u[i]
        v[i] = V + v[i]


@njit(cache=True, refcount=False)
def _scalar_state(t, xi, r0, rd0, mu, u10, V, u, v):
    r, rd = _osc(xi, r0, rd0, t)
    u[0] = u10 + V * t - mu * (r - r0)
    u[1] = u[0] + r
    v[0] = V - mu * rd
    v[1] = V + (1.0 - mu) * rd


@njit(cache=True, refcount=False)
def _scalar_advance(t, xi, r0, rd0, mu, u, v):
    """Advance a two-mass free flight from (u, v) at its start to phase time t in place, the
    velocities by increments (v1 - mu dr', v2 + (1 - mu) dr', momentum-conserving): m1's small
    chatter speeds then carry no rounding of V or mu (see _eval_gap)."""
    r, rd = _osc(xi, r0, rd0, t)
    drd = rd - rd0
    u[0] = u[0] + (v[0] + mu * rd0) * t - mu * (r - r0)
    u[1] = u[0] + r
    v[0] = v[0] - mu * drd
    v[1] = v[1] + (1.0 - mu) * drd


_RECIP = 1.0 / np.arange(1.0, 22.0)  # 1 / (j + 1): the series multiplies, never divides


@njit(cache=True, refcount=False)
def _phi1_series(x):
    """(e^x - 1) / x for complex |x| < 1/2 by its Taylor series sum x^j / (j + 1)!, Horner
    form, with as many terms as |x| needs (the first omitted term, x^(n+1) / (n+2)!, is below
    1e-19: n = 7 for |x| < 0.02, 10 for |x| < 0.1, 16 up to 1/2): no cancellation near 0."""
    ax = abs(x.real) + abs(x.imag)  # >= |x|
    n = 7 if ax < 0.02 else (10 if ax < 0.1 else 16)
    acc = 1.0 + 0.0j
    for j in range(n, 0, -1):
        acc = 1.0 + acc * (x * _RECIP[j])
    return acc


@njit(cache=True, refcount=False)
def _j_term(x, ex, T):
    """T (e^x - 1) / x given ex = e^x (x = s T, Re x <= 0): the integral of e^{s t} over [0, T].
    Below |x| = 1/2 the series (no cancellation in e^x - 1); above it e^x - 1 has an absolute
    error ~eps |e^x| <= eps, i.e. relative <= 3 eps."""
    ax2 = x.real * x.real + x.imag * x.imag
    if ax2 < 0.25:  # |x| < 1/2
        return T * _phi1_series(x)
    return ((ex - 1.0) * x.conjugate()) * (T / ax2)  # (a real factor: no complex division)


@njit(cache=True)
def _diss_modal(T, g, lam, c):
    """Integral of c (Re sum g_k e^{lam_k t})^2 over [0, T], in closed form.

    With (Re S)^2 = Re(S^2 + S conj(S)) / 2 the integral is a sum over pairs (p, q) of
    c/2 Re[g_p g_q J(lam_p + lam_q) + g_p conj(g_q) J(lam_p + conj(lam_q))],
    J(s) = (e^{sT} - 1) / s, evaluated stably near s = 0 (undamped conjugate pairs give s = 0
    exactly: J = T; see _j_term). It uses only g, lam and T, not the state propagation, so the
    energy account stays an independent check.

    Each term carries a rounding error ~eps |g_p| |g_q| |J|; where the terms cancel (their
    magnitudes sum to more than CANCEL_MAX times the integral: modes with large opposite
    amplitudes near a repeated eigenvalue, or a short interval of a small relative velocity) the
    Gauss-Legendre quadrature _diss_modal_gl, whose error grows only linearly in that
    cancellation, is used instead.
    """
    if c == 0.0 or T <= 0.0:
        return 0.0
    J1, J2 = _pair_integrals(T, lam)
    return _diss_pairs(T, g, lam, c, J1, J2)


@njit(cache=True)
def _pair_integrals(T, lam):
    """J1[p, q] = J(lam_p + lam_q) and J2[p, q] = J(lam_p + conj(lam_q)) for q >= p (see
    _diss_modal): they depend on the phase only, so every dashpot of a phase shares them.
    e^{(lam_p + lam_q) T} is formed as the product e^{lam_p T} e^{lam_q T} (one complex
    exponential per mode, not per pair)."""
    nk = lam.size
    E = np.empty(nk, np.complex128)
    for k in range(nk):
        E[k] = cmath.exp(lam[k] * T)
    J1 = np.empty((nk, nk), np.complex128)
    J2 = np.empty((nk, nk), np.complex128)
    for p in range(nk):
        lp = lam[p]
        ep = E[p]
        for q in range(p, nk):
            lq = lam[q]
            eq = E[q]
            J1[p, q] = _j_term((lp + lq) * T, ep * eq, T)
            J2[p, q] = _j_term((lp + lq.conjugate()) * T, ep * eq.conjugate(), T)
    return J1, J2


@njit(cache=True, refcount=False)
def _pair_sum(g, J1, J2):
    """(sum over pairs of Re[g_p g_q J1_pq + g_p conj(g_q) J2_pq], a bound on the sum of the
    terms' magnitudes); see _diss_modal."""
    nk = g.size
    acc = 0.0
    mag = 0.0
    for p in range(nk):
        gp = g[p]
        if gp == 0.0:
            continue
        agp = abs(gp)
        for q in range(p, nk):
            gq = g[q]
            if gq == 0.0:
                continue
            w = 1.0 if q == p else 2.0  # (p, q) and (q, p) give the same (real part of) term
            a1 = gp * gq * J1[p, q]
            a2 = gp * gq.conjugate() * J2[p, q]
            acc += w * (a1.real + a2.real)
            # The rounding of a term is ~eps |g_p| |g_q| |J|, not eps |term|: the real part of
            # a product can cancel inside it (a near-critical mode pair kept once, with weight
            # 2, cancels there instead of against its dropped conjugate).
            mag += w * agp * abs(gq) * (abs(J1[p, q]) + abs(J2[p, q]))
    return acc, mag


@njit(cache=True)
def _diss_pairs(T, g, lam, c, J1, J2):
    """_diss_modal with the phase's pair integrals given (the GL fallback needs T and lam)."""
    acc, mag = _pair_sum(g, J1, J2)
    if not (mag <= CANCEL_MAX * abs(acc)):
        return _diss_modal_gl(T, g, lam, c)
    return 0.5 * c * acc


@njit(cache=True)
def _diss_modal_gl(T, g, lam, c):
    """Integral of c (Re sum g_k e^{lam_k t})^2 over [0, T] by Gauss-Legendre (round-off exact):
    the fallback of _diss_modal where its pair sum would cancel."""
    if c == 0.0 or T <= 0.0:
        return 0.0
    nk = g.size
    ng = _GL_X.size
    lmax = 1e-300
    for k in range(nk):
        if g[k] != 0.0:
            lmax = max(lmax, abs(lam[k]))
    nsub = max(int(math.ceil(T * lmax / GL_H)), 1)
    h = T / nsub
    # e^{lam t} at the nodes = e^{lam t_s} * E[k, j]; e^{lam t_s} advanced by a factor per
    # sub-interval and recomputed from scratch every ANCHOR sub-intervals.
    E = np.empty((nk, ng), np.complex128)
    step = np.empty(nk, np.complex128)
    base = np.empty(nk, np.complex128)
    for k in range(nk):
        step[k] = cmath.exp(lam[k] * h)
        for j in range(ng):
            E[k, j] = cmath.exp(lam[k] * (0.5 * h * (1.0 + _GL_X[j])))
    acc = 0.0
    for s in range(nsub):
        if s % ANCHOR == 0:
            for k in range(nk):
                base[k] = g[k] * cmath.exp(lam[k] * (s * h))
        bmax = 0.0
        for k in range(nk):
            bmax = max(bmax, abs(base[k]))
        cut = 1e-18 * bmax  # terms this small change the integrand below round-off
        part = 0.0
        for j in range(ng):
            val = 0.0
            for k in range(nk):
                if abs(base[k]) > cut:
                    val += (base[k] * E[k, j]).real
            part += _GL_W[j] * val * val
        acc += part
        for k in range(nk):
            base[k] *= step[k]
    return c * 0.5 * h * acc


@njit(cache=True, refcount=False)
def _diss_modal_inf(g, lam, c):
    """Integral of c (Re sum g_k e^{lam_k t})^2 over [0, inf), in closed form.

    With x_k = g_k e^{lam_k t}, (Re sum x)^2 = 1/2 sum_pq Re(x_p x_q + x_p conj(x_q)), whose
    integrals are g_p g_q / -(lam_p + lam_q) and g_p conj(g_q) / -(lam_p + conj(lam_q)). For a
    permanent contact, whose decay can be 1e10 times slower than its fastest mode, so that
    quadrature to "infinity" would need ~1e11 sub-intervals. Returns inf if a term present does
    not decay (the motion never comes to rest: the caller's energy check then fails).
    """
    if c == 0.0:
        return 0.0
    acc = 0.0
    for p in range(g.size):
        if g[p] == 0.0:
            continue
        for q in range(g.size):
            if g[q] == 0.0:
                continue
            a = lam[p] + lam[q]
            b = lam[p] + lam[q].conjugate()
            if a.real >= 0.0 or b.real >= 0.0:
                return math.inf
            acc += (g[p] * g[q] / -a).real + (g[p] * g[q].conjugate() / -b).real
    return 0.5 * c * acc


@njit(cache=True)
def _diss_scalar(T, xi, r0, rd0, c):
    """Integral of c r'^2 over [0, T], r'' + 2 xi r' + r = 0, in closed form.

    r' = e^{-xi t} (A C(t) + B S(t)) with A = rd0, B = -(r0 + xi rd0) (see _osc) is written as
    an exponential sum, Re g e^{lam t} with lam = -xi + i w, g = A - i B / w (xi < 1), or two
    real terms with lam = -xi -+ sqrt(xi^2 - 1) (xi > 1), and integrated by _pair_sum. Near
    xi = 1 the amplitudes grow like 1 / |1 - xi^2|^(1/2) and cancel; there (and at xi = 1, no
    exponential sum) Gauss-Legendre on the closed-form r', _diss_scalar_gl, is used.
    """
    if c == 0.0 or T <= 0.0:
        return 0.0
    a = rd0
    bb = -(r0 + xi * rd0)
    d = 1.0 - xi * xi
    if d > 0.0:
        # one term: _pair_sum's single pair (p = q = 0) written out (no arrays: this runs once
        # per free flight of every damped two-mass scene)
        w = math.sqrt(d)
        g0 = complex(a, -bb / w)
        lam0 = complex(-xi, w)
        if g0 == 0.0:
            return 0.0
        e0 = cmath.exp(lam0 * T)
        j1 = _j_term((lam0 + lam0) * T, e0 * e0, T)
        j2 = _j_term((lam0 + lam0.conjugate()) * T, e0 * e0.conjugate(), T)
        a1 = g0 * g0 * j1
        a2 = g0 * g0.conjugate() * j2
        acc = a1.real + a2.real
        mag = abs(g0) * abs(g0) * (abs(j1) + abs(j2))
        if not (mag <= CANCEL_MAX * abs(acc)):
            return _diss_scalar_gl(T, xi, r0, rd0, c)
        return 0.5 * c * acc
    elif d < 0.0:
        s = math.sqrt(-d)
        g = np.empty(2, np.complex128)
        lam = np.empty(2, np.complex128)
        g[0] = 0.5 * (a + bb / s)
        g[1] = 0.5 * (a - bb / s)
        lam[0] = -1.0 / (xi + s)  # = s - xi without cancellation
        lam[1] = -(xi + s)
    else:
        return _diss_scalar_gl(T, xi, r0, rd0, c)
    J1, J2 = _pair_integrals(T, lam)
    acc, mag = _pair_sum(g, J1, J2)
    if not (mag <= CANCEL_MAX * abs(acc)):
        return _diss_scalar_gl(T, xi, r0, rd0, c)
    return 0.5 * c * acc


@njit(cache=True, refcount=False)
def _diss_scalar_gl(T, xi, r0, rd0, c):
    """Integral of c r'^2 over [0, T] by Gauss-Legendre (round-off exact): the fallback of
    _diss_scalar."""
    if c == 0.0 or T <= 0.0:
        return 0.0
    lmax = max(1.0, xi + math.sqrt(max(xi * xi - 1.0, 0.0)))
    nsub = max(int(math.ceil(T * lmax / GL_H)), 1)
    h = T / nsub
    acc = 0.0
    for s in range(nsub):
        part = 0.0
        for j in range(_GL_X.size):
            t = (s + 0.5 + 0.5 * _GL_X[j]) * h
            rd = _osc(xi, r0, rd0, t)[1]
            part += _GL_W[j] * rd * rd
        acc += part
    return c * 0.5 * h * acc
