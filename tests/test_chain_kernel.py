"""The general linear-chain kernel (restitution.kernels.exact_chain) against an independent
reference.

The reference below is a slow pure-Python solver that shares nothing with the kernel: every phase
is propagated with scipy.linalg.expm of the phase's first-order system matrix (no eigenvectors,
no modal form), on a grid of 1/256 of the fastest period; every local minimum of the monitored gap
is bracketed by the sign change of the exact velocity between grid points and found with brentq,
and every crossing with brentq on the gap. A free flight ends by the energy bound of the
non-increasing relative energy (no further contact possible). Draws whose sequence passes within
a relative 1e-6 of a grazing point (a gap minimum that barely stays positive or barely goes
negative) are reported by the reference and excluded from the COR comparison: round-off decides
there and the COR is continuous across them (tested separately below).
"""

import math

import numba
import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq

from restitution.kernels.exact_chain import sample_chain, solve_chain, solve_chain_batch
from restitution.kernels.layout import (
    FLAG_STICKING,
    H_IMPULSE,
    H_TEND,
    H_TSTART,
    N_HIST,
    OUT_COR,
    OUT_EDISS,
    OUT_ERR,
    OUT_ETRANS,
    OUT_EVIB,
    OUT_FLAGS,
    OUT_NCOL,
    OUT_STATUS,
    OUT_TCOL,
    STATUS_INVALID,
    STATUS_OK,
)
from restitution.kernels.paper_chain import solve_linear

NOHIST = np.zeros((0, N_HIST))
GRAZE = 1e-6


def chain_mats(m, k, c):
    n = len(m)
    K = np.zeros((n, n))
    C = np.zeros((n, n))
    for i in range(n - 1):
        for A, a in ((K, k[i]), (C, c[i])):
            A[i, i] += a
            A[i + 1, i + 1] += a
            A[i, i + 1] -= a
            A[i + 1, i] -= a
    return K, C


class Reference:
    """(cor, contacts, t_last, e_vib, near_graze) of a chain by expm stepping (see module doc)."""

    def __init__(self, m, k, c, kc, max_contacts=400):
        self.m = np.asarray(m, float)
        self.n = self.m.size
        self.K, self.C = chain_mats(m, k, c)
        self.k = np.asarray(k, float)
        self.kc = kc
        self.max_contacts = max_contacts
        # Length scale of the gap: V0 / omega with omega^2 = k12/m1 + k12/m2.
        self.scale = 1.0 / math.sqrt(k[0] / m[0] + k[0] / m[1])
        self.near = False
        Kc = self.K.copy()
        if kc != math.inf:
            Kc[0, 0] += kc
        self.A_free = self._system(self.K)
        self.A_con = self._system(Kc)
        mt = self.m.sum()
        # Free flight: |u1 - X| <= sqrt(2 E_rel g), E_rel (relative kinetic + springs) never grows.
        Q = np.linalg.svd(self.m[None, :])[2][1:].T
        self.g = Q[0] @ np.linalg.solve(Q.T @ self.K @ Q, Q[0])
        self.mt = mt

    def _system(self, K):
        n = self.n
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -K / self.m[:, None]
        A[n:, n:] = -self.C / self.m[:, None]
        return A

    def _phase(self, A, y, sign, free):
        """Run one phase from y (u1 = 0) until sign*u1 crosses below zero; returns (duration,
        state) or (None, state) when a free flight provably has no further contact."""
        n = self.n
        fast = max(np.max(np.abs(np.linalg.eigvals(A))), 1e-3)
        dt = 2 * math.pi / fast / 256  # at 1/64 one draw of 160 missed a gap extremum
        E = expm(A * dt)
        t = 0.0
        ycur = y.copy()
        for _ in range(20_000_000):
            if free:
                u, v = ycur[:n], ycur[n:]
                V = self.m @ v / self.mt
                X = self.m @ u / self.mt
                erel = 0.5 * (self.m @ (v - V) ** 2) + 0.5 * u @ self.K @ u
                if V > 0 and X - math.sqrt(2 * erel * self.g) > 1e-9 * self.scale:
                    return None, ycur
            ynext = E @ ycur
            g0, g1 = sign * ycur[0], sign * ynext[0]
            d0, d1 = sign * ycur[n], sign * ynext[n]

            def gap(s, y0=ycur):
                return sign * (expm(A * s) @ y0)[0]

            def slope(s, y0=ycur):
                return sign * (expm(A * s) @ y0)[n]

            hit = None
            if g1 < 0.0:
                lo = 0.0
                if d0 < 0.0 < d1:  # a minimum inside: the crossing is before it
                    pass
                hit = brentq(gap, lo, dt, xtol=1e-15, rtol=1e-15) if g0 > 0 else 0.0
                if t + hit == 0.0:  # the phase starts on the wall: only a later crossing counts
                    hit = None
            elif d0 < 0.0 < d1:
                s_min = brentq(slope, 0.0, dt, xtol=1e-15, rtol=1e-15)
                gmin = gap(s_min)
                if abs(gmin) < GRAZE * self.scale:
                    self.near = True
                if gmin < 0.0:
                    hit = brentq(gap, 0.0, s_min, xtol=1e-15, rtol=1e-15)
            if hit is not None:
                yh = expm(A * hit) @ ycur
                yh[0] = 0.0
                return t + hit, yh
            ycur = ynext
            t += dt
        raise RuntimeError("reference phase did not end")

    def vib(self, y):
        n = self.n
        u, v = y[:n], y[n:]
        V = self.m @ v / self.mt
        return 0.5 * (self.m @ (v - V) ** 2) + 0.5 * u @ self.K @ u

    def run(self):
        n = self.n
        y = np.concatenate([np.zeros(n), -np.ones(n)])
        rigid = self.kc == math.inf
        t = 0.0
        count = 1
        t_last = 0.0
        if rigid:
            y[n] = 1.0
        else:
            te, y = self._phase(self.A_con, y, -1.0, False)
            t += te
            t_last = t
        y_last = y.copy()  # state at the last separation (where the kernel's energies are taken)
        while count < self.max_contacts:
            te, y = self._phase(self.A_free, y, 1.0, True)
            if te is None:
                e0 = 0.5 * self.mt
                cor = self.m @ y[n:] / self.mt
                return cor, count, t_last, self.vib(y_last) / e0, self.near
            t += te
            count += 1
            if rigid:
                y[n] = -y[n]
            else:
                te, y = self._phase(self.A_con, y, -1.0, False)
                t += te
            t_last = t
            y_last = y.copy()
        raise RuntimeError("reference: too many contacts")


