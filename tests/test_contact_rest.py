"""m1 at rest in a contact: the adaptive kernel's Zeno guard (kernels/stepping.py, ZENO_FLIPS).

After a long press m1 can creep out of a contact so slowly that its velocity is zero to within
the integration error. At a loose rtol the kernel then saw turns and rises of m1 a millionth of a
step apart until its work budget ran out (``work_budget_exhausted`` in 1.5 s where rtol 1e-8
finished in 7 ms). The scenes are the one that showed it and the two rows of a random sweep of
damped scissor chains (docs/solvers.md) that ran out of budget before the guard, and two
two-mass scenes where a guarded contact ends at rest (m1 pulled off the wall, or pushed in).
"""

import numpy as np

import restitution as R

SCISSOR = "scissor"
# 4 masses, strong dashpots, a soft scissor first link: the 7th contact lasts 46 time units and
# m1 leaves it at 7.5e-9 of the approach speed.
CREEP = dict(
    masses=[0.4129465611650897, 0.760117261408711, 1.4169288395228266, 1.4656355703686068],
    springs=[0.43450745910911664, 1.291164377620845, 0.6417010156791465],
    dashpots=[0.8280125518101003, 0.19433140198957533, 0.5579550448070784],
    contact={"law": "linear", "k": 141.99768781397793},
    links=[
        {"law": SCISSOR, "ks": 0.0043450745910911664, "L": 8.519684440900704},
        {"law": "linear"},
        {"law": "linear"},
    ],
)
# the sweep's rows (seed 11, rows 120 and 207): a linear and a Hunt-Crossley contact
SWEEP_LINEAR = dict(
    masses=[0.38031418020581476, 1.103003499347886, 0.5527625843172724, 0.340880992599202],
    springs=[2.7276988570264495, 2.1493720723375045, 1.3628991717980432],
    dashpots=[1.1181717568777225, 0.9363655948624016, 0.5792070234232517],
    contact={"law": "linear", "k": 17.48006419668375},
    links=[{"law": SCISSOR, "ks": 0.01566396198924364, "L": 3.8201909542214336}]
    + [{"law": "linear"}] * 2,
)
SWEEP_LINEAR_COR = 0.008305069320688349  # precise_scissor, 2 contacts (10.4 min)
SWEEP_HUNT_CROSSLEY = dict(
    masses=[0.7774088239366107, 2.3390091190611773, 1.248835001480444],
    springs=[0.36290892103932315, 0.8580969845928313],
    dashpots=[1.2023801759759276, 0.4158602595504247],
    contact={"law": "hunt_crossley", "k": 38.50268216014363, "alpha": 0.05},
    links=[
        {"law": SCISSOR, "ks": 0.0018658096387811213, "L": 8.757905894437025},
        {"law": "linear"},
    ],
)


def _solve(scene, rtol):
    return R.solve(R.Chain(**scene), method="adaptive", rtol=rtol)


def test_sweep_rows_finish_within_their_estimates():
    r = _solve(SWEEP_LINEAR, 1e-4)
    assert r.status == "ok"
    assert abs(r.cor - SWEEP_LINEAR_COR) <= r.error_estimate
    # no independent reference for Hunt-Crossley with scissor links: the loose run agrees with a
    # tight one within the two estimates
    loose, tight = _solve(SWEEP_HUNT_CROSSLEY, 1e-4), _solve(SWEEP_HUNT_CROSSLEY, 1e-9)
    assert loose.status == tight.status == "ok"
    assert abs(loose.cor - tight.cor) <= loose.error_estimate + tight.error_estimate


def test_creep_trajectory_reaches_its_last_sample():
    times = np.linspace(0.0, 60.0, 31)
    d = R.trajectory(R.Chain(**CREEP), times, rtol=1e-5)
    samples = d[d["event"] == "sample"]
    assert np.allclose(samples["t"].to_numpy(), times, rtol=0.0, atol=1e-12)
    assert np.isfinite(samples["u_1"]).all()


def test_two_masses_at_rest_within_the_estimate_of_scipy():
    """The paper's form, a strongly damped first link with a soft scissor: one of 69 rows of a
    random sweep (docs/solvers.md) that ran out of budget at rtol 1e-4..1e-6; the referee is
    scipy's DOP853 with events at rtol 1e-12 (method="reference"), no code of the kernel."""
    kw = dict(alpha=4.085001626994877, beta=0.004771215265777184, xi=2.396906942611448)
    kw.update(structure=SCISSOR, ks_ratio=0.0012483077188746928, L=10.441726162865335)
    ref = R.solve(**kw, method="reference", rtol=1e-12)
    assert ref.status == "ok"
    for rtol in (1e-5, 1e-6):
        r = R.solve(**kw, method="adaptive", rtol=rtol)
        assert r.status == "ok"
        assert abs(r.cor - ref.cor) <= r.error_estimate


# Two paper-form scenes of the same sweep; their COR by scipy's DOP853 with events at rtol 1e-12
# (``R.solve(**scene, method="reference", rtol=1e-12)``: 6.4 s and 4.1 s, too slow to run here;
# no code of the adaptive kernel).
PULLED_OFF = dict(alpha=2.792749506391019, beta=0.015297671171672442, xi=2.404780077920204)
PULLED_OFF.update(structure=SCISSOR, ks_ratio=0.0015702456502440087, L=5.911133274040745)
PULLED_OFF_COR = 0.0001441082027157228  # reference, 3 contacts
PUSHED_IN = dict(alpha=8.646786035274442, beta=0.0012721973085498164, xi=1.0189605267354274)
PUSHED_IN.update(structure=SCISSOR, ks_ratio=0.00204310550193042, L=24.01111169194193)
PUSHED_IN_COR = 0.002802050477774937  # reference, 12 contacts


def test_m1_pulled_off_at_rest_leaves_the_wall():
    """A guarded contact whose separation comes with m1 moving into the wall within the band
    (v1 = -7.7e-7 at rtol 1e-4, t = 34.9) while the link pulls it off: m1 leaves at rest. It
    touched again at once before, 12,679 contacts until the budget ran out."""
    # At rtol 1e-4 the returned run (rtol 1e-6) leaves at rest and finishes, but the check run at
    # 1e-4 still breaks the creep into touches until its budget runs out (29,269 contacts): the
    # row is unchecked (until 2026-12-07 it was ok with an infinite estimate, which this test's
    # bound passed whatever the COR). From 1e-5 both runs finish.
    r = R.solve(**PULLED_OFF, method="adaptive", rtol=1e-4)
    assert r.status == "unchecked" and r.n_collisions < 10
    assert abs(r.cor - PULLED_OFF_COR) <= 1e-8  # (1.7e-10 off the reference)
    for rtol in (1e-5, 1e-6):
        r = R.solve(**PULLED_OFF, method="adaptive", rtol=rtol)
        assert r.status == "ok"
        assert r.n_collisions < 10
        assert abs(r.cor - PULLED_OFF_COR) <= r.error_estimate


def test_m1_pushed_in_at_rest_keeps_its_state():
    """The same event while the links push m1 into the wall: no separation at rest, the state
    is kept (setting v1 = 0 there made the next flight touch at once, a loop at one instant)."""
    for rtol in (1e-5, 1e-6):
        r = R.solve(**PUSHED_IN, method="adaptive", rtol=rtol)
        assert r.status == "ok"
        assert abs(r.cor - PUSHED_IN_COR) <= r.error_estimate < 1e-2
