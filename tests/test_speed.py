"""Fig. 9: the COR against the impact speed with Hertz contact (restitution.analysis.speed) and the
workflow scripts that draw it, checked against closed forms and independent solvers.

- The Hertz time scale and the free modes against their closed forms (quadrature; the uniform
  chain's sine spectrum).
- Rigid-wall limit: the COR at large V0 (the adaptive integrator on the Hertz law) extrapolated
  to omega t_c = 0 (Richardson, through a quadratic in omega t_c) against the exact impulsive
  solution of the same chain at a rigid wall. The tolerance is Richardson's own error estimate
  (the change from the linear to the quadratic extrapolation) plus the extrapolation's
  amplification of the rows' error estimates.
- Soft limit: the leading-order envelope bounds 1 - COR up to corrections of relative order 1/q
  (the structure's compliance shifts the pulse), and a single mode reaches it.
- Count changes: every bracket holds a change of the contact count, checked by fresh solves of
  its ends, and the counts at the two ends of the V0 range are the soft (one contact) and the
  rigid-wall ones.
- The caption's numbers are those of the tables; only ok rows are drawn.
"""

import logging
import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import quad

import restitution
from conftest import load_script
from restitution import Chain, plotting
from restitution.analysis import speed

LOG = logging.getLogger("test_speed")
RTOL = 1e-12  # the integrator's tolerance of Fig. 9 (config fig9.rtol)


def _paper(alpha, n=2):
    ch = Chain.paper(alpha, n_masses=n)
    return ch.masses.tolist(), ch.springs.tolist()


# --- closed forms ---------------------------------------------------------------------------
def test_hertz_time_scale_and_contact_time_against_quadrature():
    i_quad, err = quad(lambda s: 1.0 / math.sqrt(1.0 - s**2.5), 0.0, 1.0, limit=200)
    assert err < 1e-10 and speed.HERTZ_I == pytest.approx(i_quad, rel=1e-10)
    for m, k, v in [(1.0, 1.0, 1.0), (3.5, 50.0, 1e-4), (0.2, 1e3, 1e5)]:
        x_max = (5.0 * m * v**2 / (4.0 * k)) ** 0.4  # m v^2/2 = (2/5) k x_max^(5/2)
        assert speed.hertz_time_scale(m, k, v) == pytest.approx(x_max / v, rel=1e-14)
        assert speed.hertz_contact_time(m, k, v) == pytest.approx(
            2.0 * i_quad * x_max / v, rel=1e-10
        )


@pytest.mark.parametrize("n", [2, 4, 8])
def test_free_modes_of_the_uniform_chain(n):
    """Free-free chain of n masses m and springs k: omega_j = 2 sqrt(k/m) sin(j pi / 2n) and
    phi_j(1)^2 = (2 / (n m)) cos(j pi / 2n)^2, j = 1..n-1."""
    m, k = 1.7, 0.3
    omega, weight = speed.free_modes([m] * n, [k] * (n - 1))
    j = np.arange(1, n)
    np.testing.assert_allclose(omega, 2 * math.sqrt(k / m) * np.sin(j * np.pi / (2 * n)),
                               rtol=1e-12)  # fmt: skip
    np.testing.assert_allclose(weight, 2 / (n * m) * np.cos(j * np.pi / (2 * n)) ** 2,
                               rtol=1e-10)  # fmt: skip


# --- rigid-wall limit -----------------------------------------------------------------------
# The COR depends on V0 through k_h^2 V0 alone, so raising k_h at the largest V0 the solvers
# take (1e6) reaches omega t_c below the figure's grid: t_c falls by 10^0.4 per decade of k_h.
K_HERTZ = (1e2, 1e3, 1e4)
RIGID_CASES = {"alpha = 0.5 (one contact)": (0.5, 2), "alpha = 2": (2.0, 2),
               "alpha = 5": (5.0, 2), "N = 4": (1.0, 4)}  # fmt: skip


