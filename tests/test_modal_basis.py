"""The damped modal basis (one term per conjugate pair) and the locator's two-scale step, against
the matrix exponential of the phase's first-order system (no eigenvectors, no modal form):
mpmath's at 40 digits for the basis (scipy.linalg.expm is itself 1e-12 off on the stiff cases,
more than the basis), scipy's for the locator."""

import math

import mpmath
import numpy as np
import pytest
from scipy.linalg import expm

from restitution.kernels.constants import EPS
from restitution.kernels.exact_chain import PH_CONTACT, _modal_model, _modal_state, _run
from restitution.kernels.layout import N_HIST
from restitution.kernels.locator import N_INFO, _locate
from restitution.kernels.paper_chain import _paper_chain
from restitution.kernels.quadratic_refine import REFINE_REL
from test_chain_kernel import chain_mats


def _system(m, k, c, kg):
    """First-order system matrix of the chain with a ground spring kg on mass 0."""
    n = len(m)
    K, C = chain_mats(m, k, c)
    K[0, 0] += kg
    Mi = np.diag(1.0 / np.asarray(m))
    return np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ C]])


A = np.array
CASES = {
    # a near-critical pair (Im/|lam| = 0.01, large cancelling projectors) next to light modes:
    # doubling one member of the complex inverse's pair left 5e-10 here
    "near-critical": (*_paper_chain(100.0, 0.0, 1.0, 5)[:3], 0.0),
    "underdamped contact": (*_paper_chain(20.0, 1e-3, 0.3, 2)[:3], 0.0),
    "overdamped (real modes)": (A([1.0, 2.0, 0.5]), A([1.0, 0.5]), A([9.0, 6.0]), 3.0),
    "mixed general": (A([1.0, 0.3, 2.0, 0.7]), A([0.4, 1.3, 0.8]), A([0.0, 0.9, 0.05]), 40.0),
}


@pytest.mark.parametrize("name", list(CASES))
def test_halved_basis_reproduces_the_motion(name):
    m, k, c, kg = CASES[name]
    if name == "underdamped contact":
        kg = k[0] / 1e-3
    n = len(m)
    free = kg == 0.0  # a free phase: the rigid mode is dropped, states relative to the centre
    lam, U, P, cond = _modal_model(m, k, c, kg, 0.0, free)
    assert cond < 1e6
    # one term per conjugate pair: at most 2n terms, n when every mode is underdamped
    n_pairs = int(np.sum(lam.imag > 0))
    assert lam.size == 2 * (n - free) - n_pairs
    assert np.all(np.abs(lam[lam.imag <= 0].imag) == 0.0)  # the rest are real
    rng = np.random.default_rng(3)
    S = mpmath.matrix(_system(m, k, c, kg).tolist())
    top = np.abs(lam).max()
    for _ in range(3):
        y0 = rng.normal(size=2 * n)
        if free:
            y0[:n] -= m @ y0[:n] / m.sum()
            y0[n:] -= m @ y0[n:] / m.sum()
        z = P @ y0.astype(complex)
        scale = np.abs(y0).max()
        for t in (0.0, 1e-3, 0.7, 5.0):
            u = np.empty(n)
            v = np.empty(n)
            _modal_state(t, z, lam, U, 0.0, 0.0, u, v)
            with mpmath.workdps(40):
                ref = np.array([float(x) for x in mpmath.expm(S * t) * mpmath.matrix(list(y0))])
            err = max(np.abs(u - ref[:n]).max(), np.abs(v - ref[n:]).max())
            # the basis's round-off, plus 16 ulps of phase per radian of the fastest mode (any
            # double-precision exponential of rounded rates drifts so)
            bound = scale * max(cond, 1.0) * (1e-13 + 16 * EPS * top * t)
            assert err <= bound, (name, t, err, bound)


@pytest.mark.parametrize("cg", [0.5, 2.0 * math.sqrt(2.0), 3.0, 30.0])
def test_ground_dashpot_model_reproduces_the_motion(cg):
    # The sticking phase's model (a dashpot from mass 0 to the ground), from light damping
    # through overdamped modes (real eigenvalues) to a very stiff dashpot.
    m = np.array([1.0, 1.0])
    k = np.array([1.0])
    c = np.array([0.0])
    lam, U, P, cond = _modal_model(m, k, c, 1.0, cg, False)
    S = _system(m, k, c, 1.0)
    S[2, 2] -= cg  # the ground dashpot on mass 0
    y0 = np.array([0.3, -0.2, 1.0, 0.5])
    z = P @ y0.astype(complex)
    for t in (0.0, 0.5, 3.0):
        u = np.empty(2)
        v = np.empty(2)
        _modal_state(t, z, lam, U, 0.0, 0.0, u, v)
        ref = expm(S * t) @ y0
        assert np.abs(np.r_[u, v] - ref).max() <= 1e-12 * max(cond, 1.0)


