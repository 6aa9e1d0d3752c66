"""Draw a user study's standard plots: each output against the first axis, one curve per value
of the second axis. Only rows with status ok are drawn (the others are counted in the log)."""

import math

from matplotlib.ticker import FuncFormatter


def style(study, table, curve: float, index: int) -> dict:
    """One colour, one meaning (restitution.plotting): a curve per beta, xi or alpha takes that
    value's colour of every figure; any other curve a neutral line style."""
    from restitution import plotting

    param = study.axes[1].param if len(study.axes) > 1 else None
    colour = {"beta": plotting.beta_colour, "xi": plotting.xi_colour,
              "alpha": plotting.alpha_colour}.get(param)  # fmt: skip
    if colour is None or math.isnan(curve):
        return plotting.series_style(index)
    return {"color": colour(curve, [float(v) for v in table["curve"].dropna().unique()])}


def _minor_label(value: float, _pos=None) -> str:
    """Text of a minor tick of a log axis: 2, 3, 5 times a power of ten, others blank."""
    mantissa = value / 10 ** math.floor(math.log10(value) + 1e-9)
    return f"{value:g}" if round(mantissa, 6) in (2.0, 3.0, 5.0) else ""


def draw(table, study, output: str, logger):
    from restitution import plotting
    from restitution_workflow.study import OUTPUTS

    first = study.axes[0]
    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    for index, part in table.groupby("curve_index"):
        good = part[part["status"] == "ok"].sort_values(first.param)
        dropped = len(part) - len(good)
        if dropped:
            logger.warning("curve %d: %d rows not ok, not drawn", index, dropped)
        curve = float(part["curve"].iloc[0])
        text = None if math.isnan(curve) else study.axes[1].curve_text(curve)
        ax.plot(good[first.param], good[output], lw=0.9, label=text,
                **style(study, table, curve, int(index)))  # fmt: skip
    if first.log:
        plotting.log_axis(ax, "x")
        if first.values.max() / first.values.min() < 100:  # under two decades: label 2, 3, 5 too
            ax.xaxis.set_minor_formatter(FuncFormatter(_minor_label))
    ax.set_xlabel(first.title)  # the study's label and unit, or the parameter's name
    ax.set_ylabel(OUTPUTS[output])
    if output == "cor":
        ax.set_ylim(min(0.0, float(table["cor"].min())), 1.02)
    if len(study.axes) > 1:
        ax.legend(loc="best")
    ax.set_title(study.name, fontsize="medium")
    return fig


def main(sweep_path, pngs, pdfs, study_mapping, logger):
    from restitution import plotting
    from restitution.tables.io import read_table
    from restitution_workflow.study import check_study

    study = check_study(study_mapping)
    table = read_table(sweep_path)
    for output, png, pdf in zip(study.outputs, pngs, pdfs, strict=True):
        fig = draw(table, study, output, logger)
        plotting.save_outputs(fig, png, pdf, logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "study plot"):
        main(
            snakemake.input.sweep,  # noqa: F821
            list(snakemake.output.png),  # noqa: F821
            list(snakemake.output.pdf),  # noqa: F821
            snakemake.params.study,  # noqa: F821
            log,
        )
