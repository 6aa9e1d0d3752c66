"""restitution.trajectory of the scenes the adaptive method solves (Hertz and plastic contact,
scissor links), against an independent scipy solve_ivp integration with event location, the
energy balance and closed forms; the sampler's run is the solver's own (bit for bit)."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from restitution import Chain, SceneError, solve, trajectory
from restitution.kernels import layout as LY
from restitution.kernels import stepping
from restitution.model.chain import paper_with_laws
from restitution.model.laws import structure_force
from restitution.solvers.numerical import _default_etol, packed

RTOL = 1e-10  # the sampler's tolerance in the comparisons below
# Positions and velocities are O(1) here: DOP853 at rtol 1e-10 (atol = rtol v0) over a few
# contacts keeps its global error within ~100 rtol; the reference runs at 1e-12.
TOL = 1e-8


# ------------------------------------------------------------------------------ reference --
def _reference(masses, link, law, v0, t_eval, t_end):
    """States (len(t_eval), 2n) and the contact events [(t, kind)] of the chain by scipy's
    DOP853 at rtol 1e-12, one solve_ivp per phase, each phase ended by an event function.

    ``link(i, x)`` is link i's force at extension x; ``law`` is ("hertz", k), ("plastic", k1,
    kappa, eta) or ("rigid",) in the chain's own units: x = -u_1 the compression."""
    m = np.asarray(masses, float)
    n = m.size
    y = np.concatenate([np.zeros(n), np.full(n, -v0)])
    kind = law[0]
    mem = {"xmax": 0.0, "fmax": 0.0, "xp": 0.0}
    events = []
    if kind == "rigid":
        y[n] = -y[n]
        mode = "free"
        events.append((0.0, "impact"))
    else:
        mode = "load"
        events.append((0.0, "contact_start"))

    def force(mode, x):
        if mode == "free":
            return 0.0
        if kind == "hertz":
            return law[1] * max(x, 0.0) ** 1.5
        if mode == "load":
            return law[2] * max(x, 0.0) ** law[3]
        return mem["fmax"] - law[1] * (mem["xmax"] - x)

    def rhs(t, s, mode):
        u, v = s[:n], s[n:]
        a = np.zeros(n)
        for i in range(n - 1):
            f = link(i, u[i + 1] - u[i])
            a[i] += f
            a[i + 1] -= f
        a[0] += force(mode, -u[0])
        return np.concatenate([v, a / m])

    def ev(fun, direction):
        fun.terminal, fun.direction = True, direction
        return fun

    t = 0.0
    out = np.full((len(t_eval), 2 * n), np.nan)
    t_eval = np.asarray(t_eval, float)
    while t < t_end:
        if mode == "free":
            if kind == "rigid":
                evs = [ev(lambda t, s: s[0], -1)]
            else:
                evs = [ev(lambda t, s: -s[0] - mem["xp"], 1)]
        elif kind == "hertz":
            evs = [ev(lambda t, s: s[0], 1)]
        elif mode == "load":
            evs = [ev(lambda t, s: s[n], 1)]  # the turn: v_1 rises through 0
        else:  # plastic, on the elastic line: separation at the dent, reload past xmax
            evs = [ev(lambda t, s: -s[0] - mem["xp"], -1), ev(lambda t, s: -s[0] - mem["xmax"], 1)]
        sol = solve_ivp(lambda t, s, mode=mode: rhs(t, s, mode), (t, t_end), y, method="DOP853",
                        rtol=1e-12, atol=1e-14 * v0, events=evs, dense_output=True)  # fmt: skip
        t_next = sol.t[-1]
        inside = (t_eval >= t) & (t_eval <= t_next)
        if inside.any():
            out[inside] = sol.sol(t_eval[inside]).T
        y = sol.y[:, -1].copy()
        t = t_next
        if sol.status != 1:
            break
        which = next(i for i, e in enumerate(sol.t_events) if len(e))
        if mode == "free":
            if kind == "rigid":
                y[n] = -y[n]
                events.append((t, "impact"))
            else:
                mode = "load" if kind == "hertz" or mem["fmax"] == 0.0 else "unload"
                events.append((t, "contact_start"))
        elif kind == "hertz" or (mode == "unload" and which == 0):
            mode = "free"
            events.append((t, "contact_end"))
        elif mode == "load":  # the turn
            x = -y[0]
            if x >= mem["xmax"]:
                mem["xmax"], mem["fmax"] = x, law[2] * x ** law[3]
                mem["xp"] = mem["xmax"] - mem["fmax"] / law[1]
            mode = "unload"
        else:  # reload past xmax
            mode = "load"
    return out, events


