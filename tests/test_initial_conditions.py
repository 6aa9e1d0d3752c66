"""Arbitrary initial conditions: a velocity per mass and a pre-stretch per link.

Semantics (docs/general-chains.md, "Initial conditions"): ``velocities`` are N approach
velocities (positive towards the wall), ``stretches`` N - 1 link extensions; m_1 starts touching
the wall, hitting it at t = 0 if velocities[0] > 0 and leaving it (a free flight first) if < 0.
The COR is the centre of mass's velocity after over before; the energy fractions are of the
initial kinetic + spring energy.

Independent references: the mpmath event sequence (``restitution.solvers.precise``, which shares
no code with the kernels) for linear scenes, closed forms of the two-mass free flight, and a
solve_ivp integration of the equations of motion written here (Hertz contact).
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from restitution import Chain, SceneError, solve, trajectory
from restitution.solvers.precise import solve_precise

FIELDS = ("cor", "n_collisions", "omega_t_col", "e_translational", "e_vibrational",
          "e_dissipated", "error_estimate", "method", "status", "t_col")  # fmt: skip


def _hex(r):
    return [float(getattr(r, f)).hex() if isinstance(getattr(r, f), float) else getattr(r, f)
            for f in FIELDS]  # fmt: skip


def _closes(r, tol):
    return abs(r.e_translational + r.e_vibrational + r.e_dissipated - 1.0) <= tol


LINEAR = [
    dict(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], dashpots=[0.0, 0.05]),
    dict(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], dashpots=[0.0, 0.05], k_contact=50.0),
    dict(masses=[2.0, 0.7], springs=[3.0], dashpots=[0.4]),
    dict(masses=[2.0, 0.7], springs=[3.0], k_contact=10.0),
    dict(masses=[1.0, 2.0, 2.0, 2.0], springs=[2 / 3] * 3, dashpots=[0.4, 0, 0]),  # paper-shaped
]


# ----------------------------------------------------------------------------------------------
# The default, exactly
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "scene",
    [*LINEAR, dict(masses=[1.0, 0.5], springs=[0.3], contact={"law": "hertz", "k": 50.0})],
)
@pytest.mark.parametrize("v0", [1.0, 2.5])
def test_uniform_velocities_and_zero_stretches_are_the_default(scene, v0):
    n = len(scene["masses"])
    given = solve(**scene, velocities=[v0] * n, stretches=[0.0] * (n - 1))
    assert _hex(given) == _hex(solve(**scene, v0=v0))
    assert given.scene.velocities is None and given.scene.stretches is None


@pytest.mark.parametrize("scene", LINEAR[:4])
def test_the_state_path_from_the_uniform_state_agrees_with_the_default(scene):
    """The general kernel's state path, given the uniform state itself (a velocity one ulp off
    keeps it off the default's path), lands within the estimates of the default."""
    n = len(scene["masses"])
    vel = [1.0] * n
    vel[-1] = math.nextafter(1.0, 2.0)
    a, b = solve(**scene, velocities=vel), solve(**scene)
    assert a.status == b.status == "ok" and a.n_collisions == b.n_collisions
    assert abs(a.cor - b.cor) <= a.error_estimate + b.error_estimate + 4e-16
    assert a.e_translational == pytest.approx(b.e_translational, abs=1e-12)


# ----------------------------------------------------------------------------------------------
# Against the mpmath reference
# ----------------------------------------------------------------------------------------------
def _random_scene(rng):
    n = int(rng.integers(2, 6))
    m = rng.uniform(0.3, 3.0, n)
    k = rng.uniform(0.5, 4.0, n - 1)
    c = np.where(rng.random(n - 1) < 0.5, 0.0, rng.uniform(0.0, 0.2, n - 1))
    kc = math.inf if rng.random() < 0.5 else float(rng.uniform(5.0, 100.0))
    while True:  # velocities with the centre of mass approaching, m_1 moving either way
        vel = rng.uniform(-1.0, 2.0, n)
        if np.dot(m, vel) > 0.2 * m.sum() and abs(vel[0]) > 0.05:
            break
    st = rng.uniform(-0.3, 0.3, n - 1)
    return dict(masses=m, springs=k, dashpots=c, k_contact=kc, velocities=vel, stretches=st)


