"""A numerical row whose check run did not finish is ``unchecked``, never ``ok``.

The numerical methods estimate their error from a second run at another setting
(restitution.solvers.numerical). Where only that run fails, the row keeps the finished run's COR
with an infinite estimate, under its own status: an ``ok`` row is a finished, checked result.
"""

import math

import numpy as np

import restitution as R
from restitution.kernels import layout as LY
from restitution.solvers import numerical as NU
from restitution.solvers.result import MESSAGES

HERTZ3 = R.Chain([1.0, 0.5, 2.0], [0.3, 1.2], contact={"law": "hertz", "k": 50.0})
# A work budget (right-hand sides, deterministic) between the needs of the run at rtol 1e-6 and
# of its finer run at rtol 1e-8: 440..570 leave only the finer run unfinished.
SPLIT_WORK = 500


def test_adaptive_row_whose_finer_run_ran_out_is_unchecked():
    out, _ = NU.solve_chain(HERTZ3, "adaptive", 1e-6, max_work=SPLIT_WORK)
    assert out[LY.OUT_STATUS] == LY.STATUS_UNCHECKED
    assert math.isfinite(out[LY.OUT_COR]) and math.isinf(out[LY.OUT_ERR])
    # the setting's own run, finished: its COR is the full budget's run at that rtol
    full, _ = NU.solve_chain(HERTZ3, "adaptive", 1e-6)
    assert full[LY.OUT_STATUS] == LY.STATUS_OK
    assert abs(out[LY.OUT_COR] - full[LY.OUT_COR]) <= full[LY.OUT_ERR]
    # too small for both runs: not finished at all
    cut, _ = NU.solve_chain(HERTZ3, "adaptive", 1e-6, max_work=300)
    assert cut[LY.OUT_STATUS] == LY.STATUS_WORK_BUDGET and math.isnan(cut[LY.OUT_COR])


def test_batch_rows_are_the_single_rows():
    rows = NU.solve_chains([HERTZ3, HERTZ3], "adaptive", 1e-6, max_work=SPLIT_WORK)
    single, _ = NU.solve_chain(HERTZ3, "adaptive", 1e-6, max_work=SPLIT_WORK)
    np.testing.assert_array_equal(rows[0], single)
    np.testing.assert_array_equal(rows[1], single)


def test_verlet_row_with_a_failed_check_is_unchecked_through_the_api():
    """Verlet's runs at h and h/4 check h/2; at the loosest step one of them opens its energy
    account on this plastic chain while the h/2 run closes it."""
    r = R.solve(
        masses=[1.0, 0.5, 2.0],
        springs=[0.3, 1.2],
        contact={"law": "plastic", "k": 50.0, "eta": 1.5, "dr": 0.3},
        method="verlet",
        step=0.25,
    )
    assert r.status == "unchecked"
    assert math.isfinite(r.cor) and math.isinf(r.error_estimate)
    assert "error estimate" in MESSAGES["unchecked"]


def test_ok_rows_have_finite_estimates_in_a_table():
    """Every ok row of a table of such scenes has a finite estimate (the unchecked ones are
    labelled)."""
    import pandas as pd

    frame = pd.DataFrame(
        {
            "masses": [[1.0, 0.5, 2.0]] * 3,
            "springs": [[0.3, 1.2]] * 3,
            "contact": ['{"law": "plastic", "k": 50.0, "eta": 1.5, "dr": 0.3}'] * 3,
            "method": ["verlet"] * 3,
            "step": [0.25, 0.05, 0.01],
        }
    )
    out = R.solve_many(frame)
    ok = out[out["status"] == "ok"]
    assert len(ok) >= 1 and np.isfinite(ok["error_estimate"]).all()
    assert out["status"].iloc[0] == "unchecked"
