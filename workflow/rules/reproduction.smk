# The reproduction table (issue 5): every number the paper prints next to ours, from existing
# results tables only (no solver runs), with the difference and a verdict.


rule reproduction:
    """results/reproduction.csv: paper vs ours, difference, verdict and reason."""
    input:
        special=rules.approx_points.output.table,
        finite=rules.approx_finite_beta.output.table,
        fit=rules.approx_fit.output.fit,
        minima=rules.aggregate_fig2a.output.minima,
        marginal=rules.simulate_fig3b.output.marginal,
        paper="config/paper_values.yaml",
        code=script_code("reproduction.py"),
    output:
        table=report(
            "results/reproduction.csv",
            caption="../report/reproduction.rst",
            category="Reproduction",
            labels={"figure": "-", "quantity": "paper vs ours"},
        ),
        page=report(
            "results/reproduction.html",
            caption="../report/reproduction_page.rst",
            category="Reproduction",
            labels={"figure": "-", "quantity": "paper vs ours (readable page)"},
        ),
    log:
        "logs/reproduction.log",
    benchmark:
        "logs/benchmarks/reproduction.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        # For the caption only (the script reads input.paper).
        paper=paper_values("cor_reduction", "alpha_reduction"),
    message:
        JOB_MESSAGE
    script:
        "../scripts/reproduction.py"
