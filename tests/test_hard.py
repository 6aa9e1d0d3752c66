"""The hard-case suite (issue #7 item 6): every method on every scene of
restitution_workflow.bench.scenes.

Correctness only (timings are the benchmark's job): right contact count, COR error within the
method's own stated bound plus the reference's bound, no NaN, an energy account that closes, and
no hang -- every method stops loudly with ``event_budget_exhausted`` when its contact budget runs
out. References come from independent methods (``benchmarks/reference_values.py``: mpmath for the
two-mass linear scenes, scipy for the chain and the nonlinear laws), never from the code tested.

Bounds per method:

* exact (``auto`` on linear scenes: ``impulsive`` / ``piecewise``): round-off. A backward-stable
  solver's COR error is at most a few ulps of the input times the problem's relative condition
  number kappa = |d cor / d ln alpha| (``Scene.reference_condition``, mpmath), so the bound is
  1e-13 + 64 eps kappa. kappa is O(1) except just past a grazing point, where a contact of depth
  d ~ 1e-5 makes the COR move like sqrt(d) (kappa ~ 1e3).
* ``adaptive``, ``verlet``, ``reference``: the ``error_estimate`` each Result reports (README,
  "Solvers": the method's own estimate of its COR error), plus the same round-off bound.

Exactly at a grazing point (scenes ``graze2``, ``graze5``, beta = 0) the exact solution of the
float input has n contacts and misses the (n+1)-th by 4.5e-16 (n = 2) and 1.3e-15 (n = 5): a
touch inside round-off. The exact kernels' rule (a touch within round-off does not count,
kernels/paper_chain.py, rigid2.py) gives n, and so must they. A numerical method may register that
touch: then the count is n + 1 and the COR moves along the cusp by C sqrt(d) for a touch of depth
d, C = 0.95 (mpmath: alpha 2 ulp above alpha*_2 has a touch of depth 1.7e-15 that moves the COR
by 3.9e-8). A touch a float solver registers is at most ~1e-12 deep (a few thousand ulps of the
O(1) gap), so n + 1 contacts are accepted there with a COR error up to C sqrt(1e-12) ~ 1e-6.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

import restitution
from restitution_workflow.bench.scenes import SCENES, Scene, scene

pytestmark = pytest.mark.hard

EPS = np.finfo(float).eps
GRAZING_EXACT = ("graze2", "graze5")
CUSP_C = 0.95  # COR change per sqrt(touch depth) at alpha*_2 (mpmath, see the module docstring)
MAX_TOUCH = 1e-12  # deepest touch a float64 solver may register where the exact one misses


def methods(sc: Scene) -> list[str]:
    """Methods that apply: all for two masses; Verlet needs a contact spring (beta > 0)."""
    if sc.n_masses != 2:
        return ["auto"]
    return ["auto", "adaptive", "reference"] + (["verlet"] if sc.beta > 0 else [])


CASES = [(sc.name, m) for sc in SCENES for m in methods(sc)]

# Real failures, measured and reported (issue #7): a missed contact, or an error above the
# method's own estimate at its default setting. They are xfailed by name (not by a looser bound),
# so every other case keeps its full check. Fixed since by two-setting error estimates
# (nonlinear.py): adaptive on "many" (x1.45 over its old estimate), reference on "plastic"
# (x3.6), and Verlet's |cor(h/2) - cor(h)|/3 on six scenes (x1.6-2.8); by gap-minimum events in
# restitution.solvers.reference: the shallow contacts just past alpha*_2 and alpha*_5 it used to
# miss; and by events taken off their root at a phase start (reference._off_start): on "xi3" a
# first free-flight step that already reached the wall again had put a contact at the separation
# instant (error 6.1e-6 against an estimate of 1e-9 at rtol 1e-9, the same at 1e-8).
KNOWN_FAILURES: dict = {}


def _exact_bound(sc: Scene) -> float:
    kappa = sc.reference_condition if sc.reference_condition is not None else 1.0
    return 1e-13 + 64 * EPS * kappa


def _energy_tol(method: str, linear_exact: bool) -> float:
    # The tolerances the solvers check their own energy account against (nonlinear.py):
    # 1e3 rtol (default rtol 1e-9) for adaptive / reference, (2 pi step)**2 for Verlet (step
    # 0.01). The exact kernels close it to round-off.
    if linear_exact:
        return 1e-12
    method = "adaptive" if method == "auto" else method  # auto on a nonlinear law
    return {"adaptive": 1e-6, "reference": 1e-6, "verlet": (2 * math.pi * 0.01) ** 2}[method]


def _with_known_failures(cases):
    xfail = lambda c: pytest.mark.xfail(strict=True, reason=KNOWN_FAILURES[c])  # noqa: E731
    return [pytest.param(*c, marks=xfail(c)) if c in KNOWN_FAILURES else c for c in cases]


@pytest.mark.parametrize("name, method", _with_known_failures(CASES))
def test_scene_method(name, method):
    sc = scene(name)
    assert sc.reference_cor is not None and sc.reference_bound is not None, sc
    r = restitution.solve(**sc.solve_kwargs(), method=method)
    values = [r.cor, r.omega_t_col, r.e_translational, r.e_vibrational, r.e_dissipated]
    assert r.status == "ok", r
    assert all(math.isfinite(v) for v in [*values, r.error_estimate]), r
    exact = method == "auto" and sc.linear
    total = r.e_translational + r.e_vibrational + r.e_dissipated
    assert abs(total - 1.0) <= _energy_tol(method, exact), (total, r)
    assert abs(r.e_translational - r.cor**2) <= 1e-12, r
    assert min(r.e_translational, r.e_vibrational) >= 0.0, r
    assert r.e_dissipated >= -_energy_tol(method, exact), r  # no energy created
    err = abs(r.cor - sc.reference_cor)
    if exact:
        assert r.method in ("impulsive", "piecewise")
        assert r.n_collisions == sc.reference_contacts, r
        assert err <= _exact_bound(sc) + sc.reference_bound, (err, r)
        return
    # the estimate covers truncation; round-off comes on top, as for the exact methods
    bound = r.error_estimate + _exact_bound(sc) + sc.reference_bound
    if name in GRAZING_EXACT and r.n_collisions == sc.reference_contacts + 1:
        # registered the round-off touch: the COR moved along the cusp (module docstring)
        bound += CUSP_C * math.sqrt(MAX_TOUCH)
    else:
        assert r.n_collisions == sc.reference_contacts, r
    assert err <= bound, (err, bound, r)


@pytest.mark.parametrize("name, method", CASES)
def test_event_budget_fails_loudly(name, method):
    """A budget smaller than the contacts needed ends with event_budget_exhausted, quickly."""
    sc = scene(name)
    restitution.solve(**sc.solve_kwargs(), method=method, max_events=1)  # JIT warm-up
    if sc.reference_contacts == 1:
        # one contact: the budget of one is enough, and the result must say so
        r = restitution.solve(**sc.solve_kwargs(), method=method, max_events=1)
        assert r.status == "ok" and r.n_collisions == 1
        return
    budget = max(1, sc.reference_contacts // 2)
    t0 = time.perf_counter()
    r = restitution.solve(**sc.solve_kwargs(), method=method, max_events=budget)
    elapsed = time.perf_counter() - t0
    assert r.status == "event_budget_exhausted", r
    assert not r.success
    assert r.n_collisions == budget, r
    # Not a hang: stopping early costs at most what the whole scene costs (seconds for the
    # scipy reference, milliseconds for the others).
    assert elapsed < 10.0, elapsed


def test_budget_is_checked_for_the_tiny_scene_too():
    """The one-contact scene cannot exhaust a budget; a budget of zero is refused up front."""
    sc = scene("tiny")
    for method in methods(sc):
        with pytest.raises(restitution.SceneError, match="max_events"):
            restitution.solve(**sc.solve_kwargs(), method=method, max_events=0)


@pytest.mark.parametrize("method", ["auto", "reference"])
def test_plastic_scene_reloads_past_its_earlier_maximum(method):
    """The plastic scene really reloads past the previous maximum penetration (Sec. 3.1)."""
    sc = scene("plastic")
    r = restitution.solve(**sc.solve_kwargs(), method=method, history=True)
    xm = r.history["x_max"].to_numpy()
    assert len(xm) == sc.reference_contacts
    past = [k for k in range(1, len(xm)) if xm[k] > xm[:k].max() * (1 + 1e-3)]
    assert past, xm  # at least one later contact goes deeper than every earlier one
    # measured: contacts 2 and 3 reach 1.64 and 1.73 times the first penetration
    assert past == [1, 2], xm


def test_just_past_grazing_the_shallow_contact_is_found():
    """alpha*_n (1 + 1e-6) has the (n+1)-th contact the grazing scene lacks, ~1e-5 deep."""
    for n in (2, 5):
        at, past = scene(f"graze{n}"), scene(f"graze{n}_past")
        assert at.reference_contacts == n and past.reference_contacts == n + 1
        # COR continuous, with the sqrt cusp: the jump over 1e-6 in alpha is ~ C sqrt(d)
        jump = abs(past.reference_cor - at.reference_cor)
        assert 1e-4 < jump < 1e-2, jump


# ------------------------------------------------------------------------------------------------
# Minimal reproducers of real problems found by this suite and tests/test_properties.py (strict
# xfails: they turn red when fixed, so the marker can go).
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["adaptive", "reference"])
def test_plastic_law_that_creates_energy_is_never_ok(method):
    """eta > 1: the loading slope kappa eta x**(eta-1) grows past the unloading slope k1, and a
    linear unloading from there returns more than the loading stored (known: config.yaml, fig4
    comment). It depends on the depth reached, so no input check can exclude it; the energy
    account must. alpha = 1, beta = 1, eta = 2, DR = 0: e_dissipated = -0.043 with both methods;
    both say energy_account_open (reference said ok until it checked the contact work too)."""
    r = restitution.solve(1.0, 1.0, contact="plastic", eta=2.0, dr=0.0, method=method)
    assert r.e_dissipated < -0.04  # the law did create energy here
    assert r.status != "ok", r


def test_adaptive_estimate_covers_its_error_on_a_soft_scissor():
    """Scissor spring, alpha = 1, beta = 0.01, L = 1, ks_ratio = 0.01, default rtol 1e-9: COR
    = 1 + 4.0e-7 (an elastic system gaining energy) once. Reference COR = 0.9999999973271128
    (restitution.solvers.precise_scissor, 30 digits checked at 40; scipy's reference at rtol
    1e-13 said 1 - 2.684e-9, 1.1e-11 off)."""
    r = restitution.solve(1.0, 0.01, structure="scissor", L=1.0, ks_ratio=0.01)
    assert r.status == "ok"
    assert abs(r.cor - 0.9999999973271128) <= r.error_estimate


@pytest.mark.parametrize("rtol", [1e-8, 1e-9])
def test_reference_starts_no_contact_at_a_separation(rtol):
    """scipy's reference on the overdamped chatter of "xi3": m1 leaves the wall and is pushed
    back within 0.05, less than solve_ivp's first free-flight step at these rtols. That step's
    sign change used to be located at its start (the gap is 0 at a separation): a contact at the
    separation instant with m1 moving away (v1_in > 0), the COR 6.1e-6 off at both rtols, so the
    two-setting estimate (1e-9) did not see it. Every contact must arrive with v1 < 0, at the
    exact kernel's times."""
    sc = scene("xi3")
    exact = restitution.solve(**sc.solve_kwargs(), history=True).history
    r = restitution.solve(**sc.solve_kwargs(), method="reference", rtol=rtol, history=True)
    got = r.history
    assert r.n_collisions == sc.reference_contacts == len(exact)
    assert (got["v1_in"] < 0.0).all(), got
    assert np.allclose(got["omega_t_start"], exact["omega_t_start"], rtol=0.0, atol=1e-6)
    assert abs(r.cor - sc.reference_cor) <= r.error_estimate


