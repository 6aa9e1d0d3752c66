"""Concatenate the Fig. 7 chunk tables into one sweep table (sorted by xi, alpha), check statuses.

Neighbouring chunks share their boundary alpha; the duplicate row is dropped here. Rows whose
status is not "ok" (e.g. the contact budget ran out) are logged by xi and alpha; if their fraction
exceeds ``max_not_ok_fraction`` the rule fails, so a figure is never drawn from a broken sweep
(the render rules mark the rows that remain). Two small CSVs carry the numbers quoted in prose:
``summary.csv`` (per xi: rows, not-ok rows, peak contact count and where it occurs, COR minimum)
and ``minima.csv`` (the local COR minima, i.e. the cusps, per xi).
"""

import pandas as pd

RESOLUTION = 1e-12


def summarise(sweep: pd.DataFrame) -> pd.DataFrame:
    """One row per xi: row counts, the peak of n_collisions and where it occurs, the COR minimum."""
    rows = []
    for xi, group in sweep.groupby("xi", sort=True):
        ok = group[group["status"] == "ok"].sort_values("alpha")
        peak = ok["n_collisions"].max()
        at_peak = ok.loc[ok["n_collisions"] == peak, "alpha"]
        lowest = ok.loc[ok["cor"].idxmin()]
        rows.append(
            {
                "xi": xi,
                "rows": len(group),
                "not_ok": int((group["status"] != "ok").sum()),
                "peak_collisions": int(peak),
                "peak_alpha_min": float(at_peak.min()),
                "peak_alpha_max": float(at_peak.max()),
                "collisions_at_alpha_max": int(ok["n_collisions"].iloc[-1]),
                "cor_min": float(lowest["cor"]),
                "cor_min_alpha": float(lowest["alpha"]),
                "omega_t_col_at_alpha_max": float(ok["omega_t_col"].iloc[-1]),
            }
        )
    return pd.DataFrame(rows)


def check_status(sweep: pd.DataFrame, limit: float, logger) -> None:
    """Log every xi's rows not ok; raise if their fraction of the sweep exceeds ``limit``."""
    bad = sweep[sweep["status"] != "ok"]
    for xi, group in bad.groupby("xi"):
        logger.warning(
            "xi %g: %d rows not ok %s at alpha %s",
            xi,
            len(group),
            group["status"].value_counts().to_dict(),
            ", ".join(f"{a:.6g}" for a in group["alpha"].head(20)),
        )
    fraction = len(bad) / max(len(sweep), 1)
    logger.info("rows not ok: %d of %d (%.3g%%)", len(bad), len(sweep), 100 * fraction)
    if fraction > limit:
        raise RuntimeError(
            f"{len(bad)} of {len(sweep)} Fig. 7 sweep rows are not ok "
            f"({bad['status'].value_counts().to_dict()}), more than max_not_ok_fraction = "
            f"{limit:g}: raise max_events or check the solver before plotting"
        )


def main(chunks, sweep_path, summary_path, minima_path, params, logger) -> pd.DataFrame:
    from _common import log_minima

    from restitution.analysis.sweeps import local_minima
    from restitution.solvers.result import RESULT_COLUMNS
    from restitution.tables.io import read_table, write_table

    fig7 = params.fig7
    tables = [read_table(path, columns=("xi", "beta", "alpha", *RESULT_COLUMNS)) for path in chunks]
    sweep = (
        pd.concat(tables, ignore_index=True)
        .drop_duplicates(subset=["xi", "alpha"], keep="first")
        .sort_values(["xi", "alpha"], ignore_index=True)
    )
    missing = sorted(set(map(float, fig7["xis"])) - set(sweep["xi"].unique()))
    if missing:
        raise ValueError(f"no rows for xi = {missing} in {list(chunks)}")
    if (sweep["beta"] != float(fig7["beta"])).any():
        raise ValueError(
            f"chunk tables hold beta {sorted(sweep['beta'].unique())}, "
            f"but config fig7.beta = {fig7['beta']}"
        )
    check_status(sweep, fig7["max_not_ok_fraction"], logger)
    config = {"fig7": fig7, "solver": params.solver}
    write_table(sweep, sweep_path, config=config)
    summary = summarise(sweep)
    write_table(summary, summary_path, config=config)
    for row in summary.itertuples():
        logger.info(
            "xi %g: %d rows, peak %d contacts at alpha %.4g..%.4g, %d at alpha_max, "
            "COR min %.4f at alpha %.4g",
            row.xi,
            row.rows,
            row.peak_collisions,
            row.peak_alpha_min,
            row.peak_alpha_max,
            row.collisions_at_alpha_max,
            row.cor_min,
            row.cor_min_alpha,
        )
    # Refined points closer than RESOLUTION (relative alpha) differ in COR by round-off only: one
    # point each (the lowest), so round-off wiggles are not reported as minima.
    minima = local_minima(sweep, "alpha", by="xi", resolution=RESOLUTION)
    write_table(minima, minima_path, config=config)
    log_minima(logger, minima, "xi", "alpha")
    return sweep


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "aggregate"):
        main(
            snakemake.input.chunks,  # noqa: F821
            snakemake.output.sweep,  # noqa: F821
            snakemake.output.summary,  # noqa: F821
            snakemake.output.minima,  # noqa: F821
            snakemake.params,  # noqa: F821
            log,
        )
