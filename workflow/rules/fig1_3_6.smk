# Fig. 1 and Fig. 6(a) (model schematics, drawn programmatically), Fig. 3 (the contact stiffness
# at fixed mass ratio, paper Sec. 3.1) and Fig. 6(b) (chains of N masses, Sec. 3.3 and Appendix).
# simulate_* -> parquet under results/ -> (aggregate) -> render; the render rules are named by
# the figure, so `snakemake fig3a` builds figures/fig3a.png and .pdf.


# ---------------------------------------------------------------------------------------------
# Fig. 3(a): COR against beta for the alphas of config fig3.sweep
# ---------------------------------------------------------------------------------------------
rule simulate_fig3a:
    """Solve the log-spaced beta grid for every alpha, refined at every change of the contact count."""
    input:
        code=script_code("simulate_fig3.py"),
    output:
        sweep="results/fig3/sweep.parquet",
        minima=report(
            "results/fig3/minima.csv",
            caption="../report/fig3a_minima.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 3",
            labels={"figure": "3(a)", "quantity": "table: COR minima per alpha"},
        ),
    log:
        "logs/fig3/simulate_fig3a.log",
    benchmark:
        "logs/benchmarks/fig3/simulate_fig3a.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    params:
        sweep=config["fig3"]["sweep"],
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig3.py"


rule fig3a:
    """Draw Fig. 3(a): COR against beta (log axis), one curve per alpha."""
    input:
        sweep=rules.simulate_fig3a.output.sweep,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig3a.rst",
        code=script_code("render_fig3a.py"),
    output:
        png=report(
            "figures/fig3a.png",
            caption="../../results/captions/fig3a.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 3",
            labels={"figure": "3(a)", "quantity": "COR vs beta"},
        ),
        pdf="figures/fig3a.pdf",
        caption="results/captions/fig3a.rst",
    log:
        "logs/fig3/render_fig3a.log",
    benchmark:
        "logs/benchmarks/fig3/render_fig3a.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        alphas=config["fig3"]["sweep"]["alphas"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig3a.py"


# ---------------------------------------------------------------------------------------------
# Fig. 3(b): contact compression against omega*t, and the marginal beta near 0.1
# ---------------------------------------------------------------------------------------------
rule simulate_fig3b:
    """Compression histories for the betas of fig3.compression; bisect the marginal beta."""
    input:
        code=script_code("simulate_fig3.py"),
    output:
        compression="results/fig3/compression.parquet",
        contacts=report(
            "results/fig3/contacts.csv",
            caption="../report/fig3b_contacts.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 3",
            labels={"figure": "3(b)", "quantity": "table: contacts per beta"},
        ),
        marginal=report(
            "results/fig3/marginal_beta.csv",
            caption="../report/fig3b_marginal.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 3",
            labels={"figure": "3(b)", "quantity": "table: marginal beta"},
        ),
    log:
        "logs/fig3/simulate_fig3b.log",
    benchmark:
        "logs/benchmarks/fig3/simulate_fig3b.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    params:
        compression=config["fig3"]["compression"],
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig3.py"


rule fig3b:
    """Draw Fig. 3(b): compression (negative) against omega*t, one curve per beta."""
    input:
        compression=rules.simulate_fig3b.output.compression,
        contacts=rules.simulate_fig3b.output.contacts,
        marginal=rules.simulate_fig3b.output.marginal,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig3b.rst",
        code=script_code("render_fig3b.py"),
    output:
        png=report(
            "figures/fig3b.png",
            caption="../../results/captions/fig3b.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 3",
            labels={"figure": "3(b)", "quantity": "contact compression vs omega t"},
        ),
        pdf="figures/fig3b.pdf",
        caption="results/captions/fig3b.rst",
    log:
        "logs/fig3/render_fig3b.log",
    benchmark:
        "logs/benchmarks/fig3/render_fig3b.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        betas=config["fig3"]["compression"]["betas"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig3b.py"


