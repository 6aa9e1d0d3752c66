# Beyond the paper (issue 14): Fig. 8(a), the (alpha, beta) plane of the two-mass model with the
# exact curves where the contact count steps, and Fig. 8(b), minimum-COR chain designs against N.
# simulate -> parquet under results/fig8 and results/design -> render (figure + caption from the
# tables). `snakemake fig8a` / `snakemake fig8b` build one panel; `design_extra` the costly designs
# that `all` leaves out (config fig8.design.extra).


# ---------------------------------------------------------------------------------------------
# Fig. 8(a): the (alpha, beta) map
# ---------------------------------------------------------------------------------------------
rule simulate_fig8a_map:
    """COR and contact count on one chunk of the (alpha, beta) grid (beta rows split in chunks)."""
    input:
        code=script_code("simulate_fig8a_map.py"),
    output:
        table="results/fig8/map_{chunk}.parquet",
    log:
        "logs/fig8/simulate_map_{chunk}.log",
    benchmark:
        "logs/benchmarks/fig8/simulate_map_{chunk}.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    params:
        map=config["fig8"]["map"],
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig8a_map.py"


rule simulate_fig8a_curves:
    """Trace the count-step curves from the exact beta = 0 points; seed grid steps they miss."""
    input:
        maps=expand(
            "results/fig8/map_{chunk}.parquet",
            chunk=range(config["fig8"]["map"]["chunks"]),
        ),
        code=script_code("simulate_fig8a_curves.py"),
    output:
        table=report(
            "results/fig8/curves.parquet",
            caption="../report/fig8a_curves.rst",
            category="Beyond the paper",
            subcategory="Fig. 8",
            labels={"figure": "8(a)", "quantity": "table: count-step curves"},
        ),
        untraced="results/fig8/untraced.parquet",
        minima="results/fig8/minima.parquet",
    log:
        "logs/fig8/simulate_curves.log",
    benchmark:
        "logs/benchmarks/fig8/simulate_curves.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    params:
        map=config["fig8"]["map"],
        curves=config["fig8"]["curves"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig8a_curves.py"


rule fig8a:
    """Draw Fig. 8(a) and write its caption from the tables."""
    input:
        maps=expand(
            "results/fig8/map_{chunk}.parquet",
            chunk=range(config["fig8"]["map"]["chunks"]),
        ),
        curves=rules.simulate_fig8a_curves.output.table,
        untraced=rules.simulate_fig8a_curves.output.untraced,
        minima=rules.simulate_fig8a_curves.output.minima,
        template="workflow/report/fig8a.rst",
        style="src/restitution/restitution.mplstyle",
        code=script_code("render_fig8a.py"),
    output:
        png=report(
            "figures/fig8a.png",
            caption="../../results/captions/fig8a.rst",
            category="Beyond the paper",
            subcategory="Fig. 8",
            labels={"figure": "8(a)", "quantity": "COR map over (alpha, beta)"},
        ),
        pdf="figures/fig8a.pdf",
        caption="results/captions/fig8a.rst",
    log:
        "logs/fig8/render_fig8a.log",
    benchmark:
        "logs/benchmarks/fig8/render_fig8a.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        map=config["fig8"]["map"],
        curves=config["fig8"]["curves"],
        fig2a_betas=config["fig2a"]["betas"],
        fig3_alphas=config["fig3"]["sweep"]["alphas"],
        fig3_beta_min=config["fig3"]["sweep"]["beta_min"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig8a.py"


# ---------------------------------------------------------------------------------------------
# Fig. 8(b): minimum-COR designs against N
# ---------------------------------------------------------------------------------------------
rule design_fig8b:
    """The minimum-COR chains of one family for every N its group (`all` or `extra` in config
    fig8.design) lists, smallest N first: each from a warm and a cold start, re-checked by a
    fresh solve."""
    input:
        warm=design_warm_tables,
        code=script_code("design_fig8b.py"),
    output:
        table="results/design/{group}/{family}.parquet",
    log:
        "logs/design/{group}/{family}.log",
    benchmark:
        "logs/benchmarks/design/{group}/{family}.tsv"
    wildcard_constraints:
        group="all|extra",
        family="uniform|tapered_decreasing|tapered_increasing|masses|masses_springs|robust",
    # One job a family, not one a design: the designs of free masses, masses and springs and
    # robust chains are a chain anyway (each N warm-started from N - 1), and every job pays
    # about 1 s to start (Python, the package, scipy.optimize, numba's cache), which one design
    # of a short chain barely exceeds (41 jobs of one design summed 165 s, 2026-12-07; the
    # uniform and tapered families, one parameter, take 2-7 s a family in one job). The designs
    # are the longest chain of jobs (masses, then masses+springs): run them before the other
    # ready jobs, which then fill the core the chain leaves free.
    priority: 1
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=60,
    params:
        design={
            k: v
            for k, v in config["fig8"]["design"].items()
            if k not in ("all", "extra")
        },
        ns=lambda wildcards: sorted(DESIGNS[wildcards.group][wildcards.family]),
        contains=lambda wildcards: CONTAINS.get(wildcards.family, []),
    message:
        JOB_MESSAGE
    script:
        "../scripts/design_fig8b.py"


rule design_fig8b_collect:
    """All designs of `all` in one table."""
    input:
        tables=design_tables("all"),
        code=script_code("design_fig8b_collect.py"),
    output:
        table=report(
            "results/design/designs.parquet",
            caption="../report/fig8b_designs.rst",
            category="Beyond the paper",
            subcategory="Fig. 8",
            labels={"figure": "8(b)", "quantity": "table: designs"},
        ),
    log:
        "logs/design/collect.log",
    benchmark:
        "logs/benchmarks/design/collect.tsv"
    conda:
        "../envs/restitution.yaml"
    message:
        JOB_MESSAGE
    script:
        "../scripts/design_fig8b_collect.py"


rule design_extra_collect:
    """The costly designs `all` leaves out (config fig8.design.extra), in one table."""
    input:
        tables=design_tables("extra"),
        code=script_code("design_fig8b_collect.py"),
    output:
        table="results/design/designs_extra.parquet",
    log:
        "logs/design/collect_extra.log",
    benchmark:
        "logs/benchmarks/design/collect_extra.tsv"
    conda:
        "../envs/restitution.yaml"
    message:
        JOB_MESSAGE
    script:
        "../scripts/design_fig8b_collect.py"


rule design_extra:
    """Optional target: the designs of config fig8.design.extra (robust optima for larger N)."""
    default_target: False
    input:
        rules.design_extra_collect.output.table,
    message:
        TARGET_MESSAGE


rule fig8b:
    """Draw Fig. 8(b) and write its caption from the design table."""
    input:
        table=rules.design_fig8b_collect.output.table,
        template="workflow/report/fig8b.rst",
        style="src/restitution/restitution.mplstyle",
        code=script_code("render_fig8b.py"),
    output:
        png=report(
            "figures/fig8b.png",
            caption="../../results/captions/fig8b.rst",
            category="Beyond the paper",
            subcategory="Fig. 8",
            labels={"figure": "8(b)", "quantity": "smallest COR vs N"},
        ),
        pdf="figures/fig8b.pdf",
        caption="results/captions/fig8b.rst",
    log:
        "logs/fig8/render_fig8b.log",
    benchmark:
        "logs/benchmarks/fig8/render_fig8b.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        # Only the settings the caption states; the families and N of `all` reach the figure
        # through the design table.
        design={
            key: config["fig8"]["design"][key]
            for key in (
                "beta",
                "tolerance",
                "bounds",
                "seed",
                "restart_seed",
                "popsize",
                "maxiter",
                "robust_popsize",
                "robust_maxiter",
            )
        },
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig8b.py"
