"""Force laws of Sections 3.1 and 3.2: DR -> kappa, scissor curve, parameter validation."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

import restitution
from conftest import solve_paper_law
from restitution.model import laws
from restitution.model.ranges import SceneError

K2 = 2.0 / 3.0  # alpha = 2


@pytest.mark.parametrize("eta, dr", [(0.5, 0.3), (1.0, 0.0), (1.0, 0.5), (2.0, 0.1), (0.2, 0.9)])
@pytest.mark.parametrize("v0", [1.0, 3.0])
def test_kappa_reproduces_dr_for_m1_alone(eta, dr, v0):
    k1 = 5.0
    kappa = laws.plastic_kappa(dr, eta, k1, v0)
    # loading stores all of m1's energy; the linear unloading returns (1 - DR) of it
    xmax = ((eta + 1.0) * v0 * v0 / (2.0 * kappa)) ** (1.0 / (eta + 1.0))
    fmax = kappa * xmax**eta
    assert fmax**2 / (2.0 * k1) == pytest.approx((1.0 - dr) * v0 * v0 / 2.0, rel=1e-12)
    assert xmax - fmax / k1 >= -1e-12  # the residual dent is never negative


def test_kappa_linear_limit():
    assert laws.plastic_kappa(0.0, 1.0, 7.0) == pytest.approx(7.0, rel=1e-14)


@pytest.mark.parametrize("eta, dr", [(0.5, 0.4), (2.0, 0.2)])
def test_single_mass_rebound_is_sqrt_one_minus_dr(eta, dr):
    # alpha -> 0 leaves m1 alone on the contact (k1 = k2/beta = 1 here): v_out = sqrt(1 - DR)
    a = 1e-5
    r = restitution.solve(
        a, beta=a / (1 + a), contact="plastic", eta=eta, dr=dr, rtol=1e-11, history=True
    )
    assert r.history["v1_out"].iloc[0] == pytest.approx(math.sqrt(1 - dr), abs=1e-4)


def test_hysteretic_contact_keeps_dent_and_reloads_on_power_law():
    cp = laws.contact_params(laws.C_PLASTIC, 10.0, 2.0, 0.5)
    f, xm, fm = laws.contact_hysteretic(cp, 0.0, 0.0, 0.09, 0.0)
    assert (f, xm) == (pytest.approx(2.0 * 0.3), 0.09)
    dent = xm - fm / 10.0
    assert laws.contact_hysteretic(cp, xm, fm, dent * 0.999, 0.0)[0] == 0.0  # dent persists
    assert laws.contact_hysteretic(cp, xm, fm, 0.5 * (dent + xm), 0.0)[0] == pytest.approx(
        fm - 10.0 * (xm - 0.5 * (dent + xm))
    )
    f2, xm2, _ = laws.contact_hysteretic(cp, xm, fm, 0.16, 0.0)  # past the maximum: power law again
    assert (f2, xm2) == (pytest.approx(2.0 * 0.4), 0.16)


def _scissor(theta0=math.pi / 4, ks_ratio=0.01, L=1.0, corner=1.0):  # noqa: N803
    return laws.scissor_params(K2, ks_ratio * K2, L, theta0, corner)


@pytest.mark.parametrize("theta0", [0.3, math.pi / 4, 1.2])
@pytest.mark.parametrize("L", [0.1, 1.0, 30.0])
def test_scissor_matches_eq24_slope_cap_and_continuity(theta0, L):  # noqa: N803
    sp = _scissor(theta0, 0.01 * math.tan(theta0) ** 2 * 0.5, L)
    ks = sp[laws.SP_KS]
    # Eq. 24 in parametric form, between the lock and the cap
    th = np.linspace(math.asin(sp[laws.SP_S0] ** (1 / 3)) - 1e-9, 0.05, 400)
    x = 2 * L * (np.cos(th) - math.cos(theta0))
    f_eq24 = 2 * ks * L * np.cos(th) * (math.sin(theta0) / np.sin(th) - 1)
    inside = (x >= sp[laws.SP_XLOCK]) & (x <= sp[laws.SP_XCAP])
    got = np.array([laws.structure_force(sp, v) for v in x[inside]])
    np.testing.assert_allclose(got, f_eq24[inside], rtol=1e-10, atol=1e-14 * L)
    # whole curve: finite, continuous, slope in [0, k2] and the cap k2 is reached
    xs = np.concatenate(
        [
            np.linspace(-6 * L, 3 * L, 20001),
            sp[[laws.SP_XLOCK, laws.SP_XCAP]],
            [sp[laws.SP_XLOCK] - sp[laws.SP_DC]],
        ]
    )
    xs.sort()
    f = np.array([laws.structure_force(sp, v) for v in xs])
    u = np.array([laws.structure_energy(sp, v) for v in xs])
    k = np.array([laws.structure_slope(sp, v) for v in xs])
    assert np.all(np.isfinite(f)) and np.all(np.isfinite(u)) and np.all(np.isfinite(k))
    assert k.min() >= -1e-12 and k.max() <= K2 * (1 + 1e-12)
    assert k.max() == pytest.approx(K2)
    dfdx = np.diff(f) / np.diff(xs)
    ok = np.diff(xs) > 1e-9 * L
    assert np.all(dfdx[ok] <= K2 * (1 + 1e-6)) and np.all(dfdx[ok] >= -1e-9)
    for x0 in (sp[laws.SP_XLOCK], sp[laws.SP_XCAP], sp[laws.SP_XLOCK] - sp[laws.SP_DC]):
        e = 1e-12 * L  # the slope is steep just below the cap: continuity in the limit
        for fun in (laws.structure_force, laws.structure_energy, laws.structure_slope):
            assert fun(sp, x0 - e) == pytest.approx(fun(sp, x0 + e), abs=1e-7 * max(1, L))
    # the closed-form potential integrates the force
    brk = sorted(
        sp[[laws.SP_XLOCK, laws.SP_XCAP]].tolist() + [sp[laws.SP_XLOCK] - sp[laws.SP_DC], 0.0]
    )
    for xe in (-5 * L, 1.5 * sp[laws.SP_XLOCK], 0.5 * sp[laws.SP_XCAP], 2 * L):
        pts = [b for b in brk if min(0, xe) < b < max(0, xe)]
        w, _ = quad(
            lambda v: laws.structure_force(sp, v),
            0.0,
            xe,
            points=pts or None,
            epsabs=1e-13,
            epsrel=1e-11,
            limit=200,
        )
        assert laws.structure_energy(sp, xe) == pytest.approx(w, rel=1e-8, abs=1e-12)
    assert abs(laws.structure_force(sp, 0.0)) < 1e-15
    assert laws.structure_slope(sp, 0.0) == pytest.approx(ks / math.tan(theta0) ** 2)


def test_scissor_robust_near_lock_angle():
    sp = _scissor()
    xl = sp[laws.SP_XLOCK]
    for x in xl + np.array([-1e-15, -1e-300, 0.0, 1e-300, 1e-15, 1e-8]):
        assert math.isfinite(laws.structure_force(sp, x))
        assert abs(laws.structure_slope(sp, x)) < 1e-6
    assert laws.structure_force(sp, xl) == pytest.approx(sp[laws.SP_FLOCK])
    assert math.isfinite(laws.structure_force(sp, -1e6)) and math.isfinite(
        laws.structure_force(sp, 1e6)
    )


BAD = [
    (dict(contact="plastic", eta=0.0), "eta"),
    (dict(contact="plastic", eta=-1.0), "eta"),
    (dict(contact="plastic", eta=float("nan")), "eta"),
    (dict(contact="plastic", eta=1.0, dr=1.0), "dr"),
    (dict(contact="plastic", eta=1.0, dr=-0.1), "dr"),
    (dict(contact="plastic", eta=0.5, dr=0.1), "dr"),  # below (1 - eta)/2
    (dict(contact="plastic", beta=0.0, eta=1.0, dr=0.2), "beta"),
    (dict(structure="scissor", theta0=0.0), "theta0"),
    (dict(structure="scissor", theta0=math.pi / 2), "theta0"),
    (dict(structure="scissor", L=0.0), "L"),
    (dict(structure="scissor", L=-1.0), "L"),
    (dict(structure="scissor", ks_ratio=0.0), "ks_ratio"),
    (dict(structure="scissor", theta0=0.3, ks_ratio=0.5), "ks_ratio"),
    (dict(structure="scissor", corner=0.0), "corner"),
    (dict(contact="elastic"), "contact"),
    (dict(structure="spring"), "structure"),
    (dict(v0=0.0), "v0"),
    (dict(v0=1e-7), r"v0 .*\[1e-6, 1e6\]"),  # narrowed: kappa ~ v0**(1 - eta) left float64
    (dict(contact="plastic", eta=1.0, dr=0.5, alpha=1e-9), r"alpha must be in \[1e-8, 1e8\]"),
    # (the public path names the contact's ratio to the first spring, "the range of beta")
    (dict(contact="plastic", eta=1.0, dr=0.5, beta=1e-13), r"\[1e-12, 1e\+06\].*beta"),
    (dict(structure="scissor", beta=1e-300), r"\[1e-12, 1e\+06\].*beta"),
    (dict(contact="plastic", eta=1.0, dr=1 - 1e-16), "loading secant"),
    (dict(method="rk4"), "method"),
    (dict(method="verlet", beta=0.0), "beta"),
    (dict(method="verlet", step=0.0), "step"),
    (dict(rtol=0.0), "rtol"),
    (dict(alpha=0.0), "alpha"),
    (dict(xi=-1.0), "xi"),
]


@pytest.mark.parametrize("kw, name", BAD)
def test_bad_parameters_name_themselves(kw, name):
    kw = dict(kw)
    alpha = kw.pop("alpha", 1.0)
    kw.setdefault("beta", 0.1)
    with pytest.raises(SceneError, match=name):
        restitution.solve(alpha, **kw)


def test_paper_form_laws_pack_to_their_kinds():
    from restitution.model.chain import paper_with_laws
    from restitution.solvers.numerical import packed

    ch, _ = paper_with_laws(1.0, 0.0, 0.0, 2, dict(structure="scissor"))
    _, lk, _, cp, _, kappa = packed(ch)
    assert cp[0] == laws.C_RIGID and lk[0][0] == laws.S_SCISSOR and math.isnan(kappa)
    acct = {}
    solve_paper_law(2.0, 0.1, contact="plastic", eta=0.5, dr=0.5, account=acct)
    k1 = (2.0 / 3.0) / 0.1
    assert acct["kappa"] == pytest.approx(laws.plastic_kappa(0.5, 0.5, k1), rel=1e-12)


def test_plastic_law_creating_energy_is_reported_not_ok():
    """kappa is fitted at m1's nominal depth; a turn deeper (eta > 1) where
    k < (eta + 1)/2 kappa x**(eta - 1) returns more than the loading stored (docs/physics.md):
    the run is not ok, its contact work is negative, and the message names the law."""
    from restitution.solvers.numerical import solve_chain

    m = [0.6225762273992984, 4.279763926605098, 2.2463755298407593, 0.5865758164220565]
    k, eta, dr = 3.787205085445174, 1.46625211472598, 0.10048680966001751
    ch = restitution.Chain(
        m,
        [6.419755253457218, 3.617247211821949, 6.728286088931025],
        [0.251506504999416, 0.15163236153980847, 1.447660592429925],
        contact={"law": "plastic", "k": k, "eta": eta, "dr": dr},
    )
    r = restitution.solve(ch, history=True)
    assert r.status == "energy_account_open"
    assert "plastic contact" in r.message
    # the law's kappa in closed form (m1 alone at v0 = 1: stores m1/2, returns (1 - DR) m1/2)
    fmax = math.sqrt((1.0 - dr) * k * m[0])
    kappa = fmax / ((eta + 1.0) * m[0] / (2.0 * fmax)) ** eta
    x = r.history["compression"].max()
    assert k < (eta + 1.0) / 2.0 * kappa * x ** (eta - 1.0)
    account = {}
    solve_chain(ch, "adaptive", 1e-9, account=account)
    assert account["dissipated_contact"] < -0.05
    assert abs(account["residual"]) < 1e-9
