"""Fig. 8(a) curves: where the contact count steps in the (alpha, beta) plane, traced exactly.

Seeds: the exact rigid-wall grazing points alpha*_1..alpha*_n_max (``special_points``); from each,
``restitution.analysis.cormap.trace_all`` follows the grazing condition by pseudo-arclength
continuation
and, where a curve ends on another, follows the conditions that vanish there (contact splits).
Then the map's grid is checked: every step of the count between grid neighbours along alpha that
no traced curve crosses is bisected on the count and traced from there too (components not
connected to beta = 0). The table records, for the whole grid, how many count steps the curves
explain (``coverage``, logged and stored in the table's provenance).

Two more tables for the map: the count steps no traced curve explains (``untraced``, drawn so that
none is hidden) and the smooth minima of the COR along alpha at beta > 0 (``minima``: grid minima
with one count on both sides, refined by bounded Brent with the exact solver, linked into curves),
each within the range where a grid row resolves its count steps (``resolved_limit``).
"""

import math

import numpy as np
import pandas as pd


def _crossings(curves, beta, lo, hi) -> bool:
    """Whether some traced curve crosses the segment (lo, hi) at this beta (in the grid's cell)."""
    for c in curves:
        a, b = np.asarray(c.alpha), np.asarray(c.beta)
        for i in range(a.size - 1):
            b0, b1 = b[i], b[i + 1]
            if beta == 0.0:
                hit = b0 == 0.0 and lo <= a[i] <= hi
            else:
                hit = min(b0, b1) <= beta <= max(b0, b1) and (
                    lo / 1.5 <= min(a[i], a[i + 1]) and max(a[i], a[i + 1]) <= hi * 1.5
                )
            if hit:
                return True
    return False


def grid_steps(grid: pd.DataFrame, n_max: int) -> list:
    """(alpha_lo, alpha_hi, beta, n_lo, n_hi) of the grid's count steps along alpha between
    counts up to n_max + 1 (the steps the curves of contacts 1..n_max can explain)."""
    out = []
    for beta, row in grid.groupby("beta"):
        row = row.sort_values("alpha")
        a, n = row["alpha"].to_numpy(), row["n_collisions"].to_numpy()
        for i in np.flatnonzero(np.diff(n) != 0):
            if max(n[i], n[i + 1]) <= n_max + 1:
                out.append((a[i], a[i + 1], beta, n[i], n[i + 1]))
    return out


def unexplained_steps(steps, curves) -> list:
    """The grid steps no traced curve crosses."""
    return [s for s in steps if not _crossings(curves, s[2], s[0], s[1])]


def resolved_limit(alpha, n, min_cells: int, run: int = 2) -> float:
    """Largest alpha up to which one grid row resolves its count steps: below the first of
    ``run`` consecutive steps each fewer than ``min_cells`` cells after the one before (a step of
    two counts at once counts as two steps 0 cells apart). There the cusps come closer than the
    grid and its colours alias; an isolated close pair (two curves crossing) does not end the
    range. inf: all resolved."""
    cells = []  # (position, gap to the previous step in cells)
    last = None
    for i in np.flatnonzero(np.diff(n) != 0):
        for _ in range(max(1, abs(int(n[i + 1]) - int(n[i])))):
            cells.append((i, math.inf if last is None else i - last))
            last = i
    close = 0
    for k, (_, gap) in enumerate(cells):
        close = close + 1 if gap < min_cells else 0
        if close >= run:
            return float(alpha[cells[k - run][0]])
    return math.inf


def resolved_limits(grid: pd.DataFrame, min_cells: int) -> dict:
    """{beta: resolved_limit} of every grid row."""
    out = {}
    for beta, row in grid.groupby("beta"):
        row = row.sort_values("alpha")
        out[beta] = resolved_limit(row["alpha"].to_numpy(), row["n_collisions"].to_numpy(),
                                   min_cells)  # fmt: skip
    return out


