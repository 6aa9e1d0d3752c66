# Beyond the paper (issue 27): Fig. 9, the COR against the impact speed V0 with Hertz contact on
# two masses and uniform chains, with the rigid-wall and soft-contact limits and the speeds where
# the contact count changes (restitution.analysis.speed). simulate -> parquet under
# results/fig9 -> render (figure + caption from the tables). `snakemake -c1 fig9` builds it.


rule simulate_fig9:
    """COR against V0 for every curve of Fig. 9: log grid, count changes bisected, limits."""
    input:
        code=script_code("simulate_fig9.py"),
    output:
        table=report(
            "results/fig9/speed.parquet",
            caption="../report/fig9_speed.rst",
            category="Beyond the paper",
            subcategory="Fig. 9",
            labels={"figure": "9", "quantity": "table: COR against V0"},
        ),
        limits="results/fig9/limits.parquet",
        changes="results/fig9/changes.parquet",
    log:
        "logs/fig9/simulate.log",
    benchmark:
        "logs/benchmarks/fig9/simulate.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    params:
        fig9=config["fig9"],
        max_events=config["max_events"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig9.py"


rule fig9:
    """Draw Fig. 9 and write its caption from the tables."""
    input:
        table=rules.simulate_fig9.output.table,
        limits=rules.simulate_fig9.output.limits,
        changes=rules.simulate_fig9.output.changes,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig9.rst",
        code=script_code("render_fig9.py"),
    output:
        png=report(
            "figures/fig9.png",
            caption="../../results/captions/fig9.rst",
            category="Beyond the paper",
            subcategory="Fig. 9",
            labels={"figure": "9", "quantity": "COR vs impact speed (Hertz)"},
        ),
        pdf="figures/fig9.pdf",
        caption="results/captions/fig9.rst",
    log:
        "logs/fig9/render_fig9.log",
    benchmark:
        "logs/benchmarks/fig9/render_fig9.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        fig9=config["fig9"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig9.py"
