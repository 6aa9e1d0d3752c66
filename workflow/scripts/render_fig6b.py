"""Render Fig. 6(b): COR of the chain of N masses against x = (N-1)*alpha on a log axis, one
curve per N, with the first-contact branch e1 = (1 - x)/(1 + x) (Appendix) as a light grey band.

Only rows with status "ok" are drawn (others are counted in the log). The first minima of each
curve, as ``aggregate_fig6b`` listed them in results/fig6/minima.csv, are written to the log.
"""

import numpy as np
import pandas as pd


def draw(sweep: pd.DataFrame, minima: pd.DataFrame, n_masses, logger):
    """The Fig. 6(b) figure (a matplotlib Figure on an Agg canvas)."""
    from restitution import plotting

    fig = plotting.new_figure("onehalf", aspect=0.58)
    ax = fig.add_subplot()
    x_lo, x_hi = sweep["x"].min(), sweep["x"].max()
    branch = np.geomspace(x_lo, min(x_hi, 0.95), 200)
    ax.plot(
        branch,
        (1 - branch) / (1 + branch),
        **plotting.REFERENCE_STYLE,
        zorder=1,
        label=r"$(1-x)/(1+x)$",
    )
    for i, n in enumerate(sorted(n_masses)):
        rows = sweep["n_masses"] == n
        curve = sweep[rows & (sweep["status"] == "ok")].sort_values("x")
        dropped = int((rows & (sweep["status"] != "ok")).sum())
        if curve.empty:
            raise ValueError(f"no rows with status ok for N = {n} in the sweep table")
        if dropped:
            logger.warning("N = %d: %d rows not ok, not drawn", n, dropped)
        ax.plot(
            curve["x"],
            curve["cor"],
            **plotting.series_style(i),
            lw=1.1 if n == 2 else 0.9,
            zorder=3 if n == 2 else 2,
            label=rf"$N = {n}$",
        )
        logger.info(
            "N = %d: first minima (x, COR) %s",
            n,
            ", ".join(
                f"({a:.4f}, {c:.4f})"
                for a, c in minima.loc[minima["n_masses"] == n, ["x", "cor"]].head(3).to_numpy()
            ),
        )
    plotting.log_axis(ax, "x")
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel(r"rear mass ratio $x = (N-1)\,\alpha$")
    ax.set_ylabel(plotting.COR_LABEL)
    ax.legend(loc="lower right")
    return fig


def caption_data(sweep: pd.DataFrame, minima: pd.DataFrame) -> dict:
    """How the COR orders with N on the shared x grid (sweep table), the first minimum and the
    number of minima of each curve (minima table)."""
    from render_caption import ordering

    first = minima[minima["minimum"] == 1].set_index("n_masses")["x"]
    counts = minima.groupby("n_masses").size()
    return ordering(sweep[sweep["status"] == "ok"], "n_masses", first, counts, along="x")


def main(sweep_path, minima_path, png_path, pdf_path, params, logger, smk=None):

    from restitution import plotting
    from restitution.tables.io import read_table

    sweep = read_table(sweep_path)
    minima = read_table(minima_path, columns=("n_masses", "minimum", "x", "cor"))
    for column in ("x", "n_masses", "cor", "status"):
        if column not in sweep:
            raise ValueError(f"{sweep_path}: no column {column!r} (not a Fig. 6(b) sweep table)")
    missing = sorted(set(params.n_masses) - set(sweep["n_masses"].unique()))
    if missing:
        raise ValueError(f"{sweep_path}: no rows for N = {missing}")
    fig = draw(sweep, minima, params.n_masses, logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)
    if smk is not None:
        from render_caption import write_caption

        write_caption(smk, caption_data(sweep, minima), logger)


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
