"""Parameter sweeps with their cusps refined: the shared mechanism of the workflow's sweeps.

The COR against a mass or stiffness ratio has cusp-shaped minima where one more contact just
grazes the wall: the contact count ``n_collisions`` changes there and the COR is continuous with a
kink. A grid misses their depth, so every grid interval whose count changes is bisected on the
count (geometric midpoints: halving on the log axis), all intervals at once with one batch
evaluation per step, and every point evaluated is kept. If the count changes more than once inside
one interval, bisection resolves one of the changes.

- :func:`log_grid` -- the log-spaced grid of a sweep;
- :func:`chunk` -- one job's share of a grid, the boundary point shared with the next chunk;
- :func:`solve_along` -- ``restitution.solve_many`` over paper scenes that differ in one column;
- :func:`refine_count_changes` -- the bisection, returning the new rows;
- :func:`refined_sweep` -- grid rows plus refined rows, flagged, de-duplicated and sorted;
- :func:`sweep_curve` -- one curve of a sweep job: grid, refinement, status warning, summary log;
- :func:`log_not_ok` -- the warning for rows whose status is not ``ok``;
- :func:`interior_minima` and :func:`local_minima` -- the local minima of a curve (the cusps and
  any smooth minimum), the one definition every figure, table and caption uses.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping, Sequence

import numpy as np
import pandas as pd

from restitution.kernels.constants import MAX_EVENTS_DEFAULT

__all__ = [
    "chunk",
    "interior_minima",
    "local_minima",
    "log_grid",
    "log_not_ok",
    "refine_count_changes",
    "refined_sweep",
    "solve_along",
    "sweep_curve",
]

# The paper's scene columns in the order ``solve_along`` writes them, with their defaults.
_PAPER_SCENE = {"alpha": None, "beta": 0.0, "xi": 0.0, "n_masses": 2}


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


def solve_along(
    column: str,
    values,
    scene: Mapping | None = None,
    method: str = "auto",
    max_events: int = MAX_EVENTS_DEFAULT,
    progress: bool = False,
) -> pd.DataFrame:
    """Solve paper scenes that differ only in ``column``: one row per value, in order.

    Parameters
    ----------
    column : str
        The swept column: ``alpha``, ``beta`` or ``xi``.
    values : array_like
        Its values.
    scene : mapping, optional
        The fixed columns among ``alpha, beta, xi, n_masses`` (defaults: beta 0, xi 0, two
        masses; ``alpha`` is required unless swept).
    method, max_events, progress
        Passed to :func:`restitution.solve_many` (``method`` as the column of every row).

    Returns
    -------
    pandas.DataFrame
        Columns ``alpha, beta, xi, n_masses, method`` and the result columns.

    Examples
    --------
    >>> table = solve_along("alpha", [0.5, 2.0], {"beta": 0.1})  # doctest: +SKIP
    >>> list(table.columns[:5])  # doctest: +SKIP
    ['alpha', 'beta', 'xi', 'n_masses', 'method']
    """
    from restitution.api import solve_many

    if column not in ("alpha", "beta", "xi"):
        raise ValueError(f"solve_along: column must be 'alpha', 'beta' or 'xi', got {column!r}")
    scene = dict(scene or {})
    unknown = sorted(set(scene) - set(_PAPER_SCENE) | ({column} & set(scene)))
    if unknown:
        raise ValueError(
            f"solve_along: scene may fix only {sorted(set(_PAPER_SCENE) - {column})} "
            f"(not the swept {column!r}), got {unknown}"
        )
    columns = {**_PAPER_SCENE, **scene}
    if column != "alpha" and columns["alpha"] is None:
        raise ValueError("solve_along: scene needs an 'alpha' when another column is swept")
    frame = {
        name: np.asarray(values, dtype=np.float64)
        if name == column
        else (int(value) if name == "n_masses" else float(value))
        for name, value in columns.items()
    }
    scenes = pd.DataFrame({**frame, "method": method})
    return solve_many(scenes, max_events=max_events, progress=progress)


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


def sweep_curve(
    evaluate: Callable[[np.ndarray], pd.DataFrame],
    column: str,
    grid: np.ndarray,
    steps: int,
    logger: logging.Logger | None = None,
    label: str = "",
    progress: bool = False,
) -> pd.DataFrame:
    """One curve of a sweep job: the grid evaluated, its cusps refined, the rows not ok warned.

    The body every refined sweep of the workflow shares: :func:`refined_sweep` of
    ``evaluate(grid)``, then (with a ``logger``) :func:`log_not_ok` and one summary line (rows,
    refined rows, contact counts, COR range, largest error estimate where there is one).

    Parameters
    ----------
    evaluate : callable
        ``evaluate(values) -> DataFrame``, as for :func:`refine_count_changes`; its table needs
        the columns ``n_collisions``, ``cor`` and ``status``.
    column : str
        The swept column.
    grid : numpy.ndarray
        The grid values (e.g. :func:`log_grid` or one :func:`chunk` of it).
    steps : int
        Bisection steps per change of the contact count.
    logger, label, progress
        As for :func:`refine_count_changes`.

    Returns
    -------
    pandas.DataFrame
        As :func:`refined_sweep`.

    Examples
    --------
    >>> def evaluate(x):
    ...     x = np.asarray(x)
    ...     return pd.DataFrame({"x": x, "n_collisions": (x > 2.0).astype(int),
    ...                          "cor": 1.0 / (1.0 + x), "status": "ok"})
    >>> curve = sweep_curve(evaluate, "x", log_grid(1.0, 4.0, 3), 10)
    >>> len(curve), int(curve["refined"].sum())
    (13, 10)
    """
    table = refined_sweep(evaluate(grid), evaluate, column, steps, logger, label, progress)
    if logger is not None:
        log_not_ok(table, logger, label, where=column)
        prefix = f"{label}: " if label else ""
        errors = table["error_estimate"].max() if "error_estimate" in table else np.nan
        logger.info(
            "%s%d rows (%d refined), contacts %d..%d, COR %.6f..%.6f, largest error estimate %.2g",
            prefix,
            len(table),
            table["refined"].sum(),
            table["n_collisions"].min(),
            table["n_collisions"].max(),
            table["cor"].min(),
            table["cor"].max(),
            errors,
        )
    return table


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


def interior_minima(values) -> np.ndarray:
    """Indices of the interior local minima of a sequence (a curve sorted along its axis).

    Point ``i`` is a minimum when it is below its left neighbour and not above its right one, so
    a flat bottom counts once, at its first point. The ends never count.

    Parameters
    ----------
    values : array_like
        The values along the curve (a point that is NaN or next to a NaN is never a minimum).

    Returns
    -------
    numpy.ndarray
        The indices, increasing.

    Examples
    --------
    >>> interior_minima([3.0, 1.0, 2.0, 0.5, 0.5, 4.0])
    array([1, 3])
    """
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 1:
        raise ValueError(f"interior_minima: values must be one-dimensional, got shape {v.shape}")
    return np.flatnonzero((v[1:-1] < v[:-2]) & (v[1:-1] <= v[2:])) + 1


def local_minima(
    table: pd.DataFrame,
    along: str,
    by: str | Sequence[str] = (),
    value: str = "cor",
    columns: Sequence[str] | None = None,
    resolution: float | None = None,
    merge: float | None = None,
) -> pd.DataFrame:
    """The local minima of ``value`` along ``along`` of every curve of ``table``, numbered.

    Only rows whose ``status`` is ``ok`` count (all rows if there is no ``status`` column). Each
    curve (one value of the ``by`` columns; the whole table if none) is sorted along ``along``
    and its :func:`interior_minima` are listed from small ``along`` up as ``minimum`` 1, 2, ...

    Two options remove round-off from refined cusps, whose last points lie a few ulps apart:

    - ``resolution``: before the minima are looked for, points of a curve closer than this on
      the log axis (``log(x[i+1]/x[i]) <= resolution``) are one point, the lowest;
    - ``merge``: minima closer than this (relative: ``x[k+1]/x[k] - 1 <= merge``) are one
      minimum, the lowest.

    Parameters
    ----------
    table : pandas.DataFrame
        The sweep: columns ``along``, ``value``, the ``by`` columns and ``columns``.
    along : str
        The curve's axis (positive where ``resolution`` or ``merge`` are used).
    by : str or sequence of str
        The columns that name a curve (NaN is a name of its own).
    value : str
        The column whose minima are sought.
    columns : sequence of str, optional
        The columns listed after ``minimum``; default ``(along, value, "n_collisions")``.
    resolution, merge : float, optional
        As above (``>= 0``); None or 0 leaves the points as they are.

    Returns
    -------
    pandas.DataFrame
        Columns ``*by, "minimum", *columns``, curves in sorted order, a fresh index.

    Examples
    --------
    >>> sweep = pd.DataFrame({"beta": 0.0, "alpha": [0.5, 1.0, 2.0, 4.0, 8.0],
    ...                       "cor": [0.4, 0.2, 0.5, 0.3, 0.6], "n_collisions": [1, 2, 2, 3, 3]})
    >>> local_minima(sweep, "alpha", by="beta")
       beta  minimum  alpha  cor  n_collisions
    0   0.0        1    1.0  0.2             2
    1   0.0        2    4.0  0.3             3
    """
    by = [by] if isinstance(by, str) else list(by)
    columns = [along, value, "n_collisions"] if columns is None else list(columns)
    for name, option in (("resolution", resolution), ("merge", merge)):
        if option is not None and not option >= 0:
            raise ValueError(f"local_minima: {name} must be >= 0 (or None), got {option!r}")
    missing = sorted({along, value, *by, *columns} - set(table.columns))
    if missing:
        raise ValueError(f"local_minima: the table has no column {missing} (along = {along!r})")
    ok = table[table["status"] == "ok"] if "status" in table else table
    curves = ok.groupby(by, sort=True, dropna=False) if by else [((), ok)]
    found = []
    for _, curve in curves:
        curve = curve.sort_values(along).reset_index(drop=True)
        if resolution:
            step = np.diff(np.log(curve[along].to_numpy()))
            cluster = np.concatenate([[0], np.cumsum(step > resolution)])
            curve = curve.loc[curve.groupby(cluster)[value].idxmin().to_numpy()]
        rows = curve.iloc[interior_minima(curve[value].to_numpy())][[*by, *columns]].copy()
        if merge:
            x = rows[along].to_numpy()
            cluster = np.concatenate([[0], np.cumsum(x[1:] / x[:-1] - 1 > merge)])
            rows = rows.loc[rows.groupby(cluster)[value].idxmin().to_numpy()]
        rows.insert(len(by), "minimum", np.arange(1, len(rows) + 1))
        found.append(rows)
    if not found:
        return pd.DataFrame(columns=[*by, "minimum", *columns])
    return pd.concat(found, ignore_index=True)
