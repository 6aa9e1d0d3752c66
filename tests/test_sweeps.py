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
