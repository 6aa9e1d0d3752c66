"""The count-step curves of the (alpha, beta) plane against independent references.

References: the exact beta = 0 grazing gap of ``special_points`` (its own closed form), and
bisection on the contact count returned by ``restitution.solve`` (the curves are where the count
steps, so the count itself is the defining condition).
"""

import math

import numpy as np
import pytest

import restitution
from restitution.analysis import cormap, special_points


@pytest.fixture(scope="module")
def stars():
    return special_points.special_points(4)


@pytest.mark.parametrize("alpha", [0.3, 0.69, 0.75, 1.5, 2.5, 4.0])
@pytest.mark.parametrize("n", [1, 2, 3])
def test_new_contact_condition_at_rigid_wall_is_the_exact_grazing_gap(alpha, n):
    try:
        ref = special_points.grazing_gap(alpha, n)
    except ValueError:
        assert math.isnan(cormap.G(alpha, 0.0, n, "new").value)
        return
    got = cormap.G(alpha, 0.0, n, "new").value
    if math.isinf(ref):
        assert got == ref
    else:
        assert got == pytest.approx(ref, abs=1e-12)


def test_propagated_states_meet_the_kernel_contacts():
    # The closed-form modal propagation between the kernel's contact times must put m1 on the
    # wall at every contact start and end, with the kernel's velocities (an independent check of
    # both: they share only the event times).
    m, k, kc = [1.0, 0.8, 0.8], [0.8 / 1.8, 0.8 / 1.8], (0.8 / 1.8) / 0.05
    res = restitution.solve(alpha=0.8, beta=0.05, n_masses=3, history=True)
    hist = res.history
    free = cormap.Modes.of(np.array(m), cormap.stiffness(k))
    touch = cormap.Modes.of(np.array(m), cormap.stiffness(k, kc))
    u, v, t = np.zeros(3), -np.ones(3), 0.0
    for row in hist.itertuples():
        u, v = free.advance(u, v, row.omega_t_start - t)
        assert abs(u[0]) < 1e-10
        assert v[0] == pytest.approx(row.v1_in, abs=1e-10)
        u, v = touch.advance(u, v, row.omega_t_end - row.omega_t_start)
        assert abs(u[0]) < 1e-10
        assert v[0] == pytest.approx(row.v1_out, abs=1e-10)
        t = row.omega_t_end
    assert res.n_collisions == len(hist) >= 2


def _count(alpha, beta):
    return restitution.solve(alpha=alpha, beta=beta).n_collisions


def _bisect_count(f, lo, hi, steps=48):
    """Where the integer function f steps between lo and hi (geometric bisection)."""
    c_lo, c_hi = f(lo), f(hi)
    assert c_lo != c_hi, "no count step in the bracket"
    for _ in range(steps):
        mid = math.sqrt(lo * hi)
        if f(mid) == c_lo:
            lo = mid
        else:
            hi = mid
    return math.sqrt(lo * hi), c_lo, c_hi


@pytest.fixture(scope="module")
def curves(stars):
    return cormap.trace_all(stars["alpha_star"].to_numpy()[:3])


def test_curves_start_at_the_exact_rigid_wall_points_and_stay_on_their_condition(curves, stars):
    new = [c for c in curves if c.kind == "new"]
    assert [c.n for c in new] == [1, 2, 3]
    for c in new:
        assert c.beta[0] == 0.0
        assert c.alpha[0] == pytest.approx(stars["alpha_star"][c.n - 1], rel=1e-15)
        assert len(c.alpha) > 5
        assert max(abs(r) for r in c.residual) < 1e-10
    # Split curves exist (a contact splits in two at larger beta) and are traced too.
    assert any(c.kind == "split" for c in curves)
    for c in curves:
        assert max(abs(r) for r in c.residual) < 1e-10


def test_curve_points_are_where_the_count_steps_by_bisection(curves):
    checked = 0
    for c in curves:
        for i in range(1, len(c.alpha) - 1, max(1, len(c.alpha) // 3)):
            a, b = c.alpha[i], c.beta[i]
            if b < 1e-6:
                continue
            # Bisect along the coordinate the curve crosses most steeply.
            ga, gb = cormap.gradient(c.n, c.kind, (math.log(a), math.sqrt(b)))
            if abs(ga) >= abs(gb):
                x, lo, hi = a, a * (1 - 1e-5), a * (1 + 1e-5)
                found, n_lo, n_hi = _bisect_count(lambda s, b=b: _count(s, b), lo, hi)
            else:
                x, lo, hi = b, b * (1 - 1e-5), b * (1 + 1e-5)
                found, n_lo, n_hi = _bisect_count(lambda s, a=a: _count(a, s), lo, hi)
            assert found == pytest.approx(x, rel=1e-9), (c.kind, c.n, a, b)
            assert abs(n_hi - n_lo) == 1
            checked += 1
    assert checked >= 10


def test_split_condition_sign_matches_the_count():
    # Across the split curve of the first contact at alpha = 10 (beta ~ 0.22): at the smaller
    # beta the first contact dips below zero force and splits (G < 0, two contacts more: the
    # split and what follows), at the larger it holds (G > 0). The root of G in beta must be the
    # step of the count found by bisection.
    split, held = cormap.G(10.0, 0.15, 1, "split"), cormap.G(10.0, 0.3, 1, "split")
    assert split.value < 0.0 < held.value
    assert split.n_collisions > held.n_collisions
    from scipy.optimize import brentq

    root = brentq(lambda b: cormap.G(10.0, b, 1, "split").value, 0.15, 0.3, xtol=1e-15)
    found, n_lo, n_hi = _bisect_count(lambda b: _count(10.0, b), 0.15, 0.3)
    assert found == pytest.approx(root, rel=1e-9)


def test_bad_kind_is_refused():
    with pytest.raises(ValueError, match="kind"):
        cormap.G(1.0, 0.1, 1, "graze")
    with pytest.raises(ValueError, match="split"):
        cormap.G(1.0, 0.0, 1, "split")


def test_first_velocity_is_first_bit_for_bit():
    """The velocity-only scan of first_minimum gives the very bits of Modes.first's velocity
    (rigid-body mode skipped, the same operations on the others): the design study's results
    do not move when the scan gets cheaper."""
    rng = np.random.default_rng(7)
    for trial in range(200):
        n = int(rng.integers(2, 9))
        m = np.exp(rng.uniform(np.log(0.01), np.log(100.0), n))
        m[0] = 1.0
        k = np.exp(rng.uniform(-2.0, 2.0, n - 1))
        kc = 0.0 if trial % 2 else float(np.exp(rng.uniform(0.0, 4.0)))
        modes = cormap.Modes.of(m, cormap.stiffness(k, kc))
        u, v = rng.normal(size=n), rng.normal(size=n)
        t = np.linspace(0.0, rng.uniform(0.1, 200.0), int(rng.integers(1, 3000)) + 1)
        for ts in (t, t[-1:]):
            want = modes.first(u, v, ts)[1]
            got = modes.first_velocity(u, v, ts)
            assert got.shape == want.shape
            assert np.array_equal(got.view(np.int64), want.view(np.int64))
        # Brent's evaluator (velocity_from, the modal state's invariants done once), one time
        # at a time as brentq calls it: the same bits again
        at = modes.velocity_from(*modes.coords(u, v))
        for s in t[:: max(1, t.size // 7)]:
            one = at(np.array([s]))
            assert one.view(np.int64)[0] == modes.first(u, v, np.array([s]))[1].view(np.int64)[0]
