"""The general chain API: the scene model, its checks, units, the solver table, list columns.

The independent reference is written here: scipy's solve_ivp (DOP853, tight tolerances) on the
chain's equations of motion in the user's units, with u_1 = 0 crossings as events (a rigid wall
reverses v_1 there; a contact spring acts while u_1 < 0), run long enough that no further contact
can come. It shares no code with the package.
"""

import json
import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

import restitution
from restitution import Chain, SceneError, solve, solve_many
from restitution.solvers import exact
from restitution.solvers import methods as M
from restitution.solvers.result import RESULT_COLUMNS


# ----------------------------------------------------------------------------------------------
# Independent reference
# ----------------------------------------------------------------------------------------------
def reference(masses, springs, dashpots, k_contact, v0=1.0, t_end=None):
    """(cor, contacts, t_col) of a linear chain by solve_ivp, in the user's units."""
    m, k, c = (np.asarray(a, dtype=float) for a in (masses, springs, dashpots))
    n = len(m)
    w = math.sqrt(k[0] / m[0] + k[0] / m[1])
    t_end = 200.0 / w if t_end is None else t_end

    def rhs(t, y, contact):
        u, v = y[:n], y[n:]
        f = np.zeros(n)
        d, dv = np.diff(u), np.diff(v)
        link = k * d + c * dv  # tension of each link
        f[:-1] += link
        f[1:] -= link
        if contact:
            f[0] += -k_contact * u[0]
        return np.concatenate([v, f / m])

    def touch(t, y, contact):
        return y[0]

    touch.terminal = True
    y = np.concatenate([np.zeros(n), -v0 * np.ones(n)])
    t, contacts, t_first, t_last = 0.0, 0, 0.0, 0.0
    rigid = math.isinf(k_contact)
    # at t = 0 m1 is at the wall moving in: the first contact starts
    contacts = 1
    if rigid:
        y[n] = v0
        t_last = 0.0
        in_contact = False
    else:
        in_contact = True
    while t < t_end:
        touch.direction = 1.0 if in_contact else -1.0
        sol = solve_ivp(rhs, (t, t_end), y, args=(in_contact,), method="DOP853", rtol=1e-12,
                        atol=1e-14, events=touch)  # fmt: skip
        if sol.status != 1:
            break
        t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
        y[0] = 0.0
        if in_contact:  # separation
            in_contact = False
            t_last = t
        elif rigid:
            contacts += 1
            y[n] = -y[n]
            t_last = t
        else:
            contacts += 1
            in_contact = True
    cor = float(np.dot(m, y[n:]) / (m.sum() * v0))
    return cor, contacts, t_last - t_first


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("k_contact", [math.inf, 40.0])
def test_general_chain_matches_independent_reference(seed, k_contact):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 6))
    masses = rng.uniform(0.3, 3.0, n)
    springs = rng.uniform(0.5, 4.0, n - 1)
    dashpots = np.where(rng.random(n - 1) < 0.5, 0.0, rng.uniform(0.0, 0.2, n - 1))
    r = solve(masses=masses, springs=springs, dashpots=dashpots, k_contact=k_contact)
    cor, contacts, t_col = reference(masses, springs, dashpots, k_contact)
    assert r.success
    assert r.n_collisions == contacts
    assert r.cor == pytest.approx(cor, abs=1e-8)
    assert r.t_col == pytest.approx(t_col, rel=1e-7)
    assert r.method == ("impulsive" if math.isinf(k_contact) else "piecewise")
    total = r.e_translational + r.e_vibrational + r.e_dissipated
    assert total == pytest.approx(1.0, abs=1e-9)