def _linear(springs):
    return lambda i, x: springs[i] * x


def _compare(frame, ref, ref_events, n, tol=TOL):
    s = frame[frame["event"] == "sample"]
    for i in range(n):
        assert s[f"u_{i + 1}"].to_numpy() == pytest.approx(ref[:, i], abs=tol), f"u_{i + 1}"
        assert s[f"v_{i + 1}"].to_numpy() == pytest.approx(ref[:, n + i], abs=tol), f"v_{i + 1}"
    got = frame[frame["event"] != "sample"]
    lo, hi = frame["t"].min(), frame["t"].max()
    want = [(t, k) for t, k in ref_events if lo <= t <= hi]
    assert list(got["event"]) == [k for _, k in want]
    assert got["t"].to_numpy() == pytest.approx([t for t, _ in want], abs=tol)


def _plastic_kappa(k1, eta, dr, m1, v0):
    """The law's kappa (docs/general-chains.md): m1 alone rebounds at v0 sqrt(1 - dr)."""
    fmax = v0 * math.sqrt((1.0 - dr) * k1 * m1)
    xmax = (eta + 1.0) * m1 * v0 * v0 / (2.0 * fmax)
    return fmax / xmax**eta


# ------------------------------------------------------------------------------- the scenes --
HERTZ2 = dict(masses=[0.5, 0.8], springs=[20.0], contact={"law": "hertz", "k": 400.0}, v0=0.7)
HERTZ3 = dict(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], contact={"law": "hertz", "k": 50.0})
PLASTIC = dict(
    masses=[1.0, 2.0, 1.5],
    springs=[0.6, 0.9],
    contact={"law": "plastic", "k": 10.0, "eta": 1.5, "dr": 0.3},
    v0=1.3,
)
# two masses on an undamped linear link: the elastic line is a closed form (kernels/elastic2.py);
# reloads past xmax on the second and third contacts
PLASTIC2 = dict(
    masses=[1.0, 5.0],
    springs=[0.8],
    contact={"law": "plastic", "k": 80.0, "eta": 0.5, "dr": 0.3},
    v0=1.0,
)

# the damped contact laws: the force-zero end inside the penetration (Kelvin-Voigt), and a
# velocity-dependent power law (Hunt-Crossley)
KELVIN_VOIGT = dict(
    masses=[1.0, 3.0], springs=[0.3], contact={"law": "kelvin_voigt", "k": 100.0, "c": 40.0}
)
HUNT_CROSSLEY = dict(
    masses=[1.0, 0.5, 2.0],
    springs=[0.3, 1.2],
    contact={"law": "hunt_crossley", "k": 50.0, "alpha": 0.2},
)
DAMPED = [KELVIN_VOIGT, HUNT_CROSSLEY]


def _times(ch, factor=1.3, count=61):
    r = solve(ch)
    assert r.status == "ok"
    return np.linspace(0.0, factor * r.t_col + 0.5 / ch.omega, count), r


@pytest.mark.parametrize("scene", [HERTZ2, HERTZ3], ids=["two masses", "three masses"])
def test_hertz_chain_against_solve_ivp(scene):
    ch = Chain(**scene)
    times, r = _times(ch)
    frame = trajectory(ch, times, rtol=RTOL)
    assert frame.attrs == {"method": "adaptive", "rtol": RTOL, "scaled": False, "status": "ok"}
    assert r.n_collisions >= 2  # several contacts and free flights in the range
    law = ("hertz", scene["contact"]["k"])
    ref, events = _reference(scene["masses"], _linear(scene["springs"]), law,
                             scene.get("v0", 1.0), times, times[-1])  # fmt: skip
    _compare(frame, ref, events, ch.n_masses)
    # the event rows are the states at the contact surface, x = 0 (up to round-off)
    assert np.abs(frame.loc[frame["event"] != "sample", "u_1"]).max() <= 1e-15
    x = np.maximum(-frame["u_1"].to_numpy(), 0.0)
    on = frame["event"] == "sample"
    assert frame["f_contact"].to_numpy()[on] == pytest.approx(law[1] * x[on] ** 1.5, abs=1e-6)


