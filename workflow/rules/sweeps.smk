# Simulation stage: parameter sweeps solved by the package, written as parquet under results/.
# Fig. 2(a): COR against alpha = m2/m1 for a rigid wall (beta = 0) and finite contact stiffness;
# simulate_fig2a (one job per beta and alpha chunk) -> aggregate_fig2a (one table).


rule simulate_fig2a:
    """Solve one chunk of the alpha grid for one beta, refined at every change of the contact count."""
    input:
        code=script_code("simulate_fig2a.py"),
    output:
        table="results/fig2a/beta~{beta}/chunk_{chunk}.parquet",
    log:
        "logs/fig2a/simulate/beta~{beta}/chunk_{chunk}.log",
    benchmark:
        "logs/benchmarks/fig2a/simulate/beta~{beta}/chunk_{chunk}.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    params:
        grid=fig2a_grid(),
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig2a.py"


rule aggregate_fig2a:
    """One sweep table from the chunks (shared boundary rows once), and its COR minima as CSV."""
    input:
        chunks=fig2a_chunk_tables(),
        code=script_code("aggregate_fig2a.py"),
    output:
        sweep="results/fig2a/sweep.parquet",
        minima=report(
            "results/fig2a/minima.csv",
            caption="../report/fig2a_minima.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 2",
            labels={"figure": "2(a)", "quantity": "table: COR minima per beta"},
        ),
    log:
        "logs/fig2a/aggregate.log",
    benchmark:
        "logs/benchmarks/fig2a/aggregate.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        fig2a=config["fig2a"],
        solver=solver_settings(),
        # For the caption only (the paper's beta = 0 minima it compares with).
        paper=paper_values("rigid_min1_cor", "rigid_min2_cor", "rigid_min3_cor"),
    message:
        JOB_MESSAGE
    script:
        "../scripts/aggregate_fig2a.py"
