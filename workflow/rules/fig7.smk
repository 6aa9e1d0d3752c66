# Fig. 7 (paper Section 3.4): a dashpot F_v = 2*xi*k2*(u2' - u1')/omega between m1 and m2, beta
# from config["fig7"] (paper: 0.001).
# Sweep:  simulate_fig7 (one job per xi and alpha chunk, cusps refined) -> aggregate_fig7 ->
#         fig7a (COR), fig7b (number of contacts), fig7c (omega*t_col), all from one sweep table.
# Traces: simulate_fig7d (closed-form compression s1(t) for a few (xi, alpha)) -> fig7d.
# The render rules are named by the panel, so `snakemake -c2 fig7a` builds exactly that panel.
# Helpers from common.smk: script_code(), solver_settings(), beta_label() (a short exact path
# label for any float, used here for xi). No functions here (lint: rules and functions apart).

FIG7_GRID = {
    key: config["fig7"][key]
    for key in (
        "beta",
        "alpha_min",
        "alpha_max",
        "n_alpha",
        "chunk_size",
        "refine_steps",
    )
}
FIG7_CHUNK_TABLES = expand(
    "results/fig7/xi~{xi}/chunk_{chunk}.parquet",
    xi=[beta_label(xi) for xi in config["fig7"]["xis"]],
    chunk=range(math.ceil((FIG7_GRID["n_alpha"] - 1) / FIG7_GRID["chunk_size"])),
)
FIG7_PLOT = {
    key: config["fig7"][key] for key in ("beta", "xis", "alpha_min", "alpha_max")
}


rule simulate_fig7:
    """Solve one chunk of the alpha grid for one xi (dashpot), refined at every change of the contact count."""
    input:
        code=script_code("simulate_fig7.py"),
    output:
        table="results/fig7/xi~{xi}/chunk_{chunk}.parquet",
    log:
        "logs/fig7/simulate/xi~{xi}/chunk_{chunk}.log",
    benchmark:
        "logs/benchmarks/fig7/simulate/xi~{xi}/chunk_{chunk}.tsv"
    wildcard_constraints:
        xi=r"\d+(\.\d+)?(e[+-]?\d+)?",
        chunk=r"\d+",
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    params:
        grid=FIG7_GRID,
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig7.py"


rule aggregate_fig7:
    """One sweep table from the chunks, a status check, and per-xi numbers (peak contact count, minima)."""
    input:
        chunks=FIG7_CHUNK_TABLES,
        code=script_code("aggregate_fig7.py"),
    output:
        sweep="results/fig7/sweep.parquet",
        summary=report(
            "results/fig7/summary.csv",
            caption="../report/fig7_summary.rst",
            category="Sect. 3.4: dashpot between the masses",
            subcategory="Fig. 7",
            labels={
                "figure": "7(a)-(c)",
                "quantity": "table: contact-count peak per xi",
            },
        ),
        minima=report(
            "results/fig7/minima.csv",
            caption="../report/fig7_minima.rst",
            category="Sect. 3.4: dashpot between the masses",
            subcategory="Fig. 7",
            labels={"figure": "7(a)", "quantity": "table: COR minima per xi"},
        ),
    log:
        "logs/fig7/aggregate.log",
    benchmark:
        "logs/benchmarks/fig7/aggregate.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        fig7={
            **FIG7_GRID,
            "xis": config["fig7"]["xis"],
            "max_not_ok_fraction": config["fig7"]["max_not_ok_fraction"],
        },
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/aggregate_fig7.py"


rule fig7a:
    """Fig. 7(a): COR against alpha, one curve per damping ratio xi."""
    input:
        sweep=rules.aggregate_fig7.output.sweep,
        minima=rules.aggregate_fig7.output.minima,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig7a.rst",
        code=script_code("render_fig7.py"),
    output:
        png=report(
            "figures/fig7a.png",
            caption="../../results/captions/fig7a.rst",
            category="Sect. 3.4: dashpot between the masses",
            subcategory="Fig. 7",
            labels={"figure": "7(a)", "quantity": "COR vs alpha, dashpot"},
        ),
        pdf="figures/fig7a.pdf",
        caption="results/captions/fig7a.rst",
    log:
        "logs/fig7/render_fig7a.log",
    benchmark:
        "logs/benchmarks/fig7/render_fig7a.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        panel="fig7a",
        fig7=FIG7_PLOT,
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig7.py"