@pytest.mark.parametrize("seed", range(12))
def test_random_initial_states_against_the_mpmath_reference(seed):
    sc = _random_scene(np.random.default_rng(100 + seed))
    r = solve(**sc)
    ref = solve_precise(sc["masses"], sc["springs"], sc["dashpots"], sc["k_contact"],
                        velocities=sc["velocities"], stretches=sc["stretches"])  # fmt: skip
    assert ref.status == "ok" and ref.digits > 25
    assert r.status == "ok", r.status
    assert r.method == ("impulsive" if math.isinf(sc["k_contact"]) else "piecewise")
    assert r.n_collisions == ref.n_collisions
    assert abs(r.cor - ref.cor) <= r.error_estimate, (r.cor, ref.cor, r.error_estimate)
    assert r.e_translational == pytest.approx(ref.e_translational, abs=1e-9)
    assert r.e_vibrational == pytest.approx(ref.e_vibrational, abs=1e-9)
    assert r.t_col == pytest.approx(ref.t_col, rel=1e-9, abs=1e-12)
    assert _closes(r, 1e-9)


def test_the_precise_method_takes_the_initial_state():
    sc = _random_scene(np.random.default_rng(7))
    r, p = solve(**sc), solve(**sc, method="precise")
    assert p.method == "precise" and p.n_collisions == r.n_collisions
    assert abs(r.cor - p.cor) <= r.error_estimate + p.error_estimate


# ----------------------------------------------------------------------------------------------
# Linearity and the energy account
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("lam", [1e-3, 3.7, 250.0])
@pytest.mark.parametrize("seed", [1, 2])
def test_linear_scenes_are_invariant_under_scaling_the_state(seed, lam):
    sc = _random_scene(np.random.default_rng(seed))
    a = solve(**sc)
    b = solve(**{**sc, "velocities": lam * sc["velocities"], "stretches": lam * sc["stretches"]})
    assert a.n_collisions == b.n_collisions
    assert abs(a.cor - b.cor) <= a.error_estimate + b.error_estimate
    assert b.e_vibrational == pytest.approx(a.e_vibrational, abs=1e-10)
    assert b.t_col == pytest.approx(a.t_col, rel=1e-10)
    assert b.scene.v0 == pytest.approx(lam * a.scene.v0, rel=1e-15)


@pytest.mark.parametrize("seed", range(5))
def test_energy_account_closes_from_stretched_states(seed):
    rng = np.random.default_rng(50 + seed)
    sc = _random_scene(rng)
    sc["stretches"] = rng.uniform(-2.0, 2.0, len(sc["masses"]) - 1)  # mostly spring energy
    r = solve(**sc)
    assert r.status == "ok" and _closes(r, 1e-9)
    assert 0.0 <= r.e_translational <= 1.0 and r.e_dissipated >= -1e-12


# ----------------------------------------------------------------------------------------------
# Closed forms of the two-mass free flight
# ----------------------------------------------------------------------------------------------
def _first_contact(m1, m2, k, p, q):
    """First omega*t > 0 at which m1 returns to the wall, and its velocity there (kernel sign:
    negative towards the wall), for two masses joined by an undamped spring k, unstretched, m1 at
    the wall with velocity p > 0 (leaving) and m2 with q: the centre of mass moves at V, the
    spring's extension is r = (q - p) sin(s) / omega, and u1 = V t - (m2/M) r."""
    big_m = m1 + m2
    w = math.sqrt(k / m1 + k / m2)
    vc = (m1 * p + m2 * q) / big_m

    def u1(s):
        return (vc * s - (m2 / big_m) * (q - p) * math.sin(s)) / w

    grid = np.linspace(1e-9, 60.0, 600001)
    vals = np.array([u1(s) for s in grid[::100]])
    i = int(np.flatnonzero(vals < 0.0)[0])
    s = brentq(u1, grid[::100][i - 1], grid[::100][i], xtol=1e-15, rtol=1e-15)
    return s, vc - (m2 / big_m) * (q - p) * math.cos(s)