def test_issue_example_and_units():
    r = solve(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], dashpots=[0.0, 0.05], k_contact=math.inf)
    assert r.success and r.n_masses == 3 and r.alpha == 0.5 and r.beta == 0.0
    omega = math.sqrt(0.3 / 1.0 + 0.3 / 0.5)
    assert r.t_col == pytest.approx(r.omega_t_col / omega, rel=1e-15)
    # the same chain in other units: masses x 7, stiffnesses x 3, dashpots x sqrt(21)
    s = solve(masses=[7.0, 3.5, 14.0], springs=[0.9, 3.6], dashpots=[0.0, 0.05 * math.sqrt(21)])
    assert s.cor == pytest.approx(r.cor, abs=1e-12)
    assert s.n_collisions == r.n_collisions
    assert s.t_col == pytest.approx(r.t_col * math.sqrt(7 / 3), rel=1e-12)


PAPER_SCENES = [(2.0, 0.0, 0.0, 2), (5.0, 0.01, 0.3, 2), (3.0, 0.0, 0.2, 4), (0.8, 0.05, 0.0, 3)]


@pytest.mark.parametrize("alpha, beta, xi, n", PAPER_SCENES)
def test_paper_preset_is_the_paper_scene(alpha, beta, xi, n):
    paper = solve(alpha, beta, xi, n)
    preset = solve(Chain.paper(alpha, beta, xi, n))
    assert preset.cor == paper.cor and preset.n_collisions == paper.n_collisions
    assert preset.method == paper.method
    ch = Chain.paper(alpha, beta, xi, n)
    assert ch.omega == 1.0 and ch.paper_form == (alpha, beta, xi, n)
    # written out in other units it is recognised and gives the same COR
    k = alpha / (1 + alpha)
    c = [2 * xi * k * 2.0] + [0.0] * (n - 2)
    general = solve(masses=[2.0] + [2.0 * alpha] * (n - 1), springs=[2.0 * k] * (n - 1),
                    dashpots=c, k_contact=math.inf if beta == 0 else 2.0 * k / beta)  # fmt: skip
    assert general.cor == pytest.approx(paper.cor, abs=1e-12)
    assert general.n_collisions == paper.n_collisions


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(masses=[1.0, 2.0], springs=[1.0, 2.0]), r"springs must have 1 entries"),
        (dict(masses=[1.0, 2.0, 3.0], springs=[1.0, 1.0], dashpots=[0.0]), "dashpots must have 2"),
        (dict(masses=[1.0, -2.0], springs=[1.0]), r"masses\[1\] must be in \[1e-100, 1e100\]"),
        (dict(masses=[1.0, 0.0], springs=[1.0]), r"masses\[1\] must be in \[1e-100, 1e100\]"),
        (dict(masses=[1.0, math.inf], springs=[1.0]), r"masses\[1\] must be in \[1e-100, 1e100\]"),
        (dict(masses=[1.0, 2.0], springs=[math.nan]), r"springs\[0\] must be in \[1e-100, 1e100\]"),
        (dict(masses=[1.0, 2.0], springs=[1.0], dashpots=[-0.1]), r"dashpots\[0\] must be in \[0,"),
        # Values inside their own range whose ratios the kernels cannot take (issue 17: a declared
        # range is a handled range): named with the ratio's range, before any work.
        (dict(masses=[5e-324, 1.0], springs=[1.0]), r"masses\[0\] must be in \[1e-100, 1e100\]"),
        (dict(masses=[1.0, 2.0, 3e9], springs=[1.0, 2.0]), r"masses\[i\]/masses\[0\] .*\(i = 2\)"),
        (dict(masses=[1.0, 2.0, 3.0], springs=[1.0, 1e-9]), r"springs\[i\]/springs\[0\] must"),
        (dict(masses=[1.0, 1.0], springs=[1.0], k_contact=5e-324), r"beta = springs\[0\]/k_cont"),
        (dict(masses=[1.0, 2.0], springs=[1.0], dashpots=[1e5]), r"damping ratio .* \[0, 1000\]"),
        (dict(masses=[], springs=[]), "masses must not be empty"),
        (dict(masses=[1.0], springs=[1.0]), "masses must have between 2 and 512 entries"),
        (dict(masses=[1.0] * 513, springs=[1.0] * 512), r"between 2 and 512"),
        (dict(masses=[1.0, True], springs=[1.0]), "masses must be a list of numbers"),
        (dict(masses="1,2", springs=[1.0]), "masses must be a list of numbers"),
        (dict(masses=[1.0, 2.0], springs=[1.0], k_contact=0.0), r"k_contact must be > 0"),
        (dict(masses=[1.0, 2.0], springs=[1.0], k_contact=-1.0), r"k_contact must be > 0"),
        (dict(masses=[1.0, 2.0], springs=[1.0], v0=0.0), r"v0 must be in \[1e-6, 1e6\]"),
        (dict(masses=[1.0, 2.0], springs=[1.0], contact={"law": "soft"}), "contact law must be"),
        (dict(masses=[1.0, 2.0], springs=[1.0], contact={"law": "hertz"}), "needs k"),
        # unknown keys of the linear laws (they were dropped: c=3 solved without a dashpot)
        (
            dict(masses=[1.0, 2.0], springs=[1.0], contact={"law": "linear", "k": 5.0, "c": 3.0}),
            r"unknown parameter\(s\) c for the 'linear' law; allowed: k",
        ),  # fmt: skip
        (
            dict(masses=[1.0, 2.0], springs=[1.0], contact={"law": "linear", "k": 5.0, "foo": 1}),
            r"unknown parameter\(s\) foo",
        ),  # fmt: skip
        (
            dict(masses=[1.0, 2.0], springs=[1.0], contact={"law": "rigid", "k": 5.0}),
            r"unknown parameter\(s\) k for the 'rigid' law; allowed: none",
        ),  # fmt: skip
        (dict(masses=[1.0, 2.0], springs=[1.0], links=[{"law": "x"}]), r"links\[0\].*law must"),
        (dict(masses=[1.0, 2.0], springs=[1.0], links=[]), "links must be a list of 1"),
        (dict(masses=[1.0, 2.0]), "needs masses=.* and springs="),
    ],
)
def test_bad_chains_name_the_parameter_and_range(kwargs, match):
    with pytest.raises(SceneError, match=match):
        solve(**kwargs)