def test_long_ringing_contact_located_in_few_steps():
    """The last contact of alpha = 200, beta = 1e-3, xi = 0.3 lasts ~180 periods of the fast
    (contact-spring) mode. The two-scale step crosses it in a few steps; the end found is the
    first time m1 leaves the wall, checked on a grid of 1/32 fast period by expm."""
    m, k, c, kc = _paper_chain(200.0, 1e-3, 0.3, 2)
    rec = np.zeros((200, 7))
    out, nrec, _ = _run(m, k, c, kc, 1000, np.zeros((0, N_HIST)), rec, 2e7)
    last = max(i for i in range(nrec) if rec[i, 1] == PH_CONTACT)
    y0 = rec[last, 3:]
    lam, U, P, _ = _modal_model(m, k, c, kc, 0.0, False)
    info = np.zeros(N_INFO)
    b = -U[0] * (P @ y0.astype(complex))
    code = _locate(0.0, 0.0, b, lam, True, info)
    te = info[0]
    fast = np.abs(lam).max()
    assert code == 0 and te > 100 * 2 * math.pi / fast  # a long contact...
    assert info[3] <= 20  # ...in few steps (the single-scale step needed ~10 per fast period)
    S = _system(m, k, c, kc)
    h = 2 * math.pi / fast / 32
    E = expm(S * h)
    y = y0.copy()
    t = 0.0
    worst = -math.inf
    while t + h < te:
        y = E @ y
        t += h
        worst = max(worst, y[0])  # u1 > 0 would be a separation before te
    assert worst < 0.0
    yend = expm(S * te) @ y0
    assert abs(yend[0]) <= 1e-12 and yend[2] > 0.0  # at the wall, leaving it


def test_lapack_real_eigen_decomposition():
    """eig_real (dgeev through numba's LAPACK bridge) against numpy: the same eigenvalues, each
    pair adjacent and exactly conjugate, and A v = lam v for the vectors it returns."""
    from restitution.kernels.lapack import eig_real

    rng = np.random.default_rng(7)
    for n in (1, 2, 4, 9, 16):
        a = rng.normal(size=(n, n))
        keep = a.copy()
        wr, wi, vr, info = eig_real(a)
        assert info == 0 and np.array_equal(a, keep)  # input untouched
        lam = wr + 1j * wi
        assert np.allclose(np.sort_complex(lam), np.sort_complex(np.linalg.eigvals(a)), atol=1e-12)
        j = 0
        while j < n:
            if wi[j] == 0.0:
                v = vr[j].astype(complex)
                step = 1
            else:
                assert wi[j] > 0 and wr[j + 1] == wr[j] and wi[j + 1] == -wi[j]
                v = vr[j] + 1j * vr[j + 1]
                step = 2
            assert np.abs(a @ v - lam[j] * v).max() < 1e-12 * n
            j += step


@pytest.mark.parametrize("T", [1e-3, 0.4, 7.0])
def test_dashpot_work_of_all_dashpots_at_once_matches_quadrature(T):
    """_diss_phase (one pair sum over the dashpot matrices) against scipy quad of
    sum_i c_i (v_{i+1} - v_i)^2 along the expm-propagated motion: a chain with three dashpots,
    contact phase (kg > 0)."""
    from scipy.integrate import quad

    from restitution.kernels.exact_chain import _diss_matrices, _diss_phase

    m = np.array([1.0, 0.4, 2.5, 0.8])
    k = np.array([0.5, 1.7, 0.9])
    c = np.array([0.05, 0.6, 0.2])
    kg = 30.0
    lam, U, P, _ = _modal_model(m, k, c, kg, 0.0, False)
    A1, A2, B = _diss_matrices(U, lam, c, 0)
    y0 = np.array([0.0, -0.1, 0.2, 0.05, -1.0, -0.7, -1.2, -0.9])
    z = P @ y0.astype(complex)
    got, _ = _diss_phase(T, z, lam, A1, A2, B, U, c, 0, math.inf, 0.0)
    S = _system(m, k, c, kg)

    def power(t):
        v = (expm(S * t) @ y0)[4:]
        return float(np.sum(c * np.diff(v) ** 2))

    ref = quad(power, 0.0, T, epsabs=0.0, epsrel=1e-12, limit=400)[0]
    assert got == pytest.approx(ref, rel=1e-10)


