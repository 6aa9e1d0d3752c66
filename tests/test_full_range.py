"""Declared ranges are handled ranges (issue 17): every parameter of the paper's form drawn over
its full declared range (restitution.model.chain.RANGES), extreme ends and subnormals included,
through the public API, and the general form (masses, springs, dashpots, k_contact) over its
value ranges and its ratio ranges (restitution.model.chain.RATIOS). Each row is either a
finished result (ok or permanent contact: at least one contact, a passive COR in [-1e-12,
1 + 1e-12], the energy account closed within max(1e-9, its error estimate)) or an explicit
non-ok status with NaN COR; never a traceback, never unbounded (a general chain of extreme
ratios once ran for minutes: the dissipation of a permanent contact was integrated numerically
to 80 e-foldings of a decay 1e10 times slower than its fastest mode; it is now in closed
form)."""

import math

import numpy as np
import pandas as pd
import pytest

import restitution
from restitution.model.chain import RANGES, RATIOS

FINISHED = {"ok", "permanent_contact"}


def _check(frame: pd.DataFrame) -> None:
    for row in frame.itertuples():
        where = f"row {row.Index}: {row}"
        if row.status in FINISHED:
            assert row.n_collisions >= 1, where
            # Passive to within the row's own error bound (1e-12 at least): alpha = 1e-4,
            # beta = 1e6, xi = 1e3 (an overdamped pair, a contact of 3e5 time units) finishes
            # with COR 1 + 5.8e-11 under an estimate of 2.3e-9.
            bound = max(1e-12, row.error_estimate)
            assert -bound <= row.cor <= 1 + bound, where
            total = row.e_translational + row.e_vibrational + row.e_dissipated
            # The account closes to 1e-9, or to the row's own error bound where that is
            # larger (a row that claims 1e-6 is not held to 1e-9 in its energies).
            assert abs(total - 1.0) <= max(1e-9, row.error_estimate), where
        else:
            assert math.isnan(row.cor), where


def _log_uniform(rng, low, high, size):
    return 10.0 ** rng.uniform(math.log10(low), math.log10(high), size)


def test_paper_form_over_its_whole_declared_range():
    rng = np.random.default_rng(17)
    a, b, x = RANGES["alpha"], RANGES["beta"], RANGES["xi"]
    # Ends and subnormals first, then log-uniform draws over every decade of each range.
    alphas = [a.low, 1e-4, 1.0, 1e4, a.high]
    betas = [b.low, 5e-324, 1e-300, 1e-20, 1e-10, 1e-3, b.high]
    xis = [x.low, 5e-324, 1e-3, 1.0, x.high]
    ends = pd.DataFrame(
        [(al, be, xi, n) for al in alphas for be in betas for xi in xis for n in (2, 3)],
        columns=["alpha", "beta", "xi", "n_masses"],
    )
    n = 300
    draws = pd.DataFrame(
        {
            "alpha": _log_uniform(rng, a.low, a.high, n),
            "beta": np.where(rng.random(n) < 0.3, 0.0, _log_uniform(rng, 1e-300, b.high, n)),
            "xi": np.where(rng.random(n) < 0.3, 0.0, _log_uniform(rng, 1e-300, x.high, n)),
            "n_masses": rng.choice([2, 3, 4, 6, 8], n),
        }
    )
    frame = pd.concat([ends, draws], ignore_index=True)
    _check(restitution.solve_many(frame, max_events=20_000))


@pytest.mark.slow
def test_the_longest_declared_chain_finishes():
    """n_masses at the top of its range: a finished result or an honest status, bounded work."""
    top = int(RANGES["n_masses"].high)
    frame = pd.DataFrame({"alpha": [1.0, 10.0], "xi": [0.0, 1.0], "n_masses": [top, top]})
    _check(restitution.solve_many(frame))


def _general_draws(rng, count):
    """General chains over the declared ranges: scales m_1, k_12 over 180 decades, ratios over
    RATIOS (log-uniform), half the links with a dashpot of damping ratio 1e-6..1e3, the contact
    rigid or beta = k_12/k_contact over 1e-300..1e6 (k_contact finite)."""
    lo_m, hi_m = RATIOS["masses[i]/masses[0]"]
    lo_k, hi_k = RATIOS["springs[i]/springs[0]"]
    rows = []
    for _ in range(count):
        n = int(rng.choice([2, 3, 5, 8]))
        m1, k1 = _log_uniform(rng, 1e-90, 1e90, 2)
        masses = m1 * np.concatenate([[1.0], _log_uniform(rng, lo_m, hi_m, n - 1)])
        springs = k1 * np.concatenate([[1.0], _log_uniform(rng, lo_k, hi_k, n - 2)])
        omega = math.sqrt(k1 / masses[0] + k1 / masses[1])
        zeta = np.where(rng.random(n - 1) < 0.5, 0.0, _log_uniform(rng, 1e-6, 1e3, n - 1))
        low = max(1e-300, k1 * 1e-300)  # k_contact = k_12/beta stays a float
        beta = 0.0 if rng.random() < 0.4 else float(_log_uniform(rng, low, 1e6, 1)[0])
        rows.append(
            {
                "masses": masses.tolist(),
                "springs": springs.tolist(),
                "dashpots": (zeta * 2.0 * k1 / omega).tolist(),
                "k_contact": math.inf if beta == 0.0 else k1 / beta,
            }
        )
    return pd.DataFrame(rows)


def test_general_form_over_its_whole_declared_range():
    rng = np.random.default_rng(1717)
    frame = _general_draws(rng, 120)
    # Every draw is in range: the checks raise before any work otherwise.
    out = restitution.solve_many(frame, max_events=20_000)
    assert len(out) == len(frame)
    _check(out)