def test_paper_and_general_forms_do_not_mix():
    with pytest.raises(SceneError, match="not both"):
        solve(alpha=1.0, masses=[1.0, 2.0], springs=[1.0])


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(alpha=2.0, k_contact=5.0), "k_contact"),
        (dict(alpha=2.0, k_contact=math.inf), "k_contact"),
        (dict(alpha=2.0, dashpots=[1.0]), "dashpots"),
        (dict(masses=[1.0, 0.5], springs=[1.0], beta=0.1), "beta"),
        (dict(masses=[1.0, 0.5], springs=[1.0], xi=0.1), "xi"),
        (dict(masses=[1.0, 0.5], springs=[1.0], n_masses=2), "n_masses"),
        (dict(masses=[1.0, 0.5], springs=[1.0], beta=math.nan), "beta"),
        (dict(masses=[1.0, 0.5], springs=[1.0], xi="x"), "xi"),
        (dict(masses=[1.0, 0.5], springs=[1.0], beta=None), "beta"),
    ],
)
def test_a_parameter_of_the_other_form_is_refused_not_ignored(kwargs, name):
    """(Each of these returned the other form's result, status ok, the parameter unread.)"""
    with pytest.raises(SceneError, match=rf"not both; got {name}\b"):
        solve(**kwargs)


