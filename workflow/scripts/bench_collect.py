"""One work-precision table from the per-family runs, plus the summary and headline tables.

results/benchmarks/workprecision.parquet (every record), summary.csv (per scene and family: the
fastest setting reaching the target error with the right contact count, the most accurate one
within the time limit) and headline.csv (exact solvers vs the best solve_ivp setting per scene).
"""


def main(run_paths, out, params, logger):
    import pandas as pd

    from restitution.tables.io import read_provenance, read_table, write_table
    from restitution_workflow.bench import harness
    from restitution_workflow.bench.summary import headline, summary

    records = pd.concat([read_table(p, require_provenance=True) for p in run_paths])
    machines = {str(p): read_provenance(p).get("machine") for p in run_paths}
    extra = {"machine": harness.machine_info(), "machines_of_runs": machines}
    write_table(records, out.table, config=params.bench, extra=extra)
    target, limit = float(params.target_error), float(params.time_limit)
    table = summary(records, target, limit)
    write_table(table, out.summary)
    head = headline(records, target)
    write_table(head, out.headline)
    logger.info("headline (target %g):\n%s", target, head.to_string())


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "collect"):
        main(snakemake.input.runs, snakemake.output, snakemake.params, log)  # noqa: F821
