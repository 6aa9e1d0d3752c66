"""Concatenate the Fig. 6(b) per-N tables into one sweep table (sorted by N, then x), list the
local COR minima of every curve in a small CSV, and check the first-contact branch.

Check (Appendix): while the chain has a single contact with the rigid wall, the COR is
e1 = (1 - x)/(1 + x) with x = (N-1)*alpha, for every N. Rows with one contact must match it to
round-off, otherwise the job fails (a wrong chain model would show here first).
"""

import numpy as np
import pandas as pd

BRANCH_TOLERANCE = 1e-9
# Local minima closer than this (relative x) are one minimum (the one with the lowest COR).
SAME_MINIMUM = 1e-6


def check_first_branch(sweep: pd.DataFrame, logger) -> None:
    """Single-contact rows of a rigid wall must follow e1 = (1 - x)/(1 + x)."""
    single = sweep[(sweep["n_collisions"] == 1) & (sweep["beta"] == 0) & (sweep["status"] == "ok")]
    if single.empty:
        logger.info("first-contact branch: no single-contact rigid-wall rows to check")
        return
    x = single["x"].to_numpy()
    error = np.abs(single["cor"].to_numpy() - (1 - x) / (1 + x))
    for n, group in single.assign(error=error).groupby("n_masses"):
        logger.info(
            "N = %d: %d single-contact rows up to x = %.6f, largest |COR - (1-x)/(1+x)| = %.2e",
            n,
            len(group),
            group["x"].max(),
            group["error"].max(),
        )
    if error.max() > BRANCH_TOLERANCE:
        worst = single.iloc[int(np.argmax(error))]
        raise ValueError(
            f"first-contact branch violated: N = {worst['n_masses']}, x = {worst['x']!r}: "
            f"COR {worst['cor']!r} vs (1-x)/(1+x) = {(1 - worst['x']) / (1 + worst['x'])!r}"
        )


def main(tables, output_path, minima_path, params, logger) -> pd.DataFrame:
    from _common import log_minima

    from restitution.analysis.sweeps import local_minima
    from restitution.tables.io import read_table, write_table

    frames = [read_table(path) for path in tables]
    for path, frame in zip(tables, frames, strict=True):
        if frame.empty or "x" not in frame or "cor" not in frame:
            raise ValueError(f"{path}: not a Fig. 6(b) sweep table (no rows or no x/cor columns)")
    sweep = pd.concat(frames, ignore_index=True).sort_values(["n_masses", "x"], ignore_index=True)
    missing = sorted(set(params.fig6["n_masses"]) - set(sweep["n_masses"].unique()))
    if missing:
        raise ValueError(f"no rows for N = {missing} in {list(tables)}")
    for n, group in sweep.groupby("n_masses"):
        logger.info(
            "N = %d: %d rows, x %g..%g, contacts %d..%d, COR min %.6f, status %s",
            n,
            len(group),
            group["x"].min(),
            group["x"].max(),
            group["n_collisions"].min(),
            group["n_collisions"].max(),
            group["cor"].min(),
            group["status"].value_counts().to_dict(),
        )
    check_first_branch(sweep, logger)
    config = {"fig6": params.fig6}
    write_table(sweep, output_path, config=config)
    # Round-off ripples at the bottom of a bisected cusp: the lowest of each cluster counts.
    columns = ["x", "alpha", "cor", "n_collisions"]
    minima = local_minima(sweep, "x", by="n_masses", columns=columns, merge=SAME_MINIMUM)
    write_table(minima, minima_path, config=config)
    log_minima(logger, minima, "n_masses", "x")
    return sweep


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "aggregate"):
        main(
            snakemake.input.tables,  # noqa: F821
            snakemake.output.sweep,  # noqa: F821
            snakemake.output.minima,  # noqa: F821
            snakemake.params,  # noqa: F821
            log,
        )
