"""Join a user study's chunk tables into one table, and list the COR minima of every curve.

Neighbouring chunks share their boundary point (solved twice, identical): kept once. Rows whose
status is not ok are kept in the table (with their status) and counted in the log. Minima closer
than ``restitution_workflow.study.MINIMA_MERGE`` of the first axis' span are listed once (the
deepest).
"""

import numpy as np
import pandas as pd


def minima(table: pd.DataFrame, axis) -> pd.DataFrame:
    """Interior local minima of the COR of each curve (rows with status ok only), one per
    minimum: minima closer than MINIMA_MERGE of the axis' span (on its scale, log or linear) are
    one, the deepest kept.

    A smooth minimum's position is fixed only to about sqrt(machine epsilon) (~1e-8 relative):
    within that the COR is flat to round-off, and the pattern search's points there show several
    local minima of the same depth. ``axis`` is the study's first axis
    (``restitution_workflow.study.Axis``)."""
    from restitution.analysis.sweeps import interior_minima
    from restitution_workflow.study import MINIMA_MERGE

    column = axis.param
    values = np.asarray(axis.values, dtype=float)
    scale = np.log if axis.log else (lambda v: v)
    tolerance = MINIMA_MERGE * float(scale(values.max()) - scale(values.min()))
    rows = []
    for (index, curve), part in table[table["status"] == "ok"].groupby(
        ["curve_index", "curve"], dropna=False
    ):
        part = part.sort_values(column)
        cor = part["cor"].to_numpy()
        inner = interior_minima(cor)
        x = scale(part[column].to_numpy(dtype=float)[inner])
        groups = np.split(inner, np.flatnonzero(np.diff(x) > tolerance) + 1) if len(inner) else []
        for number, group in enumerate(groups, start=1):
            row = part.iloc[group[np.argmin(cor[group])]]  # the deepest of the group
            rows.append(
                {
                    "curve_index": index,
                    "curve": curve,
                    "minimum": number,
                    column: row[column],
                    "cor": row["cor"],
                    "n_collisions": int(row["n_collisions"]),
                }
            )
    columns = ["curve_index", "curve", "minimum", column, "cor", "n_collisions"]
    return pd.DataFrame(rows, columns=columns)


def main(chunk_paths, sweep_path, minima_path, study_mapping, logger):
    from restitution.analysis.sweeps import log_not_ok
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
    found = minima(table, study.axes[0])
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