# Found by a sweep of 150 random damped two-mass scenes (alpha 0.1-100, beta 1e-4-1, xi
# 0.01-10; rtol 1e-8 and 1e-9): 8 of its 300 rows were off by more than their estimate (up to
# 794x, one with a contact too many) when contacts could start at a separation; none since.
SEPARATION_SCENES = [
    (10.473385082066256, 0.0006439677392935479, 5.061663106438996),
    (8.14595174108338, 0.001991602159620811, 0.8518385470193125),
    (61.28764377849835, 0.004231126941354832, 1.7306908001601793),
    (2.893892414238938, 0.00043537006288306375, 6.491886435174666),
    (19.185642063774278, 0.00019160804732656995, 1.0836789912833038),
    (47.02624420653705, 0.007016061759228653, 0.2665021266201913),
]


@pytest.mark.parametrize("alpha, beta, xi", SEPARATION_SCENES)
@pytest.mark.parametrize("rtol", [1e-8, 1e-9])
def test_reference_estimate_covers_its_error_on_damped_chatter(alpha, beta, xi, rtol):
    exact = restitution.solve(alpha=alpha, beta=beta, xi=xi)
    r = restitution.solve(alpha=alpha, beta=beta, xi=xi, method="reference", rtol=rtol)
    assert exact.status == r.status == "ok"
    assert r.n_collisions == exact.n_collisions
    assert abs(r.cor - exact.cor) <= r.error_estimate + exact.error_estimate, r