@pytest.mark.parametrize("case", sorted(RIGID_CASES))
def test_large_speeds_extrapolate_to_the_rigid_wall(case):
    masses, springs = _paper(*RIGID_CASES[case])
    rigid = restitution.solve(Chain(masses, springs))
    assert rigid.method == "impulsive" and rigid.status == "ok"
    rows = [restitution.solve(Chain(masses, springs, contact={"law": "hertz", "k": k}, v0=1e6),
                              rtol=RTOL) for k in K_HERTZ]  # fmt: skip
    assert all(r.status == "ok" and np.isfinite(r.error_estimate) for r in rows)
    assert all(r.n_collisions == rigid.n_collisions for r in rows)
    tau = np.array([speed.hertz_contact_time(sum(masses), k, 1e6) for k in K_HERTZ])  # omega = 1
    cor = np.array([r.cor for r in rows])
    error = max(r.error_estimate for r in rows)
    # Lagrange weights at tau = 0 of the quadratic and of the line through the two smallest tau.
    quad_w = np.linalg.solve(np.vander(tau, 3, increasing=True).T, [1.0, 0.0, 0.0])
    line_w = np.linalg.solve(np.vander(tau[1:], 2, increasing=True).T, [1.0, 0.0])
    extrapolated, linear = quad_w @ cor, line_w @ cor[1:]
    tolerance = abs(extrapolated - linear) + np.abs(quad_w).sum() * error
    assert abs(extrapolated - rigid.cor) <= tolerance, (extrapolated, rigid.cor, tolerance)
    # And not trivially: the COR at these speeds is still visibly off the rigid wall's.
    assert abs(cor[0] - rigid.cor) > 10 * tolerance


def test_single_contact_approaches_the_rigid_wall_at_second_order():
    """One contact (alpha = 0.5 < alpha*_1): COR - COR_rigid ~ c (omega t_c)^2, the first order
    vanishing; (COR - COR_rigid)/(omega t_c)^2 agrees over a decade of t_c to the next order."""
    masses, springs = _paper(0.5)
    rigid = restitution.solve(Chain(masses, springs)).cor
    assert rigid == pytest.approx(1 / 3, abs=1e-14)  # (1 - alpha)/(1 + alpha)
    rows = [restitution.solve(Chain(masses, springs, contact={"law": "hertz", "k": k}, v0=1e6),
                              rtol=RTOL) for k in (1.0, *K_HERTZ)]  # fmt: skip
    tau = np.array([speed.hertz_contact_time(1.5, k, 1e6) for k in (1.0, *K_HERTZ)])
    scaled = np.array([(r.cor - rigid) for r in rows]) / tau**2
    # Next order ~ tau: the spread of the ratio over tau in [0.006, 0.24] stays within tau_max.
    assert np.ptp(scaled) <= tau.max() * abs(scaled).max(), scaled


# --- soft limit -----------------------------------------------------------------------------
SOFT_GRID = np.geomspace(1e-6, 1e-3, 61)
# Hertz constants of the soft sweeps: the chains' slowest modes are slower (omega_1 = 0.54 at
# N = 4, 0.28 at N = 8), so a softer contact keeps q_1 = omega_1 T >= 10 over the grid.
SOFT_CASES = {"alpha = 0.5": (0.5, 2, 1.0), "alpha = 2.2": (2.2, 2, 1.0),
              "N = 4": (1.0, 4, 0.01), "N = 8": (1.0, 8, 0.01)}  # fmt: skip


@pytest.fixture(scope="module")
def soft_sweeps():
    out = {}
    for name, (alpha, n, k_hertz) in SOFT_CASES.items():
        m, k = _paper(alpha, n)
        sweep = speed.cor_against_speed(m, k, k_hertz, SOFT_GRID, refine_steps=0, rtol=RTOL)
        out[name] = (m, k, k_hertz, sweep)
    return out


