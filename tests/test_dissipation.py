"""Closed-form dashpot work of the exact kernels (restitution.kernels.locator), over a phase and to
infinite time (permanent contacts), against adaptive
quadrature (scipy.integrate.quad) of the integrand itself.

The kernels integrate c (Re sum_k g_k e^{lam_k t})^2 over a phase in closed form, as a sum over
pairs of modes, and c r'^2 of the two-mass oscillator r'' + 2 xi r' + r = 0 through the same pair
sum; where the pair terms would cancel they fall back to Gauss-Legendre. The reference here shares
nothing with either: quad of the integrand evaluated directly (numpy exponentials, and for the
oscillator the solution of its initial value problem by scipy's matrix exponential).
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.linalg import expm

from restitution.kernels.locator import (
    CANCEL_MAX,
    _diss_modal,
    _diss_modal_gl,
    _diss_modal_inf,
    _diss_scalar,
    _diss_scalar_gl,
    _pair_integrals,
    _pair_sum,
)


def _cancellation(T, g, lam):
    """(pair sum, sum of the pair terms' magnitudes) of the closed form."""
    return _pair_sum(g, *_pair_integrals(T, lam))


def _reference(fn, T):
    """quad of fn over [0, T], split into pieces of at most one unit of phase time."""
    pieces = max(int(math.ceil(T)), 1)
    edges = np.linspace(0.0, T, pieces + 1)
    return sum(
        quad(fn, a, b, epsabs=0.0, epsrel=1e-13, limit=400)[0]
        for a, b in zip(edges[:-1], edges[1:], strict=True)
    )


def _modal_draw(rng, damped):
    """Conjugate-closed modal data: K pairs (lam, conj lam) with conjugate amplitudes."""
    k = int(rng.integers(1, 5))
    lam = -rng.uniform(0.0, 1.0, k) * damped + 1j * rng.uniform(0.1, 30.0, k)
    g = rng.normal(size=k) + 1j * rng.normal(size=k)
    return np.concatenate([g, g.conj()]), np.concatenate([lam, lam.conj()])


@pytest.mark.parametrize("damped", [0.0, 1.0])
def test_modal_closed_form_matches_quadrature(damped):
    rng = np.random.default_rng(7)
    for _ in range(40):
        g, lam = _modal_draw(rng, damped)
        T = 10 ** rng.uniform(-2.0, 1.0)
        c = rng.uniform(0.1, 2.0)
        ref = c * _reference(lambda t, g=g, lam=lam: (g * np.exp(lam * t)).sum().real ** 2, T)
        got = _diss_modal(T, g, lam, c)
        assert got == pytest.approx(ref, rel=1e-11, abs=0.0)
        acc, mag = _cancellation(T, g, lam)
        assert mag <= CANCEL_MAX * abs(acc)  # these draws take the closed form, not the fallback


def test_modal_closed_form_real_and_zero_sum_modes():
    # Real (overdamped) modes, an undamped pair whose sum lam_p + conj(lam_p) is exactly 0, and
    # a slow pair with |(lam_p + lam_q) T| < 1/2 (the series branch of e^x - 1).
    lam = np.array([-0.3, -4.0, 2.0j, -2.0j, -0.01 + 0.05j, -0.01 - 0.05j], np.complex128)
    g = np.array([0.7, -0.2, 0.4 - 0.1j, 0.4 + 0.1j, 1.5 + 0.3j, 1.5 - 0.3j], np.complex128)
    for T in (1e-3, 0.3, 5.0, 80.0):
        ref = 0.8 * _reference(lambda t: (g * np.exp(lam * t)).sum().real ** 2, T)
        assert _diss_modal(T, g, lam, 0.8) == pytest.approx(ref, rel=1e-11, abs=0.0)


def test_modal_cancelling_amplitudes_fall_back_and_stay_exact():
    # Two nearly equal eigenvalues with huge opposite amplitudes (near a repeated eigenvalue):
    # the pair terms cancel by ~1e16, so the closed form must hand over to the quadrature.
    d = 1e-8
    lam = np.array([-1.0 + 1j, -1.0 - 1j, -1.0 - d + 1j, -1.0 - d - 1j], np.complex128)
    big = 1.0 / d
    g = np.array([big, big, -big, -big], np.complex128)
    T = 2.0
    acc, mag = _cancellation(T, g, lam)
    assert mag > CANCEL_MAX * abs(acc)
    # the sum itself, without the cancellation: 2 e^{-t} cos(t) (1 - e^{-d t}) / d
    ref = _reference(lambda t: (2.0 * math.exp(-t) * math.cos(t) * -math.expm1(-d * t) / d) ** 2, T)
    assert _diss_modal(T, g, lam, 1.0) == _diss_modal_gl(T, g, lam, 1.0)
    # the quadrature loses ~eps * 1e8 to the cancellation inside the integrand, no more
    assert _diss_modal(T, g, lam, 1.0) == pytest.approx(ref, rel=1e-6)


def _scalar_reference(T, xi, r0, rd0):
    """Integral of r'^2 with r from the matrix exponential of [[0, 1], [-1, -2 xi]]."""
    A = np.array([[0.0, 1.0], [-1.0, -2.0 * xi]])
    y0 = np.array([r0, rd0])
    return _reference(lambda t: (expm(A * t) @ y0)[1] ** 2, T)


@pytest.mark.parametrize(
    "xi", [0.0, 0.05, 0.5, 0.9, 0.999, 1.0 - 1e-9, 1.0, 1.0 + 1e-9, 1.001, 1.5, 4.0, 30.0]
)
def test_scalar_closed_form_matches_quadrature(xi):
    for T in (1e-3, 0.2, 3.0, 25.0):
        for r0, rd0 in ((0.3, -0.7), (0.0, 1.0), (-1.2, 0.05)):
            ref = 0.6 * _scalar_reference(T, xi, r0, rd0)
            got = _diss_scalar(T, xi, r0, rd0, 0.6)
            assert got == pytest.approx(ref, rel=1e-10, abs=1e-300), (xi, T, r0, rd0)
            # and it agrees with the Gauss-Legendre form it replaces to round-off
            assert got == pytest.approx(_diss_scalar_gl(T, xi, r0, rd0, 0.6), rel=1e-13)


# ------------------------------------------------------------------------------------------------
# To infinite time (permanent contacts): closed form, no quadrature could reach it
# ------------------------------------------------------------------------------------------------


def _inf_terms(rng, slow):
    """Decaying exponential terms of a real signal: two conjugate pairs and two real ones, one of
    them decaying at ``slow`` (an overdamped mode far slower than the rest)."""
    lam = [complex(-0.3, 2.0), complex(-0.3, -2.0), complex(-0.05, 7.0), complex(-0.05, -7.0)]
    lam += [complex(-slow, 0.0), complex(-40.0, 0.0)]
    g = [complex(*rng.normal(size=2)), 0j, complex(*rng.normal(size=2)), 0j]
    g[1], g[3] = g[0].conjugate(), g[2].conjugate()
    g += [complex(rng.normal(), 0.0), complex(rng.normal(), 0.0)]
    return np.array(g), np.array(lam)


def _inf_reference(g, lam, c, T):
    def f(t):
        return c * float(np.real(np.sum(g * np.exp(lam * t)))) ** 2

    # pieces of a few periods of the fastest oscillation, up to where every oscillating term
    # has died out (e**-100), then the smooth tail: over [10, 200] and [200, inf) in one piece
    # each quad hit its subdivision limit and warned of round-off
    edges = [*np.arange(0.0, 10.0, 1.0), *np.arange(10.0, 1000.0, 5.0), 1000.0]
    edges = [e for e in edges if e < T] + [T]
    total = 0.0
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        # (the tail may be 1e-43 of the total: held to 1e-14 of the total, not of itself)
        total += quad(f, a, b, limit=500, epsabs=1e-14 * total, epsrel=1e-12)[0]
    return total


@pytest.mark.parametrize("slow", [0.5, 1e-2])
def test_closed_form_to_infinity_matches_quad(slow):
    g, lam = _inf_terms(np.random.default_rng(3), slow)
    ref = _inf_reference(g, lam, 0.7, np.inf)
    assert _diss_modal_inf(g, lam, 0.7) == pytest.approx(ref, rel=1e-12)


def test_quadrature_over_a_finite_phase_matches_quad():
    g, lam = _inf_terms(np.random.default_rng(4), 0.5)
    assert _diss_modal(13.0, g, lam, 0.7) == pytest.approx(
        _inf_reference(g, lam, 0.7, 13.0), rel=1e-10
    )


def test_a_term_that_does_not_decay_gives_inf():
    """The motion never comes to rest: inf, so the caller's energy check fails."""
    g = np.array([1.0 + 0j, 1.0 - 0j, 0.5 + 0j])
    lam = np.array([2.0j, -2.0j, -1.0 + 0j])
    assert _diss_modal_inf(g, lam, 1.0) == math.inf
    assert _diss_modal_inf(g, lam, 0.0) == 0.0
