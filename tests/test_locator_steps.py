"""The locator's safe step and its crossing certificate, against independent references: the
first root of the step's cubic from numpy.roots refined in exact rational arithmetic, and contact
ends against scipy.linalg.expm of the phase on a fine grid."""

import math
from fractions import Fraction

import numpy as np
import pytest
from scipy.linalg import expm

from restitution.kernels.exact_chain import PH_CONTACT, _modal_model, _run
from restitution.kernels.layout import N_HIST
from restitution.kernels.locator import N_INFO, _locate
from restitution.kernels.paper_chain import _paper_chain
from restitution.kernels.roots import first_cubic_root as _safe_step
from test_modal_basis import _system


def _first_root(a0, a1, a2, a3):
    """First positive root of a0 + a1 s + a2 s^2/2 - a3 s^3/6 (exact Newton from numpy's), or
    None when two positive roots are too close for numpy's to tell which is first."""
    r = np.roots([-a3 / 6.0, a2 / 2.0, a1, a0])
    pos = np.sort(r[(np.abs(r.imag) <= 1e-9 * np.abs(r)) & (r.real > 0.0)].real)
    if pos.size == 0:
        return math.inf
    if pos.size > 1 and pos[1] - pos[0] <= 1e-4 * pos[1]:
        return None
    A0, A1, A2, A3 = (Fraction(x) for x in (a0, a1, a2, a3))
    x = Fraction(pos[0])
    for _ in range(4):
        p = A0 + x * (A1 + x * (A2 / 2 - x * A3 / 6))
        dp = A1 + x * (A2 - x * A3 / 2)
        x -= p / dp
        x = Fraction(float(x))  # keep the fractions short; Newton error is ~1e-30 by now
    return float(x)


def test_safe_step_is_the_first_root_from_below():
    """Over 4000 random cubics spanning the regimes the locator meets (a0 from a band of 1e-17
    to O(1), slopes and curvatures of both signs over many decades): the step is never past the
    first root of the cubic lower bound (beyond round-off) and never short of it by more than
    1e-12 (a short step only costs work, a long one could cross a contact)."""
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(4000):
        a0 = 10 ** rng.uniform(-17, 1)
        a1 = rng.choice([-1.0, 1.0]) * 10 ** rng.uniform(-6, 2)
        a2 = rng.choice([-1.0, 1.0]) * 10 ** rng.uniform(-6, 4)
        a3 = 10 ** rng.uniform(-4, 8)
        r = _first_root(a0, a1, a2, a3)
        if r is None:
            continue
        h = _safe_step(a0, a1, a2, a3)
        assert h <= r * (1.0 + 1e-14), (a0, a1, a2, a3, h, r)
        assert h >= r * (1.0 - 1e-12), (a0, a1, a2, a3, h, r)
        checked += 1
    assert checked > 3900


def _contact_phases(alpha, beta, xi, n):
    m, k, c, kc = _paper_chain(alpha, beta, xi, n)
    rec = np.zeros((400, 3 + 2 * n))
    _, nrec, _ = _run(m, k, c, kc, 1000, np.zeros((0, N_HIST)), rec, 2e7)
    lam, U, P, _ = _modal_model(m, k, c, kc, 0.0, False)
    S = _system(m, k, c, kc)
    rows = [i for i in range(min(nrec, rec.shape[0])) if rec[i, 1] == PH_CONTACT]
    return [(rec[i, 3:].copy(), lam, U, P, S) for i in rows]


@pytest.mark.parametrize(
    "alpha, beta, xi, n",
    [
        (3.0, 1e-3, 0.0, 2),
        (40.0, 1e-3, 0.1, 2),
        (120.0, 1e-2, 0.3, 2),
        (8.0, 0.1, 1.0, 3),
        (25.0, 1e-3, 0.0, 5),
    ],
)
def test_contact_end_is_the_first_separation(alpha, beta, xi, n):
    """Every contact phase of the scene, located afresh: m1 stays at or behind the wall on a grid
    of 1/64 of the fastest period up to the end found (expm of the phase), and is at the wall
    and leaving it there. Most of these ends are certified after one step by the cubic upper
    bound; this checks that the certificate never skips a separation."""
    for y0, lam, U, P, S in _contact_phases(alpha, beta, xi, n):
        info = np.zeros(N_INFO)
        code = _locate(0.0, 0.0, -U[0] * (P @ y0.astype(complex)), lam, True, info)
        assert code == 0
        te = info[0]
        h = 2.0 * math.pi / np.abs(lam).max() / 64.0
        E = expm(S * h)
        y = y0.copy()
        scale = np.abs(y0).max()
        t = h
        while t < te:
            y = E @ y
            assert y[0] <= 1e-12 * scale, (t, te, y[0])
            t += h
        yend = expm(S * te) @ y0
        assert abs(yend[0]) <= 1e-12 * scale and yend[n] > 0.0
