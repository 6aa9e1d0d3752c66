"""restitution.analysis.sweeps: log grids, chunks with shared boundaries, cusp refinement, status
log."""

import logging
import math

import numpy as np
import pandas as pd
import pytest

from restitution.analysis import sweeps

JUMPS = (0.37, 2.5, 11.0)  # where the synthetic contact count steps up


def step_function(values):
    """A contact count with known jumps (count = number of JUMPS at or below the value)."""
    values = np.asarray(values, dtype=np.float64)
    count = np.searchsorted(np.asarray(JUMPS), values, side="right")
    return pd.DataFrame({"alpha": values, "n_collisions": count, "cor": 1.0 / (1.0 + values)})


def test_log_grid_is_geometric_and_checks_its_ends():
    grid = sweeps.log_grid(0.01, 100.0, 5)
    np.testing.assert_allclose(grid, [0.01, 0.1, 1.0, 10.0, 100.0], rtol=1e-15)
    assert grid[0] == 0.01 and grid[-1] == 100.0
    for lo, hi in [(1.0, 1.0), (2.0, 1.0), (0.0, 1.0)]:
        with pytest.raises(ValueError, match="0 < low < high"):
            sweeps.log_grid(lo, hi, 10)


@pytest.mark.parametrize("n, size", [(600, 300), (601, 300), (10, 3), (2, 2), (7, 50)])
def test_chunks_cover_the_grid_with_shared_boundaries(n, size):
    grid = sweeps.log_grid(0.1, 100.0, n)
    n_chunks = math.ceil((n - 1) / size)  # the formula of common.smk's fig2a_n_chunks
    chunks = [sweeps.chunk(grid, size, k) for k in range(n_chunks)]
    np.testing.assert_array_equal(np.unique(np.concatenate(chunks)), grid)
    assert sum(len(c) for c in chunks) == n + n_chunks - 1  # only boundaries repeat
    for left, right in zip(chunks, chunks[1:], strict=False):
        assert left[-1] == right[0]  # a change of contact count between chunks is not missed
    with pytest.raises(ValueError, match="outside the grid"):
        sweeps.chunk(grid, size, n_chunks)
    with pytest.raises(ValueError, match="outside the grid"):
        sweeps.chunk(grid, size, -1)


@pytest.mark.parametrize("steps", [1, 10, 30])
def test_refine_converges_to_known_jumps_within_the_bisection_bound(steps):
    grid = sweeps.log_grid(0.1, 100.0, 13)
    table = step_function(grid)
    calls = []

    def evaluate(values):
        calls.append(len(values))
        return step_function(values)

    new = sweeps.refine_count_changes(table, evaluate, "alpha", steps)
    assert calls == [len(JUMPS)] * steps  # all brackets at once, one call per step
    assert len(new) == len(JUMPS) * steps  # every evaluated point kept
    points = np.sort(np.concatenate([grid, new["alpha"].to_numpy()]))
    counts = step_function(points)["n_collisions"].to_numpy()
    spacing = np.log(grid[1] / grid[0])
    for jump in JUMPS:
        # The bracket around the jump: its last point below and first point at or above.
        i = np.searchsorted(points, jump, side="right")
        lo, hi = points[i - 1], points[i]
        assert counts[i - 1] != counts[i]
        assert lo <= jump < hi or lo < jump <= hi
        assert np.log(hi / lo) <= spacing * 2.0**-steps + 1e-14  # + round-off of the midpoints


def test_refined_sweep_flags_dedupes_and_sorts():
    grid = sweeps.log_grid(0.1, 100.0, 13)
    out = sweeps.refined_sweep(step_function(grid), step_function, "alpha", 8)
    assert out["alpha"].is_monotonic_increasing and out["alpha"].is_unique
    assert (~out["refined"]).sum() == len(grid)
    assert out["refined"].sum() == len(JUMPS) * 8


def test_refine_without_changes_or_steps_returns_no_rows():
    flat = pd.DataFrame({"alpha": [1.0, 2.0, 4.0], "n_collisions": [3, 3, 3]})
    assert sweeps.refine_count_changes(flat, step_function, "alpha", 20).empty
    table = step_function(sweeps.log_grid(0.1, 100.0, 5))
    empty = sweeps.refine_count_changes(table, step_function, "alpha", 0)
    assert empty.empty and list(empty.columns) == list(table.columns)


