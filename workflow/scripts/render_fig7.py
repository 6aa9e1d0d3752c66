"""Render Fig. 7(a), 7(b) or 7(c) (``params.panel``) from the Fig. 7 sweep table.

- 7(a): COR against alpha = m2/m1 (log axis), one curve per damping ratio xi.
- 7(b): number of contacts n_collisions against alpha (a step curve: the count is constant
  between the refined changes).
- 7(c): normalised total duration omega*t_col against alpha, log-log (it spans three decades).

Rows with status "ok" are drawn as curves. Any other row (aggregate_fig7 has already failed the
run if there are more than ``max_not_ok_fraction`` of them) is logged and marked with a red cross
along the bottom of the axes at its alpha, never drawn as data (its values are not final).
"""

import numpy as np
import pandas as pd

#: Okabe-Ito colours in the house order, one per xi.
COLOURS = ["black", "#E69F00", "#0072B2", "#009E73", "#D55E00", "#CC79A7", "#56B4E9"]

PANELS = {
    "a": ("cor", "coefficient of restitution $e$"),
    "b": ("n_collisions", "number of contacts $n$"),
    "c": ("omega_t_col", r"collision duration $\omega t_\mathrm{col}$"),
}


def xi_text(xi: float) -> str:
    return rf"$\xi = {xi:g}$"


def mark_not_ok(ax, bad: pd.DataFrame, logger) -> None:
    """Red crosses along the bottom of the axes at the alphas of rows whose status is not ok.

    Their values are not final (e.g. the contact budget ran out), so they are shown where they
    are, never at a value; the log lists them per xi.
    """
    for xi, rows in bad.groupby("xi", sort=True):
        logger.warning(
            "xi %g: %d rows not ok %s, marked at the bottom, not drawn as data, at alpha %s",
            xi,
            len(rows),
            rows["status"].value_counts().to_dict(),
            ", ".join(f"{a:.6g}" for a in rows["alpha"].head(20)),
        )
    if bad.empty:
        return
    ax.plot(bad["alpha"], np.full(len(bad), 0.03), "x", color="red", ms=4, mew=0.8, zorder=5,
            clip_on=False, transform=ax.get_xaxis_transform(),
            label=f"status not ok ({len(bad)} rows)")  # fmt: skip


def draw(sweep: pd.DataFrame, panel: str, fig7: dict, logger):
    """The figure of one panel (a matplotlib Figure on an Agg canvas)."""
    from restitution import plotting

    column, ylabel = PANELS[panel]
    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    for i, xi in enumerate(sorted(fig7["xis"])):
        rows = sweep[sweep["xi"] == xi].sort_values("alpha")
        curve = rows[rows["status"] == "ok"]
        if curve.empty:
            raise ValueError(f"no rows with status ok for xi = {xi} in the sweep table")
        colour = COLOURS[i % len(COLOURS)]
        # Rows not ok become NaN: the curve is broken there instead of bridged across them.
        y = rows[column].where(rows["status"] == "ok").astype(float)
        if panel == "b":
            ax.step(rows["alpha"], y, where="post", color=colour, lw=0.8, label=xi_text(xi))
        else:
            ax.plot(rows["alpha"], y, color=colour, lw=0.8, label=xi_text(xi))
        logger.info(
            "xi %g: %d rows drawn, %s %.5g..%.5g",
            xi,
            len(curve),
            column,
            curve[column].min(),
            curve[column].max(),
        )
    drawn = sweep["xi"].isin([float(xi) for xi in fig7["xis"]])
    mark_not_ok(ax, sweep[drawn & (sweep["status"] != "ok")], logger)
    plotting.log_axis(ax, "x")
    ax.set_xlim(fig7["alpha_min"], fig7["alpha_max"])
    ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    ax.set_ylabel(ylabel)
    title = plotting.beta_text(fig7["beta"])
    if panel == "a":
        ax.set_ylim(0.0, 1.02)
        ax.legend(loc="lower right", title=title)
    elif panel == "b":
        ax.set_ylim(0, None)
        ax.legend(loc="upper left", title=title)
    else:
        plotting.log_axis(ax, "y")
        ax.legend(loc="upper left", title=title)
    return fig


def main(sweep_path, png_path, pdf_path, params, logger):

    from restitution import plotting
    from restitution.io import read_table

    if params.panel not in PANELS:
        raise ValueError(f"panel must be one of {sorted(PANELS)}, got {params.panel!r}")
    sweep = read_table(sweep_path)
    missing = sorted(set(map(float, params.fig7["xis"])) - set(sweep["xi"].unique()))
    if missing:
        raise ValueError(f"{sweep_path}: no rows for xi = {missing}")
    fig = draw(sweep, params.panel, params.fig7, logger)
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