def test_verlet_estimate_covers_a_plateau_of_its_error():
    """Verlet on a stiff contact (beta 2e-4): its runs at steps h, h/2 and h/4 (0.002 here)
    share an error of 1e-6 that shrinks only at h/8, so their changes are 10 times smaller than
    it; the estimate with the old factor 4 was 2.67 times below the error."""
    alpha, beta = 2.7233322727708535, 0.00019995266925001832
    exact = restitution.solve(alpha=alpha, beta=beta)
    r = restitution.solve(alpha=alpha, beta=beta, method="verlet", step=0.002)
    assert exact.status == r.status == "ok" and r.n_collisions == exact.n_collisions
    assert abs(r.cor - exact.cor) > 5e-7  # the plateau is there
    assert abs(r.cor - exact.cor) <= r.error_estimate + exact.error_estimate, r


# Plastic loading x**eta with 2 eta not an integer: its force sigma**(2 eta) is not smooth in
# sigma = sqrt(x) either, and DOP853's estimate of the first sigma step is not its error. With
# the first step capped at a quarter of the stretch, a run and its check at rtol/10 took the
# same first step and shared its error (below: 3.8e-9 and 1.6e-8 off, estimates 2.6e-9 and
# 5.8e-9). From 2026-11-27 the cap was 0.9 there, so that the two runs differed; since
# 2026-11-28 the step at a non-smooth sigma = 0 is |span| rtol**(1/(2 eta + 2)) long
# (integrators.sigma_end_zone), its error about rtol.
ROUGH_SIGMA_SCENES = [
    dict(
        alpha=0.3364950157803586,
        beta=0.9954378814753467,
        xi=2.44436458480894,
        eta=0.8392503564285079,
        dr=0.35904444446297373,
    ),
    dict(
        alpha=11.587213913694015,
        beta=0.006785039420246381,
        xi=0.0,
        eta=0.9191610633032286,
        dr=0.3543328877671789,
    ),
]


