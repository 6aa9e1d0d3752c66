# Work-precision benchmarks (issue 7): `snakemake -c2 benchmarks` (`make benchmarks`), NOT part of
# `all` -- timings differ from run to run, so figures/benchmarks/ is left out of the comparison of
# committed figures.
# bench_run (one timing job per method family) -> bench_collect (one table, summary, headline)
#   -> bench_workprecision (diagrams); bench_scaling -> bench_scaling_plot.
# Timing jobs declare threads: 2 although they time on one numba thread: on the 2-core machine
# they then never share the CPU with another job, so no timing competes with other work.

from restitution_workflow.bench.scenes import SCENES as BENCH_SCENES

BENCH = config["benchmarks"]
# Checks the schema cannot express, before any job runs (scenes.py is cheap to import).
_unknown = sorted(set(BENCH["scenes"]) - {s.name for s in BENCH_SCENES})
if _unknown:
    raise WorkflowError(
        f"Invalid configuration: benchmarks.scenes = {BENCH['scenes']!r}: unknown scene(s) "
        f"{_unknown}; known: {[s.name for s in BENCH_SCENES]}"
    )
if not BENCH["scaling"]["sweep_alpha_min"] < BENCH["scaling"]["sweep_alpha_max"]:
    raise WorkflowError(
        "Invalid configuration: benchmarks.scaling.sweep_alpha_max must exceed sweep_alpha_min"
    )


rule bench_run:
    """Time and score every setting of one method family on every benchmark scene."""
    input:
        code=script_code("bench_run.py"),
    output:
        table="results/benchmarks/runs/{family}.parquet",
    log:
        "logs/workprecision/run_{family}.log",
    wildcard_constraints:
        family="|".join(BENCH["families"]),
    conda:
        "../envs/restitution.yaml"
    threads: 2
    params:
        bench=BENCH,
    message:
        JOB_MESSAGE
    script:
        "../scripts/bench_run.py"


rule bench_collect:
    """All records in one table; per-scene summary and the exact-vs-solve_ivp headline."""
    input:
        runs=expand(
            "results/benchmarks/runs/{family}.parquet", family=BENCH["families"]
        ),
        code=script_code("bench_collect.py"),
    output:
        table=report(
            "results/benchmarks/workprecision.parquet",
            caption="../report/bench_records.rst",
            category="Work-precision",
        ),
        summary=report(
            "results/benchmarks/summary.csv",
            caption="../report/bench_summary.rst",
            category="Work-precision",
        ),
        headline=report(
            "results/benchmarks/headline.csv",
            caption="../report/bench_headline.rst",
            category="Work-precision",
        ),
    log:
        "logs/workprecision/collect.log",
    conda:
        "../envs/restitution.yaml"
    params:
        bench=BENCH,
        target_error=BENCH["target_error"],
        time_limit=BENCH["time_limit"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/bench_collect.py"


rule bench_workprecision:
    """Work-precision diagrams: time per scene vs COR error, one panel per scene."""
    input:
        table=rules.bench_collect.output.table,
        code=script_code("bench_plot_workprecision.py"),
    output:
        png=report(
            "figures/benchmarks/workprecision.png",
            caption="../report/bench_workprecision.rst",
            category="Work-precision",
        ),
        pdf="figures/benchmarks/workprecision.pdf",
    log:
        "logs/workprecision/plot.log",
    conda:
        "../envs/restitution.yaml"
    params:
        ivp=ivp_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/bench_plot_workprecision.py"


rule bench_scaling:
    """Cost vs alpha, vs chain length N, and solve_many sweep size on 1 and 2 threads."""
    input:
        code=script_code("bench_scaling.py"),
    output:
        table="results/benchmarks/scaling.parquet",
        exponents=report(
            "results/benchmarks/scaling_exponents.csv",
            caption="../report/bench_exponents.rst",
            category="Work-precision",
        ),
    log:
        "logs/workprecision/scaling.log",
    conda:
        "../envs/restitution.yaml"
    threads: 2
    params:
        scaling=BENCH["scaling"],
        bench=BENCH,
    message:
        JOB_MESSAGE
    script:
        "../scripts/bench_scaling.py"


rule bench_scaling_plot:
    """Scaling diagrams with the fitted exponents."""
    input:
        table=rules.bench_scaling.output.table,
        exponents=rules.bench_scaling.output.exponents,
        code=script_code("bench_plot_scaling.py"),
    output:
        png=report(
            "figures/benchmarks/scaling.png",
            caption="../report/bench_scaling.rst",
            category="Work-precision",
        ),
        pdf="figures/benchmarks/scaling.pdf",
    log:
        "logs/workprecision/scaling_plot.log",
    conda:
        "../envs/restitution.yaml"
    params:
        match_error=BENCH["scaling"]["match_error"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/bench_plot_scaling.py"


rule benchmarks:
    """The work-precision study: tables, diagrams and scaling (not part of `all`)."""
    input:
        rules.bench_collect.output.summary,
        rules.bench_collect.output.headline,
        rules.bench_workprecision.output.png,
        rules.bench_workprecision.output.pdf,
        rules.bench_scaling_plot.output.png,
        rules.bench_scaling_plot.output.pdf,
    message:
        TARGET_MESSAGE
