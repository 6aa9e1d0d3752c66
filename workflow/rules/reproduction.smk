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
    output:
        table=report(
            "results/reproduction.csv",
            caption="../report/reproduction.rst",
            category="Reproduction",
            labels={"figure": "-", "quantity": "paper vs ours"},
        ),
    log:
        "logs/reproduction.log",
    benchmark:
        "logs/benchmarks/reproduction.tsv"
    conda:
        "../envs/restitution.yaml"
    script:
        "../scripts/reproduction.py"


rule reproduction_page:
    """results/reproduction.html: the reproduction table as its own page of the report."""
    input:
        table=rules.reproduction.output.table,
    output:
        page=report(
            "results/reproduction.html",
            caption="../report/reproduction.rst",
            category="Reproduction",
            labels={"figure": "-", "quantity": "paper vs ours, as a page"},
        ),
    log:
        "logs/reproduction_page.log",
    benchmark:
        "logs/benchmarks/reproduction_page.tsv"
    conda:
        "../envs/restitution.yaml"
    script:
        "../scripts/render_reproduction_page.py"
