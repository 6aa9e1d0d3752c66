"""Fig. 8(a) curves: where the contact count steps in the (alpha, beta) plane, traced exactly.

Seeds: the exact rigid-wall grazing points alpha*_1..alpha*_n_max (``special_points``); from each,
``restitution.analysis.cormap.trace_all`` follows the grazing condition by pseudo-arclength
continuation
and, where a curve ends on another, follows the conditions that vanish there (contact splits).
Then the map's grid is checked: every step of the count between grid neighbours along alpha that
no traced curve crosses is bisected on the count and traced from there too (components not
connected to beta = 0). The table records, for the whole grid, how many count steps the curves
explain (``coverage``, logged and stored in the table's provenance).
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


def main(params, map_paths, output_path, logger) -> pd.DataFrame:
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
    write_table(
        table,
        output_path,
        config={"fig8": {"curves": cfg, "map": dict(params.map)}},
        extra={"coverage": coverage, "grid_steps": total, "unexplained": len(missing_after)},
    )
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
        )