@pytest.mark.parametrize("kw", ROUGH_SIGMA_SCENES)
@pytest.mark.parametrize("rtol", [1e-7, 1e-8, 1e-9])
def test_adaptive_estimate_covers_a_power_law_rough_in_sigma(kw, rtol):
    # the independent referee: scipy's DOP853 (restitution.solvers.reference) at rtol 1e-12
    ref = restitution.solve(**kw, contact="plastic", method="reference", rtol=1e-12)
    r = restitution.solve(**kw, contact="plastic", method="adaptive", rtol=rtol)
    assert ref.status == r.status == "ok" and r.n_collisions == ref.n_collisions
    assert abs(r.cor - ref.cor) <= r.error_estimate + ref.error_estimate, r


# Two-mass plastic scenes, one contact, a light second mass: the first sigma step's error was
# the result's (3.8e-7 and 2.4e-7 off at the setting rtol 1e-4, 1.06 and 1.02 times the
# estimate: both runs took a step of 0.9 and 0.73 of the stretch).
ROUGH_SIGMA_CHAINS = [
    (0.00039112673310151476, 0.9379130826796506, 46.60216321053809, 0.6869274949577142,
     0.7442788951173691),
    (0.0026197378510528085, 0.41222055789057027, 3.715099585336242, 0.7679241347171213,
     0.8039321248908188),
]  # fmt: skip


@pytest.mark.parametrize("row", ROUGH_SIGMA_CHAINS)
@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8])
def test_adaptive_estimate_covers_the_first_sigma_step(row, rtol):
    m2, k, k1, eta, dr = row
    contact = {"law": "plastic", "k": k1, "eta": eta, "dr": dr}
    ch = restitution.Chain([1.0, m2], [k], contact=contact)
    ref = restitution.solve(ch, method="reference", rtol=1e-12)
    r = restitution.solve(ch, method="adaptive", rtol=rtol)
    assert ref.status == r.status == "ok" and r.n_collisions == ref.n_collisions
    assert abs(r.cor - ref.cor) <= r.error_estimate + ref.error_estimate, r


