"""The kernels' root finders, written once.

A finder that solves a function is specialised for it by a factory: ``bisection(f)`` returns a
compiled bisection of ``f``, ``newton_bracketed(fdf)`` a bracketed Newton iteration of ``fdf``,
and so on; the kernel keeps the function and calls the finder with its extra arguments as one
tuple, ``find(lo, hi, args)`` for ``f(x, *args)``. (The function is not passed as an argument:
numba refuses to cache a kernel that passes a function to another, so every process would
compile the kernels again. A finder closing over its function compiles into each kernel that
calls it, and that kernel is cached; the finder itself is not, being compiled anew only with a
kernel that calls it.)

Conventions: ``f(x, *args)`` returns f(x); ``fdf(x, *args)`` returns (f(x), f'(x));
``fd2(x, *args)`` returns (f(x), f'(x), f''(x)). Finders that need no function (the cubics of
the locator's step and of rigid2's first guess) are plain functions.

Users: the event locator (``first_cubic_root``, ``newton_polish``, ``bisection`` of the gap's slope
for x_max), the two-mass walk rigid2 (``halley_bracketed``, ``newton_bracketed``,
``newton_descent``, ``expansion``, ``hermite_cubic_root``), the chain kernel's eigenvalues
(``threshold_bisection``), the stepping kernel's closed-form free flight and the plastic law's
closed-form elastic phase (``newton_bisection``) and the integrators' events (``first_root``: the
first root of a polynomial on [0, 1], certified by Bernstein bounds, polished by
``newton_bisection``). Not here: ``restitution.model.laws.structure_extent`` (the model layer
imports no kernel).
"""

import math

import numpy as np

from restitution.jit import njit
from restitution.kernels.constants import EPS

MAX_ITER = 200  # iterations of a Newton-type finder before it reports no convergence


# ----------------------------------------------------------------------------------------------
# Finders of a function: factories
# ----------------------------------------------------------------------------------------------
def bisection(f):
    """``find(lo, hi, args) -> (lo, hi)``: the bracket of a sign change, f(lo) > 0 >= f(hi),
    halved to round-off (until its midpoint is one of its ends; at most 200 halvings)."""

    @njit(error_model="numpy")
    def find(lo, hi, args):
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            if f(mid, *args) > 0.0:
                lo = mid
            else:
                hi = mid
        return lo, hi

    return find


def newton_bisection(fdf, refcount=True):
    """``find(lo, hi, args) -> (lo, hi)``: ``bisection``'s result (f(lo) > 0 >= f(hi), the
    bracket shrunk until its midpoint is one of its ends) in a handful of evaluations of
    ``fdf`` instead of ~55: Newton steps inside the bracket, a bisection wherever a step would
    leave it or would not halve the one before (rtsafe's rule); a Newton step below a few ulps
    converges from one side only, so it is stepped across the root instead and the bracket
    closes there. ``refcount=False`` for callers compiled without reference counts."""

    @njit(error_model="numpy", refcount=refcount)
    def find(lo, hi, args):
        wide = hi - lo  # the length of the last step (Newton or bisection)
        x = 0.5 * (lo + hi)
        for _ in range(200):
            f, df = fdf(x, *args)
            if f > 0.0:
                lo = x
            else:
                hi = x
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            dx = f / df if df != 0.0 else math.inf
            xn = x - dx
            if lo < xn < hi and abs(dx) < 0.5 * wide:
                wide = abs(dx)
                tiny = 4.0 * EPS * max(abs(x), abs(xn))
                if abs(dx) < tiny:  # converged on one side: a probe just across the root
                    xn = x + tiny if f > 0.0 else x - tiny
                    if not lo < xn < hi:
                        xn = mid
            else:
                wide = hi - lo
                xn = mid
            x = xn
        return lo, hi

    return find


def threshold_bisection(above):
    """``find(lo, hi, args) -> x``: the point where the predicate ``above(x, *args)`` turns
    True, between lo (False) and hi (True), to a few ulps: the midpoint of the final bracket.
    The midpoints are geometric while the bracket spans more than a factor 4 (lo > 0), so a
    threshold decades below hi is found as fast as one near it."""

    @njit(error_model="numpy")
    def find(lo, hi, args):
        for _ in range(400):
            if lo > 0.0 and hi > 4.0 * lo:
                mid = math.sqrt(lo * hi)
            else:
                mid = 0.5 * (lo + hi)
            if not (lo < mid < hi) or hi - lo <= 2.0 * EPS * hi:
                break
            if above(mid, *args):
                hi = mid
            else:
                lo = mid
        return 0.5 * (lo + hi)

    return find


