"""Rigid-wall dashpot chatter and the sticking limit, budgets and extreme parameters of the
exact kernels (restitution.kernels.exact_chain, rigid2, linear).

Chatter: a dashpot on link 1 at a rigid wall makes m1 bounce with speeds that decay only like
1/k, so the contact sequence is unbounded; the kernels continue it with its sticking limit (m1
held at the wall while the force on it is compressive, lift-off when it turns tensile) once the
approach speed is below a cut-off, and flag it. References: the same scene with a cut-off ten
times smaller (the limit must not depend on it beyond the error bound the kernel reports), the
momentum balance of the contact history, and the independent two-mass kernel rigid2.
"""

import math

import numpy as np
import pytest

from restitution.kernels.exact_chain import (
    BETA_FALLBACK,
    BETA_RIGID,
    EXTRAP_BELOW,
    WORK_MAX,
    _run,
    _solve,
    solve_chain,
    solve_chain_batch,
)
from restitution.kernels.layout import (
    FLAG_EXTRAPOLATED,
    FLAG_RIGID_LIMIT,
    FLAG_STICKING,
    H_IMPULSE,
    H_VOUT,
    N_HIST,
    N_OUT,
    OUT_COR,
    OUT_EDISS,
    OUT_ERR,
    OUT_ETRANS,
    OUT_EVIB,
    OUT_FLAGS,
    OUT_NCOL,
    OUT_STATUS,
    STATUS_OK,
    STATUS_PERMANENT_CONTACT,
    STATUS_WORK_BUDGET,
)
from restitution.kernels.paper_chain import _paper_chain, solve_linear
from restitution.kernels.rigid2 import _rigid2, rigid2

NOHIST = np.zeros((0, N_HIST))
GRID_ALPHA = [5.0, 20.0, 50.0, 100.0, 200.0]
GRID_XI = [0.05, 0.3, 1.0, 3.0]


def _chain(alpha, xi, n, beta=0.0):
    return _paper_chain(float(alpha), float(beta), float(xi), int(n))


@pytest.mark.parametrize("n", [2, 3, 5])
def test_chatter_grid_finishes_ok(n):
    """The grid of issue 17 (a subset of it here; benchmarks/bench_chain.py runs all of it and
    prints the times): every scene finishes ok, with the energy account closed."""
    for alpha in GRID_ALPHA:
        for xi in GRID_XI:
            out = solve_chain(*_chain(alpha, xi, n), 100_000, NOHIST)
            assert out[OUT_STATUS] == STATUS_OK, (alpha, xi, n, out)
            assert -1e-12 <= out[OUT_COR] <= 1.0 + 1e-12
            assert abs(out[OUT_ETRANS] + out[OUT_EVIB] + out[OUT_EDISS] - 1.0) < 1e-9


@pytest.mark.parametrize("alpha", [150.0, 200.0])
def test_rigid2_sticks_at_xi_half(alpha):
    """These ended event_budget_exhausted after 100,000 contacts with the 1e-4 cut-off."""
    out = rigid2(alpha, 0.5, 100_000, NOHIST)
    assert out[OUT_STATUS] == STATUS_OK
    assert 0.0 < out[OUT_ERR] <= 1e-6
    finer = _rigid2(alpha, 0.5, 2_000_000, NOHIST, 3e-4)
    assert finer[OUT_STATUS] == STATUS_OK
    assert abs(finer[OUT_COR] - out[OUT_COR]) < out[OUT_ERR]


@pytest.mark.parametrize("alpha, xi, n", [(50.0, 0.3, 3), (100.0, 1.0, 3), (20.0, 0.5, 5)])
def test_sticking_limit_independent_of_cutoff(alpha, xi, n):
    m, k, c, kc = _chain(alpha, xi, n)
    rows = 200_000
    hist = np.zeros((rows, N_HIST))
    out = solve_chain(m, k, c, kc, 100_000, hist)
    assert out[OUT_STATUS] == STATUS_OK and int(out[OUT_FLAGS]) & FLAG_STICKING
    # the reported bound covers the change to a cut-off ten times smaller
    rec = np.zeros((0, 3 + 2 * n))
    fine = _run(m, k, c, kc, 1_000_000, NOHIST, rec, 1e12, 3e-4, 2000)[0]
    assert fine[OUT_STATUS] == STATUS_OK
    assert abs(fine[OUT_COR] - out[OUT_COR]) < out[OUT_ERR]
    # momentum: the wall's impulses (and the sticking phases' holding force) add up
    nc = int(out[OUT_NCOL])
    assert abs(hist[:nc, H_IMPULSE].sum() - m.sum() * (out[OUT_COR] + 1.0)) < 1e-9 * m.sum()
    assert np.any(hist[:nc, H_VOUT] == 0.0)  # a sticking phase ends with m1 at rest