def _kernel(m, k, c, kc, rows=0):
    hist = np.zeros((rows, N_HIST))
    out = solve_chain(
        np.asarray(m, float), np.asarray(k, float), np.asarray(c, float), float(kc), 100_000, hist
    )
    return (out, hist) if rows else out


def _random_chain(rng, nmax, rigid, damped):
    n = int(rng.integers(2, nmax + 1))
    m = 10 ** rng.uniform(-0.7, 0.7, n)
    k = 10 ** rng.uniform(-0.7, 0.7, n - 1)
    c = np.zeros(n - 1)
    if damped:
        for i in range(n - 1):
            if rng.random() < 0.5:
                # damping ratio up to 1.2 of the link's own oscillator
                mred = m[i] * m[i + 1] / (m[i] + m[i + 1])
                c[i] = 2 * rng.uniform(0, 1.2) * math.sqrt(k[i] * mred)
        if rigid:
            c[0] = 0.0  # a dashpot on link 1 at a rigid wall chatters (tested separately)
    kc = math.inf if rigid else k[0] / 10 ** rng.uniform(-3, 0.5)
    return m, k, c, kc


def _compare(draws):
    bad = []
    skipped = 0
    for m, k, c, kc in draws:
        out = _kernel(m, k, c, kc)
        assert out[OUT_STATUS] == STATUS_OK, (m, k, c, kc, out)
        # energy closed (the kernel integrates the dissipation per dashpot independently)
        assert abs(out[OUT_ETRANS] + out[OUT_EVIB] + out[OUT_EDISS] - 1.0) < 1e-9
        cor, cnt, t_last, evib, near = Reference(m, k, c, kc).run()
        if near:
            skipped += 1
            continue
        omega = math.sqrt(k[0] / m[0] + k[0] / m[1])
        off = abs(out[OUT_COR] - cor) > 1e-9 or abs(out[OUT_EVIB] - evib) > 1e-9
        off = off or abs(out[OUT_TCOL] / omega - t_last) > 1e-8 * max(1.0, t_last)
        if off or out[OUT_NCOL] != cnt:
            bad.append((m, k, c, kc, out[OUT_COR], cor, out[OUT_NCOL], cnt, out[OUT_EVIB], evib))
    assert not bad, bad
    assert skipped <= len(draws) // 10, skipped


