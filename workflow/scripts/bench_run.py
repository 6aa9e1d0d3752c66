"""Work-precision records of one method family on every benchmark scene (one timing job).

Reads the `benchmarks` config section (params.bench) and the family (wildcard), runs
``restitution_workflow.bench.harness.run_suite`` on one numba thread, and writes
results/benchmarks/runs/<family>.parquet with machine information in its provenance.
"""


def main(family, out_path, bench, logger):
    from restitution.tables.io import write_table
    from restitution_workflow.bench import harness
    from restitution_workflow.bench.scenes import SCENES

    cfg = harness.check_config(bench, [s.name for s in SCENES])
    scenes = [s for s in SCENES if not cfg["scenes"] or s.name in cfg["scenes"]]
    logger.info("family %s on %d scenes; machine %s", family, len(scenes), harness.machine_info())
    records = harness.run_suite(scenes, cfg, families=[family], log=logger)
    extra = {"machine": harness.machine_info(), "family": family}
    write_table(records, out_path, config=bench, extra=extra)
    counts = records["status"].value_counts().to_dict()
    logger.info("wrote %s: %d records, statuses %s", out_path, len(records), counts)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "benchmark run"):
        main(
            snakemake.wildcards.family,  # noqa: F821
            snakemake.output.table,  # noqa: F821
            dict(snakemake.params.bench),  # noqa: F821
            log,
        )