# ---------------------------------------------------------------------------------------------
# Fig. 6(b): COR of a chain of N masses against (N-1)*alpha, one simulate job per N
# ---------------------------------------------------------------------------------------------
rule simulate_fig6b:
    """Solve the log-spaced x = (N-1)*alpha grid for one chain length N, cusps refined."""
    input:
        code=script_code("simulate_fig6b.py"),
    output:
        table="results/fig6/n~{n}.parquet",
    log:
        "logs/fig6/simulate/n~{n}.log",
    benchmark:
        "logs/benchmarks/fig6/simulate/n~{n}.tsv"
    wildcard_constraints:
        n=r"[1-9]\d*",
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    params:
        sweep=config["fig6"]["sweep"],
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig6b.py"


rule aggregate_fig6b:
    """One table from the per-N tables; its COR minima as CSV; check the first-contact branch."""
    input:
        tables=expand("results/fig6/n~{n}.parquet", n=config["fig6"]["n_masses"]),
        code=script_code("aggregate_fig6b.py"),
    output:
        sweep="results/fig6/sweep.parquet",
        minima=report(
            "results/fig6/minima.csv",
            caption="../report/fig6b_minima.rst",
            category="Sect. 3.3: chains of N masses",
            subcategory="Fig. 6",
            labels={"figure": "6(b)", "quantity": "table: COR minima per N"},
        ),
    log:
        "logs/fig6/aggregate.log",
    benchmark:
        "logs/benchmarks/fig6/aggregate.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        fig6=config["fig6"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/aggregate_fig6b.py"


rule fig6b:
    """Draw Fig. 6(b): COR against (N-1)*alpha (log axis), one curve per N."""
    input:
        sweep=rules.aggregate_fig6b.output.sweep,
        minima=rules.aggregate_fig6b.output.minima,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig6b.rst",
        code=script_code("render_fig6b.py"),
    output:
        png=report(
            "figures/fig6b.png",
            caption="../../results/captions/fig6b.rst",
            category="Sect. 3.3: chains of N masses",
            subcategory="Fig. 6",
            labels={"figure": "6(b)", "quantity": "COR vs (N-1) alpha"},
        ),
        pdf="figures/fig6b.pdf",
        caption="results/captions/fig6b.rst",
    log:
        "logs/fig6/render_fig6b.log",
    benchmark:
        "logs/benchmarks/fig6/render_fig6b.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        n_masses=config["fig6"]["n_masses"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig6b.py"


# ---------------------------------------------------------------------------------------------
# Fig. 1 and Fig. 6(a): the models, drawn with matplotlib patches (no data)
# ---------------------------------------------------------------------------------------------
rule fig1:
    """Draw Fig. 1: the two-mass model at the wall (contact spring k1, structural spring k2)."""
    input:
        style="src/restitution/restitution.mplstyle",
        code=script_code("render_schematics.py"),
    output:
        png=report(
            "figures/fig1.png",
            caption="../report/fig1.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 1",
            labels={"figure": "1", "quantity": "two-mass model"},
        ),
        pdf="figures/fig1.pdf",
    log:
        "logs/fig1/render.log",
    benchmark:
        "logs/benchmarks/fig1/render.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        model="two_mass",
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_schematics.py"


rule fig6a:
    """Draw Fig. 6(a): the chain of N masses at the wall."""
    input:
        style="src/restitution/restitution.mplstyle",
        code=script_code("render_schematics.py"),
    output:
        png=report(
            "figures/fig6a.png",
            caption="../report/fig6a.rst",
            category="Sect. 3.3: chains of N masses",
            subcategory="Fig. 6",
            labels={"figure": "6(a)", "quantity": "chain of N masses"},
        ),
        pdf="figures/fig6a.pdf",
    log:
        "logs/fig6/render_fig6a.log",
    benchmark:
        "logs/benchmarks/fig6/render_fig6a.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        model="chain",
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_schematics.py"