@pytest.mark.parametrize("rigid", [True, False])
@pytest.mark.parametrize("damped", [False, True])
def test_random_general_chains_against_reference(rigid, damped):
    rng = np.random.default_rng(100 + 2 * rigid + damped)
    _compare([_random_chain(rng, 6, rigid, damped) for _ in range(8)])


@pytest.mark.slow
@pytest.mark.parametrize("rigid", [True, False])
@pytest.mark.parametrize("damped", [False, True])
def test_random_general_chains_against_reference_large(rigid, damped):
    rng = np.random.default_rng(200 + 2 * rigid + damped)
    _compare([_random_chain(rng, 8, rigid, damped) for _ in range(40)])


def test_paper_scene_is_a_preset():
    """The paper's scene written as a chain gives solve_linear's result bit for bit (one kernel),
    also in other units (rescaled on entry: cor and counts are unit-free, times are omega t)."""
    rng = np.random.default_rng(5)
    for _ in range(30):
        n = int(rng.integers(2, 6))
        alpha = 10 ** rng.uniform(-1, 1.5)
        beta = 0.0 if rng.random() < 0.3 else 10 ** rng.uniform(-3, 0)
        xi = 0.0 if rng.random() < 0.5 else rng.uniform(0, 2)
        k2 = alpha / (1 + alpha)
        m = np.full(n, alpha)
        m[0] = 1.0
        k = np.full(n - 1, k2)
        c = np.zeros(n - 1)
        c[0] = 2 * xi * k2
        kc = k2 / beta if beta else math.inf
        ref = solve_linear(alpha, beta, xi, n, 100_000, NOHIST)
        if ref[OUT_STATUS] != STATUS_OK:
            continue
        out = _kernel(m, k, c, kc)
        tol = 1e-12 if n > 2 or beta else 1e-12 + 1e-15 * out[OUT_NCOL]
        assert abs(out[OUT_COR] - ref[OUT_COR]) < tol
        assert out[OUT_NCOL] == ref[OUT_NCOL]
        # user units: masses x 7, time scale x 3 (k x 7 * 9, c x 7 * 3)
        scaled = _kernel(7 * m, 63 * k, 21 * c, 63 * kc)
        assert scaled[OUT_NCOL] == ref[OUT_NCOL]
        assert abs(scaled[OUT_COR] - ref[OUT_COR]) < 1e-9
        assert abs(scaled[OUT_TCOL] - ref[OUT_TCOL]) < 1e-8 * max(1.0, ref[OUT_TCOL])


def test_two_masses_map_to_alpha_beta_xi():
    """Any two-mass (m, k, c, kc) is the paper's (alpha, beta, xi) with alpha = m2/m1,
    xi = c (1/m1 + 1/m2) / (2 omega), beta = k/kc."""
    m1, m2, k, c = 2.0, 5.0, 3.0, 0.7
    alpha = m2 / m1
    omega = math.sqrt(k / m1 + k / m2)
    xi = c * (1 / m1 + 1 / m2) / (2 * omega)
    for beta in (0.0, 0.02, 0.5):
        kc = k / beta if beta else math.inf
        a = _kernel([m1, m2], [k], [c], kc)
        b = solve_linear(alpha, beta, xi, 2, 100_000, NOHIST)
        assert a[OUT_NCOL] == b[OUT_NCOL]
        assert abs(a[OUT_COR] - b[OUT_COR]) < 1e-12


# ------------------------------------------------------------------------------------------------
# Hand-made hard cases
# ------------------------------------------------------------------------------------------------


def _count_step(fn, lo, hi):
    """Bisect a parameter to the point where the contact count changes; returns both sides."""
    nlo = fn(lo)[OUT_NCOL]
    assert fn(hi)[OUT_NCOL] != nlo
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if fn(mid)[OUT_NCOL] == nlo:
            lo = mid
        else:
            hi = mid
    return fn(lo), fn(hi)


def test_grazing_contact_of_a_general_chain_is_continuous():
    """Across a grazing point of a general three-mass chain the count steps by one and the COR
    moves by no more than the impulse of a contact that just qualifies (~sqrt(tol))."""
    k = np.array([0.4, 1.3])
    c = np.array([0.0, 0.05])

    def fn(x):
        return _kernel([1.0, x, 0.6], k, c, math.inf)

    counts = {int(fn(x)[OUT_NCOL]) for x in np.linspace(0.3, 3.0, 40)}
    assert len(counts) > 1
    xs = np.linspace(0.3, 3.0, 40)
    for a, b in zip(xs[:-1], xs[1:], strict=True):
        if fn(a)[OUT_NCOL] != fn(b)[OUT_NCOL]:
            oa, ob = _count_step(fn, a, b)
            assert abs(oa[OUT_NCOL] - ob[OUT_NCOL]) == 1
            assert abs(oa[OUT_COR] - ob[OUT_COR]) < 1e-5
            break