@pytest.mark.parametrize("name", ["alpha = 0.5", "alpha = 2.2", "N = 4", "N = 8"])
def test_soft_limit_envelope_bounds_the_loss(soft_sweeps, name):
    """1 - COR <= (1 + 1/q) envelope + error estimate where q = omega_1 T >= 10: the envelope is
    the leading order; the structure's compliance corrects the pulse at relative order 1/q. And
    COR <= 1 + error estimate everywhere (undamped: no energy is made)."""
    masses, springs, k_hertz, sweep = soft_sweeps[name]
    t = sweep.table
    assert (t["status"] == "ok").all()
    finite = t[np.isfinite(t["error_estimate"])]
    assert len(finite) >= 0.9 * len(t)
    omega, _ = speed.free_modes(masses, springs)
    v0 = finite["v0"].to_numpy()
    q = omega[0] * speed.hertz_time_scale(sum(masses), k_hertz, v0)
    envelope = speed.soft_limit_envelope(masses, springs, k_hertz, v0)
    loss, error = 1.0 - finite["cor"].to_numpy(), finite["error_estimate"].to_numpy()
    assert np.all(loss >= -error)
    soft = q >= 10.0
    assert soft.sum() >= 20
    assert np.all(loss[soft] <= (1.0 + 1.0 / q[soft]) * envelope[soft] + error[soft])
    # The smallest speed is deep in the soft limit: the COR is 1 to within the envelope there.
    assert 1.0 - t["cor"].iloc[0] <= 2.0 * envelope[0] + error[0]


@pytest.mark.parametrize("name", ["alpha = 0.5", "alpha = 2.2"])
def test_soft_limit_envelope_is_reached_by_one_mode(soft_sweeps, name):
    """Two masses have one mode: 1 - COR follows (envelope) cos^2(q I - 5 pi/4) up to O(1/q) in
    the phase, so over every two oscillations of the cosine (Delta q = 2 pi / I) it reaches the
    envelope to within the grid's sampling of the peak and the 1/q corrections: 20 points a
    decade of V0 step the phase q I by at most 0.7 rad at q <= 20, so a sampled peak is at least
    cos(0.35)^2 = 0.88 of the envelope, less O(1/q)."""
    masses, springs, k_hertz, sweep = soft_sweeps[name]
    t = sweep.table
    v0 = t["v0"].to_numpy()
    q = speed.free_modes(masses, springs)[0][0] * speed.hertz_time_scale(sum(masses), k_hertz, v0)
    ratio = (1.0 - t["cor"].to_numpy()) / speed.soft_limit_envelope(masses, springs, k_hertz, v0)
    edges = np.arange(q.min(), q.max() - 2 * math.pi / speed.HERTZ_I, 2 * math.pi / speed.HERTZ_I)
    assert len(edges) >= 3
    for lo in edges:
        window = (q >= lo) & (q < lo + 2 * math.pi / speed.HERTZ_I)
        assert ratio[window].max() >= 0.8, (lo, ratio[window].max())


