# The restitution workflow: every figure of the paper from exact simulations.
# A table of contents only; the rules live in workflow/rules/, one file per stage.
# Run: `make all` (or `snakemake -c2 all` in an activated environment). Target first, then
# options: `snakemake -c2 all --configfile config/small.yaml` (docs/runs.md).

from snakemake.utils import min_version

min_version("9.0")


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"


# Any run but the paper's writes under runs/<run>/ (config key `run`, docs/runs.md).
if RUN_DIR is not None:

    workdir: RUN_DIR


include: "workflow/rules/sweeps.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/fig1_3_6.smk"
include: "workflow/rules/approx.smk"
include: "workflow/rules/fig4_5.smk"
include: "workflow/rules/fig7.smk"
include: "workflow/rules/reproduction.smk"
include: "workflow/rules/benchmarks.smk"
include: "workflow/rules/design.smk"
include: "workflow/rules/fig9.smk"
include: "workflow/rules/study.smk"


rule all:
    default_target: True
    input:
        rules.fig1.output.png,
        rules.fig1.output.pdf,
        rules.fig2a.output.png,
        rules.fig2a.output.pdf,
        rules.fig2b.output.png,
        rules.fig2b.output.pdf,
        rules.fig2c.output.png,
        rules.fig2c.output.pdf,
        rules.fig2d.output.png,
        rules.fig2d.output.pdf,
        rules.approx_finite_beta.output.table,
        rules.fig3a.output.png,
        rules.fig3a.output.pdf,
        rules.fig3b.output.png,
        rules.fig3b.output.pdf,
        rules.simulate_fig3b.output.marginal,
        rules.fig4a.output.png,
        rules.fig4a.output.pdf,
        rules.fig4b.output.png,
        rules.fig4b.output.pdf,
        rules.fig4c.output.png,
        rules.fig4c.output.pdf,
        rules.fig4d.output.png,
        rules.fig4d.output.pdf,
        rules.fig5a.output.png,
        rules.fig5a.output.pdf,
        rules.fig5b.output.png,
        rules.fig5b.output.pdf,
        rules.fig6a.output.png,
        rules.fig6a.output.pdf,
        rules.fig6b.output.png,
        rules.fig6b.output.pdf,
        rules.aggregate_fig6b.output.minima,
        rules.fig7a.output.png,
        rules.fig7a.output.pdf,
        rules.fig7b.output.png,
        rules.fig7b.output.pdf,
        rules.fig7c.output.png,
        rules.fig7c.output.pdf,
        rules.fig7d.output.png,
        rules.fig7d.output.pdf,
        rules.reproduction.output.table,
        rules.fig8a.output.png,
        rules.fig8a.output.pdf,
        rules.fig8b.output.png,
        rules.fig8b.output.pdf,
        rules.fig9.output.png,
        rules.fig9.output.pdf,
        # Every documented result table (workflow/tables.yaml, docs/tables.md): a deleted one is
        # rebuilt even when no figure needs it.
        result_tables(),
    message:
        TARGET_MESSAGE