def test_refine_bisects_any_column_and_logs(caplog):
    table = step_function(sweeps.log_grid(0.1, 100.0, 7)).rename(columns={"alpha": "beta"})

    def evaluate(values):
        return step_function(values).rename(columns={"alpha": "beta"})

    logger = logging.getLogger("test_sweeps")
    with caplog.at_level(logging.INFO, logger="test_sweeps"):
        new = sweeps.refine_count_changes(table, evaluate, "beta", 30, logger, label="demo")
    assert "beta" in new.columns and len(new) == len(JUMPS) * 30
    assert "demo: 3 changes of the contact count to refine, 30 steps each" in caplog.text


@pytest.mark.parametrize("statuses, expected", [(["ok"] * 4, 0), (["ok", "a", "b", "a"], 3)])
def test_log_not_ok_counts(caplog, statuses, expected):
    table = pd.DataFrame({"alpha": [1.0, 2.0, 3.0, 4.0], "status": statuses})
    logger = logging.getLogger("test_sweeps")
    with caplog.at_level(logging.WARNING, logger="test_sweeps"):
        assert sweeps.log_not_ok(table, logger, "fig", where="alpha") == expected
    if expected:
        assert f"fig: {expected} of 4 scenes not ok: {{'a': 2, 'b': 1}}" in caplog.text
        assert "first at alpha [2.0, 3.0, 4.0]" in caplog.text
    else:
        assert caplog.text == ""


# --- the one definition of a local minimum --------------------------------------------------------


def test_interior_minima_by_hand():
    # Below the left neighbour and not above the right one: a flat bottom counts at its first
    # point, the ends never, a point next to a NaN never (comparisons with NaN are false).
    assert list(sweeps.interior_minima([3.0, 1.0, 2.0, 0.5, 0.5, 4.0])) == [1, 3]
    assert list(sweeps.interior_minima([0.0, 1.0, 2.0])) == []
    assert list(sweeps.interior_minima([2.0, np.nan, 1.0, 3.0])) == []
    assert list(sweeps.interior_minima([2.0, 1.0, 3.0, np.nan])) == [1]
    assert list(sweeps.interior_minima([])) == []
    with pytest.raises(ValueError, match="one-dimensional"):
        sweeps.interior_minima([[1.0, 0.0, 1.0]])


def _curves():
    """Two curves |sin(pi x)| + x/100 on x in (0.3, 5.7): minima near x = 1..5 (unsorted rows)."""
    x = np.geomspace(0.3, 5.7, 401)
    rows = [
        pd.DataFrame({"beta": b, "alpha": x, "cor": np.abs(np.sin(np.pi * x)) + b * x,
                      "n_collisions": np.floor(x).astype(int), "status": "ok"})
        for b in (0.01, 0.02)
    ]  # fmt: skip
    return pd.concat(rows, ignore_index=True).sample(frac=1.0, random_state=1)


def test_local_minima_per_curve_numbered_along_the_axis():
    found = sweeps.local_minima(_curves(), "alpha", by="beta")
    assert list(found.columns) == ["beta", "minimum", "alpha", "cor", "n_collisions"]
    for _, group in found.groupby("beta"):
        assert list(group["minimum"]) == [1, 2, 3, 4, 5]
        # Each minimum is the grid point nearest to the integer (spacing ~0.4 %).
        np.testing.assert_allclose(group["alpha"], [1, 2, 3, 4, 5], rtol=5e-3)
    one = sweeps.local_minima(_curves().query("beta == 0.02"), "alpha")  # no ``by``: one curve
    assert list(one.columns) == ["minimum", "alpha", "cor", "n_collisions"]
    same = found[found["beta"] == 0.02].drop(columns="beta").reset_index(drop=True)
    pd.testing.assert_frame_equal(one, same)


def test_local_minima_skip_rows_not_ok_and_list_asked_columns():
    table = _curves()
    before = sweeps.local_minima(table, "alpha", by="beta")
    at = before.loc[(before["beta"] == 0.01) & (before["minimum"] == 2), "alpha"].iloc[0]
    table.loc[(table["beta"] == 0.01) & (table["alpha"] == at), "status"] = "max_events"
    found = sweeps.local_minima(table, "alpha", by="beta", columns=["alpha", "status"])
    assert list(found.columns) == ["beta", "minimum", "alpha", "status"]
    assert (found["status"] == "ok").all()
    assert at not in set(found.loc[found["beta"] == 0.01, "alpha"])
    assert len(found) == len(before)  # a neighbour of the bad row is the minimum now
    empty = sweeps.local_minima(table.assign(status="nan"), "alpha", by="beta")
    assert empty.empty and list(empty.columns) == [
        "beta",
        "minimum",
        "alpha",
        "cor",
        "n_collisions",
    ]