def newton_bracketed(fdf):
    """``find(lo, hi, args) -> (root, converged)``: f monotone on [lo, hi] with f(lo), f(hi) of
    opposite signs (or zero); Newton from the midpoint, a step leaving the bracket replaced by
    bisection. Converged when the step or the bracket is within a few ulps."""

    @njit(error_model="numpy")
    def find(lo, hi, args):
        flo, _ = fdf(lo, *args)
        x = 0.5 * (lo + hi)
        for _ in range(MAX_ITER):
            f, df = fdf(x, *args)
            if f == 0.0:
                return x, True
            if (f > 0.0) == (flo > 0.0):
                lo = x
            else:
                hi = x
            xn = x - f / df if df != 0.0 else 0.5 * (lo + hi)
            if not (min(lo, hi) < xn < max(lo, hi)):
                xn = 0.5 * (lo + hi)
            if abs(xn - x) <= 2.0 * EPS * abs(x) or abs(hi - lo) <= 4.0 * EPS * max(
                abs(hi), abs(lo)
            ):
                return xn, True
            x = xn
        return x, False

    return find


def halley_bracketed(fd2):
    """``find(lo, hi, x, args) -> (root, converged)``: f(lo) >= 0 >= f(hi), f monotone; Halley
    from x, a step leaving the bracket replaced by bisection."""

    @njit(error_model="numpy")
    def find(lo, hi, x, args):
        for _ in range(MAX_ITER):
            g, gp, gpp = fd2(x, *args)
            if g == 0.0:
                return x, True
            if g > 0.0:
                lo = x
            else:
                hi = x
            den = 2.0 * gp * gp - g * gpp
            xn = x - 2.0 * g * gp / den if den != 0.0 else 0.5 * (lo + hi)
            if not (lo < xn < hi):
                xn = 0.5 * (lo + hi)
            if abs(xn - x) <= 4.0 * EPS * abs(x) or hi - lo <= 4.0 * EPS * abs(hi):
                return xn, True
            x = xn
        return x, False

    return find


def newton_descent(fdf):
    """``find(x, args) -> (root, converged)``: the root left of x of f concave and decreasing on
    [root, x] with f(x) < 0. Newton steps from x then decrease monotonically onto the root (each
    tangent lies above f), so no bracket is needed."""

    @njit(error_model="numpy")
    def find(x, args):
        for _ in range(MAX_ITER):
            g, gp = fdf(x, *args)
            if g >= 0.0 or gp >= 0.0:  # at the root (to round-off)
                return x, True
            xn = x - g / gp
            if not (xn < x) or x - xn <= 2.0 * EPS * abs(x):
                return xn, True
            x = xn
        return x, False

    return find


def newton_polish(fdf):
    """``find(lo, hi, f_lo, df_lo, args) -> x``: the root of f on [lo, hi] with f(lo) = f_lo > 0
    > f(hi) (f strictly decreasing there, or at least past its last crossing), by safeguarded
    Newton from lo to machine precision; returns the iterate of smallest |f|. f(lo) and f'(lo)
    are given (a caller often has them already)."""

    @njit(error_model="numpy")
    def find(lo, hi, f, df, args):
        if f <= 0.0:
            return lo
        x = lo
        best = lo
        bestf = f
        for _ in range(MAX_ITER):
            if abs(f) < bestf:
                best = x
                bestf = abs(f)
            if f == 0.0:
                return x
            if f > 0.0:
                lo = x
            else:
                hi = x
            if hi - lo <= 2.0 * EPS * max(abs(hi), 1.0):
                break
            xn = x - f / df if df < 0.0 else 0.5 * (lo + hi)
            if df < 0.0 and abs(xn - x) <= 2.0 * EPS * abs(x):
                # Newton has converged (maybe one-sided): its step is below round-off at x.
                # Tested before the bracket, since a step that rounds to x = lo leaves the
                # bracket and would start a bisection of the whole (stale) bracket: ~40 more
                # evaluations for every event of a damped contact, and the same root.
                break
            if not (lo < xn < hi):
                xn = 0.5 * (lo + hi)
            x = xn
            f, df = fdf(x, *args)
        return best

    return find


def expansion(fdf):
    """``find(lo, sgn, thresh, args) -> hi``: on a monotone tail from lo, the first of
    lo + 2^j max(1, lo) (j = 0, 1, ...) where sgn f < thresh; inf if none within 2100
    doublings (a bracket's far end for the finders above)."""

    @njit(error_model="numpy")
    def find(lo, sgn, thresh, args):
        step = max(1.0, lo)
        for _ in range(2100):
            hi = lo + step
            f, _ = fdf(hi, *args)
            if sgn * f < thresh:
                return hi
            step *= 2.0
        return math.inf

    return find


