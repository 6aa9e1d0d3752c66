"""Render Fig. 3(a): COR against the stiffness ratio beta = k2/k1 on a log axis, one curve per
alpha (paper Sec. 3.1: 2, 2.2, 2.5).

Only rows with status "ok" are drawn (others are counted in the log). The sharp minima are the
cusps where the number of contacts changes (the sweep is refined there); the number of contacts
of each branch is written to the log.
"""

import numpy as np
import pandas as pd

DASHES = ["-", "--", "-.", ":"]


def draw(sweep: pd.DataFrame, alphas, logger):
    """The Fig. 3(a) figure (a matplotlib Figure on an Agg canvas)."""
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    for k, alpha in enumerate(alphas):
        rows = sweep["alpha"] == alpha
        curve = sweep[rows & (sweep["status"] == "ok")].sort_values("beta")
        dropped = int((rows & (sweep["status"] != "ok")).sum())
        if curve.empty:
            raise ValueError(f"no rows with status ok for alpha = {alpha} in the sweep table")
        if dropped:
            logger.warning("alpha %g: %d rows not ok, not drawn", alpha, dropped)
        ax.plot(
            curve["beta"],
            curve["cor"],
            color=plotting.alpha_colour(alpha, alphas),
            ls=DASHES[k % len(DASHES)],
            lw=1.0,
            label=rf"$\alpha = {alpha:g}$",
        )
        count = curve["n_collisions"].to_numpy()
        changes = np.flatnonzero(count[1:] != count[:-1])
        logger.info(
            "alpha %g: contacts %s, changing at beta %s",
            alpha,
            [int(count[0])] + [int(count[i + 1]) for i in changes],
            ", ".join(f"{curve['beta'].iloc[i]:.6g}" for i in changes),
        )
    plotting.log_axis(ax, "x")
    ax.set_xlim(sweep["beta"].min(), sweep["beta"].max())
    low = sweep.loc[sweep["status"] == "ok", "cor"].min()
    ax.set_ylim(max(0.0, np.floor(low * 10) / 10 - 0.05), 1.01)
    ax.set_xlabel(r"stiffness ratio $\beta = k_2/k_1$")
    ax.set_ylabel(plotting.COR_LABEL)
    ax.legend(loc="lower right")
    return fig


def caption_data(sweep: pd.DataFrame, alphas) -> dict:
    """Per alpha: where the curve is lowest. An interior lowest point is the sharp minimum the
    paper discusses; a curve lowest at the smallest beta (the rigid-wall side) has none."""
    sharp, none = [], []
    for alpha in alphas:
        curve = sweep[(sweep["alpha"] == alpha) & (sweep["status"] == "ok")].sort_values("beta")
        curve = curve.reset_index(drop=True)
        i = int(curve["cor"].idxmin())
        start = curve.iloc[0]
        if i == 0:
            none.append(
                f"alpha = {alpha:g} (COR {start['cor']:.3f} at beta = {start['beta']:g}, "
                f"its lowest point)"
            )
        else:
            low = curve.iloc[i]
            sharp.append(
                f"alpha = {alpha:g}: from {start['cor']:.3f} at beta = {start['beta']:g} down to "
                f"{low['cor']:.3f} at beta = {low['beta']:.4g} ({int(low['n_collisions'])} "
                "contacts)"
            )
    return {
        "sharp": "; ".join(sharp) or "none of the curves",
        "none": "; ".join(none) or "none",
        "none_count": len(none),
    }


def main(sweep_path, png_path, pdf_path, params, logger, smk=None):

    from restitution import plotting
    from restitution.tables.io import read_table

    sweep = read_table(sweep_path)
    for column in ("alpha", "beta", "cor", "n_collisions", "status"):
        if column not in sweep:
            raise ValueError(f"{sweep_path}: no column {column!r} (not a Fig. 3(a) sweep table)")
    missing = sorted(set(params.alphas) - set(sweep["alpha"].unique()))
    if missing:
        raise ValueError(f"{sweep_path}: no rows for alpha = {missing}")
    fig = draw(sweep, params.alphas, logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)
    if smk is not None:
        from render_caption import write_caption

        write_caption(smk, caption_data(sweep, params.alphas), logger)


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
            snakemake,  # noqa: F821
        )
