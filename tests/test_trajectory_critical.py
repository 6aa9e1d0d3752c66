"""restitution.trajectory of linear scenes next to critical damping, where a phase's modal basis
degenerates (the exact kernels flag it FLAG_NEAR_DEFECTIVE; tests/test_near_defective.py for the
rows). The exact sampler's samples come from that basis: 2e-8 off on a six-mass chain at its
contact phase's critical damping, and a rigid-wall chain at alpha = 1e8, xi = 1 went through
the wall (u_1 = -100 at t = 100). Such a scene is sampled by the adaptive method at rtol 1e-12
where the numerical ranges allow it, else from the exact sampler's runs with the dashpots
scaled off that point (``+critical-bracket``). References: scipy's DOP853 at rtol 1e-12 phase
by phase, and, for the heavy chains the integrators do not reach, the quadratic through the
exact samples at xi = 1 -+ 1e-3 and 1 -+ 2e-3, where the basis is sound.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import restitution
from restitution.trajectories import CRITICAL_RTOL, _exact_parts
from test_near_defective import _critical_scale, _paper_arrays


def _ivp_linear(m, k, c, kc, t_eval):
    """States (len(t_eval), 2n) of a linear chain with dashpots on a linear contact spring kc
    (u_1 < 0 compresses it), all masses at -1 at t = 0 with m_1 on the surface: DOP853 at rtol
    1e-12, one solve_ivp per phase, each ended by u_1 crossing 0."""
    m, k, c = (np.asarray(a, float) for a in (m, k, c))
    n = m.size

    def rhs(t, s, contact):
        u, v = s[:n], s[n:]
        f = k * np.diff(u) + c * np.diff(v)  # link tensions
        a = np.zeros(n)
        a[:-1] += f
        a[1:] -= f
        if contact:
            a[0] -= kc * u[0]
        return np.concatenate([v, a / m])

    y = np.concatenate([np.zeros(n), -np.ones(n)])
    t, contact, t_end = 0.0, True, float(np.max(t_eval))
    out = np.full((len(t_eval), 2 * n), np.nan)
    while t < t_end:
        ev = lambda t, s, contact: s[0]  # noqa: E731
        ev.terminal, ev.direction = True, (1 if contact else -1)
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        events=ev, dense_output=True, args=(contact,))  # fmt: skip
        inside = (t_eval >= t) & (t_eval <= sol.t[-1])
        out[inside] = sol.sol(t_eval[inside]).T
        t, y = sol.t[-1], sol.y[:, -1].copy()
        if sol.status != 1:
            break
        y[0] = 0.0
        contact = not contact
    return out


@pytest.mark.parametrize("alpha, beta, n", [(30.0, 1.0, 4), (3.0, 0.05, 6)])
def test_contact_phase_critical_damping_sampled_by_adaptive(alpha, beta, n):
    m, k, c, kc = _paper_arrays(alpha, beta, n)
    xi = _critical_scale(m, k, c, kc, 0.5, 10.0)
    r = restitution.solve(alpha=alpha, beta=beta, xi=xi, n_masses=n)
    assert r.method == "piecewise+critical-bracket"
    times = np.linspace(0.0, 1.2 * r.omega_t_col, 150)
    frame = restitution.trajectory(alpha=alpha, beta=beta, xi=xi, n_masses=n, times=times)
    assert frame.attrs["method"] == "adaptive" and frame.attrs["rtol"] == CRITICAL_RTOL
    ref = _ivp_linear(m, k, xi * np.asarray(c), kc, times)
    s = frame[frame["event"] == "sample"]
    cols = [f"u_{i + 1}" for i in range(n)] + [f"v_{i + 1}" for i in range(n)]
    # (The exact sampler alone, on the degenerate basis, was 1.9e-8 off here at n = 6 and 4.5e-9
    # at n = 4 on an AMD EPYC, 6e-12 at n = 6 on an Intel Xeon: its round-off depends on the CPU's
    # code, so the routing above, not that difference, is what this test holds.)
    assert np.abs(s[cols].to_numpy() - ref).max() < 1e-10


def _xi_quadratic(beta, n, times):
    """The exact samples at xi = 1 extrapolated from xi = 1 -+ 1e-3, 1 -+ 2e-3 (and their
    spread, the reference's own error scale)."""
    g = {}
    for d in (-2e-3, -1e-3, 1e-3, 2e-3):
        f = restitution.trajectory(alpha=1e8, beta=beta, xi=1.0 + d, n_masses=n, times=times)
        assert f.attrs["method"] in ("piecewise", "impulsive")
        g[d] = f[f["event"] == "sample"].filter(regex="^[uv]_").to_numpy()
    near, far = 0.5 * (g[-1e-3] + g[1e-3]), 0.5 * (g[-2e-3] + g[2e-3])
    return (4.0 * near - far) / 3.0, np.abs(far - near)


@pytest.mark.parametrize("beta, n", [(1e-3, 3), (0.0, 3), (0.0, 17)])
def test_heavy_chain_at_xi_one_bracketed(beta, n):
    """alpha = 1e8, xi = 1: outside the numerical methods' frequency spread, so the samples are
    extrapolated from the exact sampler's runs off the critical point. At the rigid wall the
    sampler alone had m_1 sticking inside the wall (u_1 = -100 at omega t = 100)."""
    r = restitution.solve(alpha=1e8, beta=beta, xi=1.0, n_masses=n)
    times = np.linspace(0.0, 1.1 * r.omega_t_col, 300)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no fallback warning
        frame = restitution.trajectory(alpha=1e8, beta=beta, xi=1.0, n_masses=n, times=times)
    assert frame.attrs["method"].endswith("+critical-bracket")
    s = frame[frame["event"] == "sample"].filter(regex="^[uv]_").to_numpy()
    ref, spread = _xi_quadratic(beta, n, times)
    assert np.abs(s - ref).max() < 1e-8 + 10.0 * spread.max()  # (measured 8e-10 at most)
    if beta == 0.0:
        assert frame["u_1"].min() > -1e-9  # never inside the wall
        impacts = frame[frame["event"] == "impact"]
        assert len(impacts) == r.n_collisions


def test_far_from_critical_the_exact_sampler_as_before():
    times = np.linspace(0.0, 20.0, 41)
    for xi in (0.3, 1.001, 5.0):
        ch = restitution.Chain.paper(1e8, 1e-3, xi, 5)
        frame = restitution.trajectory(ch, times=times)
        assert frame.attrs["method"] == "piecewise"
        u, v, *_ = _exact_parts(ch, times, 10_000)
        assert np.array_equal(frame.filter(regex="^u_").to_numpy(), u)


def test_samples_next_to_impacts_bracketed_from_each_runs_own_impact():
    """Samples at and next to the impacts (3e-5 off): there the runs' impacts fall between each
    other's samples (their times move by about 1e-4 with the damping after 200 impacts), so
    each run is sampled as far from its own impact. The result is the limit of the exact
    motion at xi = 1 + e as e -> 0: its distance to the runs at 1 + 1e-6 and 1 + 1e-7 falls
    tenfold."""
    r = restitution.solve(alpha=1e8, beta=0.0, xi=1.0, n_masses=3, history=True)
    ti = r.history["omega_t_start"].to_numpy()[:100]
    times = np.sort(np.concatenate([ti, ti + 3e-5, ti[1:] - 3e-5]))
    frame = restitution.trajectory(alpha=1e8, beta=0.0, xi=1.0, n_masses=3, times=times)
    assert frame.attrs["method"] == "impulsive+critical-bracket"
    s = frame[frame["event"] == "sample"]
    assert s["u_1"].min() > -1e-9
    diff = {}
    for e in (1e-6, 1e-7):
        near = restitution.trajectory(alpha=1e8, beta=0.0, xi=1.0 + e, n_masses=3, times=times)
        near = near[near["event"] == "sample"]
        diff[e] = {
            q: np.abs(
                near.filter(regex=f"^{q}_").to_numpy() - s.filter(regex=f"^{q}_").to_numpy()
            ).max()
            for q in "uv"
        }
    for q in "uv":
        assert 5.0 < diff[1e-6][q] / diff[1e-7][q] < 20.0, diff
    assert diff[1e-7]["u"] < 1e-7 and diff[1e-7]["v"] < 1e-5  # (4.9e-8 and 3.9e-6 measured)


def test_a_sequence_cut_by_max_events_is_not_sampled_beyond_it():
    """The exact sampler flies on through the wall after the last contact it was allowed
    (m_1 through it, silently): a time past the end of contact max_events is
    refused, naming max_events; times up to it are the motion of the full sequence."""
    r = restitution.solve(alpha=300.0, n_masses=17, max_events=100)
    assert r.status == "event_budget_exhausted"
    reached = float(restitution.solve(alpha=300.0, n_masses=17, max_events=100, history=True)
                    .history["omega_t_end"].iloc[-1])  # fmt: skip
    with pytest.raises(restitution.SceneError, match="max_events = 100"):
        restitution.trajectory(alpha=300.0, n_masses=17, max_events=100, times=[0.0, 1.5 * reached])
    times = np.linspace(0.0, reached, 30)
    cut = restitution.trajectory(alpha=300.0, n_masses=17, max_events=100, times=times)
    full = restitution.trajectory(alpha=300.0, n_masses=17, max_events=10_000, times=times)
    assert cut.attrs["status"] == "event_budget_exhausted" and full.attrs["status"] == "ok"
    cols = [c for c in full.columns if c.startswith(("u_", "v_"))]
    s = cut["event"] == "sample"
    assert np.array_equal(cut.loc[s, cols].to_numpy(), full.loc[full["event"] == "sample", cols])


def test_an_unresolvable_sequence_is_sampled_with_a_warning():
    """A rigid-wall chain whose sequence round-off decides (ill_conditioned: its replicas
    differ by more than 1e-4; method='precise' finds 171 contacts, adaptive at rtol 1e-12 172):
    the samples come with a RuntimeWarning and attrs['status'] says so."""
    kw = dict(
        masses=[0.17792474157755944, 0.020958875578220237, 13.57560399153016],
        springs=[1.9383711173749685, 0.020386627318823892],
        dashpots=[0.002773097349168684, 0.0],
    )
    assert restitution.solve(**kw).status == "ill_conditioned"
    with pytest.warns(RuntimeWarning, match="ill_conditioned"):
        frame = restitution.trajectory(**kw, times=np.linspace(0.0, 50.0, 11))
    assert frame.attrs["status"] == "ill_conditioned"
    ok = restitution.trajectory(alpha=2.0, beta=0.1, times=[0.0, 1.0])
    assert ok.attrs["status"] == "ok"


def test_an_adaptive_sequence_cut_by_max_events_is_sampled_up_to_the_cut():
    """The adaptive sampler's side of the same rule: times up to the end of contact max_events
    are the full run's samples; a later time is a SceneError naming max_events (before, any
    time was refused with the run's status)."""
    kw = dict(masses=[1.0, 50.0, 50.0], springs=[1.0, 1.0], contact={"law": "hertz", "k": 50.0})
    h = restitution.solve(**kw, max_events=3, history=True).history
    reached = float(h["omega_t_end"].iloc[-1]) / restitution.Chain(**kw).omega
    times = np.linspace(0.0, reached, 12)
    cut = restitution.trajectory(**kw, max_events=3, times=times)
    full = restitution.trajectory(**kw, times=times)
    assert cut.attrs["status"] == "event_budget_exhausted" and full.attrs["status"] == "ok"
    cols = [c for c in full.columns if c.startswith(("u_", "v_"))]
    a, b = cut[cut["event"] == "sample"], full[full["event"] == "sample"]
    assert np.array_equal(a[cols].to_numpy(), b[cols].to_numpy())
    with pytest.raises(restitution.SceneError, match="max_events = 3"):
        restitution.trajectory(**kw, max_events=3, times=[0.0, 2.0 * reached])
