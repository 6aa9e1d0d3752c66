"""The closed-form elastic phase of the plastic contact for two masses on an undamped linear link
(``kernels/elastic2.py``) against scipy's DOP853 at rtol 1e-13 with event location, over mass
and stiffness ratios of six and seven decades; its energy account; the starts it leaves to the
integrator; and whole scenes against the integrated elastic phase."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import restitution as R
from conftest import solve_paper_law
from restitution.kernels import elastic2 as E


def _reference(y0, xp, xmax, m1, m2, k, k1):
    """(code, time, state) of the phase by solve_ivp: m1 on the line F = k1 (x - xp), x = -u1,
    until x falls to xp (separation, code 0) or rises to xmax (reload, code 1).

    Sign changes between steps miss a shallow crossing (a dip of x past xmax within one step:
    DOP853 at rtol 1e-13 stepped over one 1.6e-6 deep), so every extremum of u1 (v1 = 0) is an
    event too: between two of them u1 is monotone, and the first crossing is found on the first
    such stretch whose end is past a level (brentq on the dense output)."""

    def rhs(t, s):
        u1, u2, v1, v2 = s
        f = k * (u2 - u1)
        return [v1, v2, (k1 * (-u1 - xp) + f) / m1, -f / m2]

    def sep(t, s):
        return s[0] + xp  # rises through 0

    def reload(t, s):
        return s[0] + xmax  # falls through 0

    def turn(t, s):
        return s[2]

    sep.terminal, sep.direction = True, 1
    reload.terminal, reload.direction = True, -1
    w = math.sqrt((k1 + k) / m1 + k / m2)
    atol = 1e-16 * (1 + np.abs(y0[:4]).max())
    sol = solve_ivp(rhs, (0.0, 1e4 / w), y0[:4], method="DOP853", rtol=1e-13, atol=atol,
                    dense_output=True, events=[sep, reload, turn])  # fmt: skip
    assert sol.status == 1
    a = 0.0
    for b in sol.t_events[2]:
        if b <= 1e-9 / w:
            continue  # the start's own turn
        ub = sol.sol(b)[0]
        for code, level in ((0, -xp), (1, -xmax)):
            if (ub - level) * (1 if code == 0 else -1) >= 0.0:
                t = brentq(lambda t, lv=level: sol.sol(t)[0] - lv, a, b, xtol=1e-15, rtol=1e-15)
                return code, t, sol.sol(t)
        a = b
    return (0 if len(sol.t_events[0]) else 1), sol.t[-1], sol.y[:, -1]  # the terminal event


def _start(rng, turn):
    """A random phase start: entering at the dent (x = xp, v1 < 0) or turning at xmax (v1 = 0,
    m1 accelerated away from the wall)."""
    m1 = 1.0
    m2 = 10 ** rng.uniform(-3, 3)
    k = 10 ** rng.uniform(-2, 1)
    k1 = k * 10 ** rng.uniform(-3, 4)
    xp = rng.uniform(0.0, 0.5)
    L = 10 ** rng.uniform(-3, 0)
    xmax = xp + L
    v2 = rng.uniform(-1, 1)
    if turn:
        # the acceleration of u1 at x = xmax: (k1 L + k (u2 + xmax)) / m1 > 0
        u2 = -xmax + rng.uniform(-k1 * L / k * 0.9, 1.0)
        y = np.array([-xmax, u2, 0.0, v2, 0.0, 0.0])
    else:
        y = np.array([-xp, -xp + rng.uniform(-1, 1), -rng.uniform(0.01, 1), v2, 0.0, 0.0])
    return y, xp, xmax, m1, m2, k, k1


@pytest.mark.parametrize("turn", [False, True], ids=["entering", "after_turn"])
def test_phase_against_solve_ivp(turn):
    rng = np.random.default_rng(11 + turn)
    codes = set()
    for _ in range(60):
        y, xp, xmax, m1, m2, k, k1 = _start(rng, turn)
        code_ref, t_ref, s_ref = _reference(y, xp, xmax, m1, m2, k, k1)
        work = np.array([1e9])
        y1 = y.copy()
        code, t, err = E.elastic_phase(y1, xp, xmax, m1, m2, k, k1, work)
        assert code == code_ref
        codes.add(code)
        w = math.sqrt((k1 + k) / m1 + k / m2)
        assert t == pytest.approx(t_ref, rel=1e-9, abs=1e-11 / w)
        vs = 1.0 + np.abs(y[2:4]).max()
        assert y1[0] == (-xp if code == E.EL_SEPARATED else -xmax)  # on the event's surface
        assert y1[1] == pytest.approx(s_ref[1], abs=1e-10 * (1.0 + abs(s_ref[1])))
        assert y1[2:4] == pytest.approx(s_ref[2:4], abs=1e-9 * vs)
        assert 0.0 < err < 1e-12 * (m1 + m2) * vs * (1.0 + w * t)
    assert codes == {E.EL_SEPARATED, E.EL_RELOAD}  # both events met


def test_energy_account_of_the_phase():
    """Kinetic + link + the line's stored energy are constant; W takes the line's change."""
    rng = np.random.default_rng(5)
    for turn in (False, True):
        for _ in range(30):
            y, xp, xmax, m1, m2, k, k1 = _start(rng, turn)
            y1 = y.copy()
            E.elastic_phase(y1, xp, xmax, m1, m2, k, k1, np.array([1e9]))

            def total(s, xp=xp, m1=m1, m2=m2, k=k, k1=k1):
                f = s[0] + xp
                return 0.5 * (m1 * s[2] ** 2 + m2 * s[3] ** 2 + k * (s[1] - s[0]) ** 2 + k1 * f * f)

            assert total(y1) == pytest.approx(total(y), rel=1e-11)
            f0, f1 = y[0] + xp, y1[0] + xp
            assert y1[4] - y[4] == pytest.approx(0.5 * k1 * (f1 * f1 - f0 * f0), rel=1e-14)


def test_samples_are_the_phase():
    """``elastic_at`` at the phase's end is the state the phase returns (the trajectories')."""
    y, xp, xmax, m1, m2, k, k1 = _start(np.random.default_rng(2), True)
    y1 = y.copy()
    _, t, _ = E.elastic_phase(y1, xp, xmax, m1, m2, k, k1, np.array([1e9]))
    out = np.empty(6)
    force = E.elastic_at(y, xp, m1, m2, k, k1, t, out)
    assert np.array_equal(out[1:4], y1[1:4])
    assert out[0] == pytest.approx(y1[0], abs=1e-12)
    assert force == pytest.approx(-k1 * (out[0] + xp))


@pytest.mark.parametrize(
    "y",
    [
        [-0.1, 0.0, 0.3, 0.0, 0.0, 0.0],  # on the dent moving out: not in contact
        [-0.1, 0.0, 0.0, 0.0, 0.0, 0.0],  # on the dent at rest
        [-0.6, 0.0, -0.2, 0.0, 0.0, 0.0],  # at xmax moving in: the power law, not this line
        [-0.7, 0.0, 0.0, 0.0, 0.0, 0.0],  # beyond xmax
    ],
)
def test_starts_it_does_not_take_are_left_to_the_integrator(y):
    y = np.array(y)
    y1 = y.copy()
    work = np.array([100.0])
    code, _, _ = E.elastic_phase(y1, 0.1, 0.6, 1.0, 2.0, 1.0, 50.0, work)
    assert code == E.EL_INTEGRATE
    assert np.array_equal(y1, y) and work[0] == 100.0


def test_work_budget_ends_a_long_phase():
    # a soft contact under a heavy second mass: many fast periods of m1 before it separates
    y = np.array([-0.1, -0.1 - 1e-3, -1e-4, -1.0, 0.0, 0.0])
    work = np.array([50.0])
    code, _, _ = E.elastic_phase(y, 0.1, 0.1 + 1e-6, 1.0, 1e4, 1e4, 1.0, work)
    assert code in (E.EL_FAIL, E.EL_RELOAD)
    if code == E.EL_FAIL:
        assert work[0] <= 0.0


@pytest.mark.parametrize(
    "alpha, beta, eta, dr",
    [(5.0, 1e-2, 0.5, 0.3), (0.7, 0.3, 1.5, 0.2), (20.0, 1e-3, 0.8, 0.6), (2.0, 1.0, 1.2, 0.4)],
)
def test_scenes_agree_with_the_integrated_elastic_line(alpha, beta, eta, dr):
    """The two-mass plastic scene with the elastic line in closed form (and the free flight)
    against the same scene integrated throughout (``free_closed`` False), both at rtol 1e-12:
    within their estimates, same contacts."""
    law = {"contact": "plastic", "eta": eta, "dr": dr}
    a = solve_paper_law(alpha, beta=beta, rtol=1e-12, **law)
    b = solve_paper_law(alpha, beta=beta, rtol=1e-12, free_closed=False, **law)
    assert a.status == b.status == "ok"
    assert a.n_collisions == b.n_collisions
    assert abs(a.cor - b.cor) <= a.error_estimate + b.error_estimate + 1e-14


def test_damped_link_and_chains_still_integrate_their_elastic_line():
    """The closed form is for an undamped link: with a dashpot the integrator takes the elastic
    line, and its run stays within its estimate of a tight one."""
    ch = R.Chain([1.0, 2.0], [0.6], dashpots=[0.05], contact={"law": "plastic", "k": 30.0,
                 "eta": 0.5, "dr": 0.3})  # fmt: skip
    r = R.solve(ch, method="adaptive", rtol=1e-8)
    tight = R.solve(ch, method="adaptive", rtol=1e-12)
    assert r.status == "ok" and abs(r.cor - tight.cor) <= r.error_estimate