# --- count changes --------------------------------------------------------------------------
@pytest.mark.parametrize("alpha, n", [(2.2, 2), (5.0, 2), (1.0, 4)])
def test_count_change_speeds_bracket_a_change(alpha, n):
    masses, springs = _paper(alpha, n)
    grid = np.geomspace(1e-6, 1e6, 97)
    sweep = speed.cor_against_speed(masses, springs, 1.0, grid, refine_steps=30, rtol=RTOL)
    t, ch = sweep.table, sweep.changes
    assert len(ch) >= 1 and ch["resolved"].all()
    assert (ch["width"] <= 0.125 * 2.0**-30 * 1.001).all()  # 12 decades / 96 steps, halved 30 times
    for c in ch.itertuples():
        hertz = {"law": "hertz", "k": 1.0}
        ends = [restitution.solve(Chain(masses, springs, contact=hertz, v0=float(v)), rtol=RTOL)
                for v in (c.v0_lo, c.v0_hi)]  # fmt: skip
        assert [e.n_collisions for e in ends] == [c.n_lo, c.n_hi] and c.n_lo != c.n_hi
        # The COR is continuous where a contact grazes or splits (a kink, not a jump): across
        # the bracket it moves by at most its steeper one-sided slope times the bracket's width
        # (measured 1e-6 outside each end; at rtol 1e-12 the estimates are ~3e-12, below the
        # slope's share over 2.3e-11 decades), plus the two ends' error estimates.
        h = 1e-6
        out = [restitution.solve(Chain(masses, springs, contact=hertz, v0=float(v)), rtol=RTOL)
               for v in (c.v0_lo * math.exp(-h), c.v0_hi * math.exp(h))]  # fmt: skip
        slope = max(abs(ends[0].cor - out[0].cor), abs(out[1].cor - ends[1].cor)) / h
        slope += sum(r.error_estimate for r in ends + out) / h
        drift = slope * math.log(c.v0_hi / c.v0_lo)
        err = ends[0].error_estimate + ends[1].error_estimate
        assert abs(ends[1].cor - ends[0].cor) <= err + drift, (ends, drift)
        # Inside one interval of the grid (where the grid's counts differ).
        i = np.searchsorted(grid, c.v0_lo, side="right") - 1
        assert grid[i] <= c.v0_lo < c.v0_hi <= grid[i + 1]
    ok = t[t["status"] == "ok"]
    # Soft end: one long contact; rigid end: the rigid wall's contact sequence.
    assert ok["n_collisions"].iloc[0] == 1
    assert ok["n_collisions"].iloc[-1] == sweep.rigid["n_collisions"]


def test_sweep_refuses_scenes_outside_the_solvers_ranges():
    with pytest.raises(restitution.SceneError, match="slope at m1's depth"):
        speed.cor_against_speed([1.0, 1.0], [0.5], 1e-6, [1e-6, 1.0])
    with pytest.raises(ValueError, match="increasing grid"):
        speed.cor_against_speed([1.0, 1.0], [0.5], 1.0, [1.0, 1e-3])


# --- the workflow scripts: tables, figure, caption ---------------------------------------------
simulate_fig9 = load_script("simulate_fig9")
render_fig9 = load_script("render_fig9")
SMALL = {"k_hertz": 1.0, "v0_min": 1e-6, "v0_max": 1e6, "n_v0": 49, "refine_steps": 20,
         "rtol": RTOL, "alphas": [0.5, 2.2], "chain_alpha": 1.0, "chain_n": [4]}  # fmt: skip


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    out = tmp_path_factory.mktemp("fig9")
    paths = {name: out / f"{name}.parquet" for name in ("table", "limits", "changes")}
    params = SimpleNamespace(fig9=SMALL, max_events=100_000)
    return simulate_fig9.main(params, paths, LOG)


def test_tables_keep_every_row_with_its_status_and_method(tables):
    t = tables["table"]
    assert set(t["curve"]) == {"alpha = 0.5", "alpha = 2.2", "N = 4"}
    for column in ("status", "method", "error_estimate", "refined", "q", "soft_envelope"):
        assert column in t
    assert (t.groupby("curve")["refined"].apply(lambda r: (~r).sum()) == SMALL["n_v0"]).all()
    limits = tables["limits"].set_index("curve")
    assert limits.loc["alpha = 0.5", "rigid_cor"] == pytest.approx(1 / 3, abs=1e-14)
    assert limits.loc["N = 4", "omega_1"] == pytest.approx(2 * math.sqrt(0.5) * math.sin(
        math.pi / 8), rel=1e-12)  # fmt: skip