# ----------------------------------------------------------------------------------------------
# Roots of cubics
# ----------------------------------------------------------------------------------------------
@njit(cache=True, refcount=False)
def cubic(a0, a1, a2, a3, s):
    """p(s) = a0 + a1 s + a2 s^2/2 - a3 s^3/6, the locator's cubic lower bound of a gap."""
    return a0 + s * (a1 + s * (0.5 * a2 - s * a3 / 6.0))


@njit(cache=True, refcount=False)
def first_cubic_root(a0, a1, a2, a3):
    """Largest h (to ~1e-13, from below) with p(s) = a0 + a1 s + a2 s^2/2 - a3 s^3/6 > 0 on
    [0, h); a0 > 0, a3 >= 0. Returns inf if p never vanishes."""
    if a0 <= 0.0:
        return 0.0
    if a3 <= 0.0:  # all higher derivatives vanish: f is linear
        if a1 < 0.0:
            return a0 / -a1
        return math.inf
    if a1 > 0.0:
        # Leaving the band edge (every phase starts so): p = a0 + s q(s) with q = a1 + a2 s/2 -
        # a3 s^2/6 concave and q(0) > 0, so p > a0 up to q's root sq, in closed form. The root of
        # p lies beyond it by ~a0 / |p'(sq)| = a0 / (sq sqrt(D)): where that is below 1e-13 sq,
        # sq is the step (no iteration).
        rd = math.sqrt(0.25 * a2 * a2 + a3 * a1 / 1.5)
        sq = 3.0 * (0.5 * a2 + rd) / a3 if a2 >= 0.0 else 2.0 * a1 / (rd - 0.5 * a2)
        if a0 <= 1e-13 * sq * sq * rd:
            return sq
    lo = 0.0
    disc = a2 * a2 + 2.0 * a1 * a3
    if disc > 0.0:
        sq = math.sqrt(disc)
        cr1 = (a2 - sq) / a3
        cr2 = (a2 + sq) / a3
        if cr1 > 0.0:  # p decreases on [0, cr1], increases on [cr1, cr2]
            if cubic(a0, a1, a2, a3, cr1) <= 0.0:
                return monotone_cubic_root(a0, a1, a2, a3, 0.0, cr1)
            lo = cr2
        elif cr2 > 0.0:
            lo = cr2
    # p decreases on [lo, inf) from p(lo) > 0.
    plo = cubic(a0, a1, a2, a3, lo)
    h = (6.0 * plo / a3) ** (1.0 / 3.0)
    d2 = a2 - a3 * lo
    if d2 <= 0.0:
        # Concave from lo on and p'(lo) <= 0: every term of p(lo + d) - p(lo) is <= 0, so the
        # root is within each term's own reach; the nearest starts Newton close to it.
        d1 = a1 + lo * (a2 - 0.5 * a3 * lo)
        if d2 < 0.0:
            h = min(h, math.sqrt(2.0 * plo / -d2))
        if d1 < 0.0:
            h = min(h, plo / -d1)
    h = max(h, 1e-300)
    hi = lo + h
    for _ in range(200):
        if cubic(a0, a1, a2, a3, hi) <= 0.0:
            break
        lo = hi
        h *= 2.0
        hi = lo + h
    return monotone_cubic_root(a0, a1, a2, a3, lo, hi)


@njit(cache=True, refcount=False)
def monotone_cubic_root(a0, a1, a2, a3, lo, hi):
    """Root of the cubic, decreasing on [lo, hi] with p(lo) > 0 >= p(hi); returns a point below
    it (p > 0 there).

    p is convex left of its inflection a2/a3 and concave right of it, so Newton started on the
    side where the tangent stays on one side of p converges monotonically (from lo where convex,
    from hi where concave) in a few steps; a start at a critical point (p' = 0 at lo) would
    instead fall back to bisection for tens of steps.
    """
    infl = a2 / a3
    if lo < infl < hi:
        if cubic(a0, a1, a2, a3, infl) > 0.0:
            lo = infl
        else:
            hi = infl
    x = lo if hi <= infl else hi
    for _ in range(100):
        p = cubic(a0, a1, a2, a3, x)
        if p > 0.0:
            lo = x
        else:
            hi = x
        dp = a1 + x * (a2 - 0.5 * a3 * x)
        if not dp < 0.0:
            break
        xn = x - p / dp
        if not (lo <= xn <= hi):
            break
        if abs(xn - x) <= 1e-9 * xn:  # converged (quadratically: xn is at round-off)
            back = 4e-15
            for _ in range(4):
                xs = xn - back * xn
                if xs <= lo:
                    break
                if cubic(a0, a1, a2, a3, xs) > 0.0:
                    return xs
                back *= 8.0
            break
        x = xn
    # Bisection (Newton stalled, e.g. on a near-double root).
    for _ in range(100):
        if hi - lo <= 1e-14 * hi:
            break
        x = 0.5 * (lo + hi)
        if cubic(a0, a1, a2, a3, x) > 0.0:
            lo = x
        else:
            hi = x
    return lo


