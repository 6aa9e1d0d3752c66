"""Hunt-Crossley contact F = k x**n (1 + lam x'), lam = 1.5 alpha, for x > 0 (Hunt and Crossley
1975; n = 1.5 by default, Hertz's exponent).

One mass m hitting the wall at v0: with v = x', m v dv/dx = -k x**n (1 + lam v) separates,

    m G(v) = m G(v0) - k x**(n + 1)/(n + 1),   G(v) = v/lam - ln(1 + lam v)/lam**2,

so the deepest point (v = 0, G(0) = 0) is x_max = ((n + 1) m G(v0)/k)**(1/(n + 1)) and the exit
speed at x = 0 is the root v_out in (-1/lam, 0) of G(v_out) = G(v0) (solved here with mpmath at
40 digits): COR = -v_out/v0, and the contact dissipates 1 - COR**2 of the energy. Chains of two
and three masses are compared with an independent solve_ivp integration written here.
"""

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import restitution
from conftest import check_table_and_cli_agree, random_soft_chain, solve_general_law
from restitution import SceneError
from restitution.kernels.layout import (
    H_XMAX,
    N_HIST,
    OUT_COR,
    OUT_EDISS,
    OUT_ERR,
    OUT_NCOL,
    OUT_STATUS,
    STATUS_OK,
)
from restitution.kernels.stepping import METHOD_ADAPTIVE, METHOD_VERLET, solve_scene
from restitution.model import laws

HC = "hunt_crossley"


def closed_form(m, k, n, alpha, v0):
    """(COR, x_max) of one mass on the Hunt-Crossley wall, at 40 digits."""
    with mp.workdps(40):
        lam = mp.mpf(1.5) * alpha
        v0 = mp.mpf(v0)

        def g(v):  # lam**2 G(v) = u - ln(1 + u), u = lam v
            u = lam * v
            return u - mp.log1p(u)

        target = g(v0)
        lo, hi = -1 / lam * (1 - mp.mpf(10) ** -30), mp.mpf(0)
        for _ in range(200):  # g falls from +inf to 0 on (-1/lam, 0): bisection
            mid = (lo + hi) / 2
            if g(mid) > target:
                lo = mid
            else:
                hi = mid
        v_out = (lo + hi) / 2
        x_max = ((n + 1) * m * target / lam**2 / k) ** (1 / mp.mpf(n + 1))
        return float(-v_out / v0), float(x_max)


def _single(m, k, n, alpha, v0, rtol=1e-12, method=METHOD_ADAPTIVE, step=0.01):
    cp = laws.hunt_crossley_params(k, n, alpha, v0, m)
    hist = np.zeros((4, N_HIST))
    etol = 1e-9 if method == METHOD_ADAPTIVE else 1.0
    out = solve_scene(
        np.array([m]), np.zeros((0, laws.N_SP)), np.zeros(0), cp, v0, method, rtol, step, etol,
        10, 1e7, hist, np.zeros(5),
    )  # fmt: skip
    return out, hist


SINGLE = [
    (1.0, 1.0, 1.5, 0.1, 1.0),
    (1.0, 1.0, 1.5, 0.5, 1.0),
    (1.0, 1.0, 1.5, 0.6, 1.0),
    (2.0, 50.0, 1.5, 0.2, 0.3),
    (0.1, 3.0, 1.0, 0.3, 2.0),
    (1.0, 10.0, 2.0, 0.05, 1.5),
    (5.0, 0.5, 2.5, 0.01, 0.7),
    # exponents whose force sigma**(2 n) is not smooth at x = 0 (integrators.sigma_end_zone)
    (1.0, 1.0, 1.3, 0.1, 1.0),
    (2.0, 5.0, 1.75, 0.2, 0.5),
]


@pytest.mark.parametrize("m, k, n, alpha, v0", SINGLE)
def test_single_mass_against_the_closed_form(m, k, n, alpha, v0):
    cor, x_max = closed_form(m, k, n, alpha, v0)
    assert 0.0 < cor < 1.0
    out, hist = _single(m, k, n, alpha, v0)
    assert out[OUT_STATUS] == STATUS_OK and out[OUT_NCOL] == 1
    assert abs(out[OUT_COR] - cor) < 1e-11
    assert abs(out[OUT_COR] - cor) <= out[OUT_ERR]
    assert abs(hist[0, H_XMAX] / x_max - 1.0) < 1e-11
    assert abs(out[OUT_EDISS] - (1.0 - cor * cor)) < 1e-11