def test_caption_numbers_equal_the_data(tables):
    t, limits, changes = tables["table"], tables["limits"], tables["changes"]
    data = render_fig9.caption_data(t, limits, changes)
    assert data["n_rows"] == len(t) and data["n_changes"] == len(changes)
    assert data["n_refined"] == int(t["refined"].sum())
    assert data["n_not_ok"] == int((t["status"] != "ok").sum())
    ok = t[t["status"] == "ok"]
    assert np.isfinite(ok["error_estimate"]).all()  # (a row without an estimate is not ok)
    assert data["change_min"] == f"{changes['v0'].min():.3g}"
    assert data["change_max"] == f"{changes['v0'].max():.3g}"
    for c in changes.itertuples():
        assert f"{c.v0:.4g} ({c.n_lo} to {c.n_hi})" in data["changes"]
    for r in limits.itertuples():
        rows = ok[ok["curve"] == r.curve].sort_values("v0")
        top, below = rows.iloc[-1], rows[rows["v0"] <= rows["v0"].max() / 10 * (1 + 1e-9)].iloc[-1]
        p = math.log(abs(below["cor"] - r.rigid_cor) / abs(top["cor"] - r.rigid_cor)) / math.log(
            below["omega_tc"] / top["omega_tc"])  # fmt: skip
        assert f"{r.curve}: {r.rigid_cor:.4g} ({r.rigid_n_collisions} contact" in data["rigid"]
        assert f"p = {p:.2f}" in data["rigid"].split(f"{r.curve}:")[1].split(". ")[0]
    soft = ok[(ok["q"] >= 10.0) & np.isfinite(ok["error_estimate"])]
    ratio = ((1.0 - soft["cor"] - soft["error_estimate"]) / soft["soft_envelope"]).max()
    assert data["soft_ratio"] == f"{ratio:.3f}"


def test_caption_template_renders_with_the_data(tables):
    from pathlib import Path

    from render_caption import render

    t, limits, changes = tables["table"], tables["limits"], tables["changes"]
    data = render_fig9.caption_data(t, limits, changes)
    template = (Path(__file__).resolve().parents[1] / "workflow/report/fig9.rst").read_text()
    text = render(template, {"max_events": 100_000}, SimpleNamespace(fig9=SMALL), data, {})
    assert text.startswith("**Fig. 9")
    assert f"{data['n_rows']} rows" in text and data["changes"] in text


def test_figure_draws_only_ok_rows_and_keeps_the_house_rules(tables):
    t = tables["table"].copy()
    # One row fails: it is not drawn and the caption counts it.
    bad = t.index[(t["curve"] == "alpha = 2.2") & ~t["refined"]][10]
    t.loc[bad, ["status", "cor"]] = ["event_budget_exhausted", np.nan]
    fig = render_fig9.draw(t, tables["limits"], tables["changes"], LOG)
    assert plotting.audit_figure(fig) == []
    ax = fig.axes[0]
    line = [ln for ln in ax.lines if ln.get_label() == r"$\alpha = 2.2$"][0]
    assert t.loc[bad, "v0"] not in set(line.get_xdata())
    drawn = (t["curve"] == "alpha = 2.2") & (t["status"] == "ok")
    assert len(line.get_xdata()) == int(drawn.sum())
    data = render_fig9.caption_data(t, tables["limits"], tables["changes"])
    assert data["n_not_ok"] == 1 and "event_budget_exhausted: 1" in data["not_ok_statuses"]


def test_config_check_refuses_a_hertz_range_the_solvers_do_not_take():
    import copy

    import yaml

    from conftest import REPO
    from restitution_workflow.config_check import ConfigError, check_config

    schema = yaml.safe_load((REPO / "workflow/schemas/config.schema.yaml").read_text())
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    bad = copy.deepcopy(config)
    bad["fig9"]["k_hertz"] = 1e-6
    with pytest.raises(ConfigError) as info:
        check_config(bad, schema)
    assert any("fig9.k_hertz = 1e-06 with fig9.v0_min = 1e-06" in p and "slope at m1's depth" in p
               for p in info.value.problems), info.value.problems  # fmt: skip
    bad = copy.deepcopy(config)
    bad["fig9"]["v0_min"], bad["fig9"]["v0_max"] = 10.0, 1.0
    with pytest.raises(ConfigError) as info:
        check_config(bad, schema)
    assert any("fig9.v0_max = 1.0: must be greater than fig9.v0_min = 10.0" in p
               for p in info.value.problems), info.value.problems  # fmt: skip
