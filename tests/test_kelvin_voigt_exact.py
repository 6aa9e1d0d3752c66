"""The exact (event-driven, closed form per phase) Kelvin-Voigt contact of kernels.exact_chain.

The contact F = max(0, k x + c x') is piecewise linear: the contact phase is the chain with the
spring k and the dashpot c from m1 to the ground, its end (k x + c x' = 0, x > 0) an exponential
sum located by the certified locator, and the free stretch inside the penetration ends where
that force rises through 0 again (a new contact) or x falls to 0. Checked against

* the closed form of one mass (Schwager and Poeschel 2007; ``closed_form`` of
  tests/test_kelvin_voigt.py) for z < 1, z = 1 and z > 1;
* ``solve_precise`` with the contact's dashpot (mpmath, 40 digits checked at 60: written
  independently of the kernel), on random chains N = 2..8 with contact damping ratios 1e-3..3,
  scenes where m1 re-contacts from inside the penetration among them (counted);
* ``adaptive`` at rtol 1e-12;

and the energy account, initial states and the method table (``auto`` picks ``piecewise``).
"""

import math

import numpy as np
import pandas as pd
import pytest

import restitution
from restitution.kernels.exact_chain import solve_chain, solve_chain_kv, solve_mass_kv
from restitution.kernels.layout import (
    H_TEND,
    H_XMAX,
    N_HIST,
    OUT_COR,
    OUT_EDISS,
    OUT_ERR,
    OUT_ETRANS,
    OUT_EVIB,
    OUT_NCOL,
    OUT_STATUS,
    OUT_TCOL,
    STATUS_ILL_CONDITIONED,
    STATUS_INVALID,
    STATUS_OK,
)
from restitution.solvers.precise import solve_precise
from test_kelvin_voigt import closed_form

KV = "kelvin_voigt"
ZETAS = [1e-3, 0.01, 0.1, 0.5, 1.0 / math.sqrt(2.0), 0.95, 0.999, 1.001, 1.05, 2.0, 5.0, 20.0]


@pytest.mark.parametrize("z", ZETAS)
@pytest.mark.parametrize(
    "m, k, v0", [(1.0, 1.0, 1.0), (3.0, 4e3, 0.2), (0.02, 5e-3, 70.0), (1e3, 0.1, 1e-3)]
)
def test_single_mass_against_the_closed_form(z, m, k, v0):
    # The kernel runs in units m1 = 1, V0 = 1 (lengths V0 / omega, times omega t with
    # omega = sqrt(k / m)): a mass m at v0 is the same motion scaled, so k and c enter as
    # k / m and c / m, and v0 only scales x_max.
    c = 2.0 * z * math.sqrt(k * m)
    t_end, cor, x_max, x_end = closed_form(m, k, c, v0)
    hist = np.zeros((4, N_HIST))
    out = solve_mass_kv(k / m, c / m, 10, hist)
    w = math.sqrt(k / m)
    assert out[OUT_STATUS] == STATUS_OK and out[OUT_NCOL] == 1
    err = abs(out[OUT_COR] - cor)
    assert err < 1e-12 * cor
    assert err <= out[OUT_ERR]
    # the end time's own conditioning (tests/test_kelvin_voigt.py): the force crosses 0 at the
    # rate k x', so a rounding of the force moves the end by (c/k) relative to it; at z = 20
    # (cond 108) the time is 1.9e-12 off, the COR 6e-17
    cond = max(1.0, (c / k) / t_end)
    assert abs(out[OUT_TCOL] / w - t_end) < 1e-12 * t_end * cond
    assert hist[0, H_TEND] == out[OUT_TCOL]
    assert abs(hist[0, H_XMAX] * v0 / w - x_max) < 1e-12 * x_max
    # the energy account: the dashpot's work and the spring's energy left at x_end > 0
    assert abs(out[OUT_ETRANS] + out[OUT_EVIB] + out[OUT_EDISS] - 1.0) < 1e-12
    assert abs(out[OUT_EDISS] - (1.0 - cor * cor)) < 1e-12
    assert x_end > 0.0


def test_single_mass_critical_damping():
    # z = 1 exactly: the contact phase's eigenbasis is defective (a double root), which the
    # kernel reports instead of a number; next to it (z = 1 -+ 1e-3, above) the closed form holds
    # and the COR tends to e**-2
    out = solve_mass_kv(1.0, 2.0, 10, np.zeros((0, N_HIST)))
    assert out[OUT_STATUS] == STATUS_ILL_CONDITIONED and math.isnan(out[OUT_COR])
    near = [solve_mass_kv(1.0, 2.0 * z, 10, np.zeros((0, N_HIST)))[OUT_COR] for z in (0.999, 1.001)]
    assert all(abs(c - math.exp(-2.0)) < 1e-3 for c in near)