def test_without_damping_it_is_the_elastic_power_law():
    out, _ = _single(1.0, 1.0, 1.5, 0.0, 1.0)
    assert abs(out[OUT_COR] - 1.0) < 1e-12


def test_single_mass_verlet_converges():
    cor, _ = closed_form(1.0, 1.0, 1.5, 0.3, 1.0)
    errs = []
    for step in (0.004, 0.002, 0.001):
        out, _ = _single(1.0, 1.0, 1.5, 0.3, 1.0, method=METHOD_VERLET, step=step)
        assert out[OUT_STATUS] == STATUS_OK and out[OUT_NCOL] == 1
        errs.append(abs(out[OUT_COR] - cor))
    assert errs[-1] < 1e-2 and errs[-1] < errs[0]


def test_force_law():
    cp = laws.hunt_crossley_params(3.0, 1.5, 0.2, 1.0, 1.0)
    f = laws.contact_force(cp, 1, 0.0, 0.0, 0.4, -0.5)
    assert f == pytest.approx(3.0 * 0.4**1.5 * (1.0 - 0.3 * 0.5), rel=1e-15)
    assert laws.contact_force(cp, 1, 0.0, 0.0, -0.1, 2.0) == 0.0
    assert laws.contact_hysteretic(cp, 0.0, 0.0, 0.4, -0.5)[0] == f
    assert laws.contact_energy(cp, 0.4) == pytest.approx(3.0 * 0.4**2.5 / 2.5, rel=1e-15)
    assert laws.contact_slope(cp, 1, 0.0, 0.4) == pytest.approx(4.5 * 0.4**0.5, rel=1e-15)


# ----------------------------------------------------------------------------------------------
# Chains against solve_ivp
# ----------------------------------------------------------------------------------------------
RTOL_REF = 1e-12


def reference(m, k, dash, kc, n_exp, alpha, v0, max_contacts=200):
    """(COR, contacts) of a chain with linear links on the Hunt-Crossley wall, by solve_ivp
    (DOP853, rtol 1e-12, user units): contact until x falls to 0, free flight until x rises to 0
    (ends when the centre of mass recedes beyond what the internal energy can bring back)."""
    m, k = np.asarray(m, float), np.asarray(k, float)
    n = m.size
    dash = np.zeros(n - 1) if dash is None else np.asarray(dash, float)
    mt = m.sum()
    lam = 1.5 * alpha

    def rhs(t, y, contact):
        u, v = y[:n], y[n:]
        a = np.zeros(n)
        if contact and u[0] < 0.0:
            a[0] = kc * (-u[0]) ** n_exp * (1.0 - lam * v[0])
        for i in range(n - 1):
            f = k[i] * (u[i + 1] - u[i]) + dash[i] * (v[i + 1] - v[i])
            a[i] += f
            a[i + 1] -= f
        return np.concatenate([v, a / m])

    def out_of(t, y, contact):
        return -y[0]

    def into(t, y, contact):
        return y[0]

    out_of.terminal, out_of.direction = True, -1
    into.terminal, into.direction = True, -1

    def proof(y):
        u, v = y[:n], y[n:]
        p = m @ v
        if p <= 0 or u[0] < 0:
            return False
        e = 0.5 * m @ (v * v) - 0.5 * p * p / mt
        e += 0.5 * sum(k[i] * (u[i + 1] - u[i]) ** 2 for i in range(n - 1))
        mu = np.array([m[i + 1 :].sum() / mt for i in range(n - 1)])
        return (m @ u) / mt - math.sqrt(2.0 * e * np.sum(mu * mu / k)) > 0

    x_deep = ((n_exp + 1) * mt * v0 * v0 / (2 * kc)) ** (1 / (n_exp + 1))
    w = math.sqrt(4.0 * max(k) / m.min() + 2 * n_exp * kc * x_deep ** (n_exp - 1) / m[0])
    max_step = 2.0 * math.pi / w / 40.0
    opts = dict(method="DOP853", rtol=RTOL_REF, atol=RTOL_REF * v0, max_step=max_step)
    y = np.concatenate([np.zeros(n), np.full(n, -v0)])
    t, ncol, phase, ysep = 0.0, 1, "contact", None
    while True:
        if phase == "contact":
            # leave x = 0 first (the event starts on its own zero)
            sol = solve_ivp(rhs, (t, t + 1e-3 * max_step), y, args=(True,), **opts)
            t, y = sol.t[-1], sol.y[:, -1]
            sol = solve_ivp(rhs, (t, t + 1e4), y, events=[out_of], args=(True,), **opts)
            assert sol.status == 1
            t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
            y[0] = 0.0
            ysep, phase = y.copy(), "free"
        else:
            sol = solve_ivp(rhs, (t, t + 200 * max_step), y, events=[into], args=(False,), **opts)
            if sol.status == 1 and sol.t_events[0][0] > t:
                t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
                y[0] = 0.0
                ncol += 1
                assert ncol <= max_contacts
                phase = "contact"
            else:
                t, y = sol.t[-1], sol.y[:, -1].copy()
                if proof(y):
                    break
    return (m @ ysep[n:]) / mt / v0, ncol