def test_very_stiff_contact_tends_to_rigid():
    """kc -> inf: the COR converges to the rigid wall's (error ~ beta^(1/2) or better)."""
    m = [1.0, 0.8, 1.7]
    k = [0.5, 1.1]
    c = [0.0, 0.1]
    rigid = _kernel(m, k, c, math.inf)
    errs = []
    for beta in (1e-4, 1e-6, 1e-8):
        out = _kernel(m, k, c, k[0] / beta)
        assert out[OUT_STATUS] == STATUS_OK
        assert out[OUT_NCOL] == rigid[OUT_NCOL]
        errs.append(abs(out[OUT_COR] - rigid[OUT_COR]))
    assert errs[2] < errs[1] < errs[0] < 1e-2
    assert errs[2] < 1e-4


def test_near_massless_end_mass():
    """A 1e-6 end mass on a stiff-enough spring rides along: against the reference, and close to
    the chain without it."""
    m, k, c = [1.0, 2.0, 1e-6], [0.6, 0.3], [0.0, 0.0]
    out = _kernel(m, k, c, math.inf)
    assert out[OUT_STATUS] == STATUS_OK
    cor, cnt, *_ = Reference(m, k, c, math.inf).run()
    assert out[OUT_NCOL] == cnt
    assert abs(out[OUT_COR] - cor) < 1e-9
    without = _kernel(m[:2], k[:1], c[:1], math.inf)
    assert abs(out[OUT_COR] - without[OUT_COR]) < 1e-4


@pytest.mark.parametrize("kc", [math.inf, 5.0])
def test_critically_damped_chain_stays_ok(kc):
    """Near the damping where two modes of the free chain coalesce (a defective state matrix)
    the kernel stays ok and the COR is continuous on both sides."""
    m = np.array([1.0, 1.0, 1.0])
    k = np.array([0.5, 0.5])

    def fn(xi):
        return _kernel(m, k, np.array([0.0, 2 * xi * 0.5]), kc)

    xs = 1.0713727076841604  # the xi of the coalescence (bisected on the count of real modes)
    vals = []
    for x in (xs * (1 - 1e-6), xs * (1 - 1e-12), xs, xs * (1 + 1e-12), xs * (1 + 1e-6)):
        out = fn(x)
        assert out[OUT_STATUS] == STATUS_OK, x
        vals.append(out[OUT_COR])
    assert max(vals) - min(vals) < 1e-6


def test_chatter_on_a_chain_finishes_with_the_sticking_limit():
    """A rigid wall and a dashpot on link 1: Zeno-like chatter is continued by sticking, flagged,
    and the result does not depend on the cut-off."""
    from restitution.kernels.exact_chain import WORK_MAX, _run
    from restitution.kernels.paper_chain import _paper_chain

    m, k, c, kc = _paper_chain(50.0, 0.0, 2.0, 3)
    out, hist = _kernel(m, k, c, kc, rows=100_000)
    assert out[OUT_STATUS] == STATUS_OK
    assert int(out[OUT_FLAGS]) & FLAG_STICKING
    assert 0.0 < out[OUT_ERR] <= 1e-5
    n = int(out[OUT_NCOL])
    assert abs(hist[:n, H_IMPULSE].sum() - m.sum() * (out[OUT_COR] + 1.0)) < 1e-9
    fine = _run(m, k, c, kc, 300_000, NOHIST, np.zeros((0, 9)), WORK_MAX, 1e-4, 0)[0]
    assert fine[OUT_STATUS] == STATUS_OK
    assert abs(fine[OUT_COR] - out[OUT_COR]) < out[OUT_ERR]


def test_invalid_input_never_raises():
    bad = [
        ([1.0, -1.0], [1.0], [0.0], 1.0),
        ([1.0, math.nan], [1.0], [0.0], 1.0),
        ([1.0, 1.0], [0.0], [0.0], 1.0),
        ([1.0, 1.0], [1.0], [-1.0], 1.0),
        ([1.0, 1.0], [1.0], [0.0], 0.0),
        ([1.0, 1.0], [1.0], [0.0], math.nan),
        ([1.0, 1.0, 1.0], [1.0], [0.0], 1.0),
    ]
    for m, k, c, kc in bad:
        out = _kernel(m, k, c, kc)
        assert out[OUT_STATUS] == STATUS_INVALID and math.isnan(out[OUT_COR])


