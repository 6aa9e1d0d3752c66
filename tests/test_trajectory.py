"""restitution.trajectory: the motion of every mass against closed forms and solve_ivp."""

import math

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

import restitution
from restitution import Chain, SceneError, solve, trajectory


def test_columns_and_free_flight_before_contact_ends():
    times = np.linspace(0.0, 3.0, 7)
    t = trajectory(alpha=0.5, beta=0.05, times=times)
    assert list(t.columns) == ["t", "omega_t", "u_1", "u_2", "v_1", "v_2", "f_contact",
                               "impulse", "event"]  # fmt: skip
    assert (t["event"] == "sample").all() and np.array_equal(t["t"], times)
    # at t = 0 everything moves at -V0 from u = 0
    assert t["u_1"].iat[0] == 0.0
    assert t["v_1"].iat[0] == pytest.approx(-1.0, abs=1e-14)
    assert t["v_2"].iat[0] == pytest.approx(-1.0, abs=1e-14)


def test_single_contact_closed_form():
    # alpha -> single contact with a linear spring: before m2 reacts much, m1 compresses the
    # contact; check against the 2-DOF closed form integrated by solve_ivp instead
    alpha, beta = 0.4, 0.2
    k2 = alpha / (1 + alpha)
    k1 = k2 / beta
    m = np.array([1.0, alpha])

    def rhs(t, y):
        u1, u2, v1, v2 = y
        f1 = k2 * (u2 - u1) - (k1 * u1 if u1 < 0 else 0.0)
        return [v1, v2, f1 / m[0], -k2 * (u2 - u1) / m[1]]

    r = solve(alpha, beta, history=True)
    end = float(r.history["omega_t_end"].iloc[0])  # inside the first contact: smooth ODE
    times = np.linspace(0.0, end, 9)[1:-1]
    ref = solve_ivp(rhs, (0, end), [0, 0, -1, -1], t_eval=times, rtol=1e-12, atol=1e-14)
    t = trajectory(alpha=alpha, beta=beta, times=times)
    assert t["u_1"].to_numpy() == pytest.approx(ref.y[0], abs=1e-9)
    assert t["v_2"].to_numpy() == pytest.approx(ref.y[3], abs=1e-9)
    assert t["f_contact"].to_numpy() == pytest.approx(k1 * np.maximum(-ref.y[0], 0), abs=1e-8)


def test_rigid_wall_impacts_are_rows_with_their_impulse():
    r = solve(alpha=5.0, history=True)
    t_end = float(r.history["omega_t_end"].iloc[-1]) + 1.0
    t = trajectory(alpha=5.0, times=np.linspace(0.0, t_end, 50))
    impacts = t[t["event"] == "impact"]
    assert len(impacts) == r.n_collisions
    assert impacts["impulse"].to_numpy() == pytest.approx(r.history["impulse"].to_numpy())
    assert (t.loc[t["event"] == "sample", "impulse"] == 0).all()
    assert (t["f_contact"] == 0).all()  # a rigid wall acts by impulses only
    assert t["t"].is_monotonic_increasing
    # total impulse = change of momentum: M (cor + 1) V0 for m1 = 1, V0 = 1
    assert impacts["impulse"].sum() == pytest.approx((1 + 5.0) * (r.cor + 1.0), rel=1e-12)


def test_general_chain_in_user_units():
    kw = dict(masses=[2.0, 1.0, 4.0], springs=[0.6, 2.4], dashpots=[0.0, 0.1], k_contact=30.0)
    ch = Chain(**kw, v0=3.0)
    r = solve(ch)
    times = np.linspace(0.0, 1.5 * r.t_col, 40)
    t = trajectory(ch, times)
    assert np.array_equal(t["t"], times)
    assert t["omega_t"].to_numpy() == pytest.approx(times * ch.omega, rel=1e-15)
    assert t["v_3"].iat[0] == pytest.approx(-3.0, abs=1e-13)  # user speed
    # after the last contact the centre of mass moves away at cor * v0
    late = t.iloc[-1]
    p = sum(m * late[f"v_{i + 1}"] for i, m in enumerate(kw["masses"]))
    assert p / (sum(kw["masses"]) * 3.0) == pytest.approx(r.cor, abs=1e-10)
    assert (t.loc[t["t"] > r.t_col * 1.0001, "f_contact"] == 0).all()
    # unit check: the same chain at v0 = 1 has positions 3 times smaller
    t1 = trajectory(Chain(**kw), times)
    assert t1["u_2"].to_numpy() * 3.0 == pytest.approx(t["u_2"].to_numpy(), abs=1e-12)