@pytest.mark.parametrize("alpha", [0.6, 2.0, 6.0])
def test_m1_leaving_the_wall_first_contact_in_closed_form(alpha):
    # m1 leaves the wall at 0.5, m2 approaches at 1.5 (positive: towards the wall)
    m, k = [1.0, alpha], [1.3]
    r = solve(masses=m, springs=k, velocities=[-0.5, 1.5], history=True)
    s, v1 = _first_contact(1.0, alpha, 1.3, 0.5, -1.5)
    h = r.history
    assert r.status == "ok" and r.n_collisions >= 1
    assert h["omega_t_start"].iloc[0] == pytest.approx(s, rel=1e-12)
    assert h["velocity_in"].iloc[0] == pytest.approx(v1, rel=1e-12, abs=1e-13)


@pytest.mark.parametrize("alpha", [2.0, 4.5, 4.7, 9.0])
def test_only_m1_moving_impact_then_closed_form(alpha):
    """m1 hits the rigid wall at v, m2 at rest: after the impact m1 leaves at v, and
    u1 = (m1 v / (M w)) (s + alpha sin s) returns to 0 only if alpha > 4.6033... (the minimum of
    -s / sin s, at tan s = s): below it one contact, COR 1 and e_translational = m1 / M."""
    r = solve(masses=[1.0, alpha], springs=[0.8], velocities=[2.0, 0.0], history=True)
    assert r.status == "ok"
    s_star = brentq(lambda s: math.tan(s) - s, 4.4, 4.6)
    threshold = -s_star / math.sin(s_star)
    assert threshold == pytest.approx(4.6033, abs=1e-4)
    if alpha < threshold:
        assert r.n_collisions == 1 and r.cor == pytest.approx(1.0, abs=1e-14)
        assert r.e_translational == pytest.approx(1.0 / (1.0 + alpha), abs=1e-14)
        assert r.e_vibrational == pytest.approx(alpha / (1.0 + alpha), abs=1e-13)
    else:
        s, v1 = _first_contact(1.0, alpha, 0.8, 2.0, 0.0)
        assert r.n_collisions >= 2
        assert r.history["omega_t_start"].iloc[1] == pytest.approx(s, rel=1e-12)
        assert r.history["velocity_in"].iloc[1] == pytest.approx(v1, rel=1e-11)


def test_trajectory_starts_at_the_given_state():
    sc = dict(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], k_contact=50.0)
    f = trajectory(**sc, velocities=[-0.2, 1.0, 0.8], stretches=[0.1, -0.3], times=[0.0, 1.0])
    row = f[f["event"] == "sample"].iloc[0]
    assert [row["u_1"], row["u_2"], row["u_3"]] == pytest.approx([0.0, 0.1, -0.2], abs=1e-15)
    assert [row["v_1"], row["v_2"], row["v_3"]] == pytest.approx([0.2, -1.0, -0.8], rel=1e-15)


# ----------------------------------------------------------------------------------------------
# Nonlinear laws: the adaptive method from the given state
# ----------------------------------------------------------------------------------------------
def _hertz_reference(m, k, kh, vel, st, t_end):
    """(cor, contacts) of a chain with a Hertz contact F = kh x**1.5 (x = -u1 > 0), integrated
    by solve_ivp (DOP853, rtol 1e-12) phase by phase between u1 = 0 crossings."""
    m, k = np.asarray(m, float), np.asarray(k, float)
    n = len(m)

    def rhs(t, y):
        u, v = y[:n], y[n:]
        f = np.zeros(n)
        tension = k * np.diff(u)
        f[:-1] += tension
        f[1:] -= tension
        if u[0] < 0.0:
            f[0] += kh * (-u[0]) ** 1.5
        return np.concatenate([v, f / m])

    def cross(t, y):
        return y[0]

    cross.terminal = True
    y = np.concatenate([[0.0], np.cumsum(st), -np.asarray(vel, float)])
    t, contacts = 0.0, 0
    inside = y[n] < 0.0
    contacts += inside
    while t < t_end:
        cross.direction = 1.0 if inside else -1.0
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        events=cross)  # fmt: skip
        y = sol.y[:, -1].copy()
        if sol.status != 1:
            break
        t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
        y[0] = 0.0
        inside = not inside
        contacts += inside
    p0 = float(np.dot(m, vel))
    return float(np.dot(m, y[n:])) / p0, contacts


