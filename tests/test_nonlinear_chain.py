"""General nonlinear chains against an independent reference written here (scipy solve_ivp).

The reference integrates every phase with DOP853 at rtol 1e-12 in the user's units (no scaling),
with the contact laws written out below (linear, Hertz, Hunt-Crossley, the paper's plastic law
with its dent) and terminal events that switch them (the Kelvin-Voigt contact, which ends off
the surface, has its own reference in test_kelvin_voigt.py); the gap's minima are events too,
so a contact shallower than one step is not stepped over. Only the scissor link's curve is taken
from ``laws`` (it is checked against Eq. 24 in test_laws.py). The sequence ends when the centre
of mass recedes and the internal energy cannot bring m1 back (energy bound written here).
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import restitution
from conftest import solve_general_law as solve_nonlinear_chain
from conftest import solve_general_many as solve_nonlinear_chain_many
from restitution.model import laws
from restitution.model.ranges import SceneError
from restitution.solvers.methods import choose

RTOL_REF = 1e-12
# laws without memory (their contacts rise and fall; Hunt-Crossley's force also depends on x')
ELASTIC_REF = ("linear", "hertz", "hunt_crossley")


def _link_models(k, links):
    """Force and energy functions of each link (user units)."""
    out = []
    for i, spec in enumerate(links or ["linear"] * len(k)):
        if spec == "linear" or spec.get("law") == "linear":
            out.append((lambda r, ki=k[i]: ki * r, lambda r, ki=k[i]: 0.5 * ki * r * r))
        else:
            sp = laws.scissor_params(
                k[i], spec["ks"], spec["L"], spec.get("theta0", math.pi / 4), spec.get("corner", 1)
            )
            out.append(
                (
                    lambda r, sp=sp: laws.structure_force(sp, r),
                    lambda r, sp=sp: laws.structure_energy(sp, r),
                )
            )
    return out


def reference(m, k, c, contact, links, v0, max_contacts=500, rtol=RTOL_REF):
    """(cor, n_contacts, t_col) of a chain, by solve_ivp (see the module docstring)."""
    m = np.asarray(m, float)
    n = m.size
    c = np.zeros(n - 1) if c is None else np.asarray(c, float)
    mt = m.sum()
    lm = _link_models(k, links)
    law = contact["law"]
    st = dict(phase="contact", branch="load", xmax=0.0, fmax=0.0, xp=0.0)
    if law == "plastic":
        k1, eta, dr = contact["k"], contact["eta"], contact["dr"]
        fmax = v0 * math.sqrt((1 - dr) * k1 * m[0])  # m1 alone at v0 returns (1 - DR)
        xm = (eta + 1) * m[0] * v0 * v0 / (2 * fmax)
        kappa = fmax / xm**eta

    def wall_force(x, xd):
        if st["phase"] != "contact" or law == "rigid":
            return 0.0
        if law == "linear":
            return contact["k"] * x
        if law == "hertz":
            return contact["k"] * max(x, 0.0) ** 1.5
        if law == "hunt_crossley":
            n_hc = contact.get("n", 1.5)
            return contact["k"] * max(x, 0.0) ** n_hc * (1.0 + 1.5 * contact["alpha"] * xd)
        if st["branch"] == "load":
            return kappa * max(x, 0.0) ** eta
        return st["fmax"] - k1 * (st["xmax"] - x)

    def rhs(t, y):
        u, v = y[:n], y[n:]
        a = np.zeros(n)
        a[0] = wall_force(-u[0], -v[0])
        for i in range(n - 1):
            f = lm[i][0](u[i + 1] - u[i]) + c[i] * (v[i + 1] - v[i])
            a[i] += f
            a[i + 1] -= f
        return np.concatenate([v, a / m])

    def proof(y):
        u, v = y[:n], y[n:]
        p = m @ v
        if p <= 0:
            return False
        e = 0.5 * m @ (v * v) - 0.5 * p * p / mt
        e += sum(lm[i][1](u[i + 1] - u[i]) for i in range(n - 1))
        bound = 0.0
        for i in range(n - 1):
            mu = m[i + 1 :].sum() / mt
            r = 1.0
            while lm[i][1](r) < e:
                r *= 2
            bound += mu * r  # |r_i| <= r: U_i(r_i) <= e, U_i increasing for r > 0
        return (m @ u) / mt + st["xp"] - bound > 0

    def ev(fun, terminal=True, direction=-1):
        fun.terminal, fun.direction = terminal, direction
        return fun

    w_max = math.sqrt(max(4 * max(k) / m.min(), 1e-300))
    if law in ("linear", "plastic"):
        w_max = math.sqrt(w_max**2 + contact["k"] / m[0])
    max_step = 2 * math.pi / w_max / 40
    y = np.concatenate([np.zeros(n), np.full(n, -v0)])
    t, tcol, ncol = 0.0, 0.0, 1
    ysep = y.copy()
    if law == "rigid":
        y[n] = -y[n]
        ysep = y.copy()
        st["phase"] = "free"
    elif law == "plastic":
        st["branch"] = "load"
    while True:
        if st["phase"] == "contact":
            if st["branch"] == "load" or law in ELASTIC_REF and st["branch"] == "rise":
                events = [ev(lambda t, y: -y[n])]  # turn: x' = -v1 falls to 0
            else:
                xp, xm = st["xp"], st["xmax"]
                events = [
                    ev(lambda t, y, xp=xp: -y[0] - xp),  # separation
                    ev(lambda t, y, xm=xm: -y[0] - xm, True, 1)
                    if law == "plastic"
                    else ev(lambda t, y: y[n]),  # reload past xmax / rising again
                    ev(lambda t, y: -y[n], False, 1),  # minima of x: a missed separation
                ]
            sol = solve_ivp(
                rhs, (t, t + 1e4), y, "DOP853", rtol=rtol, atol=rtol * v0,
                events=events, max_step=max_step, dense_output=True,
            )  # fmt: skip
            hits = [(te[0], j) for j, te in enumerate(sol.t_events[:2]) if len(te)]
            assert hits, "contact phase without an end"
            te, j = min(hits)
            ye = sol.sol(te)
            if len(events) == 3:
                # x dipped below the dent between steps (for elastic laws the rise event is that
                # minimum): that was the separation, at the root before the minimum
                lows = [s for s in sol.t_events[2] if s <= te and -sol.sol(s)[0] < st["xp"]]
                if j == 1 and law in ELASTIC_REF and -ye[0] < st["xp"]:
                    lows = [te]
                if lows:
                    t0 = sol.t[0]
                    f = sol.sol
                    te = brentq(lambda s, f=f: -f(s)[0] - st["xp"], t0, lows[0], xtol=1e-15)
                    ye, j = sol.sol(te), 0
            t, y = te, ye.copy()
            if st["branch"] in ("load", "rise"):
                y[n] = 0.0
                if law == "plastic" and -y[0] >= st["xmax"]:
                    st["xmax"] = -y[0]
                    st["fmax"] = kappa * st["xmax"] ** eta
                    st["xp"] = st["xmax"] - st["fmax"] / k1
                st["branch"] = "fall"
            elif j == 1:
                if law == "plastic":
                    y[0] = -st["xmax"]
                    st["branch"] = "load"
                else:
                    y[n] = 0.0
                    st["branch"] = "rise"
            else:
                y[0] = -st["xp"]
                st["phase"] = "free"
                tcol, ysep = t, y.copy()
        else:
            xp = st["xp"]
            sol = solve_ivp(
                rhs, (t, t + 20 * max_step * 40), y, "DOP853", rtol=rtol,
                atol=rtol * v0, max_step=max_step, dense_output=True,
                events=[ev(lambda t, y, xp=xp: y[0] + xp), ev(lambda t, y: y[n], False, 1)],
            )  # fmt: skip
            hit = sol.t_events[0]
            end = hit[0] if len(hit) else sol.t[-1]
            below = [s for s in sol.t_events[1] if s < end and sol.sol(s)[0] + xp < 0]
            if below:
                lows = list(sol.t_events[1])
                kk = lows.index(below[0])
                start = lows[kk - 1] if kk > 0 else sol.t[0]
                ts = np.linspace(start, below[0], 65)
                g = [sol.sol(s)[0] + xp for s in ts]
                i0 = next(i for i in range(64) if g[i] >= 0 > g[i + 1])
                f = sol.sol
                end = brentq(lambda s, f=f, xp=xp: f(s)[0] + xp, ts[i0], ts[i0 + 1], xtol=1e-15)
            elif not len(hit):
                t, y = sol.t[-1], sol.y[:, -1].copy()
                if proof(y):
                    break
                continue
            t, y = end, sol.sol(end).copy()
            y[0] = -xp
            ncol += 1
            assert ncol <= max_contacts
            if law == "rigid":
                y[n] = -y[n]
                tcol, ysep = t, y.copy()
            else:
                st["phase"] = "contact"
                elastic = law in ELASTIC_REF or st["fmax"] == 0.0
                st["branch"] = "load" if elastic else "fall"
                if law in ELASTIC_REF:
                    st["branch"] = "rise"
    return (m @ ysep[n:]) / (mt * v0), ncol, tcol


def _omega(m, k):
    return math.sqrt(k[0] / m[0] + k[0] / m[1])


def _random_chain(rng, n):
    m = rng.uniform(0.3, 3.0, n)
    k = rng.uniform(0.3, 3.0, n - 1)
    c = rng.uniform(0.0, 0.05, n - 1) * (rng.random(n - 1) < 0.5)
    return m, k, c


CONTACTS = [
    {"law": "hertz", "k": 20.0},
    {"law": "plastic", "k": 30.0, "eta": 1.5, "dr": 0.3},
    {"law": "plastic", "k": 10.0, "eta": 0.5, "dr": 0.4},
    {"law": "hertz", "k": 3.0},
    {"law": "linear", "k": 8.0},
    # alpha below its bound 1/(1.5 v0 sqrt(M/m1)) for every drawn chain (M/m1 <= 50, v0 <= 2)
    {"law": "hunt_crossley", "k": 20.0, "alpha": 0.04},
    {"law": "hunt_crossley", "k": 10.0, "n": 1.0, "alpha": 0.03},
]
CASES = [(n, i) for n in (2, 3, 4, 5) for i in range(len(CONTACTS))]


@pytest.mark.parametrize("n, which", CASES)
def test_random_chains_agree_with_solve_ivp(n, which):
    rng = np.random.default_rng(1000 * n + which)
    m, k, c = _random_chain(rng, n)
    contact = CONTACTS[which]
    v0 = float(rng.uniform(0.5, 2.0))
    r = solve_nonlinear_chain(m, k, c, contact, None, v0, rtol=1e-12)
    # the reference at scipy's tightest rtol: at 1e-12 it was 1.0e-9 off in t_col on one
    # five-mass Hunt-Crossley chain and 1.2e-11 off in the COR of the two-mass Hertz chain (2, 0)
    # against mpmath (benchmarks/mp_nonlinear.py), where the kernel's result (then its rtol/10 run)
    # was 1.4e-14 off with an estimate of 1.1e-12; at 1e-13 it was 9.1e-12 off on (3, 6), where
    # at 2.5e-14 it met the kernel's runs at rtol 1e-11..1e-14 (which agree to 8e-15) to 5e-14
    cor, ncol, tcol = reference(m, k, c, contact, None, v0, rtol=2.5e-14)
    assert r.status == "ok"
    assert r.n_collisions == ncol
    # the adaptive kernel at rtol 1e-12 against DOP853 at rtol 1e-12: measured at most 8e-11
    # (COR) and 4e-11 (relative t_col) over these 20 chains; the error estimate 1e-10..7e-10
    assert abs(r.cor - cor) < 1e-9, (r.cor, cor)
    assert abs(r.omega_t_col / _omega(m, k) - tcol) < 1e-9 * max(1.0, tcol)
    assert abs(r.cor - cor) <= 10 * r.error_estimate and r.error_estimate < 1e-8


SCISSOR = {"law": "scissor", "L": 1.0, "ks": 0.004}


@pytest.mark.parametrize(
    "contact", [{"law": "rigid"}, {"law": "hertz", "k": 10.0}, {"law": "plastic", "k": 5.0,
                                                                 "eta": 1.0, "dr": 0.3}]
)  # fmt: skip
def test_chain_with_a_scissor_link_agrees_with_solve_ivp(contact):
    m, k = [1.0, 1.5, 0.8], [0.6, 1.0]
    links = [dict(SCISSOR, ks=0.01 * k[0]), "linear"]
    r = solve_nonlinear_chain(m, k, [0.0, 0.02], contact, links, 1.3, rtol=1e-12)
    cor, ncol, tcol = reference(m, k, [0.0, 0.02], contact, links, 1.3)
    assert r.status == "ok" and r.n_collisions == ncol
    assert abs(r.cor - cor) < 1e-8, (r.cor, cor)
    assert abs(r.omega_t_col / _omega(m, k) - tcol) < 1e-7 * max(1.0, tcol)


@pytest.mark.parametrize(
    "scene",
    [
        dict(alpha=2.0, beta=0.1, contact="plastic", eta=0.5, dr=0.5),
        dict(alpha=3.0, beta=0.1, eta=2.0, dr=0.2, xi=0.05, contact="plastic"),
        dict(alpha=2.0, beta=1.0, L=2.0, structure="scissor", ks_ratio=0.01),
    ],
)
def test_two_masses_in_the_general_form_are_the_paper_form(scene):
    # the paper form with laws (restitution.solve(alpha, ..., contact=...)) and the same scene
    # written as a general chain give the same result (one stack; k rounds differently)
    alpha, beta, xi = scene["alpha"], scene["beta"], scene.get("xi", 0.0)
    k2 = alpha / (1 + alpha)
    contact = {"law": "linear", "k": k2 / beta}
    if scene.get("contact") == "plastic":
        contact = {"law": "plastic", "k": k2 / beta, "eta": scene["eta"], "dr": scene["dr"]}
    links = None
    if scene.get("structure") == "scissor":
        links = [{"law": "scissor", "L": scene["L"], "ks": scene["ks_ratio"] * k2}]
    r = solve_nonlinear_chain([1.0, alpha], [k2], [2 * xi * k2], contact, links, 1.0, rtol=1e-11)
    q = restitution.solve(**scene, rtol=1e-11, method="adaptive")
    assert r.status == q.status == "ok" and r.n_collisions == q.n_collisions
    assert abs(r.cor - q.cor) < 1e-8
    assert abs(r.omega_t_col - q.omega_t_col) < 1e-7


def test_verlet_chain_converges_to_the_adaptive_result():
    args = ([1.0, 0.8, 1.2], [1.0, 0.7], [0.0, 0.0], {"law": "hertz", "k": 15.0}, None, 1.0)
    a = solve_nonlinear_chain(*args, rtol=1e-11)
    errs = []
    for step in (0.01, 0.005, 0.0025):
        v = solve_nonlinear_chain(*args, method="verlet", step=step)
        assert v.method == "verlet" and v.n_collisions == a.n_collisions
        errs.append(abs(v.cor - a.cor))
    assert errs[-1] < errs[0] and errs[-1] < 1e-4


def test_batch_matches_single_rows_and_names_a_bad_row():
    rng = np.random.default_rng(7)
    chains = [_random_chain(rng, n) for n in (2, 3, 5, 4)]
    contacts = [CONTACTS[0], CONTACTS[1], CONTACTS[2], {"law": "rigid"}]
    links = [None, None, None, ["linear", dict(SCISSOR, ks=0.001), "linear"]]
    df = solve_nonlinear_chain_many(
        [ch[0] for ch in chains], [ch[1] for ch in chains], [ch[2] for ch in chains], contacts,
        links, 1.0, rtol=1e-10,
    )  # fmt: skip
    for i, (m, k, c) in enumerate(chains):
        r = solve_nonlinear_chain(m, k, c, contacts[i], links[i], 1.0, rtol=1e-10)
        assert df["cor"][i] == r.cor and df["n_collisions"][i] == r.n_collisions
        assert df["status"][i] == r.status == "ok"
        assert df["t_col"][i] == pytest.approx(r.omega_t_col / _omega(m, k), rel=1e-15)
    bad = [ch[1] for ch in chains]
    bad[2] = [1.0, -1.0, 1.0, 1.0]
    with pytest.raises(SceneError, match=r"springs\[1\].*row 2"):
        solve_nonlinear_chain_many([ch[0] for ch in chains], bad)


BAD = [
    (dict(m=[1.0]), "masses"),
    (dict(m=[1.0, -2.0]), r"masses\[1\]"),
    (dict(m=[1.0, float("nan")]), r"masses\[1\]"),
    (dict(k=[1.0, 2.0]), "springs must have 1"),
    (dict(k=[0.0]), r"springs\[0\]"),
    (dict(c=[-0.1]), r"dashpots\[0\]"),
    (dict(contact_law={"law": "hertz"}), "needs k"),
    (dict(contact_law={"law": "hertz", "k": -1.0}), "contact.k"),
    (dict(contact_law={"law": "hertz", "k": 1.0, "eta": 2}), "unknown parameter"),
    (dict(contact_law={"law": "elastic"}), "contact law must be one of"),
    (dict(contact_law={"law": "kelvin_voigt", "k": 1.0}), "needs c"),
    (dict(contact_law={"law": "kelvin_voigt", "k": 1.0, "c": -1.0}), "contact.c"),
    (dict(contact_law={"law": "kelvin_voigt", "k": 1.0, "c": 1e4}), "damping ratio"),
    (dict(contact_law={"law": "hunt_crossley", "k": 1.0}), "needs alpha"),
    (dict(contact_law={"law": "hunt_crossley", "k": 1.0, "alpha": 0.1, "n": 11}), "contact.n"),
    (dict(contact_law={"law": "hunt_crossley", "k": 1.0, "alpha": 1.0}), "contact.alpha"),
    (dict(contact_law={"law": "plastic", "k": 1.0, "eta": 0.5, "dr": 0.1}), "dr"),
    (dict(link_laws=[{"law": "scissor", "L": 1.0}]), "needs ks"),
    (dict(link_laws=[{"law": "scissor", "L": 1.0, "ks": 5.0}]), "ks_ratio"),
    (dict(link_laws=["linear", "linear"]), "links must be a list of 1"),
    (dict(v0=0.0), "v0"),
    (dict(method="rk4"), "method"),
    (dict(method="verlet", contact_law="rigid"), "verlet"),
]


@pytest.mark.parametrize("kw, match", BAD)
def test_bad_parameters_name_themselves(kw, match):
    args = dict(m=[1.0, 2.0], k=[1.0], contact_law={"law": "hertz", "k": 1.0})
    args.update(kw)
    with pytest.raises(SceneError, match=match):
        solve_nonlinear_chain(**args)


# ---------------------------------------------------------------- declared ranges (issue 17.2) --


def _sane(status, cor, ncol, passive=True, tol=1e-12):
    """A finished row (ok, >= 1 contact, COR in [-tol, 1 + tol] for a passive law) or an
    explicit failure: any other status, with a NaN COR unless only the energy account is open.
    ``tol`` is 1e-12 for the exact methods and the energy tolerance for the numerical ones (a
    COR above 1 by more would open the energy account)."""
    if status == "ok":
        return ncol >= 1 and (not passive or -tol <= cor <= 1 + tol)
    if status == "energy_account_open":
        return np.isfinite(cor)
    return math.isnan(cor)  # (the names of codes 5-8 come with result.py of the chain-api branch)


def _draw_range_end(rng, low, high, log=True):
    """A value of [low, high]: either end exactly, the float next to it, or log-uniform."""
    pick = rng.integers(5)
    if pick == 0:
        return low
    if pick == 1:
        return high
    if pick == 2:
        return float(np.nextafter(low, high))
    if pick == 3:
        return float(np.nextafter(high, low))
    return (
        float(math.exp(rng.uniform(math.log(low), math.log(high))))
        if log
        else rng.uniform(low, high)
    )


def test_full_declared_ranges_finish_or_fail_explicitly():
    # Every parameter over its declared range, ends and their neighbours included (eta down to
    # the smallest subnormal): a row is either rejected before any work (SceneError naming the
    # range), finished and sane, or NaN with a status naming what failed. Never a traceback.
    rng = np.random.default_rng(17)
    masses, springs, dashpots, contacts, speeds = [], [], [], [], []
    rejected = 0
    for _ in range(120):
        n = int(rng.integers(2, 5))
        m = [_draw_range_end(rng, 1e-3, 1e3) for _ in range(n)]
        k = [_draw_range_end(rng, 1e-3, 1e3) for _ in range(n - 1)]
        c = [0.0 if rng.random() < 0.5 else _draw_range_end(rng, 1e-6, 1.0) for _ in range(n - 1)]
        v0 = _draw_range_end(rng, laws.V0_MIN, laws.V0_MAX)
        law = ("hertz", "plastic", "linear")[int(rng.integers(3))]
        if law == "plastic":
            eta = _draw_range_end(rng, 5e-324, 10.0)
            dr_low = max(0.0, (1 - eta) / 2)
            contact = {"law": law, "k": _draw_range_end(rng, 1e-2, 1e6), "eta": eta,
                       "dr": _draw_range_end(rng, max(dr_low, 1e-300), 1 - 1e-6)}  # fmt: skip
        else:
            contact = {"law": law, "k": _draw_range_end(rng, 1e-2, 1e6)}
        try:  # the scene and the method's handled ranges (restitution.solvers.methods)
            choose(restitution.Chain(m, k, c, v0=v0, contact=contact), "adaptive")
        except SceneError as e:
            assert "must be" in str(e)  # names the range it left
            rejected += 1
            continue
        masses.append(m)
        springs.append(k)
        dashpots.append(c)
        contacts.append(contact)
        speeds.append(v0)
    # most draws leave the handled frequency spread (mass and spring ratios up to 1e6)
    assert len(masses) >= 20 and rejected >= 40, rejected
    df = solve_nonlinear_chain_many(
        masses, springs, dashpots, contacts, None, speeds, rtol=1e-8, max_events=2000
    )
    for i, row in df.iterrows():
        passive = not (contacts[i]["law"] == "plastic" and contacts[i]["eta"] > 1)
        # rtol 1e-8: energy tolerance 1e3 * rtol (measured: one stiff Hertz row at 1 + 1.2e-6)
        ok = _sane(row["status"], row["cor"], row["n_collisions"], passive, 1e-5)
        assert ok, (row, contacts[i])
        if row["status"] == "ok":
            assert abs(row["e_translational"] + row["e_vibrational"] + row["e_dissipated"] - 1) < (
                1e-5
            )
        if passive:  # a handled range: every in-range passive row finishes
            assert row["status"] == "ok", (row, contacts[i])


def test_kernel_batch_never_raises_and_never_leaves_a_row_unset():
    # garbage that bypassed the Python checks: the kernel's own guard makes the row invalid
    from restitution.kernels.layout import OUT_COR, OUT_STATUS, STATUS_INVALID, STATUS_OK
    from restitution.kernels.stepping import solve_scene_batch

    rows = 6
    m = np.ones((rows, 3))
    lk = np.zeros((rows, 2, laws.N_SP))
    lk[:, :, laws.SP_K2] = 1.0
    c = np.zeros((rows, 2))
    n = np.full(rows, 3, dtype=np.int64)
    cp = np.tile(laws.hertz_params(10.0, 1.0, 3.0), (rows, 1))
    v0 = np.ones(rows)
    m[1, 2] = np.nan
    lk[2, 0, laws.SP_K2] = 0.0
    v0[3] = np.inf
    n[4] = 7  # more masses than the padded arrays hold
    c[5, 1] = -1.0
    out = solve_scene_batch(m, lk, c, n, cp, v0, 0, 1e-9, 0.01, 1e-6, 100, 1e6)
    assert out[0, OUT_STATUS] == STATUS_OK and 0 < out[0, OUT_COR] <= 1
    for i in range(1, rows):
        assert out[i, OUT_STATUS] == STATUS_INVALID and math.isnan(out[i, OUT_COR])


def test_work_budget_ends_a_scene_honestly():
    # a budget far too small (max_work 300: 600 evaluations per adaptive run, FINER_WORK = 2):
    # a NaN COR and the status that names it, the same on every machine
    r = solve_nonlinear_chain(
        [1.0, 2.0, 1.0], [1.0, 1.0], None, {"law": "hertz", "k": 10.0}, None, 1.0, max_work=300
    )
    from restitution.kernels.layout import STATUS_WORK_BUDGET
    from restitution.solvers.result import status_name

    assert r.status == status_name(STATUS_WORK_BUDGET) and math.isnan(r.cor) and not r.success


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(v0=1e-7), r"v0 .*\[1e-6, 1e6\]"),
        (dict(contact_law={"law": "linear", "k": 1e-12}), r"beta = .*\[0, 1e\+06\]"),
        (dict(contact_law={"law": "hertz", "k": 1e-12}), "slope at m1's depth"),
        (
            dict(contact_law={"law": "plastic", "k": 10.0, "eta": 1.0, "dr": 1 - 1e-16}),
            "loading secant",
        ),
        (dict(m=[1.0, 1e9]), r"masses\[i\]/masses\[0\] must be in \[1e-08, 1e\+08\]"),
    ],
)
def test_unhandled_corners_are_rejected_naming_the_range(kw, match):
    args = dict(m=[1.0, 2.0], k=[1.0], contact_law={"law": "hertz", "k": 1.0})
    args.update(kw)
    with pytest.raises(SceneError, match=match):
        solve_nonlinear_chain(**args)


def test_struct_cells_with_every_laws_fields_are_read():
    # a parquet struct column holds the union of the laws' fields: None/NaN means "not given"
    contact = {"law": "hertz", "k": 4.0, "eta": None, "dr": float("nan")}
    links = [{"law": "linear", "L": None, "ks": None, "theta0": None, "corner": None}]
    r = solve_nonlinear_chain([1.0, 2.0], [1.0], None, contact, links, 1.0)
    q = solve_nonlinear_chain([1.0, 2.0], [1.0], None, {"law": "hertz", "k": 4.0}, None, 1.0)
    assert r.status == "ok" and r.cor == q.cor


def test_batch_is_bit_identical_for_any_thread_count():
    import numba

    rng = np.random.default_rng(11)
    chains = [_random_chain(rng, n) for n in (2, 3, 4, 5, 3, 2)]
    args = ([ch[0] for ch in chains], [ch[1] for ch in chains], [ch[2] for ch in chains])
    contacts = [CONTACTS[i % len(CONTACTS)] for i in range(len(chains))]
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = solve_nonlinear_chain_many(*args, contacts, rtol=1e-9)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = solve_nonlinear_chain_many(*args, contacts, rtol=1e-9)
    finally:
        numba.set_num_threads(before)
    assert one.equals(two)
    for i, (m, k, c) in enumerate(chains):  # and each row is its single solve, bit for bit
        r = solve_nonlinear_chain(m, k, c, contacts[i], None, 1.0, rtol=1e-9)
        assert one["cor"][i] == r.cor and one["error_estimate"][i] == r.error_estimate