def test_chain_sticking_agrees_with_rigid2():
    """Two masses through the general kernel's sticking (clamped chain of one mass) and through
    rigid2's closed-form sticking: same limit."""
    for alpha, xi in [(30.0, 1.0), (200.0, 0.3), (10.0, 3.0)]:
        m, k, c, kc = _chain(alpha, xi, 2)
        a = _run(m, k, c, kc, 100_000, NOHIST, np.zeros((0, 7)), WORK_MAX)[0]
        b = rigid2(alpha, xi, 100_000, NOHIST)
        assert a[OUT_STATUS] == b[OUT_STATUS] == STATUS_OK
        assert abs(a[OUT_COR] - b[OUT_COR]) < max(a[OUT_ERR], b[OUT_ERR])


def test_short_chatter_stays_exact():
    """Chatters that end within 2000 contacts are finished contact by contact (no flag)."""
    out = solve_linear(8.038352633891236, 0.0, 2.5, 2, 100_000, NOHIST)
    assert out[OUT_STATUS] == STATUS_OK and int(out[OUT_NCOL]) == 1725
    assert int(out[OUT_FLAGS]) == 0


def test_work_budget_is_counted_in_operations():
    """A tiny work budget ends the scene with its own status and a NaN COR, identically on every
    run (operations, not time)."""
    m, k, c, kc = _chain(20.0, 0.5, 5)
    outs = [_solve(m, k, c, kc, 100_000, NOHIST, 1e3) for _ in range(2)]
    assert outs[0][OUT_STATUS] == STATUS_WORK_BUDGET
    assert math.isnan(outs[0][OUT_COR])
    assert np.array_equal(outs[0], outs[1], equal_nan=True)


@pytest.mark.slow
def test_long_chain_chatter_is_bounded():
    """N = 128, alpha = 10, xi = 1 ran 308 s before giving up: it now ends, ok or by its work
    budget, never unbounded."""
    out = solve_chain(*_chain(10.0, 1.0, 128), 100_000, NOHIST)
    assert out[OUT_STATUS] in (STATUS_OK, STATUS_WORK_BUDGET)


# ------------------------------------------------------------------------------------------------
# Extremes: handled, or an explicit status with a NaN COR; never a raise, never a garbage ok
# ------------------------------------------------------------------------------------------------

BETAS = [5e-324, 1e-310, 1e-308, 1e-300, 1e-100, 1e-30, 1e-20, 1e-16, 1e-14, 1e-12, 1e-10]


def _check_row(out):
    st = int(out[OUT_STATUS])
    if st == STATUS_OK:
        # Passive, and the energy account closed, to within the row's own error bound (1e-12
        # and 1e-9 at least): alpha = 1e-8, beta = 1, xi = 1e3 (an overdamped pair of rates
        # 4e6 apart, over a contact of 3e4 time units) finishes with COR 1 + 1.8e-10 under an
        # estimate of 1.5e-9 (the 30-digit reference: 1 to double precision).
        err = out[OUT_ERR]
        assert out[OUT_NCOL] >= 1
        assert -max(1e-12, err) <= out[OUT_COR] <= 1.0 + max(1e-12, err)
        assert abs(out[OUT_ETRANS] + out[OUT_EVIB] + out[OUT_EDISS] - 1.0) <= max(1e-9, err)
    elif st == STATUS_PERMANENT_CONTACT:
        assert out[OUT_COR] == 0.0
    else:
        assert math.isnan(out[OUT_COR])


