"""Scaling measurements: cost per scene vs alpha and vs chain length N, solve_many sweep size on
1 and 2 threads; fitted exponents (results/benchmarks/scaling.parquet, scaling_exponents.csv).
"""


def main(out, scaling, bench, logger):
    import numba

    from restitution.tables.io import write_table
    from restitution_workflow.bench import harness
    from restitution_workflow.bench import scaling as sc

    numba.set_num_threads(1)
    t, r = float(bench["min_time"]), int(bench["min_repeats"])
    rows = sc.alpha_scaling(
        scaling["alphas"],
        float(scaling["beta"]),
        scaling["ivp_method"],
        [float(v) for v in bench["ivp_rtols"]],
        float(scaling["ivp_alpha_max"]),
        t,
        r,
        float(bench["time_budget"]),
        match_error=float(scaling["match_error"]),
        atol_over_rtol=float(bench["ivp_atol_over_rtol"]),
    )
    logger.info("alpha scaling done (%d rows)", len(rows))
    rows += sc.chain_scaling(
        scaling["chain_ns"], float(scaling["chain_alpha"]), float(scaling["chain_beta"]), t, r
    )
    logger.info("chain scaling done")
    threads = [1, 2] if numba.config.NUMBA_NUM_THREADS >= 2 else [1]
    rows += sc.sweep_scaling(
        scaling["sweep_counts"],
        threads,
        float(scaling["sweep_alpha_min"]),
        float(scaling["sweep_alpha_max"]),
        float(scaling["sweep_beta"]),
        t,
        r,
    )
    table = sc.frame(rows)
    extra = {"machine": harness.machine_info()}
    write_table(table, out.table, config={"scaling": scaling, "bench": bench}, extra=extra)
    fits = sc.fit_exponents(
        table,
        float(scaling["alpha_fit_min"]),
        float(scaling["chain_fit_min"]),
        float(scaling["sweep_fit_min"]),
    )
    write_table(fits, out.exponents)
    logger.info("exponents:\n%s", fits.to_string())


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "scaling"):
        main(
            snakemake.output,  # noqa: F821
            dict(snakemake.params.scaling),  # noqa: F821
            dict(snakemake.params.bench),  # noqa: F821
            log,
        )
