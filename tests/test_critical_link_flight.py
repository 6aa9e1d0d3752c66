"""The closed-form free flight of two masses on a damped linear link next to critical damping.

A link given c = 2 sqrt(k mu) has xi = 1 to a few ulps. Above 1 the flight's basis S(x) =
e^{-xi x} sinh(wh x) / wh was formed as a difference of two exponentials, which keeps only wh x
of its digits, with wh from xi**2 - 1, itself rounded to eps: at xi = 1 + 1e-15 the flights of
a Hertz scene with several contacts were 1.2e-9 off, outside the adaptive method's estimates.
References: mpmath at 50 digits for the basis; the integrated flight (``free_closed=False``)
and scipy's Radau at rtol 1e-12 for whole scenes.
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import restitution
from restitution.kernels.stepping import _basis
from restitution.model.chain import make_chain
from restitution.solvers import numerical


@pytest.mark.parametrize("d", [2.2e-16, 1e-15, 1e-12, 1e-8, 1e-4, 0.5, 10.0])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_basis_next_to_critical_damping_against_mpmath(d, sign):
    xi = 1.0 + sign * d if sign > 0 or d < 1.0 else 0.5
    mp.mp.dps = 50
    X = mp.mpf(xi)
    for x in (0.6, 1.0, 5.0, 30.0):
        c, s = _basis(x, xi)
        if xi > 1.0:
            w = mp.sqrt(X * X - 1)
            ref_c = mp.exp(-X * x) * mp.cosh(w * x)
            ref_s = mp.exp(-X * x) * mp.sinh(w * x) / w
        else:
            w = mp.sqrt(1 - X * X)
            ref_c = mp.exp(-X * x) * mp.cos(w * x)
            ref_s = mp.exp(-X * x) * mp.sin(w * x) / w
        floor = float(mp.exp(-X * x) * (1 + x))  # (an underdamped C or S passes through 0)
        assert abs(c - float(ref_c)) <= 1e-14 * (abs(float(ref_c)) + floor), (xi, x, c, ref_c)
        assert abs(s - float(ref_s)) <= 1e-14 * (abs(float(ref_s)) + floor), (xi, x, s, ref_s)


def _radau_hertz(m, k, c, kh):
    """COR of two masses on a damped link against a Hertz contact: scipy's Radau at rtol 1e-12,
    phase by phase, until m1 leaves for good (the centre of mass receding faster than any
    swing of the link at its remaining energy can bring m1 back)."""
    m = np.asarray(m, float)

    def rhs(t, y, contact):
        u1, u2, v1, v2 = y
        f = k * (u2 - u1) + c * (v2 - v1)
        fc = kh * max(-u1, 0.0) ** 1.5 if contact else 0.0
        return [v1, v2, (f + fc) / m[0], -f / m[1]]

    y, t, contact = np.array([0.0, 0.0, -1.0, -1.0]), 0.0, True
    for _ in range(200):
        ev = lambda t, y, contact: y[0]  # noqa: E731
        ev.terminal, ev.direction = True, (1 if contact else -1)
        sol = solve_ivp(rhs, (t, t + 1e3), y, method="Radau", rtol=1e-12, atol=1e-14,
                        events=ev, args=(contact,))  # fmt: skip
        if sol.status != 1:
            break
        t, y = sol.t[-1], sol.y[:, -1].copy()
        y[0] = 0.0
        contact = not contact
    return float((m @ y[2:]) / m.sum())


@pytest.mark.parametrize("f", [1.0, 1.0 + 1e-15, 1.0 + 1e-12])
@pytest.mark.parametrize("m2", [2.0, 5.0])
def test_hertz_scene_with_a_critically_damped_link(m2, f):
    k, kh = 1.0, 1000.0
    c = 2.0 * math.sqrt(k * m2 / (1.0 + m2)) * f
    kw = dict(masses=[1.0, m2], springs=[k], dashpots=[c], contact={"law": "hertz", "k": kh})
    r = restitution.solve(**kw, method="adaptive", rtol=1e-12)
    assert r.status == "ok" and r.n_collisions >= 3
    out, _ = numerical.solve_chain(make_chain(**kw), "adaptive", 1e-12, free_closed=False)
    assert abs(r.cor - out[0]) <= r.error_estimate + out[8]  # (1.2e-9 against 2.5e-10 before)
    assert r.error_estimate < 1e-10
    assert abs(r.cor - _radau_hertz([1.0, m2], k, c, kh)) < 1e-9
