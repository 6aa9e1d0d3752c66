# Plotting stage: figures from results/ tables only (restyling never reruns a simulation).


rule fig2a:
    """Draw Fig. 2(a) in the house style (png for the report, pdf for print)."""
    input:
        sweep=rules.aggregate_fig2a.output.sweep,
        minima=rules.aggregate_fig2a.output.minima,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig2a.rst",
        code=script_code("render_fig2a.py"),
    output:
        png=report(
            "figures/fig2a.png",
            caption="../../results/captions/fig2a.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 2",
            labels={"figure": "2(a)", "quantity": "COR vs alpha"},
        ),
        pdf="figures/fig2a.pdf",
        caption="results/captions/fig2a.rst",
    log:
        "logs/fig2a/render.log",
    benchmark:
        "logs/benchmarks/fig2a/render.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        betas=config["fig2a"]["betas"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig2a.py"