@pytest.mark.parametrize(
    "vel, st", [([1.0, 0.4, 1.5], [0.05, -0.1]), ([-0.3, 1.2, 1.0], [0.0, 0.2])]
)
def test_hertz_chain_from_a_given_state_against_solve_ivp(vel, st):
    m, k, kh = [1.0, 0.5, 2.0], [0.3, 1.2], 50.0
    r = solve(masses=m, springs=k, contact={"law": "hertz", "k": kh}, velocities=vel,
              stretches=st, rtol=1e-11)  # fmt: skip
    cor, contacts = _hertz_reference(m, k, kh, vel, st, t_end=400.0)
    assert r.method == "adaptive" and r.status == "ok"
    assert r.n_collisions == contacts
    assert abs(r.cor - cor) <= max(r.error_estimate, 1e-9), (r.cor, cor, r.error_estimate)
    assert _closes(r, 1e-8)


@pytest.mark.parametrize("seed", range(4))
def test_adaptive_from_a_given_state_agrees_with_the_exact_route(seed):
    """A linear-contact scene forced onto the adaptive method: within its estimate of the exact
    kernel's COR, with the same contact count."""
    sc = _random_scene(np.random.default_rng(200 + seed))
    sc["k_contact"] = 30.0
    ex = solve(**sc)
    ad = solve(**sc, method="adaptive", rtol=1e-11)
    assert ad.status == "ok" and ex.status == "ok"
    assert ad.n_collisions == ex.n_collisions
    assert abs(ad.cor - ex.cor) <= ad.error_estimate + ex.error_estimate
    assert ad.e_translational == pytest.approx(ex.e_translational, abs=1e-7)
    assert _closes(ad, 1e-8)


def test_verlet_from_a_given_state_agrees_with_the_exact_route():
    sc = dict(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], k_contact=20.0,
              velocities=[-0.2, 1.0, 0.8], stretches=[0.1, -0.3])  # fmt: skip
    ex, vv = solve(**sc), solve(**sc, method="verlet", step=0.005)
    assert vv.method == "verlet" and vv.status == "ok" and vv.n_collisions == ex.n_collisions
    assert abs(vv.cor - ex.cor) <= vv.error_estimate + ex.error_estimate


@pytest.mark.parametrize(
    "contact",
    [
        {"law": "kelvin_voigt", "k": 4.0, "c": 1.2},
        {"law": "hunt_crossley", "k": 4.0, "alpha": 0.1},
        {"law": "plastic", "k": 4.0, "eta": 1.5, "dr": 0.3},
    ],
)
def test_nonlinear_contacts_from_a_given_state_close_their_energy_account(contact):
    r = solve(masses=[1.0, 2.0, 1.0], springs=[1.0, 0.5], contact=contact,
              velocities=[0.8, 1.4, 0.2], stretches=[0.1, -0.05])  # fmt: skip
    exact = contact["law"] == "kelvin_voigt"  # piecewise linear: the exact method
    assert r.method == ("piecewise" if exact else "adaptive") and r.status == "ok"
    assert _closes(r, 1e-6)
    assert 0.0 < r.cor <= 1.0 + r.error_estimate


TWO_MASS_LAWS = [
    dict(k_contact=5.0, links=[{"law": "scissor", "L": 1.0, "ks": 0.01}]),
    dict(contact={"law": "plastic", "k": 5.0, "eta": 1.5, "dr": 0.3}),
    dict(k_contact=5.0),  # linear: the scipy reference against the exact kernel as well
]


