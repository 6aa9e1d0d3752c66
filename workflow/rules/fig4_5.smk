# Fig. 4 (plastic contact, paper Sec. 3.1) and Fig. 5 (scissor structural spring, Sec. 3.2).
# Sweeps: simulate_fig4{b,c,d} and simulate_fig5b, one job per panel (a panel's curves together
# take a few seconds, less than the start-up of one job per curve), each writing the sweep table
# and a per-curve summary CSV (minima, Eq. 23 margin, rows not ok). Renders: rules fig4a..fig5b,
# named after the figure so that `snakemake fig4c` builds figures/fig4c.{png,pdf}.
# Panels (a) are drawn from the force laws in restitution/model/laws.py (no simulation).


rule simulate_fig4b:
    """COR against alpha, plastic contact, several DR at one eta (Fig. 4(b))."""
    input:
        code=script_code("simulate_fig4.py"),
    output:
        table="results/fig4/b/sweep.parquet",
        summary=report(
            "results/fig4/b/summary.csv",
            caption="../report/fig4_summary.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 4",
            labels={"figure": "4(b)", "quantity": "table: minima per curve"},
        ),
    log:
        "logs/fig4/simulate_b.log",
    benchmark:
        "logs/benchmarks/fig4/simulate_b.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    params:
        name="b",
        sweep=config["fig4"]["sweep"],
        panel=config["fig4"]["b"],
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig4.py"


rule simulate_fig4c:
    """COR against alpha, plastic contact, several eta at beta = 0.01; Eq. 23 checked (Fig. 4(c))."""
    input:
        code=script_code("simulate_fig4.py"),
    output:
        table="results/fig4/c/sweep.parquet",
        summary=report(
            "results/fig4/c/summary.csv",
            caption="../report/fig4_summary.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 4",
            labels={
                "figure": "4(c)",
                "quantity": "table: minima and Eq. 23 margin per curve",
            },
        ),
    log:
        "logs/fig4/simulate_c.log",
    benchmark:
        "logs/benchmarks/fig4/simulate_c.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    params:
        name="c",
        sweep=config["fig4"]["sweep"],
        panel=config["fig4"]["c"],
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig4.py"


rule simulate_fig4d:
    """As simulate_fig4c at beta = 0.1 (Fig. 4(d))."""
    input:
        code=script_code("simulate_fig4.py"),
    output:
        table="results/fig4/d/sweep.parquet",
        summary=report(
            "results/fig4/d/summary.csv",
            caption="../report/fig4_summary.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 4",
            labels={
                "figure": "4(d)",
                "quantity": "table: minima and Eq. 23 margin per curve",
            },
        ),
    log:
        "logs/fig4/simulate_d.log",
    benchmark:
        "logs/benchmarks/fig4/simulate_d.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    params:
        name="d",
        sweep=config["fig4"]["sweep"],
        panel=config["fig4"]["d"],
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig4.py"


rule simulate_fig5b:
    """COR against alpha with the scissor structural spring, several L (Fig. 5(b))."""
    input:
        helpers="workflow/scripts/simulate_fig4.py",
        code=script_code("simulate_fig5.py"),
    output:
        table="results/fig5/b/sweep.parquet",
        summary=report(
            "results/fig5/b/summary.csv",
            caption="../report/fig5b_summary.rst",
            category="Sect. 3.2: scissor structural spring",
            subcategory="Fig. 5",
            labels={"figure": "5(b)", "quantity": "table: minima per curve"},
        ),
        scan=report(
            "results/fig5/b/free_choice_scan.csv",
            caption="../report/fig5b_scan.rst",
            category="Sect. 3.2: scissor structural spring",
            subcategory="Fig. 5",
            labels={"figure": "5(b)", "quantity": "table: L trend vs theta0, corner"},
        ),
    log:
        "logs/fig5/simulate_b.log",
    benchmark:
        "logs/benchmarks/fig5/simulate_b.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    params:
        spring=config["fig5"]["spring"],
        panel=config["fig5"]["b"],
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig5.py"