CHAIN = Chain([1.0, 2.0], [1.0], contact={"law": "hertz", "k": 50.0})


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(v0=100.0),
        dict(k_contact=5.0),
        dict(dashpots=[0.1]),
        dict(masses=[1.0, 2.0]),
        dict(springs=[1.0]),
        dict(contact={"law": "rigid"}),
        dict(links=[{"law": "linear"}]),
        dict(velocities=[1.0, 1.0]),
        dict(stretches=[0.1]),
        dict(beta=0.1),
        dict(xi=0.0),
        dict(n_masses=2),
    ],
)
def test_scene_parameters_with_a_chain_are_refused_not_ignored(kwargs):
    """A Chain carries its whole scene: solve(chain, v0=100) solved it at the Chain's v0."""
    (name,) = kwargs
    with pytest.raises(SceneError, match=rf"unknown keyword\(s\) {name} with a Chain"):
        solve(CHAIN, **kwargs)


@pytest.mark.parametrize(
    "kwargs, name, method",
    [
        (dict(alpha=2.0, rtol=1e-6), "rtol", "impulsive"),
        (dict(alpha=2.0, beta=0.5, step=0.1), "step", "piecewise"),
        (dict(alpha=2.0, beta=0.5, method="verlet", rtol=1e-6), "rtol", "verlet"),
        (dict(alpha=2.0, beta=0.5, method="adaptive", step=0.1), "step", "adaptive"),
        (dict(alpha=2.0, beta=0.5, method="precise", rtol=1e-6), "rtol", "precise"),
        (dict(masses=[1.0, 2.0], springs=[1.0], rtol=1e-6), "rtol", "impulsive"),
        (dict(alpha=Chain([1.0, 2.0], [1.0], k_contact=5.0), step=0.1), "step", "piecewise"),
    ],
)
def test_a_setting_the_method_does_not_read_is_refused(kwargs, name, method):
    """(Each was accepted and did nothing, where a table refused it.)"""
    with pytest.raises(SceneError, match=rf"{name} would do nothing: the method {method!r}"):
        solve(**kwargs)


def test_the_settings_a_method_reads_are_taken():
    loose = solve(alpha=2.0, beta=0.5, method="adaptive", rtol=1e-4)
    assert loose.cor != solve(alpha=2.0, beta=0.5, method="adaptive", rtol=1e-11).cor
    coarse = solve(alpha=2.0, beta=0.5, method="verlet", step=0.1)
    assert coarse.cor != solve(alpha=2.0, beta=0.5, method="verlet", step=0.01).cor


def test_a_chain_takes_the_settings_and_the_defaults_keep_their_meaning():
    r = solve(CHAIN, method="adaptive", rtol=1e-8, max_events=1000)
    assert r.status == "ok" and r.method == "adaptive"
    assert solve(CHAIN).cor == solve(masses=[1.0, 2.0], springs=[1.0], contact=CHAIN.contact).cor
    # not given: the paper form's beta 0, xi 0, n_masses 2; the general form's rigid wall
    assert solve(2.0).cor == solve(2.0, 0.0, 0.0, 2).cor
    rigid = solve(masses=[1.0, 2.0], springs=[1.0])
    assert rigid.method == "impulsive" and rigid.cor == solve(Chain([1.0, 2.0], [1.0])).cor


def test_solver_table_dispatch_and_forced_methods():
    rigid = Chain([1.0, 2.0, 1.0], [1.0, 1.0])
    spring = Chain([1.0, 2.0, 1.0], [1.0, 1.0], k_contact=50.0)
    hertz = Chain([1.0, 2.0, 1.0], [1.0, 1.0], contact={"law": "hertz", "k": 50.0})
    assert M.choose(rigid).name == "impulsive"
    assert M.choose(spring).name == "piecewise"
    assert M.choose(hertz).name == "adaptive"
    assert rigid.rigid and not spring.rigid and not hertz.rigid and not hertz.linear
    assert hertz.beta == pytest.approx(1.0 / 50.0 * 1.0)
    with pytest.raises(SceneError, match="'piecewise' needs beta > 0"):
        M.choose(rigid, "piecewise")
    with pytest.raises(SceneError, match="'impulsive'.*linear contact and links"):
        M.choose(hertz, "impulsive")
    with pytest.raises(SceneError, match="'reference'.*two masses only"):
        M.choose(spring, "reference")
    with pytest.raises(SceneError, match="method must be one of auto, impulsive"):
        M.choose(rigid, "rk4")
    assert set(M.METHODS) == {
        "impulsive",
        "piecewise",
        "adaptive",
        "verlet",
        "reference",
        "precise",
    }
    for name, m in M.METHODS.items():
        assert m.name == name and callable(m.applies) and callable(m.run)


