"""Closed-form elastic phase of the plastic contact for two masses on an undamped linear link.

Below its largest penetration the paper's plastic law (Sec. 3.1) is the straight line
F = k1 (x - xp) (x = -u1, xp the dent): with the dent as origin, u~ = u + xp, the two masses are
the linear system m1 u~1'' = -k1 u~1 + k (u~2 - u~1), m2 u~2'' = -k (u~2 - u~1), solved in its two
modes. So an unloading or reloading phase is a closed form, not an integration: the adaptive
method integrates only the power-law loading (``stepping._adaptive``; measured on the benchmark's
plastic scene, the elastic phases took three quarters of its right-hand-side evaluations).

The phase ends at the first of two events of f = u~1 (a sum of two sinusoids): separation, f
rises through 0 (x falls to the dent), and reload, f falls through -L with L = xmax - xp (x
reaches xmax: the power law again). They are located as ``stepping.free_flight_linear`` locates
its contact: a scan whose intervals are passed only where the bound |f''| <= G2 proves that f
stays strictly between the two levels (the linear interpolation's error G2 h**2/8), and a
crossing is polished only on an interval where f is proven monotone (|f' - f'(s)| <= G2 (t - s)),
so it is the first one. A phase that starts on a level leaves it by its first nonzero derivative:
at the surface (a contact from the free flight) f' = v1 < 0; after the turn at xmax, f' = 0 and
f'' > 0 (the bound G3 on f''' keeps f above -L over the first stretch). Any other start returns
``EL_INTEGRATE`` and the caller integrates the phase as before.

Energy: the contact's work W gains k1 (f_end**2 - f_start**2) / 2 (the line's stored energy),
exactly; no dashpot. Round-off: the state is formed once from the modal amplitudes, with an error
of a few ulps of the modal velocities and of the phase w T; that momentum error is returned for
the adaptive run's sum of local errors (its estimate's floor: both of its runs share this phase).
"""

import math

from restitution.jit import njit
from restitution.kernels.constants import EPS
from restitution.kernels.roots import newton_bisection

EL_SEPARATED = 0  # the event codes of the contact branch's rows (stepping._setup_contact_events)
EL_RELOAD = 1
EL_INTEGRATE = -1  # a start this closed form does not take: the caller integrates the phase
EL_FAIL = -2  # the work budget ran out

# The scan's evaluations of f per unit of the work budget: about one right-hand side each.
EVAL_WORK = 1.0
# The state's rounding, in ulps of the modal velocities times (1 + the phase w T): the modal
# projection, two sinusoids and the way back (a handful of operations each).
ROUND_ULPS = 8.0


@njit(cache=True, error_model="numpy", refcount=False)
def _modes(m1, m2, k, k1):
    """(w1, w2, cs, sn): frequencies of the two modes (w1 >= w2) of the mass-normalised
    stiffness [[(k1 + k)/m1, -k/sqrt(m1 m2)], [-k/sqrt(m1 m2), k/m2]], whose unit eigenvectors
    are (cs, sn) and (-sn, cs). The smaller eigenvalue as det / larger: no cancellation when the
    contact is far stiffer or softer than the link."""
    a = (k1 + k) / m1
    d = k / m2
    b = -k / math.sqrt(m1 * m2)
    th = 0.5 * math.atan2(2.0 * b, a - d)
    lam1 = 0.5 * (a + d) + math.hypot(0.5 * (a - d), b)
    lam2 = (k1 / m1) * (k / m2) / lam1
    return math.sqrt(lam1), math.sqrt(lam2), math.cos(th), math.sin(th)


@njit(cache=True, error_model="numpy", refcount=False)
def _mode(s, w, q, p):
    """(q(s) - q, q'(s)) of one mode, q(s) = q cos(w s) + (p/w) sin(w s), from q(0) = q and
    q'(0) = p; cos - 1 as -2 sin(w s/2)**2, accurate where s is small."""
    x = w * s
    h = math.sin(0.5 * x)
    sx = math.sin(x)
    return -2.0 * q * h * h + (p / w) * sx, -q * w * sx + p * math.cos(x)


