"""No missed shallow contact (issue 29, item 1), against the independent mpmath reference.

A contact counts when the gap goes below zero by more than round-off of the gap's own scale at
that moment (kernels.locator.BAND_ULPS ulps of the magnitudes that cancel in it), and the
decision is certified: the replicas locate contacts with bands of BAND_LOW and BAND_HIGH times
that, so a touch within round-off of the band's edge gives a spread, i.e. an error estimate
that covers the COR's jump across the cusp (or the row is ill-conditioned).

The chains below are random N = 9..16 chains at a rigid wall (mass ratios 1e-2..1e2, equal
springs, as the design study's ``masses`` family) with m_2 tuned by bisection onto the point
where the kernel with the old band (64 ulps of a scale without the phase-rounding term) stepped
from n to n + 1 contacts, the last float below it. There the dip of the (n + 1)-th contact was
~64 ulps of the scale deep: the old kernel passed it as a graze with an estimate of 1e-11..4e-11
although the reference counts it (seed 7: 58 against 59 contacts, COR off by 6.9e-7). Each scene
is also taken 1e-9 further on. The seeds are the 3 of a scan of 30 (m_2 x 1..1.5) whose old
step had a small estimate on its lower side; the reference never sees the kernel.

Approach speeds down to 1e-8 of V0 need a finer knob than a mass: one ulp of any mass or spring
moves a dip by ~1e-14 here, i.e. by an approach speed of ~1e-7. A dashpot on the first link does
it: the dip's depth is linear in c_1, and c_1 ~ 1e-12 has ulps of 1e-28. The slow-approach scenes
below are tuned with the reference alone, which also checks each scene's approach speed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import restitution as R
from restitution.solvers.precise import solve_precise


def tuned_chain(seed: int, factor: float):
    """The random chain of ``seed`` with m_2 multiplied by ``factor`` (rigid wall, omega = 1)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(8, 17))
    m = np.r_[1.0, 10 ** rng.uniform(-2, 2, n - 1)]
    m[1] *= factor
    k = np.ones(n - 1) / (1.0 + 1.0 / m[1])
    return m, k


# (seed, factor): the last float below the old kernel's n -> n + 1 step.
EDGES = [(7, 1.0058347670924417), (8, 1.0208274241104545), (14, 1.0409233138291158)]
CASES = [(s, f) for s, f in EDGES] + [(s, f * (1.0 + 1e-9)) for s, f in EDGES if s != 8]


def check_against_reference(m, k, r, ref):
    assert ref.status == "ok" and ref.digits > 18, ref
    if r.status != "ok":  # only an honest refusal
        assert r.status == "ill_conditioned" and math.isnan(r.cor), r
        return
    actual = abs(r.cor - ref.cor)
    assert actual <= r.error_estimate, (actual, r.error_estimate, r, ref.n_collisions)
    if r.error_estimate < 1e-9:  # a certain count is the reference's
        assert r.n_collisions == ref.n_collisions, (r, ref)


@pytest.mark.slow
@pytest.mark.parametrize("seed,factor", CASES)
def test_shallow_contact_is_counted_or_certified(seed, factor):
    m, k = tuned_chain(seed, factor)
    r = R.solve(masses=list(m), springs=list(k), k_contact=math.inf)
    ref = solve_precise(m, k, dps=30)
    check_against_reference(m, k, r, ref)


def test_dip_deeper_than_the_band_is_a_contact():
    """Seed 7 at the old kernel's edge: the 59th contact (a dip ~64 ulps of the gap's scale
    deep, far beyond its round-off) is counted. The reference's count, 59, is the slow test's."""
    m, k = tuned_chain(*EDGES[0])
    r = R.solve(masses=list(m), springs=list(k), k_contact=math.inf)
    assert r.n_collisions == 59, r


@pytest.mark.slow
def test_design_optimiser_result_rechecked_by_the_reference():
    from restitution.analysis.design import minimize_cor, scaled_chain

    d = minimize_cor(8, popsize=4, maxiter=3, seed=1, progress=None)
    m, k, kc = scaled_chain(d.masses, d.springs, 0.0)
    r = R.solve(masses=list(m), springs=list(k), k_contact=kc)
    ref = solve_precise(m, k, kc=kc, dps=30)
    check_against_reference(m, k, r, ref)
    assert abs(d.cor_check - ref.cor) <= max(r.error_estimate, 1e-12), (d, ref)


def _own_step(seed: int, lo: float, hi: float):
    """The last factor below the present kernel's contact-count step in [lo, hi] (bisection to
    adjacent floats: the kernel tunes its own adversary) and the first one above it."""

    def count(f):
        m, k = tuned_chain(seed, f)
        return R.solve(masses=list(m), springs=list(k), k_contact=math.inf).n_collisions

    n_lo = count(lo)
    assert count(hi) != n_lo, (seed, lo, hi)
    while True:
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            return lo, hi
        if count(mid) == n_lo:
            lo = mid
        else:
            hi = mid