@pytest.mark.parametrize("scene", [PLASTIC, PLASTIC2], ids=["three_masses", "two_masses"])
def test_plastic_contact_against_solve_ivp(scene):
    ch = Chain(**scene)
    times, r = _times(ch)
    frame = trajectory(ch, times, rtol=RTOL)
    c = scene["contact"]
    kappa = _plastic_kappa(c["k"], c["eta"], c["dr"], scene["masses"][0], scene["v0"])
    law = ("plastic", c["k"], kappa, c["eta"])
    ref, events = _reference(scene["masses"], _linear(scene["springs"]), law, scene["v0"],
                             times, times[-1])  # fmt: skip
    assert r.n_collisions >= 2  # a reload on the elastic line after the first contact
    _compare(frame, ref, events, ch.n_masses)
    # the force: power-law loading to the first turn, then the unloading line through the dent
    s = frame[frame["event"] == "sample"]
    first_end = frame.loc[frame["event"] == "contact_end", "t"].iat[0]
    x = -s["u_1"].to_numpy()
    turn = s["t"].to_numpy()[np.argmax(np.where(s["t"] <= first_end, x, -1.0))]
    loading = (s["t"] < turn - 0.01) & (x > 0)
    assert s.loc[loading, "f_contact"].to_numpy() == pytest.approx(
        kappa * x[loading.to_numpy()] ** c["eta"], rel=1e-8
    )
    assert (s["f_contact"] >= 0).all() and (s.loc[s["t"] > r.t_col, "f_contact"] == 0).all()


def test_scissor_link_at_a_rigid_wall_against_solve_ivp():
    ch, _ = paper_with_laws(2.0, 0.0, 0.0, 2, {"structure": "scissor"})
    _, lk, _, _, _, _ = packed(ch)
    assert ch.omega == 1.0 and ch.v0 == 1.0  # kernel units are the scene's
    times, _ = _times(ch, count=41)
    r = solve(ch, rtol=RTOL)  # the run the trajectory samples
    frame = trajectory(alpha=2.0, structure="scissor", times=times, rtol=RTOL)
    assert r.method == "adaptive" and r.n_collisions >= 2
    ref, events = _reference(ch.masses, lambda i, x: structure_force(lk[i], x), ("rigid",), 1.0,
                             times, times[-1])  # fmt: skip
    _compare(frame, ref, events, 2)
    impacts = frame[frame["event"] == "impact"]
    assert impacts["impulse"].sum() == pytest.approx((1 + 2.0) * (r.cor + 1.0), rel=1e-12)
    assert (frame["f_contact"] == 0).all()


def test_energy_balance_of_an_undamped_hertz_chain():
    ch = Chain(**HERTZ3)
    times, _ = _times(ch, count=201)
    f = trajectory(ch, times, rtol=RTOL)
    m, k, kh = np.array(HERTZ3["masses"]), np.array(HERTZ3["springs"]), 50.0
    u = f[[f"u_{i}" for i in (1, 2, 3)]].to_numpy()
    v = f[[f"v_{i}" for i in (1, 2, 3)]].to_numpy()
    x = np.maximum(-u[:, 0], 0.0)
    e = 0.5 * (m * v * v).sum(1) + 0.5 * (k * np.diff(u, axis=1) ** 2).sum(1) + 0.4 * kh * x**2.5
    assert e == pytest.approx(0.5 * m.sum(), rel=1e-8)


@pytest.mark.parametrize(
    "scene",
    [HERTZ2, HERTZ3, PLASTIC, *DAMPED],
    ids=["hertz2", "hertz3", "plastic", "kelvin_voigt", "hunt_crossley"],
)
def test_velocities_after_the_last_contact_give_the_cor(scene):
    # cor = velocity of the centre of mass after the final separation / v0 (docs/physics.md)
    ch = Chain(**scene)
    r = solve(ch)
    f = trajectory(ch, [0.5 * r.t_col, 1.2 * r.t_col, 3.0 * r.t_col])
    if f.attrs["method"] != r.method:  # Kelvin-Voigt: solved by piecewise, sampled by adaptive
        r = solve(ch, method=f.attrs["method"], rtol=f.attrs["rtol"])
    late = f[f["event"] == "sample"].iloc[-1]
    m = np.array(scene["masses"])
    p = sum(mi * late[f"v_{i + 1}"] for i, mi in enumerate(m))
    assert p / (m.sum() * ch.v0) == pytest.approx(r.cor, abs=1e-12)
    ends = f.loc[f["event"] == "contact_end", "t"]
    assert ends.iat[-1] == pytest.approx(r.t_col, rel=1e-14)