@njit(cache=True, error_model="numpy", refcount=False)
def _f_change(s, c1, c2, w1, w2, q1, p1, q2, p2):
    """f(s) - f(0) and f'(s) for f = c1 q1(s) + c2 q2(s)."""
    d1, e1 = _mode(s, w1, q1, p1)
    d2, e2 = _mode(s, w2, q2, p2)
    return c1 * d1 + c2 * d2, c1 * e1 + c2 * e2


@njit(cache=True, error_model="numpy", refcount=False)
def _crossing(s, sgn, level, c1, c2, w1, w2, q1, p1, q2, p2):
    """sgn ((f(s) - f(0)) - level) and its slope: > 0 before the crossing, <= 0 from it on
    (sgn = -1 for a level f rises to, +1 for one it falls to)."""
    df, slope = _f_change(s, c1, c2, w1, w2, q1, p1, q2, p2)
    return sgn * (df - level), sgn * slope


_polish = newton_bisection(_crossing, refcount=False)


@njit(cache=True, error_model="numpy", refcount=False)
def _modal(y, xp, m1, m2, k, k1):
    """Modal set-up from y = [u1, u2, v1, v2, ...]: (w1, w2, cs, sn, c1, c2, q1, p1, q2, p2)
    with f = u1 + xp = c1 q1 + c2 q2."""
    w1, w2, cs, sn = _modes(m1, m2, k, k1)
    r1 = math.sqrt(m1)
    r2 = math.sqrt(m2)
    z1 = r1 * (y[0] + xp)
    z2 = r2 * (y[1] + xp)
    v1 = r1 * y[2]
    v2 = r2 * y[3]
    q1 = cs * z1 + sn * z2
    q2 = -sn * z1 + cs * z2
    p1 = cs * v1 + sn * v2
    p2 = -sn * v1 + cs * v2
    return w1, w2, cs, sn, cs / r1, -sn / r1, q1, p1, q2, p2


@njit(cache=True, error_model="numpy", refcount=False)
def _state_at(y0, xp, m1, m2, k, k1, s):
    """(u1, u2, v1, v2) at local time s of the elastic phase from y0; the displacements as
    changes from y0's, accurate where s is small."""
    w1, w2, cs, sn, _, _, q1, p1, q2, p2 = _modal(y0, xp, m1, m2, k, k1)
    dq1, pe1 = _mode(s, w1, q1, p1)
    dq2, pe2 = _mode(s, w2, q2, p2)
    r1 = math.sqrt(m1)
    r2 = math.sqrt(m2)
    return (
        y0[0] + (cs * dq1 - sn * dq2) / r1,
        y0[1] + (sn * dq1 + cs * dq2) / r2,
        (cs * pe1 - sn * pe2) / r1,
        (sn * pe1 + cs * pe2) / r2,
    )


@njit(cache=True, error_model="numpy", refcount=False)
def elastic_at(y0, xp, m1, m2, k, k1, s, out):
    """The state at local time s of the elastic phase from y0 into out (W with the line's
    stored-energy change, D unchanged); returns the contact force there."""
    out[0], out[1], out[2], out[3] = _state_at(y0, xp, m1, m2, k, k1, s)
    f0 = y0[0] + xp
    f = out[0] + xp
    out[4] = y0[4] + 0.5 * k1 * (f * f - f0 * f0)
    out[5] = y0[5]
    return -k1 * f