@njit(cache=True, refcount=False)
def hermite_cubic_root(sa, ga, gpa, sb, gb, gpb):
    """Root in (sa, sb) of the Hermite cubic through (sa, ga, gpa) and (sb, gb, gpb), found by
    Newton from sb (gb < 0 > gpb): a first guess only, or -1.0."""
    h = sb - sa
    a1 = h * gpa
    a2 = 3.0 * (gb - ga) - h * (2.0 * gpa + gpb)
    a3 = 2.0 * (ga - gb) + h * (gpa + gpb)
    x = 1.0
    for _ in range(8):
        p = ga + x * (a1 + x * (a2 + x * a3))
        dp = a1 + x * (2.0 * a2 + 3.0 * x * a3)
        if not dp < 0.0:
            return -1.0
        x -= p / dp
    return sa + x * h if 0.0 < x < 1.0 else -1.0


# ----------------------------------------------------------------------------------------------
# The first root of a polynomial on [0, 1] (the integrators' events along the dense output)
# ----------------------------------------------------------------------------------------------
MAX_DEGREE = 7  # the DOP853 dense output's
_BINOM = np.array(
    [[math.comb(i, j) for j in range(MAX_DEGREE + 1)] for i in range(MAX_DEGREE + 1)],
    dtype=np.float64,
)


@njit(cache=True, error_model="numpy", refcount=False)
def _poly_at(c, s, m, t):
    """The degree-m polynomial with coefficients c[s], ..., c[s + m] at t (Horner)."""
    acc = 0.0
    for k in range(m, -1, -1):
        acc = acc * t + c[k + s]
    return acc


@njit(cache=True, error_model="numpy", refcount=False)
def _poly_fdf(t, c, s, m):
    """The polynomial of ``_poly_at`` and its derivative at t (Horner)."""
    acc = 0.0
    der = 0.0
    for k in range(m, -1, -1):
        der = der * t + acc
        acc = acc * t + c[k + s]
    return acc, der


_polish_poly = newton_bisection(_poly_fdf, refcount=False)


@njit(cache=True, error_model="numpy", refcount=False)
def _bernstein_min(c, s, m, a, b, d):
    """Smallest Bernstein coefficient on [a, b] of the degree-m polynomial c[s:s + m + 1]
    (d: scratch of m + 1 entries)."""
    # Taylor shift to a, then scale by (b - a)**k: monomials in s in [0, 1].
    for k in range(m + 1):
        d[k] = c[k + s]
    for i in range(m):
        for k in range(m - 1, i - 1, -1):
            d[k] += a * d[k + 1]
    sc = 1.0
    for k in range(m + 1):
        d[k] *= sc
        sc *= b - a
    # monomial -> Bernstein: b_i = sum_j C(i,j)/C(m,j) d_j
    low = math.inf
    for i in range(m + 1):
        acc = 0.0
        for j in range(i + 1):
            acc += _BINOM[i, j] / _BINOM[m, j] * d[j]
        low = min(low, acc)
    return low


@njit(cache=True, error_model="numpy", refcount=False)
def first_root(c, n, strip, d):
    """First theta in (0, 1] where the polynomial goes from > 0 to <= 0; -1.0 if none.

    ``strip`` leading coefficients are known to be exactly zero (the event starts on its surface);
    they are divided out. Returns 0.0 if the function moves to the negative side at once.
    ``d``: scratch of n + 1 entries (no allocation: this runs on most steps near an event).

    The search halves [0, 1] depth first, left half first, and drops a piece whose Bernstein
    bound proves it root-free (or narrower than 1e-13: a tangency below round-off); the piece at
    depth L is [i, i + 1] / 2**L, held as (L, i) instead of on a stack of intervals.
    """
    m = n - strip
    if c[strip] <= 0.0:
        return 0.0
    if m == 0:
        return -1.0
    # |p(theta) - p(0)| <= sum |q_k| on [0, 1]: most steps end here, far from any event
    spread = 0.0
    for k in range(1, m + 1):
        spread += abs(c[k + strip])
    if c[strip] > spread:
        return -1.0
    level = 0
    i = 0
    while True:
        w = math.ldexp(1.0, -level)
        a = i * w  # exact: dyadic
        b = a + w
        if _poly_at(c, strip, m, b) <= 0.0:  # bracketed: p(a) > 0 >= p(b)
            return _polish_poly(a, b, (c, strip, m))[1]
        if not (_bernstein_min(c, strip, m, a, b, d) > 0.0 or w < 1e-13):
            level += 1  # its left half next
            i *= 2
            continue
        while i % 2 == 1:  # root-free: on to the next piece to the right, up the tree
            i //= 2
            level -= 1
        if level == 0:
            return -1.0
        i += 1