@pytest.mark.parametrize("law", TWO_MASS_LAWS)
@pytest.mark.parametrize(
    "vel, st", [([1.0, 0.6], [0.02]), ([-0.4, 1.1], [-0.05]), ([1.2, 0.0], [0.0])]
)
def test_two_masses_from_a_given_state_against_the_scipy_reference(law, vel, st):
    """``method="reference"`` (scipy solve_ivp, DOP853 with events, in Python) from the state:
    the adaptive method within both estimates, the same contacts; and both within the exact
    kernel's COR for the linear law."""
    sc = dict(masses=[1.0, 1.3], springs=[0.5], **law, velocities=vel, stretches=st)
    ad = solve(**sc, method="adaptive", rtol=1e-11)  # (auto: piecewise for the linear law)
    ref = solve(**sc, method="reference", rtol=1e-12)
    assert ad.status == "ok" and ref.status == "ok", (ad.status, ref.status)
    assert ad.n_collisions == ref.n_collisions
    assert abs(ad.cor - ref.cor) <= ad.error_estimate + ref.error_estimate + 1e-10
    assert _closes(ad, 1e-8) and _closes(ref, 1e-8)
    if "contact" not in law and "links" not in law:
        ex = solve(**sc)
        assert ex.method == "piecewise" and ex.n_collisions == ref.n_collisions
        assert abs(ex.cor - ref.cor) <= ex.error_estimate + ref.error_estimate + 1e-10


# ----------------------------------------------------------------------------------------------
# Refused inputs: one per class, each naming the parameter and its range
# ----------------------------------------------------------------------------------------------
TWO = dict(masses=[1.0, 2.0], springs=[1.0])


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(velocities=[1.0, 1.0, 1.0]), r"velocities must have 2 entries"),
        (dict(stretches=[0.1, 0.2]), r"stretches must have 1 entries"),
        (dict(velocities=[1.0, math.nan]), r"velocities\[1\] must be in \[-1e6, 1e6\]"),
        (dict(velocities=[1.0, math.inf]), r"velocities\[1\] must be in"),
        (dict(velocities=[1.0, 2e6]), r"velocities\[1\] must be in \[-1e6, 1e6\]"),
        (dict(velocities=[1.0, "fast"]), r"velocities must be a list of numbers"),
        (dict(velocities=1.0), r"velocities must be a list of numbers"),
        (dict(stretches=[math.inf]), r"stretches\[0\] must be in"),
        (dict(velocities=[0.0, 1.0]), r"velocities\[0\] must not be 0"),
        (dict(velocities=[1.0, -1.0]), r"the centre of mass must approach the wall"),
        (dict(velocities=[-1.0, -1.0]), r"the centre of mass must approach the wall"),
        (dict(velocities=[1e-7, 1e-9]), r"the centre of mass must approach.*\[1e-6, 1e6\]"),
        (dict(velocities=[-1e5, 5e4 + 1e-4]), r"velocities\[0\] / \(the centre of mass"),
        (dict(stretches=[1e9]), r"stretches\[0\] \* omega"),
        (dict(velocities=[1.0, 2.0], v0=2.0), r"either v0 .* or velocities"),
    ],
)
def test_refused_initial_states(kw, match):
    with pytest.raises(SceneError, match=match):
        solve(**TWO, **kw)


def test_initial_state_needs_the_general_form():
    with pytest.raises(SceneError, match=r"need the general form"):
        solve(alpha=2.0, velocities=[1.0, 2.0])
    with pytest.raises(SceneError, match=r"either v0 .* or velocities"):
        Chain([1.0, 2.0], [1.0], v0=3.0, velocities=[1.0, 2.0])


@pytest.mark.parametrize("vel", [[1.0, 0.4, 1.5], [-0.3, 1.2, 1.0]])
def test_trajectory_of_a_hertz_chain_from_a_given_state(vel):
    """The adaptive run sampled from the state: the state itself at t = 0, and after the last
    contact the centre of mass moving away at cor * v0 (the run is solve's, bit for bit)."""
    sc = dict(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], contact={"law": "hertz", "k": 50.0},
              velocities=vel, stretches=[0.05, -0.1])  # fmt: skip
    r = solve(**sc)
    late = r.t_col + 50.0
    f = trajectory(**sc, times=[0.0, late])
    s = f[f["event"] == "sample"]
    first, last = s.iloc[0], s.iloc[-1]
    assert f.attrs["method"] == "adaptive"
    assert [first["u_1"], first["u_2"], first["u_3"]] == pytest.approx([0.0, 0.05, -0.05])
    assert [first["v_1"], first["v_2"], first["v_3"]] == pytest.approx([-v for v in vel])
    m = np.array(sc["masses"])
    vc = float(np.dot(m, [last["v_1"], last["v_2"], last["v_3"]]) / m.sum())
    assert vc == pytest.approx(r.cor * r.scene.v0, rel=1e-12)
    starts = f.loc[f["event"] == "contact_start", "t"].to_numpy()
    assert len(starts) == r.n_collisions and (starts[0] == 0.0) == (vel[0] > 0)


