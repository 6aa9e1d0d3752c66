"""Refinement of a damped phase's eigenpairs on the quadratic eigenproblem they come from.

The damped phases of the chain kernel expand the motion in the eigenvectors of the modal state
matrix S = [[0, sc], [-Omega^2 / sc, -D]] (``exact_chain._modal_model``). LAPACK's dgeev gives
each eigenvalue to an absolute error of about eps ||S||: where the damping is heavy (||S|| ~ D)
a slow mode loses the ratio ||S|| / |lam| of its digits, and its decay rate, a small real part
of that, far more. On the paper chain alpha = 1, beta = 1e6, xi = 1e3, N = 3 the contact mode
(|lam| = 4e-4 against ||S|| = 2e3) had its decay rate 0.4 % off (mpmath at 50 digits): the
dissipation of the contact phase, and with it the COR, 1e-9 off, which the energy account
caught (``energy_account_open``) on 26 of 576 corner scenes of the declared ranges.

Each such eigenpair (lam, x), x its modal displacement part, solves Q(lam) x = 0 with
Q(lam) = lam^2 I + lam D + Omega^2, whose entries are of the size of the slow mode's own terms:
evaluated there, the residual carries round-off of eps times those terms, not eps ||S||.
Newton on the Rayleigh functional of the complex-symmetric Q, lam <- lam - x^T Q(lam) x /
x^T Q'(lam) x (Q' = 2 lam I + D; twice), gives lam to round-off of its own size: its error is
second order in the vector's (dgeev's, about eps ||S|| / gap), which is kept. (A step of
inverse iteration for the vector first changed no COR beyond round-off on the corner and long
stiff scenes, and its complex linear solve cost 2-3 s of compile time per exact kernel.)
"""

from __future__ import annotations

import math

import numpy as np

from restitution.jit import njit
from restitution.kernels.constants import EPS

#: A mode is refined where dgeev's absolute error bound eps ||S|| exceeds this fraction of
#: |lam| (||S|| / |lam| > 4.5e4): below it the modes keep LAPACK's values bit for bit (every
#: output of `make all` did).
REFINE_REL = 1e-11


@njit(cache=True)
def _newton(lam, om, D, x):
    """One Newton step of the Rayleigh functional: lam - x^T Q(lam) x / x^T Q'(lam) x, with
    Q(lam) x = lam^2 x + lam D x + Omega^2 x and Q'(lam) = 2 lam + D."""
    num = 0.0j
    dq = 0.0j
    for q in range(om.size):
        dx = 0.0j
        for p in range(om.size):
            dx += D[q, p] * x[p]
        num += x[q] * ((lam * lam + om[q] * om[q]) * x[q] + lam * dx)
        dq += x[q] * (2.0 * lam * x[q] + dx)
    if dq == 0.0:
        return lam
    return lam - num / dq


@njit(cache=True)
def refine_pairs(wr, wi, Vr, S, om, D, sc):
    """Refine in place dgeev's eigenvalues (wr, wi) of the modal state matrix S of (sc q, q')
    where eps ||S|| > REFINE_REL |lam|, and rebuild those eigenvectors' columns of Vr (a real
    vector, or [Re v, Im v] of a pair) as (sc x, lam x) from their displacement part x. A
    refinement that moves lam by more than 64 eps ||S|| (dgeev's error is within a few), or
    towards another eigenvalue, is dropped: near a repeated eigenvalue LAPACK's pair is kept."""
    nm = om.size
    K = wr.size
    norm = 0.0  # ||S|| (infinity norm)
    for i in range(S.shape[0]):
        row = 0.0
        for j in range(S.shape[1]):
            row += abs(S[i, j])
        norm = max(norm, row)
    bound = EPS * norm
    x = np.empty(nm, np.complex128)
    j = 0
    while j < K:
        pair = wi[j] != 0.0 and j + 1 < K
        lam0 = complex(wr[j], wi[j])
        step = 2 if pair else 1
        if bound <= REFINE_REL * abs(lam0) or (pair and wi[j] < 0.0):
            j += step
            continue
        gap = math.inf  # distance to the nearest other eigenvalue (conjugates included)
        for i in range(K):
            if i != j and not (pair and i == j + 1):
                gap = min(gap, abs(complex(wr[i], wi[i]) - lam0))
        if pair:
            gap = min(gap, 2.0 * abs(wi[j]))
        if gap <= 1e3 * bound:
            j += step
            continue
        for q in range(nm):  # the displacement part, from its better-resolved half
            a = complex(Vr[q, j], Vr[q, j + 1] if pair else 0.0)
            b = complex(Vr[nm + q, j], Vr[nm + q, j + 1] if pair else 0.0)
            x[q] = a / sc[q] if abs(lam0) < sc[q] else b / lam0
        lam = _newton(lam0, om, D, x)
        lam = _newton(lam, om, D, x)
        moved = abs(lam - lam0)
        if not (math.isfinite(lam.real) and math.isfinite(lam.imag)) or moved > 64.0 * bound:
            j += step
            continue
        if moved > 0.5 * gap or (pair and lam.imag <= 0.0) or (not pair and lam.imag != 0.0):
            j += step
            continue
        wr[j] = lam.real
        wi[j] = lam.imag
        if pair:
            wr[j + 1] = lam.real
            wi[j + 1] = -lam.imag
        for q in range(nm):
            a = sc[q] * x[q]
            b = lam * x[q]  # (the velocity part, lam x, with the refined lam)
            Vr[q, j] = a.real
            Vr[nm + q, j] = b.real
            if pair:
                Vr[q, j + 1] = a.imag
                Vr[nm + q, j + 1] = b.imag
        j += step
