"""Parameter sweeps with their cusps refined: the shared mechanism of the workflow's sweeps.

The COR against a mass or stiffness ratio has cusp-shaped minima where one more contact just
grazes the wall: the contact count ``n_collisions`` changes there and the COR is continuous with a
kink. A grid misses their depth, so every grid interval whose count changes is bisected on the
count (geometric midpoints: halving on the log axis), all intervals at once with one batch
evaluation per step, and every point evaluated is kept. If the count changes more than once inside
one interval, bisection resolves one of the changes.

- :func:`log_grid` -- the log-spaced grid of a sweep;
- :func:`chunk` -- one job's share of a grid, the boundary point shared with the next chunk;
- :func:`refine_count_changes` -- the bisection, returning the new rows;
- :func:`refined_sweep` -- grid rows plus refined rows, flagged, de-duplicated and sorted;
- :func:`log_not_ok` -- the warning for rows whose status is not ``ok``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np
import pandas as pd

__all__ = ["chunk", "log_grid", "log_not_ok", "refine_count_changes", "refined_sweep"]


def log_grid(lo: float, hi: float, n: int) -> np.ndarray:
    """``n`` log-spaced values from ``lo`` to ``hi`` (both included).

    Parameters
    ----------
    lo, hi : float
        The ends of the grid, ``0 < lo < hi``.
    n : int
        Number of grid points.

    Returns
    -------
    numpy.ndarray
        ``numpy.geomspace(lo, hi, n)``.

    Examples
    --------
    >>> log_grid(0.1, 10.0, 3)
    array([ 0.1,  1. , 10. ])
    """
    if not 0 < lo < hi:
        raise ValueError(f"a log grid needs 0 < low < high, got low = {lo!r}, high = {hi!r}")
    return np.geomspace(lo, hi, n)


def chunk(grid: np.ndarray, size: int, index: int) -> np.ndarray:
    """Chunk ``index`` of ``grid``: indices ``index*size .. (index+1)*size`` inclusive.

    Neighbouring chunks share their boundary point, so a change of the contact count between
    two chunks is inside one of them and is refined (the aggregation drops the duplicate row).
    There are ``ceil((len(grid) - 1) / size)`` chunks.

    Parameters
    ----------
    grid : numpy.ndarray
        The full grid (at least two points).
    size : int
        Grid intervals per chunk.
    index : int
        The chunk, ``0 <= index < ceil((len(grid) - 1) / size)``.

    Returns
    -------
    numpy.ndarray
        ``size + 1`` grid points (fewer in the last chunk).

    Examples
    --------
    >>> grid = log_grid(1.0, 1e4, 5)
    >>> chunk(grid, 2, 0), chunk(grid, 2, 1)
    (array([  1.,  10., 100.]), array([  100.,  1000., 10000.]))
    """
    start = index * size
    if not 0 <= start < len(grid) - 1:
        raise ValueError(
            f"chunk {index} is outside the grid of {len(grid)} points ({size} a chunk)"
        )
    return grid[start : min(start + size, len(grid) - 1) + 1]


def refine_count_changes(
    table: pd.DataFrame,
    evaluate: Callable[[np.ndarray], pd.DataFrame],
    column: str,
    steps: int,
    logger: logging.Logger | None = None,
    label: str = "",
    progress: bool = False,
) -> pd.DataFrame:
    """Bisect, on a log axis, every interval of ``table`` whose contact count changes.

    Between neighbours along ``column`` whose ``n_collisions`` differ, the bracket is halved
    ``steps`` times at its geometric midpoint, keeping the half where the count changes; all
    brackets are evaluated together, one ``evaluate`` call per step.

    Parameters
    ----------
    table : pandas.DataFrame
        Evaluated points with columns ``column`` (positive) and ``n_collisions``.
    evaluate : callable
        ``evaluate(values) -> DataFrame`` with one row per value, in order, and a column
        ``n_collisions``.
    column : str
        The swept column (``alpha``, ``beta``, ...).
    steps : int
        Bisection steps; each bracket ends ``2**-steps`` of its initial width on the log axis.
    logger : logging.Logger, optional
        Receives the number of changes and the final brackets.
    label : str
        Prefix of the log messages.
    progress : bool
        A progress bar over the steps (tqdm).

    Returns
    -------
    pandas.DataFrame
        Every evaluated row, step by step (``table.iloc[:0]`` if nothing was refined).

    Examples
    --------
    >>> def evaluate(x):
    ...     return pd.DataFrame({"x": x, "n_collisions": (np.asarray(x) > 2.0).astype(int)})
    >>> new = refine_count_changes(evaluate(log_grid(1.0, 4.0, 3)), evaluate, "x", 30)
    >>> len(new), bool(abs(new["x"].iloc[-1] / 2.0 - 1.0) < 1e-8)
    (30, True)
    """
    prefix = f"{label}: " if label else ""
    table = table.sort_values(column)
    values = table[column].to_numpy()
    count = table["n_collisions"].to_numpy()
    jumps = np.flatnonzero(count[1:] != count[:-1])
    if logger is not None:
        logger.info(
            "%s%d changes of the contact count to refine, %d steps each", prefix, len(jumps), steps
        )
    if steps == 0 or len(jumps) == 0:
        return table.iloc[:0]
    lo, hi = values[jumps], values[jumps + 1]
    n_lo, n_hi = count[jumps], count[jumps + 1]
    rows = []
    if progress:
        from tqdm.auto import tqdm

        loop = tqdm(range(steps), desc="refine")
    else:
        loop = range(steps)
    for _ in loop:
        mid = np.sqrt(lo * hi)
        new = evaluate(mid)
        rows.append(new)
        n_mid = new["n_collisions"].to_numpy()
        same = n_mid == n_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        n_hi = np.where(same, n_hi, n_mid)
    if logger is not None:
        step = np.abs(n_hi - n_lo)
        logger.info(
            "%sfinal brackets: widest %.3g decades of %s; %d of %d end on a jump of more than one "
            "contact (largest %d)",
            prefix,
            np.log10(hi / lo).max(),
            column,
            int((step > 1).sum()),
            len(step),
            int(step.max()),
        )
        if len(jumps) <= 20:
            logger.info(
                "%scount changes at %s %s",
                prefix,
                column,
                ", ".join(f"{v:.10g}" for v in np.sqrt(lo * hi)),
            )
    return pd.concat(rows, ignore_index=True)


def refined_sweep(
    grid_table: pd.DataFrame,
    evaluate: Callable[[np.ndarray], pd.DataFrame],
    column: str,
    steps: int,
    logger: logging.Logger | None = None,
    label: str = "",
    progress: bool = False,
) -> pd.DataFrame:
    """The evaluated grid plus its cusp refinement, one row per value of ``column``, sorted.

    Parameters
    ----------
    grid_table : pandas.DataFrame
        ``evaluate(grid)``: the grid points.
    evaluate, column, steps, logger, label, progress
        As for :func:`refine_count_changes`.

    Returns
    -------
    pandas.DataFrame
        Grid rows (``refined`` False) and bisection rows (``refined`` True), the first row of
        each ``column`` value kept, sorted by ``column`` with a fresh index.
    """
    table = grid_table.assign(refined=False)
    extra = refine_count_changes(table, evaluate, column, steps, logger, label, progress)
    return (
        pd.concat([table, extra.assign(refined=True)], ignore_index=True)
        .drop_duplicates(subset=column, keep="first")
        .sort_values(column, ignore_index=True)
    )


def log_not_ok(
    table: pd.DataFrame, logger: logging.Logger, label: str = "", where: str | None = None
) -> int:
    """Warn about rows whose ``status`` is not ``ok``; return their number.

    Parameters
    ----------
    table : pandas.DataFrame
        Results with a ``status`` column.
    logger : logging.Logger
        Receives one warning if any row is not ok (nothing otherwise).
    label : str
        Prefix of the message.
    where : str, optional
        A column whose first five values among the bad rows are quoted.

    Returns
    -------
    int
        The number of rows not ok.

    Examples
    --------
    >>> log_not_ok(pd.DataFrame({"status": ["ok", "max_events"]}), logging.getLogger("demo"))
    1
    """
    bad = (table["status"] != "ok").to_numpy()
    if bad.any():
        prefix = f"{label}: " if label else ""
        counts = table.loc[bad, "status"].value_counts().to_dict()
        if where is None:
            logger.warning("%s%d of %d scenes not ok: %s", prefix, bad.sum(), len(table), counts)
        else:
            logger.warning(
                "%s%d of %d scenes not ok: %s; first at %s %s",
                prefix,
                bad.sum(),
                len(table),
                counts,
                where,
                table.loc[bad, where].head(5).tolist(),
            )
    return int(bad.sum())