rule fig4a:
    """Draw Fig. 4(a): loading-unloading curves of the plastic contact law (from laws.py)."""
    input:
        laws="src/restitution/model/laws.py",
        style="src/restitution/restitution.mplstyle",
        code=script_code("render_fig4.py"),
    output:
        png=report(
            "figures/fig4a.png",
            caption="../report/fig4a.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 4",
            labels={"figure": "4(a)", "quantity": "contact force vs penetration"},
        ),
        pdf="figures/fig4a.pdf",
    log:
        "logs/fig4/render_a.log",
    benchmark:
        "logs/benchmarks/fig4/render_a.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        name="fig4a",
        panel=config["fig4"]["a"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig4.py"


rule fig4b:
    """Draw Fig. 4(b): effect of DR at eta = 0.5."""
    input:
        sweep=rules.simulate_fig4b.output.table,
        summary=rules.simulate_fig4b.output.summary,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig4b.rst",
        code=script_code("render_fig4.py"),
    output:
        png=report(
            "figures/fig4b.png",
            caption="../../results/captions/fig4b.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 4",
            labels={"figure": "4(b)", "quantity": "COR vs alpha, several DR"},
        ),
        pdf="figures/fig4b.pdf",
        caption="results/captions/fig4b.rst",
    log:
        "logs/fig4/render_b.log",
    benchmark:
        "logs/benchmarks/fig4/render_b.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        name="fig4b",
        panel=config["fig4"]["b"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig4.py"


rule fig4c:
    """Draw Fig. 4(c): several eta at beta = 0.01 with the Eq. 23 bound."""
    input:
        sweep=rules.simulate_fig4c.output.table,
        summary=rules.simulate_fig4c.output.summary,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig4c.rst",
        code=script_code("render_fig4.py"),
    output:
        png=report(
            "figures/fig4c.png",
            caption="../../results/captions/fig4c.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 4",
            labels={
                "figure": "4(c)",
                "quantity": "COR vs alpha, several eta, beta = 0.01",
            },
        ),
        pdf="figures/fig4c.pdf",
        caption="results/captions/fig4c.rst",
    log:
        "logs/fig4/render_c.log",
    benchmark:
        "logs/benchmarks/fig4/render_c.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        name="fig4c",
        panel=config["fig4"]["c"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig4.py"


rule fig4d:
    """Draw Fig. 4(d): several eta at beta = 0.1 with the Eq. 23 bound."""
    input:
        sweep=rules.simulate_fig4d.output.table,
        summary=rules.simulate_fig4d.output.summary,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig4d.rst",
        code=script_code("render_fig4.py"),
    output:
        png=report(
            "figures/fig4d.png",
            caption="../../results/captions/fig4d.rst",
            category="Sect. 3.1: contact stiffness and plastic contact",
            subcategory="Fig. 4",
            labels={
                "figure": "4(d)",
                "quantity": "COR vs alpha, several eta, beta = 0.1",
            },
        ),
        pdf="figures/fig4d.pdf",
        caption="results/captions/fig4d.rst",
    log:
        "logs/fig4/render_d.log",
    benchmark:
        "logs/benchmarks/fig4/render_d.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        name="fig4d",
        panel=config["fig4"]["d"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig4.py"


rule fig5a:
    """Draw Fig. 5(a): scissor spring force-displacement curves (from laws.py)."""
    input:
        laws="src/restitution/model/laws.py",
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig5a.rst",
        code=script_code("render_fig5.py"),
    output:
        png=report(
            "figures/fig5a.png",
            caption="../../results/captions/fig5a.rst",
            category="Sect. 3.2: scissor structural spring",
            subcategory="Fig. 5",
            labels={
                "figure": "5(a)",
                "quantity": "scissor spring force vs displacement",
            },
        ),
        pdf="figures/fig5a.pdf",
        caption="results/captions/fig5a.rst",
    log:
        "logs/fig5/render_a.log",
    benchmark:
        "logs/benchmarks/fig5/render_a.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        name="a",
        spring=config["fig5"]["spring"],
        panel=config["fig5"]["a"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig5.py"


rule fig5b:
    """Draw Fig. 5(b): COR against alpha with the scissor spring, several L."""
    input:
        sweep=rules.simulate_fig5b.output.table,
        scan=rules.simulate_fig5b.output.scan,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig5b.rst",
        code=script_code("render_fig5.py"),
    output:
        png=report(
            "figures/fig5b.png",
            caption="../../results/captions/fig5b.rst",
            category="Sect. 3.2: scissor structural spring",
            subcategory="Fig. 5",
            labels={
                "figure": "5(b)",
                "quantity": "COR vs alpha, scissor spring, several L",
            },
        ),
        pdf="figures/fig5b.pdf",
        caption="results/captions/fig5b.rst",
    log:
        "logs/fig5/render_b.log",
    benchmark:
        "logs/benchmarks/fig5/render_b.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        name="b",
        spring=config["fig5"]["spring"],
        panel=config["fig5"]["b"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig5.py"
