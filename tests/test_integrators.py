"""Integrators: guaranteed event location, DOP853 against the exact kernels, Verlet's order."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from conftest import solve_paper_law
from restitution.kernels import integrators
from restitution.kernels.paper_chain import solve_linear
from restitution.kernels.rigid2 import rigid2
from restitution.kernels.roots import first_root
from restitution.kernels.stepping import METHOD_VERLET, solve_scene
from restitution.model.chain import Chain
from restitution.solvers.numerical import packed

H0 = np.zeros((0, 6))
X1 = brentq(lambda x: math.tan(x) - x, 4.4, 4.5)  # 4.4934...
ALPHA1 = 1.0 / (1.0 - 2.0 * math.cos(X1))  # alpha*_1 = 0.6971...


SCRATCH = np.empty(8)  # first_root's


def _poly(*roots_and_scale):
    return np.array(roots_and_scale, dtype=float)


def test_first_root_finds_a_dip_between_positive_samples():
    # (t - 0.3)(t - 0.3 + 1e-7): positive at 0, 1 and at any coarse sample, negative in a 1e-7 gap
    a, b = 0.3, 0.3 - 1e-7
    c = np.array([a * b, -(a + b), 1.0, 0.0, 0.0])
    th = first_root(c, 4, 0, SCRATCH)
    assert th == pytest.approx(b, abs=1e-9)  # the root itself is ill-conditioned (1e-7 gap)
    # a dip that stays positive is not an event
    c2 = np.array([a * a + 1e-12, -2 * a, 1.0, 0.0, 0.0])
    assert first_root(c2, 4, 0, SCRATCH) == -1.0


def test_first_root_strips_a_start_on_the_surface():
    c = np.array([0.0, 0.7, -1.0, 0.0, 0.0])  # theta*(0.7 - theta): leaves, returns at 0.7
    assert first_root(c, 4, 1, SCRATCH) == pytest.approx(0.7, abs=1e-15)
    c = np.array([0.0, 0.0, 1.0, -1.25, 0.0])  # double zero at 0, root at 0.8
    assert first_root(c, 4, 2, SCRATCH) == pytest.approx(0.8, abs=1e-15)
    assert first_root(c, 4, 0, SCRATCH) == 0.0  # without the strip it would fire at once


def _first_root_slow(c, n, strip):
    """first_root written plainly: the Bernstein subdivision with a stack of intervals, in
    Python (the kernel walks the same pieces as (depth, index) without a stack)."""
    q = [float(v) for v in c[strip : n + 1]]
    m = n - strip
    if q[0] <= 0.0:
        return 0.0
    if m == 0 or q[0] > sum(abs(v) for v in q[1:]):
        return -1.0

    def val(t):
        acc = 0.0
        for v in reversed(q):
            acc = acc * t + v
        return acc

    def bernstein_min(a, b):
        d = list(q)
        for i in range(m):
            for k in range(m - 1, i - 1, -1):
                d[k] += a * d[k + 1]
        d = [v * (b - a) ** k for k, v in enumerate(d)]
        return min(
            sum(math.comb(i, j) / math.comb(m, j) * d[j] for j in range(i + 1))
            for i in range(m + 1)
        )

    stack = [(0.0, 1.0)]
    while stack:
        a, b = stack.pop()
        if val(b) <= 0.0:
            while True:
                mid = 0.5 * (a + b)
                if mid <= a or mid >= b:
                    return b
                a, b = (mid, b) if val(mid) > 0.0 else (a, mid)
        if bernstein_min(a, b) > 0.0 or b - a < 1e-13:
            continue
        mid = 0.5 * (a + b)
        stack += [(mid, b), (a, mid)]
    return -1.0


def test_first_root_walks_the_pieces_of_a_plain_subdivision():
    """On polynomials of degree 7 with dips near the axis (roots, near misses, tangencies, a
    strip), the kernel finds the root that a plain stack subdivision with bisection finds: the
    same outcome (root or none), a float where the polynomial's sign changes, and the same root
    to within its condition (the polish is Newton's, which may end on another float where
    round-off flips the sign back and forth: at most Horner's error bound over the slope)."""
    rng = np.random.default_rng(7)
    hits = 0
    for trial in range(400):
        # (theta - r1)(theta - r2) * cubic + small offset: dips that may or may not cross
        r1, r2 = np.sort(rng.uniform(0.0, 1.0, 2))
        if trial % 4 == 0:
            r2 = r1 + 10.0 ** rng.uniform(-12, -3)  # a narrow dip
        p = np.polynomial.polynomial.polyfromroots([r1, r2])
        p = np.polynomial.polynomial.polymul(p, rng.uniform(0.5, 2.0, 4) * [1, 0.1, 0.1, 0.1])
        p = np.pad(p, (0, 8 - p.size))
        p[0] += rng.choice([0.0, 1e-14, -1e-14, 1e-6]) * (trial % 3 != 0)
        strip = 0
        if trial % 10 == 0:
            p = np.concatenate([[0.0], p[:-1]])  # theta * p: starts on its surface
            strip = 1
        got = first_root(p, 7, strip, SCRATCH)
        want = _first_root_slow(p, 7, strip)
        assert (got > 0.0) == (want > 0.0) and (got == 0.0) == (want == 0.0), (trial, got, want)
        if want > 0.0:
            q = np.polynomial.Polynomial(p[strip:8])
            assert q(got) <= 0.0 < q(np.nextafter(got, -1.0)), trial  # a sign change at got
            noise = 2 * 8 * np.finfo(float).eps * np.abs(p).sum()  # Horner's error, |t| <= 1
            assert abs(got - want) * abs(q.deriv()(want)) <= noise, (trial, got, want)
        hits += got > 0.0
    assert 100 < hits < 400  # both outcomes well represented


def _exact(alpha, beta, xi=0.0):
    if beta == 0.0:
        return rigid2(alpha, xi, 10_000, H0)
    return solve_linear(alpha, beta, xi, 2, 10_000, H0)


LINEAR = [
    (0.5, 0.1, 0.0),
    (2.2, 0.1, 0.0),
    (3.0, 0.05, 0.05),
    (6.0, 0.01, 0.0),
    (1.0, 1.0, 0.2),
    (0.8, 0.0, 0.0),
    (2.5, 0.0, 0.1),
]


@pytest.mark.parametrize("alpha, beta, xi", LINEAR)
@pytest.mark.parametrize("integrate_free", [False, True])
def test_adaptive_matches_exact_on_linear_scenes(alpha, beta, xi, integrate_free):
    o = _exact(alpha, beta, xi)
    r = solve_paper_law(alpha, beta=beta, xi=xi, rtol=1e-10, free_closed=not integrate_free)
    assert r.status == "ok" and r.method == "adaptive"
    assert r.n_collisions == int(o[1])
    assert abs(r.cor - o[0]) < 1e-8
    assert abs(r.omega_t_col - o[2]) < 1e-7


@pytest.mark.parametrize("d", [-1e-4, -1e-6, -1e-8, 1e-8, 1e-6, 1e-4])
@pytest.mark.parametrize("integrate_free", [False, True])
def test_adaptive_at_the_grazing_alpha1_rigid_wall(d, integrate_free):
    # beta = 0: the second contact appears at alpha*_1 with zero depth. With integrate_free the
    # DOP853 event location must see the shallow contact. Just above alpha*_1 the COR depends on
    # the contact's approach speed ~ sqrt(depth ~ d), so any position error eps ~ rtol costs
    # ~ eps/sqrt(d) in COR: the tolerance follows that conditioning (1e-8 at |d| = 1e-4).
    o = _exact(ALPHA1 + d, 0.0)
    assert int(o[1]) == (2 if d > 0 else 1)
    r = solve_paper_law(ALPHA1 + d, beta=0.0, rtol=1e-10, free_closed=not integrate_free)
    assert r.n_collisions == int(o[1])
    tol = 1e-8 * max(1.0, 2.0 * math.sqrt(1e-4 / abs(d))) if integrate_free else 1e-10
    assert abs(r.cor - o[0]) < tol


def _count(alpha, beta):
    return int(_exact(alpha, beta)[1])


@pytest.mark.parametrize("beta, lo, hi", [(0.1, 1.0, 3.0), (0.01, 0.5, 1.0)])
def test_adaptive_at_a_grazing_alpha_with_finite_beta(beta, lo, hi):
    n_lo, n_hi = _count(lo, beta), _count(hi, beta)
    assert n_lo != n_hi
    for _ in range(45):  # bisect the exact count change (a grazing contact) to ~1e-13
        mid = 0.5 * (lo + hi)
        if _count(mid, beta) == n_lo:
            lo = mid
        else:
            hi = mid
    for a in (lo - 1e-6, hi + 1e-6, lo - 1e-9, hi + 1e-9):
        o = _exact(a, beta)
        for free in (False, True):
            r = solve_paper_law(a, beta=beta, rtol=1e-10, free_closed=not free)
            assert r.n_collisions == int(o[1]), (a, free)
            assert abs(r.cor - o[0]) < 1e-8


@pytest.mark.parametrize("alpha, beta, xi", [(0.5, 0.1, 0.0), (2.2, 0.1, 0.0), (1.0, 1.0, 0.2)])
def test_verlet_converges_at_second_order(alpha, beta, xi):
    o = _exact(alpha, beta, xi)
    m, lk, c, cp, _, _ = packed(Chain.paper(alpha, beta, xi))
    fracs = 0.04 * 2.0 ** (-np.arange(7) / 1.5)
    errs = []
    for f in fracs:
        acct = np.zeros(5)
        out = solve_scene(m, lk, c, cp, 1.0, METHOD_VERLET, 1e-9, f, 1.0, 10_000, 4e6, H0, acct)
        assert int(out[1]) == int(o[1])
        errs.append(abs(out[0] - o[0]))
    # least-squares slope: the contact kink inside a step makes single ratios jitter
    order = np.polyfit(np.log(fracs), np.log(errs), 1)[0]
    assert 1.6 < order < 2.6, order
    assert errs[-1] < 1e-4


def test_verlet_error_estimate_is_step_halving():
    r = solve_paper_law(2.2, beta=0.1, method="verlet", step=0.01)
    o = _exact(2.2, 0.1)
    assert r.method == "verlet" and r.status == "ok"
    assert 0 < r.error_estimate and abs(r.cor - o[0]) < 20 * r.error_estimate + 1e-6


@pytest.mark.parametrize("eta", [0.5, 1.0, 1.5, 2.5])
def test_a_smooth_power_law_has_no_end_zone(eta):
    assert integrators.sigma_end_zone(0.3, 1e-8, eta) == 0.0


def test_the_steps_at_a_non_smooth_end_are_sized_by_its_singular_term():
    """At x = 0 a force sigma**(2 eta) with 2 eta not an integer: the step touching sigma = 0
    is |span| rtol**(1/(2 eta + 2)) long, as the first step of an entry and as the last of an
    exit (the step before stops that far short of it)."""
    span, rtol, eta = -0.4, 1e-8, 0.69
    zone = integrators.sigma_end_zone(span, rtol, eta)
    assert zone == pytest.approx(0.4 * 1e-8 ** (1.0 / 3.38))
    assert integrators.sigma_first_step(-span, rtol, eta, 0.0) == zone  # entry from sigma = 0
    assert abs(integrators.sigma_first_step(-span, rtol, eta, 0.1)) > zone  # not from 0
    # an exit from sigma = 0.4 towards 0: a step that would land on 0 from afar stops short
    h, last = integrators.sigma_last_step(-0.3, 0.2, 0.0, zone)
    assert not last and 0.2 + h == pytest.approx(zone, rel=1e-12)
    h, last = integrators.sigma_last_step(-0.3, zone, 0.0, zone)  # then the last step
    assert last and h == -zone
    h, last = integrators.sigma_last_step(-0.05, 0.2, 0.0, zone)  # a short step goes on
    assert (h, last) == (-0.05, False)
    assert integrators.sigma_last_step(-0.3, 0.2, 0.0, 0.0) == (-0.2, True)  # smooth: lands
