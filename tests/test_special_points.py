"""Exact special points (beta = 0): closed forms, the project's solvers, long double."""

import math

import numpy as np
import pandas as pd
import pytest

import restitution
from restitution.analysis import special_points as sp

N_CHECK = 30


@pytest.fixture(scope="module")
def points():
    return sp.special_points(N_CHECK)


def test_alpha_star_1_closed_form(points):
    # tan x = x, first positive root, by an independent fixed-point iteration x = pi + atan(x)
    # on the branch (pi, 3pi/2) (a contraction there), then alpha = 1/(1 - 2 cos x) (Eq. 10).
    x = 4.5
    for _ in range(200):
        x = math.pi + math.atan(x)
    closed = 1.0 / (1.0 - 2.0 * math.cos(x))
    assert abs(points.alpha_star[0] - closed) < 1e-12
    assert abs(sp.alpha_star_1_closed_form() - closed) < 1e-14
    # One contact below alpha*_1: e*_1 is the single-contact COR there (Eq. 1).
    assert points.e_star[0] == pytest.approx((1 - closed) / (1 + closed), abs=1e-12)


def test_alpha_unity_2_is_one(points):
    assert abs(points.alpha_unity[1] - 1.0) < 1e-12


def test_paper_values(points):
    # Section 2.1: minima 0.178, 0.557, 0.710 at alpha = 0.697, 2.07, 3.64 (quoted to 3 digits).
    np.testing.assert_allclose(points.alpha_star[:3], [0.697, 2.07, 3.64], atol=6e-3)
    np.testing.assert_allclose(points.e_star[:3], [0.178, 0.557, 0.710], atol=1.1e-3)


def test_points_ordered_and_conditions_hold(points):
    a_star, a_unity = points.alpha_star.to_numpy(), points.alpha_unity.to_numpy()
    assert np.all(np.diff(a_star) > 0)
    assert np.all(a_star[:-1] < a_unity[1:]) and np.all(a_unity < a_star)
    assert np.all(np.abs(points.grazing_residual) < 1e-12)
    assert np.all(np.abs(points.unity_residual) < 1e-13)


def test_count_steps_by_one_in_the_project_solver(points):
    """restitution.solve (kernel rigid2) at alpha*_n -+ 1e-9: n and n + 1 contacts, same COR."""
    for n, a, e in zip(points.n, points.alpha_star, points.e_star, strict=True):
        below, above = restitution.solve(a - 1e-9), restitution.solve(a + 1e-9)
        assert (below.n_collisions, above.n_collisions) == (n, n + 1)
        # COR continuous at the cusp: it moves like sqrt(1e-9) on the right side.
        assert below.cor == pytest.approx(e, abs=1e-7)
        assert above.cor == pytest.approx(e, abs=1e-3)


def test_unity_points_in_the_project_solver(points):
    frame = pd.DataFrame({"alpha": points.alpha_unity[1:]})
    res = restitution.solve_many(frame)
    np.testing.assert_allclose(res.cor, 1.0, atol=1e-12)
    np.testing.assert_array_equal(res.n_collisions, points.n[1:])


def test_reference_agrees_with_kernel():
    a = np.geomspace(0.01, 200, 3001)
    ref = sp.rigid_reference(a)
    ker = restitution.solve_many(pd.DataFrame({"alpha": a}))
    np.testing.assert_array_equal(ref.n_collisions, ker.n_collisions)
    np.testing.assert_allclose(ref.cor, ker.cor, atol=1e-11)
    np.testing.assert_allclose(ref.omega_t_col, ker.omega_t_col, atol=1e-9)


def test_count_bisection_with_kernel_finds_the_roots(points):
    """Bisection on the kernel's contact count lands on the root-solved alpha*_n."""
    ch = sp.count_changes(sp.kernel_solver(0.0), 0.3, 30.0, n_grid=200, steps=45)
    expect = points.alpha_star[(points.alpha_star > 0.3) & (points.alpha_star < 30)].to_numpy()
    assert len(ch) == len(expect)
    np.testing.assert_allclose(ch.alpha_change, expect, atol=1e-10 * 30)
    assert np.all(ch.n_above - ch.n_below == 1)


# ---------------------------------------------------------------------------------------------
# Independent recomputation in 80-bit long double (bisection only, no shared code)
# ---------------------------------------------------------------------------------------------
LD = np.longdouble


def _ld_state(alpha, n):
    alpha = LD(alpha)
    c = alpha / (1 + alpha)
    V, r, rp = (1 - alpha) / (1 + alpha), LD(0), LD(-2)
    two_pi = LD(2) * np.arctan2(LD(0), LD(-1))  # 2 pi in long double

    def gap(s):
        return c * r * (1 - np.cos(s)) + V * s - c * rp * np.sin(s)

    for _ in range(n - 1):
        # Walk in small steps until the gap turns negative, then bisect (slow but simple).
        h, s = LD(1e-2), LD(1e-2)
        while gap(s) > 0:
            s += h
            assert s < 50 * two_pi
        lo, hi = s - h, s
        for _ in range(80):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if gap(mid) > 0 else (lo, mid)
        s = (lo + hi) / 2
        r, rp = r * np.cos(s) + rp * np.sin(s), rp * np.cos(s) - r * np.sin(s)
        v1 = V - c * rp
        V, rp = V - 2 * v1 / (1 + alpha), rp + 2 * v1
    return V, r, rp, c, gap


def _ld_grazing(alpha, n):
    V, r, rp, c, gap = _ld_state(alpha, n)
    # First minimum of the gap after the n-th contact: g' = V + R sin(s - phi) = 0, g'' > 0.
    R = np.hypot(c * r, c * rp)
    s = (np.arctan2(c * rp, c * r) + np.arcsin(-V / R)) % (LD(2) * np.arctan2(LD(0), LD(-1)))
    return gap(s)


@pytest.mark.slow
@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 15, 30])
def test_alpha_star_accurate_in_long_double(points, n):
    a = points.alpha_star[n - 1]
    h = 1e-6
    f0 = _ld_grazing(a, n)
    slope = (_ld_grazing(a + h, n) - _ld_grazing(a - h, n)) / LD(2 * h)
    assert abs(float(f0 / slope)) < 1e-12 * max(1.0, a)


@pytest.mark.slow
@pytest.mark.parametrize("n", [2, 3, 5, 8, 15, 30])
def test_alpha_unity_accurate_in_long_double(points, n):
    a = points.alpha_unity[n - 1]
    V, r, rp, _, _ = _ld_state(a, n)
    h = 1e-6
    slope = (_ld_state(a + h, n)[1] - _ld_state(a - h, n)[1]) / LD(2 * h)
    assert abs(float(r / slope)) < 1e-12 * max(1.0, a)
    assert float(1 - V) < 1e-15


@pytest.mark.slow
def test_finite_beta_small_is_close_to_rigid(points):
    """beta = 1e-3: the paper finds beta < 0.01 close to the rigid wall; the minima move little."""
    ch = sp.count_changes(sp.kernel_solver(1e-3), 0.3, 6.0, n_grid=120, steps=40)
    np.testing.assert_allclose(ch.alpha_change[:3], points.alpha_star[:3], atol=0.05)
    np.testing.assert_allclose(ch.cor_below[:3], points.e_star[:3], atol=0.03)
