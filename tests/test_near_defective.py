"""Scenes next to critical damping, where a phase's eigenbasis degenerates (a double eigenvalue).

The exact kernels flag such a phase (FLAG_NEAR_DEFECTIVE: two eigenvalues within DEFECT_REL, a
condition number above COND_DEFECT); the runners then extrapolate from rows with the dashpots
scaled off the critical point (``solvers.exact.bracketed``). Before, such scenes came back with
estimates of 1e-9..1e-5 (paper chains at xi = 1 and alpha >= 1e4), ``ill_conditioned`` (alpha =
1e8, N = 5) or unfinished (the rigid wall at alpha = 1e8). The critical points here are found
independently: by bisection on the number of real eigenvalues of the phase's state matrix,
assembled here with numpy; the references are the adaptive integrator (no modes at all).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import restitution
from restitution.kernels import layout as L
from restitution.solvers.exact import run_paper
from test_chain_kernel import chain_mats


def _state_matrix(m, k, c, kc):
    """[[0, I], [-M^-1 K, -M^-1 C]] of a chain with the contact spring kc on m1 (0: free)."""
    n = len(m)
    K, C = chain_mats(m, k, c)
    K[0, 0] += kc
    mi = np.diag(1.0 / np.asarray(m, dtype=float))
    return np.block([[np.zeros((n, n)), np.eye(n)], [-mi @ K, -mi @ C]])


def _real_count(m, k, c, kc) -> int:
    ev = np.linalg.eigvals(_state_matrix(m, k, c, kc))
    return int(np.sum(np.abs(ev.imag) <= 1e-9 * np.abs(ev)))


def _critical_scale(m, k, c, kc, lo, hi) -> float:
    """The dashpot scale s in [lo, hi] at which a pair of the contact phase's eigenvalues turns
    real (the count of real ones changes), to round-off."""
    c = np.asarray(c, dtype=float)
    n_lo = _real_count(m, k, lo * c, kc)
    assert _real_count(m, k, hi * c, kc) != n_lo
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if _real_count(m, k, mid * c, kc) == n_lo:
            lo = mid
        else:
            hi = mid
    return hi


def _paper_arrays(alpha, beta, n):
    k2 = alpha / (1.0 + alpha)
    c = np.zeros(n - 1)
    c[0] = 2.0 * k2  # xi = 1: the scale is xi
    return [1.0] + [alpha] * (n - 1), [k2] * (n - 1), c, k2 / beta


def _agrees(r, ref):
    assert ref.status == "ok" and ref.n_collisions == r.n_collisions
    assert abs(r.cor - ref.cor) <= r.error_estimate + ref.error_estimate, (r, ref)


@pytest.mark.parametrize("alpha, beta, n", [(0.5, 0.05, 3), (30.0, 1.0, 4), (3.0, 0.05, 6)])
def test_paper_chain_at_the_contact_phase_critical_damping(alpha, beta, n):
    xi = _critical_scale(*_paper_arrays(alpha, beta, n), 0.5, 10.0)
    out = run_paper(alpha, beta, xi, n, 100_000, np.zeros((0, L.N_HIST)))
    assert int(out[L.OUT_FLAGS]) & L.FLAG_NEAR_DEFECTIVE  # the kernel sees it
    r = restitution.solve(alpha=alpha, beta=beta, xi=xi, n_masses=n)
    assert r.status == "ok" and r.method == "piecewise+critical-bracket"
    assert r.error_estimate < 1e-9  # (the kernel's own: 1e-6 and more at this xi)
    ref = restitution.solve(
        alpha=alpha, beta=beta, xi=xi, n_masses=n, method="adaptive", rtol=1e-12
    )
    _agrees(r, ref)
    assert abs(r.e_translational + r.e_vibrational + r.e_dissipated - 1.0) < 1e-12
    if n == 3:  # and mpmath's modal solution at 40+ digits, which has no such trouble
        p = restitution.solve(alpha=alpha, beta=beta, xi=xi, n_masses=n, method="precise")
        _agrees(r, p)
    # the table's batch path gives the same row
    many = restitution.solve_many(
        pd.DataFrame({"alpha": [alpha], "beta": [beta], "xi": [xi], "n_masses": [n]})
    )
    assert many["method"][0] == r.method and many["cor"][0] == r.cor


def test_general_chain_at_critical_damping_and_its_history():
    m, k, c = [1.0, 2.0, 0.5, 1.5], [0.8, 1.3, 0.6], [0.4, 0.0, 0.9]
    kc = 20.0
    s = _critical_scale(m, k, c, kc, 0.5, 20.0)
    kw = dict(masses=m, springs=k, dashpots=list(s * np.asarray(c)), k_contact=kc)
    r = restitution.solve(**kw, history=True)
    assert r.status == "ok" and r.method == "piecewise+critical-bracket"
    assert r.error_estimate < 1e-9
    ref = restitution.solve(**kw, method="adaptive", rtol=1e-12, history=True)
    _agrees(r, ref)
    # the history is combined like the row: every contact's times and m1's velocities
    assert len(r.history) == r.n_collisions
    for col in ("omega_t_start", "omega_t_end", "v1_in", "v1_out"):
        assert np.allclose(r.history[col], ref.history[col], rtol=0, atol=1e-9), col
    many = restitution.solve_many(pd.DataFrame({k_: [v] for k_, v in kw.items()}))
    assert many["method"][0] == r.method and many["cor"][0] == r.cor


@pytest.mark.parametrize("beta, n", [(1.0, 5), (1e-3, 5), (1e-3, 3), (0.0, 3), (0.0, 17)])
def test_heavy_chain_critically_damped_at_xi_one(beta, n):
    """alpha = 1e8: m1 against an almost immovable m2, damped at xi = 1, is critically damped
    to about 1/alpha. Before: ill_conditioned (N = 5), estimates of 1e-5 (N = 3, beta = 1e-3)
    and unfinished at the rigid wall (event_not_converged, work_budget_exhausted). The
    numerical methods do not reach alpha = 1e8 with these spreads; the reference is the
    quadratic through runs at xi = 1 -+ 1e-3 and 1 -+ 2e-3, where the basis is sound."""
    r = restitution.solve(alpha=1e8, beta=beta, xi=1.0, n_masses=n)
    assert r.status == "ok" and "+critical-bracket" in r.method
    side = {
        d: restitution.solve(alpha=1e8, beta=beta, xi=1.0 + d, n_masses=n)
        for d in (-2e-3, -1e-3, 1e-3, 2e-3)
    }
    assert all(s.status == "ok" and "bracket" not in s.method for s in side.values())
    near = 0.5 * (side[-1e-3].cor + side[1e-3].cor)
    far = 0.5 * (side[-2e-3].cor + side[2e-3].cor)
    ref = (4.0 * near - far) / 3.0
    ref_err = abs(far - near) + 2.0 * max(s.error_estimate for s in side.values())
    assert abs(r.cor - ref) <= r.error_estimate + ref_err
    if beta > 0.0:
        assert r.error_estimate < 1e-10  # (9.2e-6 for N = 3, beta = 1e-3 before)
    else:
        assert r.method == "impulsive+critical-bracket+sticking"


def test_far_from_critical_nothing_changes():
    """Away from a degenerate basis the kernel's row stands (no flag, no bracket)."""
    for xi in (0.3, 1.001, 5.0):
        out = run_paper(1e8, 1e-3, xi, 5, 100_000, np.zeros((0, L.N_HIST)))
        assert not int(out[L.OUT_FLAGS]) & L.FLAG_NEAR_DEFECTIVE
        r = restitution.solve(alpha=1e8, beta=1e-3, xi=xi, n_masses=5)
        assert r.method == "piecewise" and r.cor == out[L.OUT_COR]
