"""Render Fig. 2(a): COR against alpha = m2/m1 on a log axis, one curve per beta.

Only rows with status "ok" are drawn (others are counted in the log). The local minima of each
curve (the cusps), as ``aggregate_fig2a`` listed them in results/fig2a/minima.csv, are written to
the log and the first three rigid-wall minima to the caption, next to the paper's values
(config/paper_values.yaml).
"""

import pandas as pd


def first_minima(minima: pd.DataFrame, beta: float, count: int = 3) -> list[tuple[float, float]]:
    """(alpha, cor) of the first ``count`` minima of the curve ``beta`` in the minima table."""
    rows = minima[minima["beta"] == beta].sort_values("minimum").head(count)
    return list(zip(rows["alpha"].astype(float), rows["cor"].astype(float), strict=True))


def draw(sweep: pd.DataFrame, minima: pd.DataFrame, betas, logger):
    """The Fig. 2(a) figure (a matplotlib Figure on an Agg canvas)."""
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    # Finite betas as broad lines underneath, the rigid wall as a thin black line on top: at
    # alpha > 10 its many narrow peaks would otherwise be hidden under the finite-beta curves,
    # and beta = 1e-3, which coincides with it almost everywhere, still shows as a coloured rim.
    for beta in sorted(betas):
        curve = sweep[(sweep["beta"] == beta) & (sweep["status"] == "ok")].sort_values("alpha")
        dropped = int(((sweep["beta"] == beta) & (sweep["status"] != "ok")).sum())
        if curve.empty:
            raise ValueError(f"no rows with status ok for beta = {beta} in the sweep table")
        if dropped:
            logger.warning("beta %g: %d rows not ok, not drawn", beta, dropped)
        rigid = beta == 0
        ax.plot(
            curve["alpha"],
            curve["cor"],
            color=plotting.beta_colour(beta, betas),
            lw=0.55 if rigid else 1.1,
            zorder=4 if rigid else 3 - 0.1 * sorted(betas).index(beta),
            label=plotting.beta_text(beta),
        )
        logger.info(
            "beta %g: first minima (alpha, COR) %s",
            beta,
            ", ".join(f"({a:.4f}, {c:.4f})" for a, c in first_minima(minima, beta)),
        )
    plotting.log_axis(ax, "x")
    ax.set_xlim(sweep["alpha"].min(), sweep["alpha"].max())
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    ax.set_ylabel(plotting.COR_LABEL)
    ax.legend(loc="lower right", ncols=1)
    return fig


def caption_data(minima: pd.DataFrame) -> dict:
    """The first three rigid-wall minima of this run (alpha, COR), as caption text."""
    minima = first_minima(minima, 0.0)
    return {
        "rigid_minima_cor": ", ".join(f"{c:.4f}" for _, c in minima) or "none in range",
        "rigid_minima_alpha": ", ".join(f"{a:.4f}" for a, _ in minima) or "none in range",
    }


def main(sweep_path, minima_path, png_path, pdf_path, params, logger, smk=None):

    from restitution import plotting
    from restitution.tables.io import read_table

    sweep = read_table(sweep_path)
    minima = read_table(minima_path, columns=("beta", "minimum", "alpha", "cor"))
    missing = sorted(set(params.betas) - set(sweep["beta"].unique()))
    if missing:
        raise ValueError(f"{sweep_path}: no rows for beta = {missing}")
    fig = draw(sweep, minima, params.betas, logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)
    if smk is not None:
        from render_caption import write_caption

        write_caption(smk, caption_data(minima), logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(
            snakemake.input.sweep,  # noqa: F821
            snakemake.input.minima,  # noqa: F821
            snakemake.output.png,  # noqa: F821
            snakemake.output.pdf,  # noqa: F821
            snakemake.params,  # noqa: F821
            log,
            snakemake,  # noqa: F821
        )
