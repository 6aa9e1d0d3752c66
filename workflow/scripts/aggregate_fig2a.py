"""Concatenate the Fig. 2(a) chunk tables into one sweep table, sorted by beta then alpha.

Neighbouring chunks share their boundary alpha; the duplicate row is dropped here. The local
minima of each curve (the cusps, where one more contact just grazes the wall) are listed in a
small CSV, so numbers quoted in prose come from a generated file.
"""

import pandas as pd


def main(chunks, output_path, minima_path, params, logger) -> pd.DataFrame:
    from _common import log_minima

    from restitution.analysis.sweeps import local_minima
    from restitution.solvers.result import RESULT_COLUMNS
    from restitution.tables.io import read_table, write_table

    tables = [read_table(path, columns=("beta", "alpha", *RESULT_COLUMNS)) for path in chunks]
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
    config = {"fig2a": params.fig2a, "solver": params.solver}
    write_table(sweep, output_path, config=config)
    minima = local_minima(sweep, "alpha", by="beta")
    write_table(minima, minima_path, config=config)
    log_minima(logger, minima, "beta", "alpha")
    return sweep


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "aggregate"):
        main(
            snakemake.input.chunks,  # noqa: F821
            snakemake.output.sweep,  # noqa: F821
            snakemake.output.minima,  # noqa: F821
            snakemake.params,  # noqa: F821
            log,
        )