@pytest.mark.parametrize("xi", [0.0, 0.3])
@pytest.mark.parametrize("n", [2, 3])
def test_tiny_beta_is_the_rigid_limit_within_its_bound(xi, n):
    rigid = solve_chain(*_chain(3.0, xi, n), 100_000, NOHIST)
    for beta in BETAS:
        scene = _chain(3.0, xi, n, beta)
        out = solve_chain(*scene, 100_000, NOHIST)
        assert out[OUT_STATUS] == STATUS_OK, beta
        _check_row(out)
        if int(out[OUT_FLAGS]) & FLAG_RIGID_LIMIT:
            assert beta < BETA_FALLBACK
            assert out[OUT_ERR] >= 10.0 * math.sqrt(beta)
        elif int(out[OUT_FLAGS]) & FLAG_EXTRAPOLATED:  # the limit corrected to beta
            assert beta < EXTRAP_BELOW
            assert out[OUT_ERR] < 10.0 * math.sqrt(beta)
        else:  # solved with the contact spring, or k/beta overflowed to a rigid wall
            assert beta >= BETA_RIGID or scene[3] == math.inf
        if out[OUT_NCOL] == rigid[OUT_NCOL]:
            # the finite-stiffness COR approaches the rigid one like sqrt(beta) (bound 10 sqrt)
            bound = 10.0 * math.sqrt(beta) + 1e-12
            assert abs(out[OUT_COR] - rigid[OUT_COR]) <= bound + out[OUT_ERR], beta


def test_extreme_parameters_never_raise_in_a_batch():
    scenes = []
    for alpha in (1e-8, 1e-3, 1.0, 1e3, 1e8):
        for beta in (0.0, 5e-324, 1e-300, 1e-12, 1e-3, 1.0, 1e6):
            for xi in (0.0, 1.0, 1e3):
                for n in (2, 3):
                    scenes.append(_chain(alpha, xi, n, beta))
    rows = len(scenes)
    M = np.ones((rows, 3))
    K = np.ones((rows, 2))
    C = np.zeros((rows, 2))
    nn = np.zeros(rows, np.int64)
    kc = np.zeros(rows)
    for i, (m, k, c, kci) in enumerate(scenes):
        nn[i] = m.size
        M[i, : m.size], K[i, : k.size], C[i, : c.size], kc[i] = m, k, c, kci
    out = solve_chain_batch(M, K, C, nn, kc, 20_000)
    assert out.shape == (rows, N_OUT)
    for row in out:
        _check_row(row)


@pytest.mark.slow
def test_sticking_limit_estimate_covers_a_chatter_that_ends_by_itself():
    """alpha = 20, xi = 0.3, N = 4: the chatter at ~2e-3 is cut by the sticking limit at 2001
    contacts, while the exact sequence ends by itself (the link lifts m1 off) at 2095; the
    sticking COR is 6.6e-6 off, 1.5 v**2 of the cut's speed, which the old estimate v**2 did not
    cover. The pure-chatter check run (replica.stick_check) finds the exact end, and the
    estimate covers the difference; the 40-digit reference has no sticking rule."""
    import restitution as R

    r = R.solve(alpha=20.0, xi=0.3, n_masses=4)
    assert r.status == "ok" and r.method == "impulsive+sticking", r
    ref = R.solve(alpha=20.0, xi=0.3, n_masses=4, method="precise")
    assert ref.status == "ok" and ref.n_collisions == 2095, ref
    actual = abs(r.cor - ref.cor)
    assert actual > 1e-6  # the case the check exists for
    assert actual <= r.error_estimate, (actual, r)


@pytest.mark.parametrize(
    "alpha, xi, ends",
    [(6.437158260198205, 5.0983171232811655, 7907), (9.042695505897878, 2.8679740678485204, 8032)],
)
def test_two_mass_sticking_estimate_covers_a_chatter_ending_long_after_the_cut(alpha, xi, ends):
    """Two masses, cut at 2001 contacts, whose chatter ends by itself 4 times later: the cut at
    half the speed gives the same COR (it cuts at the same contact), so only the pure chatter,
    now run on for up to 16 times the contacts (2.5 before), sees the sticking limit's error
    (3.4e-9 under an estimate of 1.3e-10, and 8.1e-9 under 4.0e-9 before). The 40-digit
    reference has no sticking rule."""
    import restitution as R

    r = R.solve(alpha=alpha, xi=xi)
    assert r.status == "ok" and r.method == "impulsive+sticking" and r.n_collisions == 2001, r
    ref = R.solve(alpha=alpha, xi=xi, method="precise")
    assert ref.status == "ok" and ref.n_collisions == ends, ref
    actual = abs(r.cor - ref.cor)
    assert actual > 1e-9  # the case the check exists for
    assert actual <= r.error_estimate, (actual, r)