def test_hunt_crossley_range_counts_the_initial_energy():
    """The uniform approach at the same centre-of-mass speed is within the range; the stretched
    state's energy (the law speed sqrt(2 E0 / M), 1.53 here) would let m1 leave faster than
    1/(1.5 alpha): 1.5 * 0.3 * 1.53 * sqrt(3) = 1.19."""
    hc = {"law": "hunt_crossley", "k": 4.0, "alpha": 0.3}
    assert solve(**TWO, contact=hc).status == "ok"
    assert Chain([1.0, 2.0], [1.0], stretches=[2.0]).law_speed == pytest.approx(math.sqrt(7 / 3))
    with pytest.raises(SceneError, match=r"contact.alpha: 1.5 alpha v0 sqrt\(M/m1\) is 1.19"):
        solve(**TWO, contact=hc, stretches=[2.0])


def test_command_line_takes_the_initial_state(capsys):
    import json

    from restitution.cli import main

    argv = ["cor", "--masses", "1,0.5,2", "--springs", "0.3,1.2", "--k-contact", "50",
            "--velocities=-0.2,1,0.8", "--stretches", "0.1,-0.3", "--json"]  # fmt: skip
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    r = solve(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], k_contact=50.0,
              velocities=[-0.2, 1.0, 0.8], stretches=[0.1, -0.3])  # fmt: skip
    assert d["cor"] == r.cor and d["scene"]["velocities"] == [-0.2, 1.0, 0.8]
    assert main(["cor", "--alpha", "2", "--velocities", "1,2"]) == 2
    assert "need a general chain" in capsys.readouterr().err


def test_tables_take_the_initial_state_per_row(tmp_path):
    """List columns ``velocities`` and ``stretches`` (a missing cell: the uniform approach); each
    row as ``solve`` gives it, bit for bit, from a frame and from its CSV (';'-separated)."""
    import pandas as pd

    from restitution import solve_many
    from restitution.tables.io import read_table

    rows = [
        dict(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], k_contact=math.inf,
             velocities=[-0.2, 1.0, 0.8], stretches=[0.1, -0.3]),
        dict(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], k_contact=50.0,
             velocities=None, stretches=[0.1, 0.0]),
        dict(masses=[2.0, 0.7], springs=[3.0], k_contact=10.0, velocities=None, stretches=None),
        dict(masses=[2.0, 0.7], springs=[3.0], k_contact=10.0, velocities=[1.0, 2.0],
             stretches=None),
    ]  # fmt: skip
    frame = pd.DataFrame(rows)
    out = solve_many(frame)
    for i, row in enumerate(rows):
        r = solve(**row)
        assert out["cor"].iloc[i].hex() == r.cor.hex() and out["method"].iloc[i] == r.method
        assert out["e_translational"].iloc[i].hex() == r.e_translational.hex()
    row0 = {k: v for k, v in rows[0].items() if k != "k_contact"}
    hertz = pd.DataFrame([dict(row0, contact={"law": "hertz", "k": 50.0})])
    got = solve_many(hertz)
    ref = solve(**row0, contact={"law": "hertz", "k": 50.0})
    assert got["method"].iloc[0] == "adaptive" and got["cor"].iloc[0].hex() == ref.cor.hex()
    text = frame.copy()
    for c in ("masses", "springs", "velocities", "stretches"):
        text[c] = [None if v is None else "; ".join(map(repr, v)) for v in frame[c]]
    path = tmp_path / "scenes.csv"
    text.to_csv(path, index=False)
    again = solve_many(read_table(path))
    assert [x.hex() for x in again["cor"]] == [x.hex() for x in out["cor"]]
    with pytest.raises(SceneError, match=r"velocities must have 2 entries.*row 0"):
        solve_many(pd.DataFrame([dict(masses=[1.0, 2.0], springs=[1.0], velocities=[1.0])]))