def test_undamped_contact_is_the_linear_kernel_bit_for_bit():
    rng = np.random.default_rng(5)
    for n in (2, 3, 5):
        m = rng.uniform(0.3, 3.0, n)
        k = rng.uniform(0.3, 3.0, n - 1)
        c = rng.uniform(0.0, 0.1, n - 1)
        h1, h2 = np.zeros((20, N_HIST)), np.zeros((20, N_HIST))
        a = solve_chain(m, k, c, 7.0, 1000, h1)
        b = solve_chain_kv(m, k, c, 7.0, 0.0, 1000, h2)
        assert np.array_equal(a, b, equal_nan=True) and np.array_equal(h1, h2)
    bad = solve_chain_kv(m, k, c, math.inf, 1.0, 10, np.zeros((0, N_HIST)))
    assert bad[OUT_STATUS] == STATUS_INVALID and math.isnan(bad[OUT_COR])


# ----------------------------------------------------------------------------------------------
# Chains against the mpmath reference
# ----------------------------------------------------------------------------------------------
# Scenes built to re-contact from inside the penetration: a heavy m2 behind a soft link pushes
# m1 back before x reaches 0 (tests/test_kelvin_voigt.py, against solve_ivp).
INSIDE = [
    ([1.0, 3.0], [0.3], None, 100.0, 40.0),
    ([1.0, 10.0], [0.3], None, 100.0, 40.0),
    ([1.0, 3.0, 3.0], [0.3, 0.3], None, 100.0, 40.0),
    ([1.0, 10.0], [0.3], [0.02], 100.0, 40.0),
    ([1.0, 6.0, 2.0, 4.0], [0.5, 0.2, 0.4], [0.0, 0.01, 0.0], 50.0, 30.0),
]


def _random_scenes():
    """Random chains N = 2..8: even ones masses and springs 0.3..3, contact damping ratios
    1e-3..3; odd ones a tail 3..10 times heavier behind soft links (0.05..0.5) and a stiffer,
    more damped contact (ratios 0.5..3), where about one in five re-contacts from inside the
    penetration."""
    rng = np.random.default_rng(2807)
    scenes = []
    for i in range(36):
        n = 2 + i % 7  # N = 2..8
        m = rng.uniform(0.3, 3.0, n)
        if i % 2 == 0:
            k = rng.uniform(0.3, 3.0, n - 1)
            kc = float(10 ** rng.uniform(0.0, 2.5))
            zeta = float(10 ** rng.uniform(-3.0, math.log10(3.0)))
        else:
            m[1:] *= rng.uniform(3.0, 10.0)
            k = rng.uniform(0.05, 0.5, n - 1)
            kc = float(10 ** rng.uniform(1.5, 2.5))
            zeta = float(10 ** rng.uniform(-0.3, math.log10(3.0)))
        c = rng.uniform(0.0, 0.1, n - 1) * (rng.random(n - 1) < 0.5) if i % 4 < 2 else None
        cc = 2.0 * zeta * math.sqrt(kc * m[0])
        scenes.append((m.tolist(), k.tolist(), None if c is None else c.tolist(), kc, cc))
    return scenes


SCENES = INSIDE + _random_scenes()


def _exact(m, k, c, kc, cc, **kw):
    return restitution.solve(
        masses=m, springs=k, dashpots=c, contact={"law": KV, "k": kc, "c": cc}, **kw
    )


@pytest.fixture(scope="module")
def against_precise():
    rows = []
    for m, k, c, kc, cc in SCENES:
        r = _exact(m, k, c, kc, cc, history=True, max_events=2000)
        p = solve_precise(m, k, c, kc, cc=cc, max_events=2000)
        rows.append((r, p))
    return rows


