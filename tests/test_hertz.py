"""Hertz contact F = k_h x**1.5: closed-form contact of a single mass, elastic chains.

A single mass m hitting the wall at V0 stores m V0**2/2 = (2/5) k_h x**(5/2) at its deepest point,
so x_max = (5 m V0**2 / (4 k_h))**(2/5), and with v(x) = V0 sqrt(1 - (x/x_max)**(5/2)) the
contact lasts

    t_c = 2 (x_max/V0) I,   I = int_0^1 ds / sqrt(1 - s**(5/2)) = (2/5) B(2/5, 1/2)
        = C (m/k_h)**(2/5) V0**(-1/5),   C = 2 I (5/4)**(2/5) = 3.218065...

and the mass leaves at +V0 (COR 1: the law is elastic).
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import beta as beta_fn

from conftest import solve_general_law as solve_nonlinear_chain
from restitution.kernels.layout import (
    H_XMAX,
    N_HIST,
    OUT_COR,
    OUT_EDISS,
    OUT_ERR,
    OUT_NCOL,
    OUT_STATUS,
    OUT_TCOL,
    STATUS_OK,
)
from restitution.kernels.stepping import METHOD_ADAPTIVE, METHOD_VERLET, solve_scene
from restitution.model import laws

I_HERTZ = 0.4 * beta_fn(0.4, 0.5)
C_HERTZ = 2.0 * I_HERTZ * 1.25**0.4


def test_contact_time_constant_against_quadrature():
    i_quad, err = quad(lambda s: 1.0 / math.sqrt(1.0 - s**2.5), 0.0, 1.0, limit=200)
    assert err < 1e-10
    assert I_HERTZ == pytest.approx(i_quad, rel=1e-10)
    assert 2.0 * I_HERTZ == pytest.approx(2.943275, abs=5e-7)
    assert C_HERTZ == pytest.approx(3.218065, abs=5e-7)


def _single_mass(k_h, v0, m=1.0, rtol=1e-12, method=METHOD_ADAPTIVE, step=0.01, cp=None):
    """The chain kernel with one mass (kernel units: m = 1 unless given); Hertz unless ``cp``."""
    ms = np.array([m])
    cp = laws.hertz_params(k_h, v0, m) if cp is None else cp
    hist = np.zeros((4, N_HIST))
    etol = 1e-9 if method == METHOD_ADAPTIVE else 1.0  # Verlet: its energy error is checked here
    out = solve_scene(
        ms, np.zeros((0, laws.N_SP)), np.zeros(0), cp, v0, method, rtol, step, etol, 10, 1e6,
        hist, np.zeros(5),
    )  # fmt: skip
    return out, hist


# Stiff and soft, light and heavy, slow and fast: the contact's time and depth scales span
# 1e-3..1e3 around the kernel's unit.
SINGLE = [(1.0, 1.0, 1.0), (50.0, 0.3, 1.0), (2.0, 7.0, 3.5), (1e4, 1e-3, 0.2), (1e-2, 30.0, 5.0)]


@pytest.mark.parametrize("k_h, v0, m", SINGLE)
def test_single_mass_contact_time_depth_and_unit_cor(k_h, v0, m):
    # rtol 1e-14: the closed forms to 1e-12 (relative for the time and depth, the COR's own);
    # both ends of the contact are integrated in sigma = sqrt(x), where the motion is smooth
    out, hist = _single_mass(k_h, v0, m, rtol=1e-14)
    assert out[OUT_STATUS] == STATUS_OK and out[OUT_NCOL] == 1
    t_c = C_HERTZ * (m / k_h) ** 0.4 * v0**-0.2
    assert abs(out[OUT_TCOL] / t_c - 1.0) < 1e-12
    x_max = (5.0 * m * v0 * v0 / (4.0 * k_h)) ** 0.4
    assert abs(hist[0, H_XMAX] / x_max - 1.0) < 1e-12
    # elastic: m leaves at +V0 (COR 1) and dissipates nothing; the kernel's own bound holds
    assert abs(out[OUT_COR] - 1.0) < 1e-12
    assert abs(out[OUT_COR] - 1.0) <= out[OUT_ERR]
    assert abs(out[OUT_EDISS]) < 1e-12


@pytest.mark.parametrize("rtol", [1e-8, 1e-10, 1e-12])
@pytest.mark.parametrize("k_h, v0, m", SINGLE[:3])
def test_single_mass_error_follows_the_tolerance(k_h, v0, m, rtol):
    # the actual COR error stays within 30 rtol at every setting (DP5(4) was at ~25 rtol at
    # rtol 1e-8 and far above it at 1e-12: 3.6e-11)
    out, _ = _single_mass(k_h, v0, m, rtol=rtol)
    assert out[OUT_NCOL] == 1
    assert abs(out[OUT_COR] - 1.0) < 30 * rtol


# Power-law loading (the plastic law of Sec. 3.1) of one mass: loading F = kappa x**eta from
# x = 0 to x_max = ((eta + 1) m v0**2 / (2 kappa))**(1/(eta + 1)) in
# t_load = (x_max/v0) B(1/(eta + 1), 1/2)/(eta + 1), then the linear unloading line of slope k1
# back to the dent: a quarter period pi/2 sqrt(m/k1); the mass leaves at v0 sqrt(1 - DR).
@pytest.mark.parametrize("eta", [0.5, 1.0, 1.5, 2.3, 4.0])
@pytest.mark.parametrize("k1, v0, m, dr", [(30.0, 1.0, 1.0, 0.3), (2.0, 0.05, 4.0, 0.6)])
def test_single_mass_power_law_loading_closed_form(eta, k1, v0, m, dr):
    kappa = laws.plastic_kappa(dr, eta, k1, v0, m)
    cp = laws.contact_params(laws.C_PLASTIC, k1, kappa, eta)
    out, hist = _single_mass(0.0, v0, m, rtol=1e-14, cp=cp)
    assert out[OUT_STATUS] == STATUS_OK and out[OUT_NCOL] == 1
    x_max = ((eta + 1.0) * m * v0 * v0 / (2.0 * kappa)) ** (1.0 / (eta + 1.0))
    t_load = x_max / v0 * beta_fn(1.0 / (eta + 1.0), 0.5) / (eta + 1.0)
    t_c = t_load + 0.5 * math.pi * math.sqrt(m / k1)
    assert abs(hist[0, H_XMAX] / x_max - 1.0) < 1e-12
    assert abs(out[OUT_TCOL] / t_c - 1.0) < 1e-12
    assert abs(out[OUT_COR] - math.sqrt(1.0 - dr)) < 1e-12
    assert abs(out[OUT_EDISS] - dr) < 1e-12


def test_single_mass_verlet_converges_to_the_closed_form():
    t_c = C_HERTZ
    errs = []
    for step in (0.004, 0.002, 0.001):
        out, _ = _single_mass(1.0, 1.0, method=METHOD_VERLET, step=step)
        assert out[OUT_STATUS] == STATUS_OK and out[OUT_NCOL] == 1
        errs.append(abs(out[OUT_COR] - 1.0))
    assert errs[-1] < 1e-4 and errs[-1] < errs[0]
    # the contact time is resolved to one step (contact detected at step ends)
    out, _ = _single_mass(1.0, 1.0, method=METHOD_VERLET, step=0.001)
    assert abs(out[OUT_TCOL] - t_c) < 0.02 * t_c


def test_hertz_force_energy_slope_are_consistent():
    cp = laws.hertz_params(3.0, 1.0, 2.0)
    for x in (1e-6, 0.1, 0.7, 2.0):
        f = laws.contact_force(cp, 1, 0.0, 0.0, x, 0.0)
        assert f == pytest.approx(3.0 * x**1.5, rel=1e-14)
        force = lambda s: laws.contact_force(cp, 1, 0.0, 0.0, s, 0.0)  # noqa: E731
        w, _ = quad(force, 0.0, x, epsabs=0.0, epsrel=1e-12)
        assert laws.contact_energy(cp, x) == pytest.approx(w, rel=1e-10)
        h = 1e-6 * x
        d = (
            laws.contact_force(cp, 1, 0, 0, x + h, 0.0)
            - laws.contact_force(cp, 1, 0, 0, x - h, 0.0)
        ) / (2 * h)
        assert laws.contact_slope(cp, 1, 0.0, x) == pytest.approx(d, rel=1e-7)
    for x in (0.0, -1e-3, -5.0):
        assert laws.contact_force(cp, 1, 0.0, 0.0, x, 0.0) == 0.0
        assert laws.contact_energy(cp, x) == 0.0
    # the slope scale bounds the slope at any penetration the initial energy could reach
    x_deep = (2.5 * 0.5 * 2.0 / 3.0) ** 0.4
    assert cp[1] == pytest.approx(laws.contact_slope(cp, 1, 0.0, x_deep), rel=1e-14)


@pytest.mark.parametrize(
    "m, k, k_h, v0",
    [
        ([1.0, 0.7, 2.0], [1.0, 0.5], 10.0, 0.2),
        ([1.0, 0.7, 2.0], [1.0, 0.5], 10.0, 1.0),
        ([1.0, 0.7, 2.0], [1.0, 0.5], 10.0, 5.0),
        ([1.0, 0.5, 2.0], [0.3, 1.2], 50.0, 1.0),
        ([1.0, 3.0, 0.2, 1.0, 2.0], [2.0, 0.4, 1.0, 3.0], 5.0, 0.7),
    ],
)
def test_elastic_hertz_chain_conserves_energy(m, k, k_h, v0):
    # undamped: the energy account closes and the contact returns all it took, to 1e-12 at
    # rtol 1e-13 (every term integrated independently of the others)
    acct = {}
    r = solve_nonlinear_chain(
        m, k, None, {"law": "hertz", "k": k_h}, None, v0, rtol=1e-13, account=acct
    )  # fmt: skip
    assert r.status == "ok" and r.n_collisions >= 1
    assert abs(r.e_translational + r.e_vibrational - 1.0) < 1e-12
    assert abs(acct["dissipated_contact"]) < 1e-12 and acct["dissipated_dashpot"] == 0.0
    assert 0.0 < r.cor < 1.0


def test_hertz_two_masses_closed_form_free_flight_matches_the_integrated_one():
    # two masses with a linear link fly freely in closed form; integrating that flight by the
    # same DOP853 as the contact phases (free_closed=False) must give the same sequence
    alpha = 1.7
    k2 = alpha / (1 + alpha)
    cp = laws.hertz_params(4.0, 1.0, 1.0 + alpha)
    lk = laws.linear_structure_params(k2)[None, :].copy()
    h0 = np.zeros((0, N_HIST))
    m, c = np.array([1.0, alpha]), np.zeros(1)
    args = (m, lk, c, cp, 1.0, 0, 1e-12, 0.01, 1e-9, 100, 1e7, h0)
    a = solve_scene(*args, np.zeros(5), True)
    b = solve_scene(*args, np.zeros(5), False)
    assert a[OUT_STATUS] == b[OUT_STATUS] == STATUS_OK and a[OUT_NCOL] == b[OUT_NCOL]
    assert abs(a[OUT_COR] - b[OUT_COR]) < 1e-10


def test_hertz_user_units_scale_as_documented():
    # doubling every mass and k_h, springs (time scale unchanged): the same scene; then a unit
    # change of length by s: k_h -> k_h / s**1.5 at fixed speed in the new unit
    base = dict(c=None, link_laws=None, rtol=1e-11)
    r1 = solve_nonlinear_chain([1.0, 2.0], [0.5], contact_law={"law": "hertz", "k": 3.0}, **base)
    r2 = solve_nonlinear_chain([2.0, 4.0], [1.0], contact_law={"law": "hertz", "k": 6.0}, **base)
    assert r1.n_collisions == r2.n_collisions and abs(r1.cor - r2.cor) < 1e-12
    s = 10.0  # a length unit s times smaller: positions, speeds and forces (mass * length /
    # time**2) all grow by s numerically, so springs (force/length) stay and k_h -> k_h/sqrt(s)
    r3 = solve_nonlinear_chain(
        [1.0, 2.0], [0.5], contact_law={"law": "hertz", "k": 3.0 / math.sqrt(s)}, v0=s, **base
    )
    assert r3.n_collisions == r1.n_collisions and abs(r3.cor - r1.cor) < 1e-8
