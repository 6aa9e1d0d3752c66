"""Render Fig. 2(a): COR against alpha = m2/m1 on a log axis, one curve per beta.

Only rows with status "ok" are drawn (others are counted in the log). The local minima of each
curve (the cusps) are written to the log, so the depths can be compared with the paper's
0.178, 0.557, 0.710 at alpha = 0.697, 2.07, 3.64 (rigid wall).
"""

import numpy as np
import pandas as pd


def cusp_minima(curve: pd.DataFrame, count: int = 3) -> list[tuple[float, float]]:
    """(alpha, cor) of the first ``count`` local minima of a curve sorted by alpha."""
    cor = curve["cor"].to_numpy()
    inner = np.flatnonzero((cor[1:-1] < cor[:-2]) & (cor[1:-1] <= cor[2:])) + 1
    alpha = curve["alpha"].to_numpy()
    return [(float(alpha[i]), float(cor[i])) for i in inner[:count]]


def draw(sweep: pd.DataFrame, betas, logger):
    """The Fig. 2(a) figure (a matplotlib Figure on an Agg canvas)."""
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    # Rigid wall as a broad black line underneath, finite betas thinner on top in the colour
    # cycle: beta = 1e-3 coincides with the rigid wall almost everywhere and stays visible.
    colours = ["#E69F00", "#56B4E9", "#009E73", "#D55E00", "#CC79A7", "#0072B2", "#F0E442"]
    finite = iter(colours * (1 + len(betas) // len(colours)))
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
            color="black" if rigid else next(finite),
            lw=1.3 if rigid else 0.75,
            zorder=2 if rigid else 3,
            label=plotting.beta_text(beta),
        )
        logger.info(
            "beta %g: first minima (alpha, COR) %s",
            beta,
            ", ".join(f"({a:.4f}, {c:.4f})" for a, c in cusp_minima(curve)),
        )
    plotting.log_axis(ax, "x")
    ax.set_xlim(sweep["alpha"].min(), sweep["alpha"].max())
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    ax.set_ylabel("coefficient of restitution $e$")
    ax.legend(loc="lower right", ncols=1)
    return fig


def main(sweep_path, png_path, pdf_path, params, logger):

    from restitution import plotting
    from restitution.io import read_table

    sweep = read_table(sweep_path)
    missing = sorted(set(params.betas) - set(sweep["beta"].unique()))
    if missing:
        raise ValueError(f"{sweep_path}: no rows for beta = {missing}")
    fig = draw(sweep, params.betas, logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(
            snakemake.input.sweep,  # noqa: F821
            snakemake.output.png,  # noqa: F821
            snakemake.output.pdf,  # noqa: F821
            snakemake.params,  # noqa: F821
            log,
        )