def test_batch_matches_scalar_and_any_thread_count():
    rng = np.random.default_rng(9)
    rows = 24
    nmax = 5
    M = np.zeros((rows, nmax))
    Kk = np.zeros((rows, nmax - 1))
    C = np.zeros((rows, nmax - 1))
    n = np.zeros(rows, np.int64)
    kc = np.zeros(rows)
    for i in range(rows):
        m, k, c, kci = _random_chain(rng, nmax, rng.random() < 0.5, True)
        n[i] = m.size
        M[i, : m.size], Kk[i, : k.size], C[i, : c.size], kc[i] = m, k, c, kci
    n[3] = 1  # an invalid row: refused, the rest unaffected
    ref = np.array(
        [
            _kernel(M[i, : n[i]], Kk[i, : n[i] - 1], C[i, : n[i] - 1], kc[i])
            if n[i] >= 2
            else np.full(M.shape[1] * 0 + 10, np.nan)
            for i in range(rows)
        ]
    )
    old = numba.get_num_threads()
    try:
        for nt in sorted({1, numba.config.NUMBA_NUM_THREADS}):
            numba.set_num_threads(nt)
            out = solve_chain_batch(M, Kk, C, n, kc, 100_000)
            assert out[3, OUT_STATUS] == STATUS_INVALID
            keep = np.arange(rows) != 3
            assert np.array_equal(out[keep], ref[keep], equal_nan=True)
    finally:
        numba.set_num_threads(old)


@pytest.mark.parametrize("kc", [math.inf, 4.0])
def test_sample_chain_consistent_with_history(kc):
    m = np.array([1.0, 0.5, 2.0])
    k = np.array([0.3, 1.2])
    c = np.array([0.0, 0.05])
    out, hist = _kernel(m, k, c, kc, rows=100)
    ts = np.linspace(0.0, out[OUT_TCOL] + 3.0, 2001)
    u, v, f, imp = sample_chain(m, k, c, kc, ts, 1000)
    nc = int(out[OUT_NCOL])
    # momentum after the last separation is the COR
    assert m @ v[-1] / m.sum() == pytest.approx(out[OUT_COR], abs=1e-12)
    if kc == math.inf:
        assert imp.shape == (nc, 2)
        assert np.allclose(imp[:, 0], hist[:nc, H_TSTART])
        assert np.all(f == 0.0)
    else:
        assert imp.shape == (0, 2)
        inside = np.zeros(ts.size, bool)
        for r in hist[:nc]:
            inside |= (ts > r[H_TSTART]) & (ts < r[H_TEND])
        # zero when apart (up to the round-off of u1 ~ 1e-17 at a phase start)
        assert np.all(np.abs(f[~inside]) < 1e-12) and np.all(f[inside] >= 0.0)
        # kernel units: u in V0/omega, f in m1 V0 omega, so the spring is kc / (m1 omega^2)
        kc_units = kc / (m[0] * (k[0] / m[0] + k[0] / m[1]))
        assert np.allclose(f, kc_units * np.maximum(-u[:, 0], 0.0), rtol=1e-12, atol=1e-15)
    # no penetration of a rigid wall, and positions continuous
    if kc == math.inf:
        assert u[:, 0].min() > -1e-12
    assert np.max(np.abs(np.diff(u, axis=0))) < 0.1


def test_a_larger_event_budget_raises_the_work_budget_of_a_long_chain():
    """The chain kernel's work budget (WORK_MAX operations) grows with a max_events above
    WORK_EVENTS: a 192-mass damped chain at the rigid wall stops after about a thousand contacts
    within the default budget and finishes (energy account closed, sticking limit) with ten
    times the events; a shorter scene gives the same bits either way."""
    import restitution

    scene = dict(alpha=1.0, xi=1.0, n_masses=192)
    short = restitution.solve(**scene)
    assert short.status == "work_budget_exhausted" and "max_events" in short.message
    long = restitution.solve(**scene, max_events=1_000_000)
    assert long.status == "ok" and long.n_collisions > short.n_collisions
    assert abs(long.e_translational + long.e_vibrational + long.e_dissipated - 1.0) <= max(
        1e-9, long.error_estimate
    )
    small = dict(alpha=2.2, beta=0.1, xi=0.1, n_masses=6)
    assert restitution.solve(**small).cor == restitution.solve(**small, max_events=10**6).cor