def test_numerical_method_agrees_with_exact_on_a_general_chain():
    kw = dict(masses=[1.0, 0.7, 1.5], springs=[2.0, 1.0], dashpots=[0.1, 0.0], k_contact=30.0)
    exact = solve(**kw)
    adaptive = solve(**kw, method="adaptive", rtol=1e-10)
    assert adaptive.method == "adaptive" and adaptive.n_collisions == exact.n_collisions
    assert adaptive.cor == pytest.approx(exact.cor, abs=1e-7)
    assert adaptive.t_col == pytest.approx(exact.t_col, rel=1e-6)


def test_tiny_beta_is_the_rigid_limit_with_an_error_estimate():
    rigid = solve(alpha=2.0)
    for beta, method in ((1e-21, "piecewise+extrapolated"), (1e-100, "impulsive+rigid-limit"),
                         (1e-308, "impulsive+rigid-limit")):  # fmt: skip
        # (at 1e-21 the limit's bound 10 sqrt(beta) = 3e-10 is above the extrapolation's
        # estimate; at 1e-100 it is below the rigid run's own round-off)
        r = solve(alpha=2.0, beta=beta)
        assert r.success and r.method == method, r
        # (the extrapolated COR keeps its sqrt(beta) term: 9e-12 from the rigid wall's at 1e-21)
        assert r.cor == pytest.approx(rigid.cor, abs=1e-13 + 10 * math.sqrt(beta))
        assert r.n_collisions == rigid.n_collisions
        assert 0 < r.error_estimate < 1e-9
    # the bound is honest: the COR approaches the rigid wall like sqrt(beta); the gap measured
    # in closed form at beta = 1e-16, scaled to 1e-30, stays below the bound reported there
    gap = abs(solve(alpha=2.0, beta=1e-16).cor - rigid.cor)
    limit = solve(alpha=2.0, beta=1e-30)
    assert limit.method == "impulsive+rigid-limit"
    assert gap * math.sqrt(1e-30 / 1e-16) <= limit.error_estimate
    table = solve_many(pd.DataFrame({"alpha": [2.0, 2.0], "beta": [1e-300, 0.0]}))
    assert list(table["method"]) == ["impulsive+rigid-limit", "impulsive"]
    assert list(table["status"]) == ["ok", "ok"]


