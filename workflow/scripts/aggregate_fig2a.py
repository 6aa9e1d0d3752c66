"""Concatenate the Fig. 2(a) chunk tables into one sweep table, sorted by beta then alpha.

Neighbouring chunks share their boundary alpha; the duplicate row is dropped here.
"""

import pandas as pd


def main(chunks, output_path, params, logger) -> pd.DataFrame:
    from restitution.io import read_table, write_table

    tables = [read_table(path) for path in chunks]
    sweep = (
        pd.concat(tables, ignore_index=True)
        .drop_duplicates(subset=["beta", "alpha"], keep="first")
        .sort_values(["beta", "alpha"], ignore_index=True)
    )
    for beta, group in sweep.groupby("beta"):
        logger.info(
            "beta %g: %d rows, alpha %g..%g, contacts %d..%d, COR min %.6f, status %s",
            beta,
            len(group),
            group["alpha"].min(),
            group["alpha"].max(),
            group["n_collisions"].min(),
            group["n_collisions"].max(),
            group["cor"].min(),
            group["status"].value_counts().to_dict(),
        )
    write_table(sweep, output_path, config={"fig2a": params.fig2a, "solver": params.solver})
    return sweep


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "aggregate"):
        main(snakemake.input.chunks, snakemake.output.sweep, snakemake.params, log)  # noqa: F821