@pytest.mark.slow
@pytest.mark.parametrize(
    "seed",
    [
        7,
        14,
    ],
)
def test_own_count_step_is_counted_or_certified(seed):
    """On both sides of the present kernel's own count step (adjacent floats of m_2), where the
    new contact's approach speed is as small as the kernel can see: the reference's count and
    COR within the estimate, or an honest refusal. The slowest approach reached there is
    1.2e-6 (seed 7) and 3.3e-6 (seed 14) of V0: a dip at round-off of the gap's scale, under
    the gap's curvature at that contact (approach speeds of 1e-8 need a far flatter gap)."""
    factor = dict(EDGES)[seed]
    lo, hi = _own_step(seed, factor * (1 - 1e-3), factor * (1 + 1e-3))
    slowest = math.inf
    for f in (lo, hi):
        m, k = tuned_chain(seed, f)
        r = R.solve(masses=list(m), springs=list(k), k_contact=math.inf, history=True)
        if r.status == "ok":
            slowest = min(slowest, float(np.min(np.abs(r.history["v1_in"]))))
        check_against_reference(m, k, r, solve_precise(m, k, dps=30))
    assert slowest < 1e-5, slowest


def moderate_chain(seed: int, factor: float, c1: float = 0.0):
    """A random chain of ``seed`` (N = 6..16, masses 10^-0.5..10^0.5 of m_1, omega = 1, rigid
    wall) with m_2 multiplied by ``factor`` and a dashpot ``c1`` on the first link."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(6, 17))
    m = np.r_[1.0, 10 ** rng.uniform(-0.5, 0.5, n - 1)]
    m[1] *= factor
    k = np.ones(n - 1) / (1.0 + 1.0 / m[1])
    c = np.zeros(n - 1)
    c[0] = c1
    return m, k, c


def tail_chain(seed: int, factor: float, tail: float):
    """``moderate_chain`` without damping, with a light mass 1e-4 (1 + ``tail``) added at the
    far end on a spring of 1e-4 (its own frequency ~1): the dip moves by ~1e-4 of what m_2's
    moves, so ``tail``'s ulps are ~1e-20 in the dip's depth."""
    m, k, _ = moderate_chain(seed, factor)
    return np.r_[m, 1e-4 * (1.0 + tail)], np.r_[k, 1e-4], np.zeros(len(k) + 1)


# Three chains whose n-th contact grazes: m_2's factor, 1e-11..3e-11 beyond the kernel's own
# count step, leaves the dip short of the wall; a fine knob x deepens it, v^2 = slope (x - x_star)
# for the contact's approach speed v. The knob is c_1 (the first link's dashpot) or, undamped,
# the tail mass's offset. x_star and slope come from the reference alone (two contacts at
# v ~ 1e-5, then Newton steps on v^2 at v = 1e-6, 1e-7 and 1e-8).
# name: (chain, seed, factor, x_star, slope, contacts with the new one)
SLOW = {
    "N11-damped": (moderate_chain, 1, 1.2401046278918872, 1.7336180354158998e-12, 117.2993, 12),
    "N15-damped": (moderate_chain, 0, 1.0012164752952581, 1.5920437421914587e-12, 840.4666, 21),
    "N12-undamped": (tail_chain, 1, 1.2400768567310532, 1.6740292689506633e-06, 1.21437e-4, 12),
}


@pytest.mark.slow
@pytest.mark.parametrize("side", ["contact", "miss"])
@pytest.mark.parametrize("speed", [1e-5, 1e-6, 1e-7, 3e-8, 1e-8])
@pytest.mark.parametrize("scene", SLOW)
def test_slow_approach_is_counted_or_certified(scene, speed, side):
    """A contact whose approach speed is ``speed`` (checked by the reference to 1 %), and the
    near miss by the same clearance: the kernel's COR within its estimate of the reference,
    with the reference's count wherever that estimate is below 1e-9."""
    chain, seed, factor, x_star, slope, n_new = SLOW[scene]
    dx = speed**2 / slope
    m, k, c = chain(seed, factor, x_star + dx if side == "contact" else x_star - dx)
    ref = solve_precise(m, k, c, dps=30)
    if side == "contact":
        assert ref.n_collisions == n_new, ref
        assert abs(min(ref.approach_speeds) / speed - 1) < 0.01, ref.approach_speeds
    else:
        assert ref.n_collisions == n_new - 1, ref
    r = R.solve(masses=list(m), springs=list(k), dashpots=list(c), k_contact=math.inf)
    check_against_reference(m, k, r, ref)


def test_reference_approach_speeds_are_the_kernels():
    """The reference's approach speeds (used above to check the tuned scenes) against the
    kernel's history on a well-separated sequence: two independent computations."""
    m, k, c = moderate_chain(1, SLOW["N11-damped"][2], 1e-3)
    ref = solve_precise(m, k, c, dps=30)
    r = R.solve(masses=list(m), springs=list(k), dashpots=list(c), history=True)
    assert r.error_estimate < 1e-9 and r.n_collisions == ref.n_collisions >= 5, (r, ref)
    kernel = np.abs(np.asarray(r.history["v1_in"]))
    np.testing.assert_allclose(kernel, ref.approach_speeds, rtol=0, atol=1e-9)