def test_chains_against_the_precise_reference(against_precise):
    inside = 0
    for (r, p), scene in zip(against_precise, SCENES, strict=True):
        assert p.status == "ok", scene
        assert r.status == "ok" and r.method == "piecewise", scene
        assert r.n_collisions == p.n_collisions, scene
        err = abs(r.cor - p.cor)
        assert err < 1e-10 and err <= r.error_estimate, (scene, err, r.error_estimate)
        assert abs(r.t_col - p.t_col) < 1e-9 * max(1.0, p.t_col), scene
        assert abs(r.e_translational + r.e_vibrational + r.e_dissipated - 1.0) < 1e-12, scene
        assert abs(r.e_vibrational - p.e_vibrational) < 1e-10, scene
        # a contact from inside the penetration starts with m1 moving out (x' < 0)
        kernel_inside = int((r.history["v1_in"] > 0.0).sum())
        assert kernel_inside == sum(s < 0.0 for s in p.approach_speeds), scene
        inside += kernel_inside > 0
    assert inside >= 8  # re-contacts from inside the penetration are exercised


def test_inside_contacts_are_counted_as_contacts(against_precise):
    r, p = against_precise[0]
    h = r.history
    assert (h["v1_in"] > 0.0).any() and len(h) == r.n_collisions
    # each contact's x_max is at least its start's penetration, and positive
    assert (h["x_max"] > 0.0).all()


@pytest.mark.parametrize("i", [0, 3, 8, 15, 21])
def test_chains_against_adaptive(i):
    m, k, c, kc, cc = SCENES[i]
    r = _exact(m, k, c, kc, cc)
    a = _exact(m, k, c, kc, cc, method="adaptive", rtol=1e-12)
    assert r.method == "piecewise" and a.method == "adaptive" and a.status == "ok"
    assert r.n_collisions == a.n_collisions
    assert abs(r.cor - a.cor) <= a.error_estimate + r.error_estimate
    assert abs(r.cor - a.cor) < 1e-9


# ----------------------------------------------------------------------------------------------
# Initial states, the method table, tables
# ----------------------------------------------------------------------------------------------
STATES = [
    ([1.0, 2.0, 0.5], [1.0, 0.7], None, 20.0, 3.0, [1.0, 0.5, 1.5], None),
    ([1.0, 2.0, 0.5], [1.0, 0.7], [0.05, 0.0], 20.0, 3.0, None, [0.1, -0.2]),
    ([1.0, 3.0], [0.3], None, 100.0, 40.0, [0.8, 1.2], [0.05]),
    ([1.0, 1.5, 2.0], [2.0, 1.0], None, 8.0, 0.5, [-0.5, 1.0, 1.0], [0.0, 0.1]),
]


@pytest.mark.parametrize("m, k, c, kc, cc, vel, st", STATES)
def test_initial_states_against_the_precise_reference(m, k, c, kc, cc, vel, st):
    r = _exact(m, k, c, kc, cc, velocities=vel, stretches=st)
    p = solve_precise(m, k, c, kc, cc=cc, velocities=vel, stretches=st)
    assert r.status == "ok" and p.status == "ok" and r.method == "piecewise"
    assert r.n_collisions == p.n_collisions
    err = abs(r.cor - p.cor)
    assert err < 1e-10 and err <= r.error_estimate
    assert abs(r.e_translational + r.e_vibrational + r.e_dissipated - 1.0) < 1e-12
    assert abs(r.e_translational - p.e_translational) < 1e-10


def test_auto_picks_the_exact_method_and_records_it():
    contact = {"law": KV, "k": 3.0, "c": 0.4}
    r = restitution.solve(masses=[1.0, 2.0, 0.5], springs=[1.0, 0.7], contact=contact)
    assert r.method == "piecewise" and r.status == "ok"
    forced = restitution.solve(
        masses=[1.0, 2.0, 0.5], springs=[1.0, 0.7], contact=contact, method="adaptive"
    )
    assert forced.method == "adaptive"
    # the paper's masses with a KV contact: the exact chain kernel, not the linear paper kernel
    frame = pd.DataFrame(
        {
            "masses": [[1.0, 2.0, 2.0], [1.0, 2.0, 0.5], [1.0, 2.0]],
            "springs": [[1.0, 1.0], [1.0, 0.7], [1.0]],
            "contact": [contact, contact, None],
            "k_contact": [math.inf, math.inf, 3.0],
        }
    )
    many = restitution.solve_many(frame)
    assert many["method"].tolist() == ["piecewise"] * 3
    for i in range(2):
        one = restitution.solve(
            masses=frame["masses"][i], springs=frame["springs"][i], contact=contact
        )
        assert many["cor"][i] == one.cor
    linear = restitution.solve(masses=[1.0, 2.0, 2.0], springs=[1.0, 1.0], k_contact=3.0)
    assert many["cor"][0] != linear.cor


