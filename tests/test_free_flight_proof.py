"""The end of an integrated free flight: ``integrators.no_contact_possible`` and its kept extents.

The proof bounds how far m1 can trail the centre of mass by the extent of every link at the
internal energy. A nonlinear link's extent is a bisection; the step loops keep it between steps,
found for a slightly higher energy. That bound must stay an upper bound: the kept extent is never
below the extent at the present energy, and a proof with it never succeeds where the proof with
the exact extent fails.
"""

import numpy as np

from restitution.kernels.integrators import (
    EXTENT_PAD,
    EXTENT_REUSE,
    internal_energy,
    no_contact_possible,
)
from restitution.model import laws


def _chain(rng):
    """Two or three masses, the first link a scissor link (the others linear)."""
    n = int(rng.integers(2, 4))
    m = np.concatenate([[1.0], rng.uniform(0.3, 3.0, n - 1)])
    lk = np.array(
        [
            laws.scissor_params(
                rng.uniform(0.3, 3.0), rng.uniform(1e-3, 0.1), rng.uniform(0.5, 60.0), np.pi / 4
            )
        ]  # fmt: skip
        + [laws.linear_structure_params(rng.uniform(0.3, 3.0)) for _ in range(n - 2)]
    )
    return m, lk


def _free_state(rng, m):
    """Positions near the wall, stretches and velocities of either sign, the centre of mass
    moving away from the wall (else there is nothing to prove)."""
    n = m.shape[0]
    u = np.concatenate([[0.0], np.cumsum(rng.normal(0.0, 0.5, n - 1))])
    v = rng.normal(0.0, 0.5, n)
    v += rng.uniform(0.05, 1.5) - (m @ v) / m.sum()
    return np.concatenate([u, v, [0.0, 0.0]])


def test_kept_extents_bound_the_exact_ones():
    rng = np.random.default_rng(11)
    agree = 0
    for _ in range(300):
        m, lk = _chain(rng)
        n = m.shape[0]
        y = _free_state(rng, m)
        xp = rng.uniform(-0.5, 3.0)
        e = internal_energy(y, m, lk)
        fresh = np.full((n - 1, 2), -1.0)
        exact = no_contact_possible(y, m, lk, xp, fresh)
        # a fresh call finds the extent for the padded energy
        assert fresh[0, 0] == e * EXTENT_PAD
        assert fresh[0, 1] >= laws.structure_extent(lk[0], e, 1.0)
        # kept from an earlier, higher energy anywhere in the reuse window
        kept = np.full((n - 1, 2), -1.0)
        e_hat = e / (1.0 - rng.uniform(0.0, 1.0) * (1.0 - EXTENT_REUSE))
        kept[0] = e_hat, laws.structure_extent(lk[0], e_hat, 1.0)
        before = kept.copy()
        cached = no_contact_possible(y, m, lk, xp, kept)
        if EXTENT_REUSE * e_hat <= e <= e_hat:
            assert (kept == before).all()  # reused, not found again
        assert kept[0, 1] >= laws.structure_extent(lk[0], e, 1.0)
        assert not (cached and not exact)  # never a proof the exact extent refuses
        agree += cached == exact
    assert agree > 250  # the kept bound is tight: the same answer nearly always


def test_an_energy_above_the_kept_one_finds_the_extent_again():
    rng = np.random.default_rng(3)
    m, lk = _chain(rng)
    n = m.shape[0]
    y = _free_state(rng, m)
    e = internal_energy(y, m, lk)
    kept = np.array([[0.5 * e, laws.structure_extent(lk[0], 0.5 * e, 1.0)]] * (n - 1))
    no_contact_possible(y, m, lk, 0.0, kept)
    assert kept[0, 0] == e * EXTENT_PAD  # an extent for a lower energy is no bound: found again
    assert kept[0, 1] == laws.structure_extent(lk[0], e * EXTENT_PAD, 1.0)