CHAINS = [
    ([1.0, 2.0], [1.0], None, 20.0, 1.5, 0.2, 1.0),
    ([1.0, 0.5], [2.0], None, 50.0, 1.5, 0.4, 0.7),
    ([1.0, 5.0], [0.5], [0.1], 10.0, 1.0, 0.1, 1.0),
    ([1.0, 0.7, 2.0], [1.0, 0.5], None, 10.0, 1.5, 0.2, 1.0),
    ([1.0, 3.0, 0.4], [0.8, 1.5], [0.05, 0.0], 30.0, 2.0, 0.1, 0.5),
]


@pytest.mark.parametrize("m, k, dash, kc, n_exp, alpha, v0", CHAINS)
def test_chains_against_solve_ivp(m, k, dash, kc, n_exp, alpha, v0):
    cor, ncol = reference(m, k, dash, kc, n_exp, alpha, v0)
    spec = {"law": HC, "k": kc, "n": n_exp, "alpha": alpha}
    r = solve_general_law(m, k, dash, spec, None, v0, rtol=1e-12)
    assert r.status == "ok" and r.method == "adaptive"
    assert r.n_collisions == ncol
    assert abs(r.cor - cor) < 1e-9
    assert abs(r.e_translational + r.e_vibrational + r.e_dissipated - 1.0) < 1e-9


def test_n_defaults_to_hertz_and_scales_k_with_its_unit():
    a = restitution.solve(masses=[1.0, 2.0], springs=[1.0], contact={"law": HC, "k": 20.0,
                          "alpha": 0.2}, rtol=1e-12)  # fmt: skip
    b = restitution.solve(masses=[1.0, 2.0], springs=[1.0], contact={"law": HC, "k": 20.0,
                          "n": 1.5, "alpha": 0.2}, rtol=1e-12)  # fmt: skip
    assert a.cor == b.cor
    # doubling every mass, spring and k: the same motion (time scale unchanged)
    c = restitution.solve(masses=[2.0, 4.0], springs=[2.0], contact={"law": HC, "k": 40.0,
                          "alpha": 0.2}, rtol=1e-12)  # fmt: skip
    assert abs(c.cor - a.cor) < 1e-11


BAD = [
    ({"law": HC, "k": 1.0}, "needs alpha"),
    ({"law": HC, "alpha": 0.1}, "needs k"),
    ({"law": HC, "k": -1.0, "alpha": 0.1}, "contact.k"),
    ({"law": HC, "k": 1.0, "alpha": -0.1}, "contact.alpha"),
    ({"law": HC, "k": 1.0, "alpha": 0.6}, "contact.alpha"),  # 1.5 alpha sqrt(3) > 1
    ({"law": HC, "k": 1.0, "alpha": 0.1, "n": 0.5}, "contact.n"),
    ({"law": HC, "k": 1.0, "alpha": 0.1, "n": "x"}, "contact.n"),
    ({"law": HC, "k": 1.0, "alpha": 0.1, "c": 1.0}, "unknown parameter"),
]


@pytest.mark.parametrize("contact, text", BAD)
def test_bad_parameters_name_themselves(contact, text):
    with pytest.raises(SceneError, match=text):
        restitution.Chain([1.0, 2.0], [1.0], contact=contact)


def test_solve_many_and_the_command_line_agree_with_solve():
    hc = {"law": HC, "k": 20.0, "alpha": 0.2}
    check_table_and_cli_agree(hc)