def test_one_mass_hertz_closed_form():
    # m1 alone (its link 1e-6 of the contact's slope): x_max = (5 m v0**2 / (4 k))**(2/5) at
    # t_c / 2, t_c = 2 I x_max / v0 with I = (2/5) B(2/5, 1/2) (docs/impact-speed.md). The link
    # changes m1's momentum by at most k_link x t_c ~ 1e-6 of m v0 during the contact.
    m1, kh, v0 = 2.0, 300.0, 0.4
    ch = Chain([m1, m1], [1e-6 * kh], contact={"law": "hertz", "k": kh}, v0=v0)
    x_max = (5 * m1 * v0**2 / (4 * kh)) ** 0.4
    beta = math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)
    t_c = 2 * 0.4 * beta * x_max / v0
    f = trajectory(ch, [0.25 * t_c, 0.5 * t_c, 0.75 * t_c])
    mid = f[f["event"] == "sample"].iloc[1]
    assert -mid["u_1"] == pytest.approx(x_max, rel=1e-5)
    assert mid["v_1"] == pytest.approx(0.0, abs=1e-5 * v0)
    assert mid["f_contact"] == pytest.approx(kh * x_max**1.5, rel=1e-5)
    end = f.loc[f["event"] == "contact_end", "t"]
    assert len(end) == 0  # the contact ends after the last sample
    h = solve(ch, history=True).history
    assert h["t_end"].iat[0] == pytest.approx(t_c, rel=1e-5)
    assert h["compression"].iat[0] == pytest.approx(x_max, rel=1e-5)


@pytest.mark.parametrize("z", [0.2, 0.45])  # (the stand-in link bounds c: frequency spread)
def test_kelvin_voigt_one_mass_ends_where_the_force_is_zero(z):
    # One mass (a 1e-6 link stands in for the single-mass scene, as above: it moves m1 by ~1e-6
    # relative during the contact) on F = k x + c x': the contact ends at the inflection of
    # x(t), inside the penetration (tests/test_kelvin_voigt.py derives t_end and checks the
    # kernel's critical and overdamped ends); the sampled force falls to 0 there, x > 0 still.
    m1, k, v0 = 1.5, 80.0, 0.6
    w0 = math.sqrt(k / m1)
    c = 2.0 * z * math.sqrt(k * m1)
    w = w0 * math.sqrt(1.0 - z * z)  # underdamped (critical and overdamped ends: the test file)
    t_end = math.atan2(2 * z * math.sqrt(1 - z * z), 2 * z * z - 1) / w
    x_end = v0 / w * math.exp(-z * w0 * t_end) * math.sin(w * t_end)
    ch = Chain([m1, m1], [1e-6 * k], contact={"law": "kelvin_voigt", "k": k, "c": c}, v0=v0)
    f = trajectory(ch, [0.5 * t_end, 1.5 * t_end], rtol=1e-12)
    end = f[f["event"] == "contact_end"]
    assert len(end) == 1
    assert end["t"].iat[0] == pytest.approx(t_end, rel=1e-5)
    assert -end["u_1"].iat[0] == pytest.approx(x_end, rel=1e-5)
    assert -end["u_1"].iat[0] > 0.0
    mid = f[f["event"] == "sample"].iloc[0]
    x, xd = -mid["u_1"], -mid["v_1"]
    assert mid["f_contact"] == pytest.approx(k * x + c * xd, rel=1e-9)
    assert end["f_contact"].iat[0] == pytest.approx(0.0, abs=1e-6 * c * v0)


@pytest.mark.parametrize(
    "scene",
    [HERTZ2, HERTZ3, PLASTIC, PLASTIC2, *DAMPED],
    ids=["hertz2", "hertz3", "plastic", "plastic2", "kelvin_voigt", "hunt_crossley"],
)
def test_the_sampler_runs_the_solvers_own_sequence(scene):
    # sample_scene's result row and history equal solve_scene's bit for bit
    ch = Chain(**scene)
    ms, lk, cs, cp, _, _ = packed(ch)
    v0, rtol = float(ch.v0), 1e-9
    etol = _default_etol("adaptive", rtol, 0.0)
    work = float(stepping.MAX_WORK_DEFAULT)
    h1, h2 = np.zeros((50, LY.N_HIST)), np.zeros((50, LY.N_HIST))
    acct = np.zeros(stepping.N_ACCT)
    a = stepping.solve_scene(ms, lk, cs, cp, v0, 0, rtol, 0.01, etol, 50, work, h1, acct, True)
    ts = np.linspace(0.0, 20.0, 77)
    b, ys, _, _, _ = stepping.sample_scene(ms, lk, cs, cp, v0, rtol, etol, 50, work, ts, h2)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(h1, h2)
    assert np.isfinite(ys).all()


