"""A toy method added through exactly the places docs/guides/adding-a-method.md lists.

The toy method is a slow pure-Python event loop for two masses at a rigid wall (closed-form
free flight, impulsive reversal of m1's velocity, the next contact by a scan and brentq), so it
shares no code with the kernels: beside checking the guide, it is an independent reference for
the ``impulsive`` method.
"""

import math

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import brentq

import restitution
from restitution import SceneError
from restitution.kernels import layout as L
from restitution.solvers import methods as M


def _toy_cor(m1: float, m2: float, k: float, max_events: int):
    """(COR, contacts, omega*t_col, status) of m1 - k - m2 hitting a rigid wall at speed 1."""
    a = m2 / m1
    w = math.sqrt(k / m1 + k / m2)
    mu = a / (1.0 + a)  # x1 = X - mu r (X: centre of mass, r = x2 - x1)
    r, rd, v1, v2 = 0.0, 0.0, -1.0, -1.0  # at the first contact: x1 = 0, spring relaxed
    t_last, contacts = 0.0, 0
    while True:
        contacts += 1
        if contacts > max_events:
            return math.nan, max_events, math.nan, L.STATUS_EVENT_BUDGET
        v1 = -v1  # the impact reverses m1's velocity
        V, rd = (v1 + a * v2) / (1.0 + a), v2 - v1
        X, amp = mu * r, math.hypot(r, rd / w)

        def x1(t, X=X, V=V, r=r, rd=rd):
            return X + V * t - mu * (r * math.cos(w * t) + rd / w * math.sin(w * t))

        # Scan for m1 back at the wall; none can come once V > 0 and X + V t > mu * amp.
        h = 1e-3 / w
        t, hit = h, None
        while not (V > 0.0 and X + V * t > mu * amp):
            if x1(t + h) < 0.0:
                hit = brentq(x1, t, t + h, xtol=1e-15, rtol=4 * np.finfo(float).eps)
                break
            t += h
        if hit is None:
            return V, contacts, w * t_last, L.STATUS_OK
        c, s = math.cos(w * hit), math.sin(w * hit)
        r, rd = r * c + rd / w * s, -r * w * s + rd * c
        v1, v2 = V - mu * rd, V + (1.0 - mu) * rd
        t_last += hit


def _run_toy(ch, opts):
    """The runner (guide step 1): a kernel-layout row in kernel units."""
    out = np.full(L.N_OUT, np.nan)
    m, k, _, _ = ch.scaled()
    cor, n, wt, status = _toy_cor(float(m[0]), float(m[1]), float(k[0]), opts.max_events)
    out[[L.OUT_COR, L.OUT_NCOL, L.OUT_TCOL, L.OUT_STATUS]] = cor, n, wt, status
    out[L.OUT_ETRANS] = cor * cor  # undamped: the rest of the energy is vibration
    out[L.OUT_EVIB], out[L.OUT_EDISS] = 1.0 - cor * cor, 0.0
    out[L.OUT_ERR], out[L.OUT_FLAGS], out[L.OUT_NEVENTS] = 1e-9, 0.0, n
    return out, None


def _toy_applies(ch):
    """Guide step 2: the scenes it solves, by the scene model's properties."""
    if ch.n_masses != 2 or not ch.linear or not ch.rigid:
        return "it solves two masses at a rigid wall with linear links only"
    if ch.dashpots.any():
        return "it has no dashpot"
    return None


@pytest.fixture
def toy(monkeypatch):
    """Guide step 3: one row of the table (the batch runner solves row by row)."""
    row = M.Method("toy", False, 50, _toy_applies, _run_toy, M.row_by_row("toy"), "toy loop")
    monkeypatch.setitem(M.METHODS, "toy", row)
    monkeypatch.setattr(M, "NAMES", (*M.NAMES, "toy"))
    return row


@pytest.mark.parametrize("alpha", [0.3, 0.45, 1.0, 2.2, 5.0, 17.0])
def test_the_toy_method_solves_through_solve_and_agrees_with_impulsive(toy, alpha):
    r = restitution.solve(alpha=alpha, method="toy")
    exact = restitution.solve(alpha=alpha)
    assert r.method == "toy" and r.status == "ok" and exact.method == "impulsive"
    assert r.n_collisions == exact.n_collisions
    assert abs(r.cor - exact.cor) <= 1e-9 + exact.error_estimate
    assert abs(r.omega_t_col - exact.omega_t_col) <= 1e-8


def test_the_toy_method_runs_in_tables_and_general_chains(toy):
    frame = pd.DataFrame({"alpha": [0.5, 2.0, 3.0], "method": ["toy", "auto", "toy"]})
    out = restitution.solve_many(frame)
    assert list(out["method"]) == ["toy", "impulsive", "toy"]
    for i in (0, 2):
        exact = restitution.solve(alpha=float(frame["alpha"].iat[i]))
        assert abs(out["cor"].iat[i] - exact.cor) <= 1e-9
    r = restitution.solve(masses=[2.0, 3.0], springs=[5.0], method="toy")  # user units
    assert abs(r.cor - restitution.solve(masses=[2.0, 3.0], springs=[5.0]).cor) <= 1e-9


def test_the_table_refuses_the_toy_method_where_it_does_not_apply(toy):
    with pytest.raises(SceneError, match="'toy' does not fit.*two masses at a rigid wall"):
        restitution.solve(alpha=2.0, beta=0.1, method="toy")
    with pytest.raises(SceneError, match="'toy' does not fit.*no dashpot"):
        restitution.solve(alpha=2.0, xi=0.1, method="toy")
    assert M.choose(restitution.Chain.paper(2.0)).name == "impulsive"  # auto: exact first
