"""Join a user study's chunk tables into one table, and list the COR minima of every curve.

Neighbouring chunks share their boundary point (solved twice, identical): kept once. Rows whose
status is not ok are kept in the table (with their status) and counted in the log.
"""

import pandas as pd


def main(chunk_paths, sweep_path, minima_path, study_mapping, logger):
    from restitution.analysis.sweeps import local_minima, log_not_ok
    from restitution.tables.io import read_table, write_table
    from restitution_workflow.study import check_study

    study = check_study(study_mapping)
    column = study.axes[0].param
    parts = [read_table(p, require_provenance=True, columns=("cor", "n_collisions", "status"))
             for p in chunk_paths]  # fmt: skip
    table = (
        pd.concat(parts, ignore_index=True)
        .drop_duplicates(subset=["curve_index", column], keep="first")
        .sort_values(["curve_index", column], ignore_index=True)
    )
    log_not_ok(table, logger, study.name, where=column)
    write_table(table, sweep_path, config={"study": study_mapping})
    found = local_minima(table, column, by=["curve_index", "curve"])
    write_table(found, minima_path)
    logger.info("%s: %d rows, %d COR minima", study.name, len(table), len(found))


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "study aggregate"):
        main(
            list(snakemake.input.chunks),  # noqa: F821
            snakemake.output.sweep,  # noqa: F821
            snakemake.output.minima,  # noqa: F821
            snakemake.params.study,  # noqa: F821
            log,
        )
