"""The adaptive kernel's closed-form free flight of two masses on a linear link
(``stepping.free_flight_linear``) against mpmath, and a run solved in closed form throughout (two
masses at a rigid wall) against ``method="precise"``: its error within its estimate."""

import math

import mpmath as mp
import numpy as np
import pytest

import restitution
from restitution.kernels.stepping import SERIES_X, _increments, free_flight_linear

# kernel units of a heavy second mass pressing m1 on the wall (m1 = 1, omega = 1), damped
M1, M2 = 1.0, 30.941746848571587
K = 1.0 / (1.0 / M1 + 1.0 / M2)


def _mp_flight(y, c):
    """The flight's gap g(s) and the link's motion at 50 digits (the formulas, no cancellation
    at that precision)."""
    mp.mp.dps = 50
    m1, m2, k, cc = map(mp.mpf, (M1, M2, K, c))
    m = m1 + m2
    mu = m2 / m
    inv = 1 / m1 + 1 / m2
    w = mp.sqrt(k * inv)
    xi = cc * inv / (2 * w)
    u1, u2, v1, v2 = (mp.mpf(float(v)) for v in y[:4])
    x0, v = (m1 * u1 + m2 * u2) / m, (m1 * v1 + m2 * v2) / m
    r0, w0 = u2 - u1, (v2 - v1) / w
    wd = mp.sqrt(1 - xi * xi)

    def r_of(x):
        e = mp.e ** (-xi * x)
        cx, sx = e * mp.cos(wd * x), e * mp.sin(wd * x) / wd
        return r0 * cx + (w0 + xi * r0) * sx, w0 * cx - (r0 + xi * w0) * sx

    return (lambda s: x0 + v * s - mu * r_of(w * s)[0]), r_of, w, v, mu


@pytest.mark.parametrize("zeta", [0.0, 0.3, 0.689])
def test_flight_of_a_chatter_ends_at_its_contact_to_round_off(zeta):
    """m1 just off the wall at a small speed, m2 pressing: the gap is tiny next to the centre
    of mass and the link's motion, from which it was formed (a root 5e-9 off, relative; a
    damped chatter of 2,264 contacts 5.7e-9 off in its COR)."""
    c = 2.0 * zeta * K
    rng = np.random.default_rng(3)
    worst_t = worst_v = 0.0
    n = 0
    for _ in range(120):
        y = np.array(
            [
                0.0,
                -(10 ** rng.uniform(-3, 0)),
                10 ** rng.uniform(-4, -1),
                -rng.uniform(0.05, 1),
                0,
                0,
            ]
        )
        out = y.copy()
        s = free_flight_linear(out, 0.0, M1, M2, K, c)
        if s <= 0.0:
            continue
        g, r_of, w, v, mu = _mp_flight(y, c)
        root = mp.findroot(g, mp.mpf(s))
        _, wr = r_of(w * root)
        n += 1
        worst_t = max(worst_t, abs(float((s - root) / root)))
        worst_v = max(worst_v, abs(float(out[2] - (v - mu * w * wr))) / abs(float(y[2])))
    assert n > 100
    assert worst_t < 1e-14  # adjacent floats and the gap's own round-off
    assert worst_v < 1e-13


@pytest.mark.parametrize("xi", [0.0, 0.3, 0.999, 1.0, 1.001, 7.0, 1000.0])
def test_increments_of_the_basis_against_mpmath(xi):
    """E = C - 1 + xi x and F = S - x, O(x**2): within the series' reach to a few ulps of
    themselves (where C - 1 + xi x would cancel), beyond it to a few ulps of the terms that
    cancel in them (1 and xi x; S and x)."""
    mp.mp.dps = 50
    X = mp.mpf(xi)
    eps = 2.0**-52
    for x in np.geomspace(1e-9, 20.0 / (1.0 + xi), 60):
        e, f = _increments(float(x), xi)
        xm = mp.mpf(float(x))
        if xi < 1:
            wd = mp.sqrt(1 - X * X)
            c, s = mp.e ** (-X * xm) * mp.cos(wd * xm), mp.e ** (-X * xm) * mp.sin(wd * xm) / wd
        elif xi == 1:
            c, s = mp.e ** (-xm), xm * mp.e ** (-xm)
        else:
            wh = mp.sqrt(X * X - 1)
            ep, em = mp.e ** ((wh - X) * xm), mp.e ** (-(wh + X) * xm)
            c, s = (ep + em) / 2, (ep - em) / (2 * wh)
        E, F = float(c - 1 + X * xm), float(s - xm)
        series = x * (1.0 + xi) <= SERIES_X
        scale_e = abs(E) if series else max(abs(E), 1.0 + xi * x)
        scale_f = abs(F) if series else max(abs(F), x)
        assert abs(e - E) <= 8 * eps * scale_e
        assert abs(f - F) <= 8 * eps * scale_f


@pytest.mark.parametrize("velocities", [None, [-1.4259545399149562, 1.4890106392301425]])
def test_closed_form_run_error_within_its_estimate(velocities):
    """Two masses at a rigid wall: the adaptive kernel's run is closed form throughout, so its
    runs at rtol and rtol/100 are one result. Its estimate is the flights' rounding and its
    replicas' spread (the estimate was 0, the COR 5.7e-9 off: 2,264 contacts)."""
    kw = dict(masses=[1.0, 30.941746848571587], springs=[22.33713129533995],
              dashpots=[6.4079345737101026])  # fmt: skip
    if velocities:
        kw.update(velocities=velocities, stretches=[-0.24309611633335584])
    ch = restitution.Chain(**kw)
    ref = restitution.solve(ch, method="precise")
    assert ref.status == "ok" and ref.n_collisions > 1900
    for rtol in (1e-6, 1e-10):
        r = restitution.solve(ch, method="adaptive", rtol=rtol)
        assert r.status == "ok" and r.n_collisions == ref.n_collisions
        err = abs(r.cor - ref.cor)
        assert err < 1e-12
        assert 0.0 < r.error_estimate and err <= r.error_estimate + ref.error_estimate
        assert r.error_estimate < 1e-10  # a round-off estimate, not a loose one


def test_closed_form_rows_of_a_table_are_the_single_rows():
    """solve_many's adaptive rows (the batch kernel and its replicas) are solve's, bit for bit."""
    import pandas as pd

    alpha, xi = [0.3, 0.697, 5.0, 30.9], [0.0, 0.1, 2.0, 0.689]
    frame = pd.DataFrame({"alpha": alpha, "beta": 0.0, "xi": xi})
    many = restitution.solve_many(frame, method="adaptive", rtol=1e-8)
    for i, row in frame.iterrows():
        one = restitution.solve(alpha=row.alpha, beta=0.0, xi=row.xi, method="adaptive", rtol=1e-8)
        assert many["cor"][i] == one.cor and many["error_estimate"][i] == one.error_estimate
        assert math.isfinite(one.error_estimate) and one.error_estimate > 0.0
