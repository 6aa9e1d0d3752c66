"""Declared ranges are handled ranges (issue 17): every parameter of the paper's form drawn over
its full declared range (restitution.chain.RANGES), extreme ends and subnormals included, through
the public API. Each row is either a finished result (ok: at least one contact, a passive COR in
[-1e-12, 1 + 1e-12], the energy account closed) or an explicit non-ok status with NaN COR; never a
traceback. (The general form is not here yet: one draw of extreme mass/spring ratios ran for
minutes without ending, a hole in the work budget still to close.)"""

import math

import numpy as np
import pandas as pd
import pytest

import restitution
from restitution.chain import RANGES

FINISHED = {"ok", "permanent_contact"}


def _check(frame: pd.DataFrame) -> None:
    for row in frame.itertuples():
        where = f"row {row.Index}: {row}"
        if row.status in FINISHED:
            assert row.n_collisions >= 1, where
            assert -1e-12 <= row.cor <= 1 + 1e-12, where
            if row.status == "ok":
                total = row.e_translational + row.e_vibrational + row.e_dissipated
                assert abs(total - 1.0) <= 1e-9, where
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
