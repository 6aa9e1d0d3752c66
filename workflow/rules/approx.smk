# Approximate-COR model (paper Section 2.2, Fig. 2(b)-(d)): exact special points by root solving,
# fits of the paper's laws, errors of the paper's and the improved approximation, and figures.
# Every parameter comes from config["approx"]; each rule gets only the keys it uses, so changing
# a plotting range never reruns a computation.


rule approx_points:
    """Exact beta = 0 special points alpha*_n, e*_n, alpha#_n (n = 1..n_max) by root solving."""
    input:
        code=script_code("approx_points.py"),
    output:
        table=report(
            "results/approx/special_points.parquet",
            caption="../report/approx_points.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 2",
            labels={
                "figure": "2(b)-(d)",
                "quantity": "table: exact special points, beta = 0",
            },
        ),
    log:
        "logs/approx/points.log",
    benchmark:
        "logs/benchmarks/approx/points.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    params:
        approx={"n_max": config["approx"]["n_max"]},
    message:
        JOB_MESSAGE
    script:
        "../scripts/approx_points.py"


rule approx_finite_beta:
    """Finite-beta counterparts: alphas where the contact count changes, and smooth COR minima."""
    input:
        code=script_code("approx_points.py"),
    output:
        table=report(
            "results/approx/finite_beta_points.parquet",
            caption="../report/approx_finite_beta.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 2",
            labels={"figure": "2(a)", "quantity": "table: special points, beta > 0"},
        ),
    log:
        "logs/approx/finite_beta.log",
    benchmark:
        "logs/benchmarks/approx/finite_beta.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=30,
    params:
        approx={
            k: config["approx"][k]
            for k in (
                "finite_betas",
                "finite_alpha_min",
                "finite_alpha_max",
                "finite_n_grid",
                "finite_steps",
            )
        },
        max_events=config["max_events"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/approx_points.py"


rule approx_fit:
    """Fits (Eqs. 19, 22, minima law, eta1/eta2, improved shapes) and model errors vs exact."""
    input:
        points=rules.approx_points.output.table,
        code=script_code("approx_fit.py"),
    output:
        fit=report(
            "results/approx/fit.json",
            caption="../report/approx_fit.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 2",
            labels={"figure": "2(b)-(d)", "quantity": "table: fits and model errors"},
        ),
        residuals="results/approx/law_residuals.parquet",
        errors=report(
            "results/approx/errors.parquet",
            caption="../report/approx_errors.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 2",
            labels={
                "figure": "2(d)",
                "quantity": "table: errors of the approximate models",
            },
        ),
        shapes="results/approx/shape_table.parquet",
        curves="results/approx/cor_curves.parquet",
    log:
        "logs/approx/fit.log",
    benchmark:
        "logs/benchmarks/approx/fit.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    params:
        approx={
            k: config["approx"][k]
            for k in ("alpha_min", "alpha_max", "n_alpha", "n_plot", "n_eta")
        },
    message:
        JOB_MESSAGE
    script:
        "../scripts/approx_fit.py"


rule fig2b:
    """Fig. 2(b): duration and number of contacts vs alpha with Eq. 19; minima with their law."""
    input:
        sweep=rules.aggregate_fig2a.output.sweep,
        points=rules.approx_points.output.table,
        fit=rules.approx_fit.output.fit,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig2b.rst",
        code=script_code("render_fig2bcd.py"),
    output:
        png=report(
            "figures/fig2b.png",
            caption="../../results/captions/fig2b.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 2",
            labels={"figure": "2(b)", "quantity": "t_col and contacts vs alpha"},
        ),
        pdf="figures/fig2b.pdf",
        caption="results/captions/fig2b.rst",
    log:
        "logs/approx/render_fig2b.log",
    benchmark:
        "logs/benchmarks/approx/render_fig2b.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        panel="fig2b",
        approx={k: config["approx"][k] for k in ("plot_alpha_min", "plot_alpha_max")},
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig2bcd.py"


rule fig2c:
    """Fig. 2(c): alpha*_n - alpha#_n vs n with Eq. 22 (paper and fitted) and residuals."""
    input:
        residuals=rules.approx_fit.output.residuals,
        fit=rules.approx_fit.output.fit,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig2c.rst",
        code=script_code("render_fig2bcd.py"),
    output:
        png=report(
            "figures/fig2c.png",
            caption="../../results/captions/fig2c.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 2",
            labels={"figure": "2(c)", "quantity": "alpha* - alpha# vs n"},
        ),
        pdf="figures/fig2c.pdf",
        caption="results/captions/fig2c.rst",
    log:
        "logs/approx/render_fig2c.log",
    benchmark:
        "logs/benchmarks/approx/render_fig2c.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        panel="fig2c",
        approx={k: config["approx"][k] for k in ("plot_alpha_min", "plot_alpha_max")},
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig2bcd.py"


rule fig2d:
    """Fig. 2(d): exact, paper-approximate and improved COR, with an error panel."""
    input:
        curves=rules.approx_fit.output.curves,
        errors=rules.approx_fit.output.errors,
        fit=rules.approx_fit.output.fit,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig2d.rst",
        code=script_code("render_fig2bcd.py"),
    output:
        png=report(
            "figures/fig2d.png",
            caption="../../results/captions/fig2d.rst",
            category="Sect. 2: two-mass model, rigid and elastic contact",
            subcategory="Fig. 2",
            labels={"figure": "2(d)", "quantity": "approximate COR"},
        ),
        pdf="figures/fig2d.pdf",
        caption="results/captions/fig2d.rst",
    log:
        "logs/approx/render_fig2d.log",
    benchmark:
        "logs/benchmarks/approx/render_fig2d.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        panel="fig2d",
        approx={k: config["approx"][k] for k in ("plot_alpha_min", "plot_alpha_max")},
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig2bcd.py"
