"""The adaptive kernel on power-law contacts against an independent 30-digit reference.

The reference (benchmarks/mp_nonlinear.py: mpmath Taylor series, the ends of the power law in
sigma = sqrt(x), linear free flight by matrix exponentials; no numba, no Runge-Kutta) is first
checked against the closed forms of one mass; its values for the chains below are pasted (30 and
40 digits agree to the last float64 digit; ``python benchmarks/bench_nonlinear_precision.py``
recomputes them).
"""

import math
import sys
from pathlib import Path

import pytest
from scipy.special import beta as beta_fn

import restitution as R

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import mp_nonlinear as MP  # noqa: E402

# (name, chain, reference COR, contacts): Hertz on two masses and on the three-mass chain of
# issue 27, the hard suite's plastic scene (eta = 0.5, reloads past its maximum) in kernel units
SCENES = [
    (
        "hertz2",
        dict(masses=[1.0, 2.0], springs=[2.0 / 3.0], contact={"law": "hertz", "k": 20.0}),
        0.6833725219079727,
        2,
    ),
    (
        "hertz3",
        dict(masses=[1, 0.5, 2], springs=[0.3, 1.2], contact={"law": "hertz", "k": 50}),
        0.9626530924164504,
        3,
    ),
]


@pytest.mark.parametrize("k_h, v0, m", [(1.0, 1.0, 1.0), (2.0, 7.0, 3.5)])
def test_reference_reproduces_one_mass_on_hertz(k_h, v0, m):
    r = MP.solve(MP.Chain([m], [], None, ("hertz", k_h)), v0, dps=30)
    assert r["contacts"] == 1
    assert abs(r["cor"] - 1) < 1e-18
    mp = MP.mp
    f = mp.mpf(2) / 5  # not the float 0.4
    t_c = 2 * f * mp.beta(f, mp.mpf(1) / 2) * (mp.mpf(5) / 4) ** f
    t_c *= (mp.mpf(m) / k_h) ** f * mp.mpf(v0) ** (-f / 2)
    assert abs(r["t_col"] / t_c - 1) < 1e-18


def test_reference_reproduces_one_mass_on_a_power_law():
    # loading k x**0.5 from 0, unloading on the line of slope k1: COR sqrt(1 - DR)
    from restitution.model import laws

    k1, dr, eta, v0 = 30.0, 0.3, 0.5, 1.0
    kappa = laws.plastic_kappa(dr, eta, k1, v0, 1.0)
    r = MP.solve(MP.Chain([1.0], [], None, ("plastic", k1, kappa, eta)), v0, dps=30)
    assert r["contacts"] == 1
    x_max = ((eta + 1.0) / (2.0 * kappa)) ** (1.0 / (eta + 1.0))
    t_c = x_max * beta_fn(1.0 / (eta + 1.0), 0.5) / (eta + 1.0) + 0.5 * math.pi / math.sqrt(k1)
    assert abs(float(r["cor"]) - math.sqrt(1.0 - dr)) < 1e-15
    assert abs(float(r["t_col"]) / t_c - 1.0) < 1e-13


@pytest.mark.parametrize("name, kw, ref, ncol", SCENES, ids=[s[0] for s in SCENES])
@pytest.mark.parametrize("rtol", [1e-8, 1e-10, 1e-12])
def test_adaptive_within_its_estimate_and_1e12_at_rtol_1e12(name, kw, ref, ncol, rtol):
    r = R.solve(**kw, method="adaptive", rtol=rtol)
    assert r.status == "ok" and r.n_collisions == ncol
    err = abs(r.cor - ref)
    assert err <= r.error_estimate
    if rtol <= 1e-12:
        assert err < 1e-12


def test_plastic_scene_against_the_reference():
    from restitution_workflow.bench.scenes import scene

    sc = scene("plastic")
    r = R.solve(**sc.solve_kwargs(), method="adaptive", rtol=1e-12)
    assert r.status == "ok" and r.n_collisions == sc.reference_contacts
    assert abs(r.cor - sc.reference_cor) < 1e-12 + sc.reference_bound
    assert abs(r.cor - sc.reference_cor) <= r.error_estimate + sc.reference_bound


def _plastic2(m2, k12, k1, dr):
    """Two masses on the paper's plastic contact with eta = 0.5 (m1 = 1, v0 = 1)."""
    return dict(masses=[1.0, m2], springs=[k12],
                contact={"law": "plastic", "k": k1, "eta": 0.5, "dr": dr})  # fmt: skip


# Two random Hertz chains (benchmarks/mp_nonlinear.py: 30 and 40 digits agree to 1e-20) whose
# adaptive runs at rtol 1e-6 and 1e-7 lay on one plateau of their error (1.43e-6 and 1.60e-6;
# 9.45e-7 and 1.13e-6 off): with the check one decade finer, the rtol/10 result was outside its
# estimate (2.0 and 1.3 times). The check two decades finer sees the plateau. Then two random
# two-mass plastic scenes (eta = 0.5, one contact; 30 and 40 digits agree to 1e-22) whose rtol
# 1e-5 result was outside the estimate of the runs at 1e-4 and 1e-5 (2.0 and 1.7 times).
PLATEAU = [
    (
        dict(
            masses=[1.0, 34.451416510053505],
            springs=[0.04976077016136915],
            dashpots=[0.015684767203690976],
            contact={"law": "hertz", "k": 32.28786140190496},
        ),
        0.93950859440872603917,
        21,
    ),
    (
        dict(
            masses=[1.0, 12.525210938790599, 1.0101242447044905],
            springs=[0.052270101597704, 4.13046215293787],
            contact={"law": "hertz", "k": 44.660433130849576},
        ),
        0.94939678227002860277,
        9,
    ),
    (
        _plastic2(0.07906624565945466, 0.7659650129375085, 8.138157369621515, 0.8617676273025765),
        0.3784618607989551273966,
        1,
    ),
    (
        _plastic2(0.09509049915486013, 3.8703232171252906, 37.48229531350965, 0.8707371974052436),
        0.3679391317845677659418,
        1,
    ),
]


@pytest.mark.parametrize(
    "kw, ref, ncol", PLATEAU, ids=["hertz2", "hertz3", "plastic2a", "plastic2b"]
)
@pytest.mark.parametrize("rtol", [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10, 1e-12])
def test_adaptive_estimate_holds_where_two_runs_share_their_error(kw, ref, ncol, rtol):
    r = R.solve(**kw, method="adaptive", rtol=rtol)
    assert r.status == "ok" and r.n_collisions == ncol
    assert abs(r.cor - ref) <= r.error_estimate
