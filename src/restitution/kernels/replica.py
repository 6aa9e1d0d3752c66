"""The replica check of the exact kernels: how far round-off can have moved a result.

A contact sequence is a chain of event maps, and some scenes amplify a perturbation of the state
at every contact (long, chaotic sequences; chains with mass or spring ratios far from 1; slow
impacts). The accumulated round-off of such a run can exceed any fixed number of ulps, and a
scene can be so sensitive that no double-precision run resolves it. So every finished exact
result is solved again, twice (``REPLICAS``), as *replicas*: the scene's parameters in the
kernels' units perturbed by ``REPLICA_ULPS`` ulps, and the state perturbed by as much (relative)
at the start of every phase, i.e. round-off emulated at a larger, known size (the idea of
stochastic arithmetic, CESTAC). For the general chain the parameters move as the eigen-solvers'
backward error moves the phase matrices (kernels.chain._replica_scene). The runs differ by the
sensitivity of the result times that size; the round-off of the first run is of the same kind
at a smaller size, so

    error_estimate = max(the kernel's own bound, REPLICA_SAFETY * max |cor - cor_replica|),

and a result whose replicas land more than ``ILL_TOL`` away (or end otherwise: permanent contact
against separation)
is ``STATUS_ILL_CONDITIONED``: double precision cannot resolve the scene (the ``precise`` method
can). Checked against an independent 40-digit reference (restitution.solvers.precise) on random
chains,
long sequences included (tests/test_accuracy.py, docs/accuracy.md).

The perturbations come from a Weyl sequence (deterministic: a result never depends on the run or
the thread count).
"""

import math

from restitution.jit import njit
from restitution.kernels.constants import EPS
from restitution.kernels.layout import (
    OUT_COR,
    OUT_ERR,
    OUT_STATUS,
    STATUS_ILL_CONDITIONED,
    STATUS_OK,
    STATUS_PERMANENT_CONTACT,
)

REPLICA_ULPS = 64.0  # relative size of the replica's perturbations, in ulps
JITTER = REPLICA_ULPS * EPS
# Two replicas: one replica lands close to the first run by chance with a probability that falls
# only like 1/x for a spread x times too small (the ratio of two normal deviates); the larger of
# two falls like 1/x^2. Measured against the 40-digit reference on 120 random chains with ratios
# 1e-2..1e2 (docs/accuracy.md): one replica with factor 4 was below the actual error once.
REPLICAS = 2
REPLICA_SEED = 7919  # Weyl-sequence offset between replicas (a prime: no shared points)
REPLICA_SAFETY = 8.0
# A COR that round-off can move by more than ILL_TOL is not reported (fewer than four digits).
# Below it the estimate says how far: at a grazing contact (the COR minima of the paper's sweeps)
# round-off decides whether a contact of depth ~eps happens, and its impulse is O(sqrt(eps)), so
# an estimate of ~1e-7..1e-6 there is the truth about the scene, not a failure.
ILL_TOL = 1e-4


@njit(cache=True, inline="always")
def weyl(j):
    """The j-th point of a Weyl sequence in [-1, 1) (golden-ratio step)."""
    x = j * 0.6180339887498949 + 0.5
    return 2.0 * (x - math.floor(x)) - 1.0


@njit(cache=True)
def finished(status):
    return status == STATUS_OK or status == STATUS_PERMANENT_CONTACT


@njit(cache=True)
def combine(out, reps):
    """Fold the replicas' rows ``reps`` (REPLICAS, N_OUT) into the kernel row ``out`` (in place;
    see the module docstring)."""
    st = out[OUT_STATUS]
    if not finished(st):
        return out
    spread = 0.0
    for r in range(reps.shape[0]):
        rs = reps[r, OUT_STATUS]
        if not finished(rs):
            # A replica that stops (a root search or budget of the perturbed scene) says nothing
            # about this run's round-off; the other replica, or the kernel's own bound, stands.
            continue
        if rs != st:
            spread = math.inf  # ok against permanent contact: the outcome itself is unsure
        else:
            spread = max(spread, abs(out[OUT_COR] - reps[r, OUT_COR]))
    if not spread <= ILL_TOL / REPLICA_SAFETY:
        out[OUT_STATUS] = STATUS_ILL_CONDITIONED
    out[OUT_ERR] = max(out[OUT_ERR], REPLICA_SAFETY * spread)
    return out


# The sticking limit (a Zeno chatter continued as sticking once m1's approach speed is below
# V_STICK) is checked by two more runs. First the pure chatter, no sticking, with a budget of
# STICK_BUDGET times the contacts reached: if it ends, it is the exact sequence, and the row's
# estimate covers the difference (the paper chain alpha = 20, xi = 0.3, N = 4 chatters at 2e-3
# until the link lifts m1 off by itself, 94 contacts after the cut: the sticking limit's COR was
# 6.6e-6 off, 1.5 v**2, under an estimate of v**2). A chatter that does not end (Zeno) is cut at
# half the speed instead: there the cut's COR error shrinks with the speed v (observed <= 1e-3
# v**2 for two masses), and STICK_SAFETY |cor - cor_half| bounds an error like v (2x) or v**2
# (3x).
STICK_BUDGET = 2.5
# The two-mass walk (kernels.rigid2, ~1 us a contact) checks with a budget of 16 times instead
# (at most ~32,000 contacts, ~30 ms a sticking row). Of 195 random sticking rows (alpha 1-300,
# xi 0.1-20) 43 chatters end by themselves within 300,000 contacts, and 3 of those ended more
# than 2.5 times the row's contacts after the cut (2.9, 5.6 and 10.7 times) with the sticking
# limit outside its estimate (1.05e-9 under 2.8e-11; 4.2e-8 under 2.3e-8): a later cut does not
# see that error, which comes from how such a chatter ends, not from where it is cut. The general
# chain's locator costs 10-100 us a contact, so its budget stays 2.5: of 458 random sticking rows of
# 3-5 masses, 49 chatters ended more than 2.5 times the row's contacts after the start, none outside
# its estimate (worst 0.75; docs/solvers.md).
STICK_BUDGET_RIGID2 = 16.0
STICK_SAFETY = 4.0
PURE_SAFETY = 2.0  # the exact chatter's difference, with room for both runs' round-off


@njit(cache=True)
def stick_check(out, other, safety):
    """Fold a check run ``other`` into a row ``out`` that used the sticking limit (in place): its
    estimate becomes at least ``safety`` |cor - cor_other|; a check run with the other outcome
    (permanent contact against separation) makes it ill-conditioned. An unfinished check run
    leaves the row as it is."""
    if not (finished(out[OUT_STATUS]) and finished(other[OUT_STATUS])):
        return out
    if other[OUT_STATUS] != out[OUT_STATUS]:
        out[OUT_STATUS] = STATUS_ILL_CONDITIONED
        out[OUT_ERR] = math.inf
        return out
    out[OUT_ERR] = max(out[OUT_ERR], safety * abs(out[OUT_COR] - other[OUT_COR]))
    return out