@pytest.mark.parametrize("n", [2, 3, 4, 5])
@pytest.mark.parametrize("n_exp", [1.0, 1.5, 2.0])
def test_random_chains_against_solve_ivp(n, n_exp):
    rng = np.random.default_rng(100 * n + int(10 * n_exp))
    m, k, dash = random_soft_chain(rng, n)
    kc = float(rng.uniform(5.0, 30.0))
    v0 = float(rng.uniform(0.5, 2.0))
    # alpha up to 90 % of its bound 1/(1.5 v0 sqrt(M/m1))
    alpha = float(rng.uniform(0.0, 0.9)) / (1.5 * v0 * math.sqrt(sum(m) / m[0]))
    cor, ncol = reference(m, k, dash, kc, n_exp, alpha, v0)
    spec = {"law": HC, "k": kc, "n": n_exp, "alpha": alpha}
    r = solve_general_law(m, k, dash, spec, None, v0, rtol=1e-12)
    assert r.status == "ok" and r.n_collisions == ncol
    assert abs(r.cor - cor) < 1e-9
    assert abs(r.cor - cor) <= r.error_estimate + 1e-11


def test_declared_ranges_finish_or_fail_explicitly():
    # k, n in [1, 10], alpha up to its bound and v0 over their ranges on random chains: each
    # scene is rejected before any work (naming the range), or finishes sane, or fails with an
    # explicit status and a NaN COR; never a traceback
    rng = np.random.default_rng(29)
    rows, rejected = [], 0
    for _ in range(60):
        nm = int(rng.integers(2, 5))
        m = np.exp(rng.uniform(-3, 3, nm)).tolist()
        k = np.exp(rng.uniform(-3, 3, nm - 1)).tolist()
        kc = float(np.exp(rng.uniform(-5, 12)))
        n_exp = float((1.0, 10.0, rng.uniform(1.0, 10.0))[int(rng.integers(3))])
        v0 = float(np.exp(rng.uniform(math.log(1e-6), math.log(1e6))))
        bound = 1.0 / (1.5 * v0 * math.sqrt(sum(m) / m[0]))
        alpha = float((0.0, np.nextafter(bound, 0.0), rng.uniform(0, bound))[int(rng.integers(3))])
        contact = {"law": HC, "k": kc, "n": n_exp, "alpha": alpha}
        try:
            restitution.Chain(m, k, v0=v0, contact=contact)
        except SceneError as e:
            assert "must be" in str(e)
            rejected += 1
            continue
        rows.append((m, k, contact, v0))
    assert len(rows) >= 15 and rejected >= 5
    for m, k, contact, v0 in rows:
        r = restitution.solve(masses=m, springs=k, contact=contact, v0=v0, max_events=2000)
        if r.status == "ok":
            assert r.n_collisions >= 1 and -1e-9 <= r.cor <= 1.0 + 1e-9
            assert abs(r.e_translational + r.e_vibrational + r.e_dissipated - 1.0) < 1e-6
        else:
            assert math.isnan(r.cor) or r.status == "energy_account_open"


def test_the_reference_method_refuses_it():
    with pytest.raises(SceneError, match="does not implement the 'hunt_crossley'"):
        restitution.solve(masses=[1.0, 2.0], springs=[1.0], contact={"law": HC, "k": 3.0,
                          "alpha": 0.1}, method="reference")  # fmt: skip


def test_estimates_cover_round_off_of_light_masses():
    """An elastic contact on m1 with two light masses: COR 1 - 2e-15, where the local error sums
    are below round-off. Two settings' results must lie within their summed estimates (before
    the round-off floor of ``numerical.roundoff_floor``: 2.3e-15 apart under 1.3e-15)."""
    kw = dict(
        masses=[1.0, 1e-4, 1e-4], springs=[1.0, 1.0], contact={"law": HC, "k": 0.1, "alpha": 0.0}
    )
    runs = [restitution.solve(**kw, method="adaptive", rtol=r) for r in (1e-8, 1e-10, 1e-12)]
    assert all(r.status == "ok" and r.n_collisions == 1 for r in runs)
    for a in runs:
        assert a.error_estimate >= 64 * np.finfo(float).eps
        for b in runs:
            assert abs(a.cor - b.cor) <= a.error_estimate + b.error_estimate