def test_local_minima_round_off_options():
    """A cusp whose bottom is resolved to round-off: three points 1e-15 apart with a wiggle."""
    x = np.array([0.5, 0.9, 1.0, 1.0 + 1e-15, 1.0 + 2e-15, 1.1, 1.5])
    cor = np.array([0.9, 0.5, 0.1 + 1e-16, 0.1 + 3e-16, 0.1, 0.5, 0.9])
    table = pd.DataFrame({"alpha": x, "cor": cor, "n_collisions": 1})
    assert len(sweeps.local_minima(table, "alpha")) == 2  # the wiggle makes two minima
    merged = sweeps.local_minima(table, "alpha", merge=1e-12)
    assert len(merged) == 1 and merged["cor"].iloc[0] == 0.1  # the lowest of the two
    clustered = sweeps.local_minima(table, "alpha", resolution=1e-12)
    assert len(clustered) == 1 and clustered["cor"].iloc[0] == 0.1
    # Minima further apart than ``merge`` stay apart.
    assert len(sweeps.local_minima(_curves(), "alpha", by="beta", merge=0.1)) == 10


def test_local_minima_refuse_bad_arguments():
    with pytest.raises(ValueError, match="no column \\['x'\\]"):
        sweeps.local_minima(_curves(), "x")
    with pytest.raises(ValueError, match="merge must be >= 0"):
        sweeps.local_minima(_curves(), "alpha", merge=-1e-6)
    with pytest.raises(ValueError, match="resolution must be >= 0"):
        sweeps.local_minima(_curves(), "alpha", resolution=float("nan"))


# --- solving paper scenes along one column, one sweep curve ---------------------------------------


def test_solve_along_matches_the_first_contact_branch():
    """Rigid wall, alpha below alpha*_1 = 0.697 (paper Eqs. 10-11): one contact, COR
    (1 - alpha)/(1 + alpha); the columns are the paper scene's, the swept one as given."""
    alphas = np.array([0.1, 0.3, 0.6])
    table = sweeps.solve_along("alpha", alphas, method="impulsive")
    assert list(table.columns[:5]) == ["alpha", "beta", "xi", "n_masses", "method"]
    assert (table["n_collisions"] == 1).all() and (table["status"] == "ok").all()
    np.testing.assert_allclose(table["cor"], (1 - alphas) / (1 + alphas), rtol=1e-12)
    betas = sweeps.solve_along("beta", [1e-3, 1e-2], {"alpha": 0.3})
    assert list(betas["beta"]) == [1e-3, 1e-2] and (betas["alpha"] == 0.3).all()


def test_solve_along_refuses_bad_scenes():
    with pytest.raises(ValueError, match="column must be 'alpha', 'beta' or 'xi'"):
        sweeps.solve_along("n_masses", [2, 3], {"alpha": 1.0})
    with pytest.raises(ValueError, match="not the swept 'alpha'"):
        sweeps.solve_along("alpha", [1.0], {"alpha": 2.0})
    with pytest.raises(ValueError, match=r"scene may fix only .*\['k'\]"):
        sweeps.solve_along("alpha", [1.0], {"k": 2.0})
    with pytest.raises(ValueError, match="needs an 'alpha'"):
        sweeps.solve_along("beta", [1.0])


def test_sweep_curve_is_the_refined_sweep_and_logs_it(caplog):
    grid = sweeps.log_grid(0.1, 100.0, 13)

    def evaluate(values):
        table = step_function(values)
        return table.assign(status=np.where(table["alpha"] > 50.0, "max_events", "ok"))

    logger = logging.getLogger("test_sweeps")
    with caplog.at_level(logging.INFO, logger="test_sweeps"):
        curve = sweeps.sweep_curve(evaluate, "alpha", grid, 8, logger, "demo")
    pd.testing.assert_frame_equal(curve, sweeps.refined_sweep(evaluate(grid), evaluate, "alpha", 8))
    assert "demo: 2 of 37 scenes not ok" in caplog.text  # the grid points 56.2 and 100
    assert "demo: 37 rows (24 refined), contacts 0..3" in caplog.text