def smooth_minima(grid: pd.DataFrame, limits: dict, logger) -> pd.DataFrame:
    """Smooth (not cusp) minima of the COR along alpha on every beta > 0 row, refined exactly
    and linked into curves across rows.

    A candidate is a grid point below both neighbours with one contact count on all three
    (so no count step, no cusp, between them), within the row's resolved range. It is refined by
    bounded Brent on ln alpha with ``restitution.solve`` and kept when the refined point is
    interior (not at the bracket's ends) and has the same count. Points of consecutive rows
    within 0.15 in ln alpha form one curve.
    """
    from scipy.optimize import minimize_scalar

    import restitution

    points = []
    for beta, row in sorted(grid[grid["beta"] > 0].groupby("beta"), key=lambda kv: kv[0]):
        row = row.sort_values("alpha")
        a, e, n = (row[c].to_numpy() for c in ("alpha", "cor", "n_collisions"))
        ok = (row["status"] == "ok").to_numpy()
        for i in range(1, a.size - 1):
            if a[i + 1] > limits[beta] or not ok[i - 1 : i + 2].all():
                continue
            if not (e[i] <= e[i - 1] and e[i] < e[i + 1] and n[i - 1] == n[i] == n[i + 1]):
                continue
            lo, hi = math.log(a[i - 1]), math.log(a[i + 1])

            def cor(x, beta=beta):
                return restitution.solve(alpha=math.exp(x), beta=beta).cor

            res = minimize_scalar(cor, bounds=(lo, hi), method="bounded",
                                  options={"xatol": 1e-10})  # fmt: skip
            edge = 1e-6 * (hi - lo)
            r = restitution.solve(alpha=math.exp(res.x), beta=beta)
            if lo + edge < res.x < hi - edge and r.n_collisions == n[i] and r.cor <= e[i]:
                points.append((beta, math.exp(res.x), r.cor, int(r.n_collisions)))
    # Link rows into curves (rows are in increasing beta).
    betas = sorted({p[0] for p in points})
    row_of = {b: k for k, b in enumerate(betas)}
    curves, ends = [], []  # ends: (row index, ln alpha) of each curve's last point
    for beta, alpha, cor, ncol in points:
        k, x = row_of[beta], math.log(alpha)
        best = None
        for c, (kr, xr) in enumerate(ends):
            if kr == k - 1 and abs(xr - x) < 0.15 and (best is None or abs(xr - x) < best[0]):
                best = (abs(xr - x), c)
        if best is None:
            curves.append([])
            ends.append(None)
            best = (0.0, len(curves) - 1)
        curves[best[1]].append((alpha, beta, cor, ncol))
        ends[best[1]] = (k, x)
    rows = [dict(curve=c, alpha=a, beta=b, cor=e, n_collisions=n)
            for c, pts in enumerate(curves) for a, b, e, n in pts]  # fmt: skip
    table = pd.DataFrame(rows, columns=["curve", "alpha", "beta", "cor", "n_collisions"])
    logger.info("smooth COR minima: %d points on %d rows, %d curves", len(points), len(betas),
                len(curves))  # fmt: skip
    return table


def main(params, map_paths, output_path, logger, untraced_path=None, minima_path=None):
    from restitution.analysis import cormap, special_points
    from restitution.tables.io import read_table, write_table

    cfg = dict(params.curves)
    stars = special_points.special_points(cfg["n_max"])["alpha_star"].to_numpy()
    box = (params.map["alpha_min"], params.map["alpha_max"], params.map["beta_max"])
    curves = cormap.trace_all(stars, progress=logger.info, box=box)
    grid = pd.concat([read_table(p) for p in map_paths], ignore_index=True)
    steps = grid_steps(grid, cfg["n_max"])
    total = len(steps)
    missing = unexplained_steps(steps, curves)
    logger.info("grid count steps between counts <= %d: %d, not crossed by a traced curve: %d",
                cfg["n_max"] + 1, total, len(missing))  # fmt: skip
    # Seed the unexplained steps (at most max_extra_seeds, the largest beta first: there the
    # split curves live) with the condition that vanishes at the count step.
    seeds = []
    for lo, hi, beta, n_lo, n_hi in sorted(missing, key=lambda s: -s[2])[: cfg["max_extra_seeds"]]:
        if beta == 0.0:
            continue
        a = math.sqrt(lo * hi)
        best = None
        for k in range(1, max(n_lo, n_hi) + 1):
            for kind in cormap.KINDS:
                g = cormap.G(a, beta, k, kind).value
                if math.isfinite(g) and (best is None or abs(g) < best[0]):
                    best = (abs(g), k, kind)
        if best is not None and best[0] < 0.05:
            seeds.append((best[1], best[2], a, beta))
    if seeds:
        cormap.trace_all([], extra_seeds=seeds, progress=logger.info, box=box, curves=curves)
    missing_after = unexplained_steps(steps, curves)
    coverage = 1.0 - len(missing_after) / max(total, 1)
    logger.info("after grid seeds: %d curves, %d of %d grid steps explained (%.1f %%)",
                len(curves), total - len(missing_after), total, 100 * coverage)  # fmt: skip
    table = pd.concat([c.frame(i) for i, c in enumerate(curves)], ignore_index=True)
    worst = float(np.nanmax(np.abs(table["residual"].to_numpy())))
    logger.info("largest |G| on a traced point: %.2e", worst)
    provenance = {"fig8": {"curves": cfg, "map": dict(params.map)}}
    write_table(
        table,
        output_path,
        config=provenance,
        extra={"coverage": coverage, "grid_steps": total, "unexplained": len(missing_after)},
    )
    limits = resolved_limits(grid, cfg["min_cells"])
    if untraced_path is not None:
        # The grid's count steps no traced curve crosses (drawn on the map, so none is hidden),
        # each with whether it lies where the grid resolves its row's cusps.
        untraced = pd.DataFrame(missing_after, columns=["alpha_lo", "alpha_hi", "beta", "n_lo",
                                                        "n_hi"])  # fmt: skip
        untraced["alpha"] = np.sqrt(untraced["alpha_lo"] * untraced["alpha_hi"])
        pairs = zip(untraced["alpha_hi"], untraced["beta"], strict=True)
        untraced["resolved"] = [hi <= limits[b] for hi, b in pairs]
        write_table(untraced, untraced_path, config=provenance)
    if minima_path is not None:
        write_table(smooth_minima(grid, limits, logger), minima_path, config=provenance)
    return table


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "simulate"):
        main(
            snakemake.params,  # noqa: F821
            list(snakemake.input.maps),  # noqa: F821
            snakemake.output.table,  # noqa: F821
            logger=log,
            untraced_path=snakemake.output.untraced,  # noqa: F821
            minima_path=snakemake.output.minima,  # noqa: F821
        )