@njit(cache=True, error_model="numpy", refcount=False)
def elastic_phase(y, xp, xmax, m1, m2, k, k1, work):
    """Advance y = [u1, u2, v1, v2, W, D] through the elastic phase to its first event.

    Returns (code, s, err): EL_SEPARATED (y on the dent, u1 = -xp) or EL_RELOAD (u1 = -xmax)
    after the local time s, err the momentum error of the formed state; EL_INTEGRATE (y
    untouched) where the start is not one this closed form takes; EL_FAIL when ``work[0]`` (the
    scene's budget of right-hand sides) runs out.
    """
    w1, w2, cs, sn, c1, c2, q1, p1, q2, p2 = _modal(y, xp, m1, m2, k, k1)
    a1 = math.sqrt(q1 * q1 + (p1 / w1) ** 2)
    a2 = math.sqrt(q2 * q2 + (p2 / w2) ** 2)
    g2 = abs(c1) * w1 * w1 * a1 + abs(c2) * w2 * w2 * a2  # bound on |f''|
    g3 = abs(c1) * w1 * w1 * w1 * a1 + abs(c2) * w2 * w2 * w2 * a2  # bound on |f'''|
    f0 = y[0] + xp
    hi = -f0  # separation: f - f0 rises to hi
    lo = -(xmax - xp) - f0  # reload: f - f0 falls to lo
    if not (lo < 0.0 or hi > 0.0) or not lo < hi or not g2 > 0.0:
        return EL_INTEGRATE, 0.0, 0.0
    d1 = y[2]  # f'(0) = v1
    s = 0.0
    if hi <= 0.0:  # on the dent: entering, f' < 0 (f(s) <= d1 s + g2 s**2 / 2 < 0 up to 2|d1|/g2)
        if hi < 0.0 or not d1 < 0.0:
            return EL_INTEGRATE, 0.0, 0.0
        s = -d1 / g2
    elif lo >= 0.0:  # at xmax after the turn: f' = 0, f'' > 0 (f - f0 >= f'' s**2/2 - g3 s**3/6)
        dd = (-c1 * w1 * w1 * q1) + (-c2 * w2 * w2 * q2)  # f''(0)
        if lo > 0.0 or not (d1 == 0.0 and dd > 0.0 and g3 > 0.0):
            return EL_INTEGRATE, 0.0, 0.0
        s = 1.5 * dd / g3
    # the first stretch [0, s] is monotone by construction
    fs, ds = _f_change(s, c1, c2, w1, w2, q1, p1, q2, p2)
    evals = 1
    args_up = (-1.0, hi, c1, c2, w1, w2, q1, p1, q2, p2)
    args_dn = (1.0, lo, c1, c2, w1, w2, q1, p1, q2, p2)
    hit = -1.0
    code = EL_SEPARATED
    if fs >= hi:
        hit = _polish(0.0, s, args_up)[1]
    elif fs <= lo:
        hit = _polish(0.0, s, args_dn)[1]
        code = EL_RELOAD
    h = 0.25 / w1
    tiny = 1e-12 / w1
    while hit < 0.0:
        if work[0] - evals * EVAL_WORK <= 0.0:
            work[0] -= evals * EVAL_WORK
            return EL_FAIL, s, 0.0
        fb, db = _f_change(s + h, c1, c2, w1, w2, q1, p1, q2, p2)
        evals += 1
        floor = h < tiny * max(1.0, w1 * s)  # a dip within round-off of a level: passed
        if fb >= hi:
            if ds - g2 * h > 0.0 or floor:  # f rising throughout: the first crossing
                hit = _polish(s, s + h, args_up)[1]
            else:
                h *= 0.5
        elif fb <= lo:
            if ds + g2 * h < 0.0 or floor:
                hit = _polish(s, s + h, args_dn)[1]
                code = EL_RELOAD
            else:
                h *= 0.5
        elif (max(fs, fb) + g2 * h * h / 8.0 < hi and min(fs, fb) - g2 * h * h / 8.0 > lo) or floor:
            s += h
            fs = fb
            ds = db
            h *= 2.0
        else:
            h *= 0.5
    work[0] -= (evals + 8) * EVAL_WORK  # the polish: a handful of evaluations
    _, u2, v1, v2 = _state_at(y, xp, m1, m2, k, k1, hit)
    f_end = 0.0 if code == EL_SEPARATED else -(xmax - xp)
    y[4] += 0.5 * k1 * (f_end * f_end - f0 * f0)  # the line's stored energy, exactly
    y[0] = -xp if code == EL_SEPARATED else -xmax
    y[1] = u2
    y[2] = v1
    y[3] = v2
    r1 = math.sqrt(m1)
    r2 = math.sqrt(m2)
    err = ROUND_ULPS * EPS * (r1 + r2) * (w1 * a1 * (1.0 + w1 * hit) + w2 * a2 * (1.0 + w2 * hit))
    return code, hit, err