def test_sample_order_duplicates_and_the_first_instant():
    ch = Chain(**HERTZ3)
    times = [3.0, 0.0, 1.0, 3.0, 0.25]
    f = trajectory(ch, times)
    s = f[f["event"] == "sample"]
    assert list(s["t"]) == sorted(times)
    row0 = s.iloc[0]
    assert row0["u_1"] == 0.0 and row0["v_3"] == -1.0 and row0["f_contact"] == 0.0
    assert s.iloc[3][["u_1", "u_2", "v_1"]].tolist() == s.iloc[4][["u_1", "u_2", "v_1"]].tolist()
    one = trajectory(ch, [1.0])
    assert one.loc[one["event"] == "sample", "u_2"].iat[0] == s["u_2"].iat[2]


def test_settings_are_checked():
    hertz = dict(masses=[1, 2], springs=[1], contact={"law": "hertz", "k": 5})
    with pytest.raises(SceneError, match="rtol"):
        trajectory(**hertz, times=[1.0], rtol=0.5)
    with pytest.raises(SceneError, match="rtol would do nothing: the method 'piecewise'"):
        trajectory(alpha=2.0, beta=0.1, times=[1.0], rtol=1e-9)
    with pytest.raises(SceneError, match="step"):
        trajectory(alpha=2.0, beta=0.1, contact="plastic", times=[1.0], step=0.01)
    f = trajectory(alpha=2.0, beta=0.1, contact="plastic", times=[1.0], rtol=1e-8)
    assert f.attrs == {"method": "adaptive", "rtol": 1e-8, "scaled": True, "status": "ok"}
    g = trajectory(alpha=2.0, beta=0.1, times=[1.0])
    assert g.attrs["method"] == "piecewise" and math.isnan(g.attrs["rtol"])


# -------------------------------------------------------------------- dimensional histories --
def test_history_in_the_scenes_units_two_equal_masses_at_a_rigid_wall():
    # m, k, v0 in SI: after the first impact m1 oscillates against m2 about the fixed centre of
    # mass, u1 = (v0 / omega) sin(omega t) with omega**2 = 2 k / m, and comes back at -v0 at
    # t = pi / omega: the second and last impact (then both leave at v0)
    m, k, v0 = 0.2, 500.0, 0.3
    r = solve(masses=[m, m], springs=[k], v0=v0, history=True)
    h = r.history
    t2 = math.pi * math.sqrt(m / (2 * k))
    assert h["t_start"].to_numpy() == pytest.approx([0.0, t2], abs=1e-12 * t2)
    assert h["t_end"].to_numpy() == pytest.approx([0.0, t2], abs=1e-12 * t2)
    assert h["velocity_in"].to_numpy() == pytest.approx([-v0, -v0], rel=1e-12)
    assert h["velocity_out"].to_numpy() == pytest.approx([v0, v0], rel=1e-12)
    assert h["wall_impulse"].to_numpy() == pytest.approx([2 * m * v0, 2 * m * v0], rel=1e-12)
    assert (h["compression"] == 0).all()
    # the kernel-unit columns stay as they were
    assert h["omega_t_start"].to_numpy() == pytest.approx([0.0, math.pi], abs=1e-12)
    assert list(h["v1_in"]) == pytest.approx([-1.0, -1.0], rel=1e-12)


def test_history_lengths_agree_between_the_exact_and_the_adaptive_method():
    # the exact kernels record x_max in V0/omega, the stepping kernels in (speed unit)/omega:
    # the compression column is the scene's length either way
    kw = dict(masses=[1.0, 0.5], springs=[0.3], k_contact=50.0, v0=2.0, history=True)
    exact = solve(**kw).history
    adaptive = solve(**kw, method="adaptive").history
    assert exact["compression"].to_numpy() == pytest.approx(
        adaptive["compression"].to_numpy(), rel=1e-7
    )
    assert exact["t_end"].to_numpy() == pytest.approx(adaptive["t_end"].to_numpy(), rel=1e-7)
    # one contact: the linear spring against m1 at v0 = 2 compresses by about v0 / sqrt(k/m1)
    assert exact["compression"].iat[0] == pytest.approx(2.0 / math.sqrt(50.0), rel=0.05)


def test_a_time_far_beyond_the_last_contact_is_refused_by_name():
    # the free flight of three masses is integrated on after the last contact, within the work
    # budget: 1e7 periods are beyond it
    with pytest.raises(SceneError, match="times: the free flight after the last contact"):
        trajectory(**HERTZ3, times=[1.0, 1e8])
    # two masses with a linear link fly free in closed form: any time
    f = trajectory(**HERTZ2, times=[1e8])
    assert np.isfinite(f[["u_1", "u_2", "v_1", "v_2"]].to_numpy()).all()