def test_keyword_forms_agree():
    times = np.linspace(0, 4, 5)
    a = trajectory({"alpha": 2.0, "beta": 0.1, "xi": 0.2}, times)
    b = trajectory(alpha=2.0, beta=0.1, xi=0.2, times=times)
    c = trajectory(Chain.paper(2.0, 0.1, 0.2), times)
    pd.testing.assert_frame_equal(a, b)
    pd.testing.assert_frame_equal(a, c)


def test_bad_input():
    with pytest.raises(SceneError, match="times must be"):
        trajectory(alpha=2.0, times=[-1.0, 1.0])
    with pytest.raises(SceneError, match="times must be"):
        trajectory(alpha=2.0, times=[])
    with pytest.raises(SceneError, match="alpha must be"):
        trajectory(alpha=-2.0, times=[1.0])
    with pytest.raises(SceneError, match="rtol must be"):
        trajectory(masses=[1, 2], springs=[1], contact={"law": "hertz", "k": 5}, times=[1.0],
                   rtol=-1.0)  # fmt: skip
    assert math.isfinite(restitution.trajectory(alpha=1.0, times=[0.5])["u_1"].iat[0])


@pytest.mark.parametrize(
    "scene",
    [
        dict(alpha=2.0, beta=0.1),  # exact, no impact rows
        dict(alpha=5.0),  # exact, impact rows
        dict(masses=[1.0, 0.5], springs=[1.0], contact={"law": "hertz", "k": 50.0}),  # adaptive
    ],
)
def test_rows_are_sorted_by_time_whatever_the_order_asked(scene):
    """The docstring's promise held only where event rows were merged in: times asked in any
    order (and repeated) come back sorted, each sample equal to the one asked in order."""
    asked = [3.0, 1.0, 1.0, 0.0, 2.5]
    frame = trajectory(**scene, times=asked)
    assert frame["t"].is_monotonic_increasing
    s = frame[frame["event"] == "sample"]
    assert sorted(s["t"]) == sorted(asked)
    ordered = trajectory(**scene, times=sorted(asked))
    o = ordered[ordered["event"] == "sample"]
    assert np.array_equal(s.filter(regex="^[uv]_").to_numpy(), o.filter(regex="^[uv]_").to_numpy())


def test_rigid_paper_chain_trajectory_reuses_its_checked_rows_history(monkeypatch):
    """The impacts come from the history of the checked row the trajectory computes for its
    status: no second checked solve for them, nor for the states at the impacts; the impact
    rows are those of solve(history=True)."""
    import restitution.api as api

    times = np.linspace(0.0, 30.0, 61)
    expected = restitution.solve(300.0, 0.0, 0.01, 3, history=True).history
    calls = []
    real = api.solve
    monkeypatch.setattr(api, "solve", lambda *a, **k: calls.append(a) or real(*a, **k))
    frame = restitution.trajectory(alpha=300.0, beta=0.0, xi=0.01, n_masses=3, times=times)
    assert calls == []
    impacts = frame[frame["event"] == "impact"]
    inside = expected[expected["omega_t_start"] <= 30.0]
    assert len(impacts) == len(inside) > 3
    assert np.array_equal(impacts["t"].to_numpy(), inside["t_start"].to_numpy())


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(method="adaptive"), "method"),
        (dict(history=True), "history"),
        (dict(k_contact=5.0), "k_contact"),
        (dict(foo=1.0), "foo"),
    ],
)
def test_an_unknown_paper_keyword_is_not_listed_as_allowed(kwargs, name):
    """(The list of allowed keywords was solve's: it named method, history, k_contact.)"""
    with pytest.raises(SceneError, match=rf"unknown scene parameter\(s\) {name}; allowed: ") as e:
        trajectory(alpha=2.0, times=[1.0], **kwargs)
    paper_form = str(e.value).split("allowed: ")[1].split(" (or ")[0]
    assert name not in paper_form.split(", ")
    assert "times" in paper_form.split(", ") and "rtol" in paper_form.split(", ")