def test_result_json_carries_the_law_parameters():
    r = solve(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], contact={"law": "hertz", "k": 50.0})
    d = r.to_dict()
    assert d["scene"]["contact"] == {"law": "hertz", "k": 50.0}
    assert d["scene"]["masses"] == [1.0, 0.5, 2.0] and d["scene"]["links"][0] == {"law": "linear"}
    assert solve(alpha=2.0).to_dict()["scene"]["springs"] == [2.0 / 3.0]
    p = subprocess.run(
        [sys.executable, "-m", "restitution.cli", "cor", "--masses", "1,0.5,2", "--springs",
         "0.3,1.2", "--dashpots", "0,0.05", "--k-contact", "inf", "--json"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["scene"]["contact"] == {"law": "rigid"} and d["scene"]["dashpots"] == [0.0, 0.05]
    assert d["cor"] == pytest.approx(solve(masses=[1, 0.5, 2], springs=[0.3, 1.2],
                                           dashpots=[0, 0.05]).cor, abs=1e-15)  # fmt: skip


def test_solve_many_list_columns_match_solve():
    frame = pd.DataFrame(
        {
            "masses": [[1.0, 0.5, 2.0], "1; 2; 2; 2", np.array([2.0, 1.0])],
            "springs": [[0.3, 1.2], " 1 ;1; 1", [3.0]],
            "dashpots": [[0.0, 0.05], None, "0.1"],
            "k_contact": [math.inf, 20.0, math.inf],
        }
    )
    out = solve_many(frame)
    assert set(RESULT_COLUMNS) <= set(out.columns) and "t_col" in out
    expect = [
        solve(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], dashpots=[0.0, 0.05]),
        solve(masses=[1, 2, 2, 2], springs=[1, 1, 1], k_contact=20.0),
        solve(masses=[2.0, 1.0], springs=[3.0], dashpots=[0.1]),
    ]
    for i, r in enumerate(expect):
        assert out["cor"].iat[i] == r.cor and out["n_collisions"].iat[i] == r.n_collisions
        assert out["method"].iat[i] == r.method and out["status"].iat[i] == r.status
        assert out["t_col"].iat[i] == pytest.approx(r.t_col, rel=1e-15)


def test_solve_many_struct_law_columns():
    frame = pd.DataFrame(
        {
            "masses": [[1.0, 0.5, 2.0], [1.0, 0.5, 2.0]],
            "springs": [[0.3, 1.2], [0.3, 1.2]],
            "contact": [{"law": "hertz", "k": 50.0}, None],
            "links": [None, [{"law": "linear"}, {"law": "linear"}]],
        }
    )
    out = solve_many(frame)
    assert list(out["method"]) == ["adaptive", "impulsive"]
    hertz = solve(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], contact={"law": "hertz", "k": 50.0})
    assert out["cor"].iat[0] == hertz.cor
    bad = frame.assign(contact=[{"law": "hertz"}, None])
    with pytest.raises(SceneError, match=r"needs k.*\(row 0\)"):
        solve_many(bad)


def test_failed_kernel_rows_are_nan_with_a_status(monkeypatch):
    rigid2, rigid2_batch, solve_linear, solve_linear_batch = exact.paper_kernels()

    def broken_batch(alpha, xi, max_events):
        raise ZeroDivisionError("division by zero in a parallel loop")

    def single(alpha, xi, max_events, hist):
        if alpha == 2.0:
            raise ZeroDivisionError("division by zero")
        return rigid2(alpha, xi, max_events, hist)

    monkeypatch.setattr(exact, "_PAPER_KERNELS", (single, broken_batch, solve_linear,
                                              solve_linear_batch))  # fmt: skip
    out = solve_many(pd.DataFrame({"alpha": [0.3, 2.0, 5.0]}))
    assert out["status"].iat[0] == "ok" and out["status"].iat[2] == "ok"
    assert out["cor"].iat[0] == pytest.approx(0.7 / 1.3, abs=1e-14)
    assert out["status"].iat[1].startswith("kernel_error (ZeroDivisionError")
    assert math.isnan(out["cor"].iat[1])


def test_public_names():
    for name in ("Chain", "solve", "solve_many", "trajectory", "Result", "SceneError"):
        assert hasattr(restitution, name)


def test_sticking_limit_is_named_in_the_method():
    # a damped chain chattering against a rigid wall: the kernel continues the Zeno sequence by
    # its sticking limit (OUT_FLAGS bit 0); solve and solve_many both say so
    r = solve(alpha=50.0, xi=0.5, n_masses=3)
    assert r.success and r.method == "impulsive+sticking" and r.error_estimate > 0
    table = solve_many(pd.DataFrame({"alpha": [50.0, 2.0], "xi": [0.5, 0.0], "n_masses": 3}))
    assert list(table["method"]) == ["impulsive+sticking", "impulsive"]
    assert table["cor"].iat[0] == r.cor