# A plastic scene where the reference's max_step (1/50 of a period), not rtol, sized its steps:
# 2.47e-8 off at rtol 1e-6, 1e-7 and 1e-8 alike, so its old check at 10 rtol shared the error.
MAX_STEP_BOUND = dict(alpha=6.332143252821115, beta=0.002482261020012551, xi=0.0)
MAX_STEP_BOUND.update(contact="plastic", eta=1.3985966171369189, dr=0.8697214941297388)


@pytest.mark.parametrize("rtol", [1e-7, 1e-8, 1e-9])
def test_reference_estimate_covers_a_max_step_sized_error(rtol):
    """method="reference" checks against rtol/10 (it checked against 10 rtol: at rtol 1e-8 the
    estimate was 1e-8 for an error of 2.47e-8). Referee: adaptive at rtol 1e-13 (its own
    kernel, a Taylor start of the contact in sigma; 14 contacts, estimate 1.6e-12)."""
    ref = restitution.solve(**MAX_STEP_BOUND, method="adaptive", rtol=1e-13)
    r = restitution.solve(**MAX_STEP_BOUND, method="reference", rtol=rtol)
    assert r.status == ref.status == "ok"
    assert r.n_collisions == ref.n_collisions == 14
    assert abs(r.cor - ref.cor) <= r.error_estimate + ref.error_estimate, (r.cor - ref.cor, r)


# A plastic scene whose 13th contact reloads past the largest penetration by 1.1e-5 (1e-4 of
# it) and comes back below within one solve_ivp step: 26 contacts.
SHALLOW_RELOAD = dict(alpha=18.323851820177627, beta=0.0030516658721057187, xi=0.0)
SHALLOW_RELOAD.update(contact="plastic", eta=0.33471305511217003, dr=0.7079440938822257)


def test_reference_sees_a_reload_shallower_than_a_step():
    """method="reference" watches the compression's maxima on the plastic unloading line: its
    terminal event at x = xmax saw no sign change across the 13th contact's shallow reload, so it
    stayed on the line (a dent 1e-5 off, the COR 1.19e-3 off at every rtol, 0.9300108 against
    0.9311987). Referee: adaptive at rtol 1e-13, whose history has the reload."""
    ref = restitution.solve(**SHALLOW_RELOAD, method="adaptive", rtol=1e-13, history=True)
    assert ref.history["x_max"].iloc[12] > ref.history["x_max"].iloc[11]  # the reload
    for rtol in (1e-9, 1e-12):
        r = restitution.solve(**SHALLOW_RELOAD, method="reference", rtol=rtol)
        assert r.status == "ok" and r.n_collisions == ref.n_collisions == 26
        assert abs(r.cor - ref.cor) <= r.error_estimate + ref.error_estimate, (r.cor - ref.cor, r)


# Just past the plastic scene's first count step in alpha (bisected to 1e-16): m1 comes back to
# the dent at 4e-9 of v0 at t = 4.945, a touch on the plastic unloading line.
TOUCH_ON_DENT = dict(alpha=0.4582303612099118, beta=0.02, contact="plastic", eta=1.5, dr=0.5)


def test_reference_touch_on_the_dent_is_no_loop():
    """method="reference" takes a contact that starts on the dent (x = xp, the plastic unloading
    line) off its separation root there: its first step ended below xp, so the separation was
    located at the start, and the flight from there (m1 still moving in) touched at once: a
    contact and a separation at one instant until 100,000 events (event_budget_exhausted, NaN).
    The COR is continuous across the touch: it must agree with adaptive within the estimates."""
    ref = restitution.solve(**TOUCH_ON_DENT, method="adaptive", rtol=1e-12)
    for rtol in (1e-8, 1e-10, 1e-12):
        r = restitution.solve(**TOUCH_ON_DENT, method="reference", rtol=rtol)
        assert r.status == "ok", r
        assert r.n_collisions <= 3
        assert abs(r.cor - ref.cor) <= r.error_estimate + ref.error_estimate, (r.cor - ref.cor, r)