@pytest.mark.parametrize("n, beta", [(128, 1e-3), (40, 1e-10)])
def test_modes_of_a_long_chain_on_a_stiff_contact_stay_finite(n, beta):
    """A stiff contact's mode decays by ~k_contact/k per mass away from the wall, so the shape
    recurrence towards its peak grew by that factor per mass and overflowed (N = 128, beta =
    1e-3: NaN modes; the scene then ran the locator through its whole work budget). Every mode
    is finite and solves K phi = w^2 M phi to round-off of its own terms, the modes are
    M-orthonormal, and the contact mode's amplitude falls off along the chain."""
    m, k, c = _paper_chain(1.0, beta, 0.0, n)[:3]
    kg = k[0] / beta
    lam, U, P, cond = _modal_model(m, k, c, kg, 0.0, False)
    assert cond == 1.0 and np.isfinite(U).all() and np.isfinite(P).all()
    K, _ = chain_mats(m, k, c)
    K[0, 0] += kg
    phi = U.real
    w2 = (lam * lam.conjugate()).real
    resid = K @ phi - m[:, None] * phi * w2
    terms = np.abs(K) @ np.abs(phi) + m[:, None] * np.abs(phi) * w2
    assert np.all(np.abs(resid) <= 64 * EPS * terms + 1e-300)  # (subnormal tails: absolute)
    np.testing.assert_allclose(phi.T @ (m[:, None] * phi), np.eye(n), atol=1e-12)
    top = np.abs(phi[:, np.argmax(w2)])
    assert top[0] > 0.5 and top[-1] < 1e-100  # the contact mode lives at the wall


def test_long_chain_on_a_stiff_contact_agrees_with_the_integrator():
    """The overflowing case of the exact solver (72 masses, beta = 1e-5: 'event_not_converged'
    after the first contact before) against the adaptive integrator (no modal shapes)."""
    import restitution

    exact = restitution.solve(alpha=1.0, beta=1e-5, n_masses=72)
    ref = restitution.solve(alpha=1.0, beta=1e-5, n_masses=72, method="adaptive", rtol=1e-10)
    assert exact.status == "ok" and ref.status == "ok"
    assert exact.n_collisions == ref.n_collisions
    assert abs(exact.cor - ref.cor) <= exact.error_estimate + ref.error_estimate


def _quadratic_eigenvalues(m, k, c, kg, dps=50):
    """Eigenvalues of the chain's first-order system (no modal form), assembled and solved in
    mpmath at dps digits (kg added in floating point would round away its last bits)."""
    with mpmath.workdps(dps):
        n = len(m)
        mp = mpmath.mpf
        K = mpmath.zeros(n)
        C = mpmath.zeros(n)
        K[0, 0] = mp(kg)
        for i in range(n - 1):
            for a, b, s in ((i, i, 1), (i + 1, i + 1, 1), (i, i + 1, -1), (i + 1, i, -1)):
                K[a, b] += s * mp(k[i])
                C[a, b] += s * mp(c[i])
        A_ = mpmath.zeros(2 * n)
        for i in range(n):
            A_[i, n + i] = 1
            for j in range(n):
                A_[n + i, j] = -K[i, j] / mp(m[i])
                A_[n + i, n + j] = -C[i, j] / mp(m[i])
        return [complex(e) for e in mpmath.eig(A_, left=False, right=False)]


@pytest.mark.parametrize("alpha, n", [(1.0, 3), (10.0, 2), (1.0, 4)], ids=["N3", "N2", "N4"])
def test_heavily_damped_contact_modes_to_their_own_round_off(alpha, n):
    """xi = 1e3 on a soft contact (beta = 1e6): dgeev's error eps ||S|| (||S|| ~ 2e3) is 1e-9 of
    the contact mode (|lam| ~ 4e-4) and 0.4 % of its decay rate. The modes dgeev resolves to
    worse than REFINE_REL of themselves are refined on the quadratic eigenproblem: good to
    round-off of their own size, their real part included; the others keep dgeev's eps ||S||."""
    m, k, c, kg = _paper_chain(alpha, 1e6, 1e3, n)
    lam, _, _, cond = _modal_model(m, k, c, kg, 0.0, False)
    assert cond < 1e6
    ref = _quadratic_eigenvalues(m, k, c, kg)
    top = np.abs(lam).max()  # ~ ||S||
    refined = 0
    for z in lam:
        exact = min(ref, key=lambda e: abs(e - z))
        if EPS * top > REFINE_REL * abs(z):
            refined += 1
            assert abs(z - exact) <= 1e-14 * abs(exact), (z, exact)
            assert abs(z.real - exact.real) <= 1e-8 * abs(exact.real), (z, exact)
        else:
            assert abs(z - exact) <= 16 * EPS * top, (z, exact)
    assert refined >= 1  # the contact mode


@pytest.mark.parametrize(
    "alpha, beta, xi, n",
    [(1.0, 1e6, 1e3, 3), (10.0, 1e6, 1e3, 2), (0.1, 1e6, 1e3, 5), (1e3, 1e6, 100.0, 3)],
)
def test_heavily_damped_corners_finish_within_their_estimates(alpha, beta, xi, n):
    """Corners of the declared ranges that ended ``energy_account_open`` while dgeev's slow modes
    were 1e-9 off: now ok, and within their estimates of ``method="precise"`` (mpmath)."""
    from restitution import solve

    res = solve(alpha=alpha, beta=beta, xi=xi, n_masses=n)
    ref = solve(alpha=alpha, beta=beta, xi=xi, n_masses=n, method="precise")
    assert res.status == "ok" and ref.status == "ok"
    assert res.n_collisions == ref.n_collisions
    assert abs(res.cor - ref.cor) <= res.error_estimate + ref.error_estimate