rule fig7b:
    """Fig. 7(b): number of contacts against alpha, one curve per damping ratio xi."""
    input:
        sweep=rules.aggregate_fig7.output.sweep,
        summary=rules.aggregate_fig7.output.summary,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig7b.rst",
        code=script_code("render_fig7.py"),
    output:
        png=report(
            "figures/fig7b.png",
            caption="../../results/captions/fig7b.rst",
            category="Sect. 3.4: dashpot between the masses",
            subcategory="Fig. 7",
            labels={"figure": "7(b)", "quantity": "contacts vs alpha, dashpot"},
        ),
        pdf="figures/fig7b.pdf",
        caption="results/captions/fig7b.rst",
    log:
        "logs/fig7/render_fig7b.log",
    benchmark:
        "logs/benchmarks/fig7/render_fig7b.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        panel="fig7b",
        fig7=FIG7_PLOT,
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig7.py"


rule fig7c:
    """Fig. 7(c): normalised total duration omega*t_col against alpha, one curve per xi."""
    input:
        sweep=rules.aggregate_fig7.output.sweep,
        summary=rules.aggregate_fig7.output.summary,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig7c.rst",
        code=script_code("render_fig7.py"),
    output:
        png=report(
            "figures/fig7c.png",
            caption="../../results/captions/fig7c.rst",
            category="Sect. 3.4: dashpot between the masses",
            subcategory="Fig. 7",
            labels={"figure": "7(c)", "quantity": "omega t_col vs alpha, dashpot"},
        ),
        pdf="figures/fig7c.pdf",
        caption="results/captions/fig7c.rst",
    log:
        "logs/fig7/render_fig7c.log",
    benchmark:
        "logs/benchmarks/fig7/render_fig7c.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        panel="fig7c",
        fig7=FIG7_PLOT,
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig7.py"


rule simulate_fig7d:
    """Contact compression s1(t) for each (xi, alpha) of Fig. 7(d), sampled inside every contact."""
    input:
        code=script_code("simulate_fig7d.py"),
    output:
        traces="results/fig7/traces.parquet",
        contacts="results/fig7/contacts.parquet",
        summary=report(
            "results/fig7/last_contact.csv",
            caption="../report/fig7d_last_contact.rst",
            category="Sect. 3.4: dashpot between the masses",
            subcategory="Fig. 7",
            labels={"figure": "7(d)", "quantity": "table: last contact per trace"},
        ),
    log:
        "logs/fig7/simulate_fig7d.log",
    benchmark:
        "logs/benchmarks/fig7/simulate_fig7d.tsv"
    conda:
        "../envs/restitution.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    params:
        beta=config["fig7"]["beta"],
        traces=config["fig7"]["traces"],
        solver=solver_settings(),
    message:
        JOB_MESSAGE
    script:
        "../scripts/simulate_fig7d.py"


rule fig7d:
    """Fig. 7(d): omega*s1/V0 against omega*t/(2 pi), one panel per xi, one trace per alpha."""
    input:
        traces=rules.simulate_fig7d.output.traces,
        contacts=rules.simulate_fig7d.output.contacts,
        style="src/restitution/restitution.mplstyle",
        paper="config/paper_values.yaml",
        template="workflow/report/fig7d.rst",
        code=script_code("render_fig7d.py"),
    output:
        png=report(
            "figures/fig7d.png",
            caption="../../results/captions/fig7d.rst",
            category="Sect. 3.4: dashpot between the masses",
            subcategory="Fig. 7",
            labels={"figure": "7(d)", "quantity": "contact compression vs time"},
        ),
        pdf="figures/fig7d.pdf",
        caption="results/captions/fig7d.rst",
    log:
        "logs/fig7/render_fig7d.log",
    benchmark:
        "logs/benchmarks/fig7/render_fig7d.tsv"
    conda:
        "../envs/restitution.yaml"
    params:
        beta=config["fig7"]["beta"],
        traces=config["fig7"]["traces"],
    message:
        JOB_MESSAGE
    script:
        "../scripts/render_fig7d.py"