def test_the_precise_method_takes_kelvin_voigt():
    m, k, c, kc, cc = INSIDE[0]
    r = _exact(m, k, c, kc, cc)
    p = _exact(m, k, c, kc, cc, method="precise")
    assert p.method == "precise" and p.n_collisions == r.n_collisions
    assert abs(p.cor - r.cor) <= r.error_estimate


# Beyond the numerical methods' frequency spread (laws.SPREAD_MAX = 1e3; these: 3.16e3, 1000.05
# and 5.47e3): a stiff contact on a light second mass, a contact dashpot at a damping ratio of
# 500. Solved exactly, they were refused with the numerical methods' spread error.
BEYOND_SPREAD = [
    ([1.0, 1e-4], [1e-4], [0.0], {"law": KV, "k": 1e7, "c": 1e-2}),
    ([1.0, 1e-4], [1e-4], [0.0], {"law": KV, "k": 1.0, "c": 1e3}),
    ([1.0, 1e-3, 5.0], [1e-3, 0.2], [0.0, 0.01], {"law": KV, "k": 3e7, "c": 2.0}),
]


@pytest.mark.parametrize("m, k, c, contact", BEYOND_SPREAD)
def test_beyond_the_numerical_spread_solved_exactly(m, k, c, contact):
    r = restitution.solve(masses=m, springs=k, dashpots=c, contact=contact)
    assert r.method == "piecewise" and r.status == "ok"
    p = restitution.solve(masses=m, springs=k, dashpots=c, contact=contact, method="precise")
    assert p.status == "ok" and p.n_collisions == r.n_collisions
    assert abs(r.cor - p.cor) <= r.error_estimate + p.error_estimate
    # a numerical method is still held to its range, and says which
    with pytest.raises(restitution.SceneError, match="frequency spread .* at most 1000"):
        restitution.solve(masses=m, springs=k, dashpots=c, contact=contact, method="adaptive")
    many = restitution.solve_many(
        pd.DataFrame({"masses": [m], "springs": [k], "dashpots": [c], "contact": [contact]})
    )
    assert many["status"][0] == "ok" and many["cor"][0] == r.cor


@pytest.mark.parametrize("alpha", [1.0, 1e-4, 1e4])
@pytest.mark.parametrize("dxi", [0.0, 3e-9, -3e-9])
def test_critically_damped_link_of_two_masses(alpha, dxi):
    """xi = 1 on the link of two masses: the flight inside the penetration has a defective free
    mode (ill_conditioned before, and for `precise`); now extrapolated from runs with the
    dashpots scaled off it (solvers.exact.bracketed), within its estimate of the adaptive
    integrator (which has no modes)."""
    k = alpha / (1.0 + alpha)
    kw = dict(
        masses=[1.0, alpha],
        springs=[k],
        dashpots=[2.0 * (1.0 + dxi) * k],
        contact={"law": KV, "k": 1e3, "c": 1e-2},
    )
    r = restitution.solve(**kw)
    assert r.status == "ok" and r.method == "piecewise+critical-bracket"
    ref = restitution.solve(**kw, method="adaptive", rtol=1e-12)
    assert ref.status == "ok" and ref.n_collisions == r.n_collisions
    assert abs(r.cor - ref.cor) <= r.error_estimate + ref.error_estimate
    assert r.error_estimate < 1e-8
    assert abs(r.e_translational + r.e_vibrational + r.e_dissipated - 1.0) < 1e-12
    many = restitution.solve_many(pd.DataFrame({k_: [v] for k_, v in kw.items()}))
    assert many["method"][0] == r.method and many["cor"][0] == r.cor
    # outside the bracket the modal closed form itself
    far = restitution.solve(**{**kw, "dashpots": [2.0 * (1.0 + 1e-6) * k]})
    assert far.method == "piecewise"
    if dxi == 0.0 and alpha == 1.0:
        # `precise` stalls at xi = 1 (its root search did not converge) and brackets the
        # dashpots by 1e-10 (mpmath keeps the digits): round-off-level against adaptive
        p = restitution.solve(**kw, method="precise")
        assert p.status == "ok" and p.method == "precise+critical-bracket"
        assert p.error_estimate < 1e-15
        assert abs(p.cor - ref.cor) <= ref.error_estimate + p.error_estimate
        assert abs(p.cor - r.cor) <= r.error_estimate + p.error_estimate
