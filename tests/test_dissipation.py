"""Dashpot work of a modal phase (restitution.kernels.locator): the closed form to infinite time
(permanent contacts) and the Gauss-Legendre quadrature over [0, T], against scipy's quad."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from restitution.kernels.locator import _diss_modal, _diss_modal_inf


def _terms(rng, slow):
    """Decaying exponential terms of a real signal: two conjugate pairs and two real ones, one of
    them decaying at ``slow`` (an overdamped mode far slower than the rest)."""
    lam = [complex(-0.3, 2.0), complex(-0.3, -2.0), complex(-0.05, 7.0), complex(-0.05, -7.0)]
    lam += [complex(-slow, 0.0), complex(-40.0, 0.0)]
    g = [complex(*rng.normal(size=2)), 0j, complex(*rng.normal(size=2)), 0j]
    g[1], g[3] = g[0].conjugate(), g[2].conjugate()
    g += [complex(rng.normal(), 0.0), complex(rng.normal(), 0.0)]
    return np.array(g), np.array(lam)


def _reference(g, lam, c, T):
    def f(t):
        return c * float(np.real(np.sum(g * np.exp(lam * t)))) ** 2

    # split where the fast terms have died out, so quad sees each scale
    edges = [0.0, 10.0, 200.0] + ([T] if math.isfinite(T) else [np.inf])
    edges = [e for e in edges if e < T] + [T]
    return sum(
        quad(f, a, b, limit=500, epsabs=0.0, epsrel=1e-12)[0]
        for a, b in zip(edges[:-1], edges[1:], strict=True)
    )


@pytest.mark.parametrize("slow", [0.5, 1e-2])
def test_closed_form_to_infinity_matches_quad(slow):
    g, lam = _terms(np.random.default_rng(3), slow)
    ref = _reference(g, lam, 0.7, np.inf)
    assert _diss_modal_inf(g, lam, 0.7) == pytest.approx(ref, rel=1e-10)


def test_quadrature_over_a_finite_phase_matches_quad():
    g, lam = _terms(np.random.default_rng(4), 0.5)
    assert _diss_modal(13.0, g, lam, 0.7) == pytest.approx(_reference(g, lam, 0.7, 13.0), rel=1e-10)


def test_a_term_that_does_not_decay_gives_inf():
    """The motion never comes to rest: inf, so the caller's energy check fails."""
    g = np.array([1.0 + 0j, 1.0 - 0j, 0.5 + 0j])
    lam = np.array([2.0j, -2.0j, -1.0 + 0j])
    assert _diss_modal_inf(g, lam, 1.0) == math.inf
    assert _diss_modal_inf(g, lam, 0.0) == 0.0
