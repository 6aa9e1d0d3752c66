"""Render Fig. 3(b): the contact compression, plotted negative as in the paper, against the
scaled time omega*t at alpha = fig3.compression.alpha, one curve per beta.

The compression x1 = -u1 (in units V0/omega) is zero out of contact. The paper's axis labels read
"alpha s1/V0" and "alpha t"; with omega the only frequency of the non-dimensionalisation these are
read as omega*x1/V0 and omega*t (noted in the caption). An inset magnifies the last contact, which
is marginal near beta = 0.1; the exact marginal beta (results/fig3/marginal_beta.csv) is printed
in the panel, so the number comes from the generated file.
"""

import pandas as pd

COLOURS = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000"]
DASHES = ["-", "--", "-.", ":"]


def draw(compression: pd.DataFrame, contacts: pd.DataFrame, marginal: pd.Series, betas, logger):
    """The Fig. 3(b) figure (a matplotlib Figure on an Agg canvas)."""
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=0.78)
    ax = fig.add_subplot()
    alpha = float(compression["alpha"].iloc[0])
    # Inset on the last contacts of the curves with the most contacts (the marginal one).
    most = int(contacts.groupby("beta")["contact"].max().max())
    last = contacts[contacts["contact"] == most]
    inset = None
    if len(last) and most > 1:
        t0 = float(last["omega_t_start"].min())
        t1 = float(last["omega_t_end"].max())
        pad = 0.15 * (t1 - t0)
        depth = float(last["x_max"].max())
        inset = ax.inset_axes([0.63, 0.09, 0.34, 0.36])
    for k, beta in enumerate(betas):
        curve = compression[compression["beta"] == beta].sort_values("omega_t")
        n = int((contacts["beta"] == beta).sum())
        cor = float(contacts.loc[contacts["beta"] == beta, "cor"].iloc[0])
        style = dict(color=COLOURS[k % len(COLOURS)], ls=DASHES[k % len(DASHES)], lw=1.0)
        ax.plot(
            curve["omega_t"],
            -curve["compression"],
            label=rf"$\beta = {beta:g}$: {n} contacts, $e = {cor:.3f}$",
            **style,
        )
        if inset is not None:
            inset.plot(curve["omega_t"], -curve["compression"], **style)
        logger.info("beta %g: %d contacts, COR %.6f", beta, n, cor)
    ax.axhline(0.0, color="0.6", lw=0.5, zorder=0)
    ax.set_xlim(compression["omega_t"].min(), compression["omega_t"].max())
    low = compression["compression"].max()
    ax.set_ylim(-1.2 * low, 0.42 * low)
    ax.set_xlabel(r"scaled time $\omega t$")
    ax.set_ylabel(r"compression (negative) $-\omega x_1/V_0$")
    ax.legend(
        loc="upper left",
        fontsize=6.5,
        title=rf"$\alpha = {alpha:g}$; marginal $\beta^* = {marginal['beta_marginal']:.5f}$ "
        rf"({int(marginal['n_collisions_low'])} $\to$ "
        rf"{int(marginal['n_collisions_high'])} contacts)",
        title_fontsize=6.5,
        alignment="left",
    )
    if inset is not None:
        inset.set_xlim(t0 - pad, t1 + pad)
        inset.set_ylim(-1.15 * depth, 0.15 * depth)
        inset.axhline(0.0, color="0.6", lw=0.5, zorder=0)
        inset.tick_params(labelsize=6, length=2)
        inset.set_title(f"contact {most} (magnified)", fontsize=6, pad=2)
        ax.indicate_inset_zoom(inset, edgecolor="0.5", lw=0.5)
    return fig


def main(paths, png_path, pdf_path, params, logger):

    from restitution import plotting
    from restitution.io import read_table

    compression = read_table(paths.compression)
    contacts = read_table(paths.contacts)
    marginal = read_table(paths.marginal)
    for table, path, columns in (
        (compression, paths.compression, ("alpha", "beta", "omega_t", "compression")),
        (
            contacts,
            paths.contacts,
            ("beta", "contact", "omega_t_start", "omega_t_end", "x_max", "cor"),
        ),
        (marginal, paths.marginal, ("beta_marginal", "n_collisions_low", "n_collisions_high")),
    ):
        missing = [c for c in columns if c not in table]
        if missing or table.empty:
            raise ValueError(f"{path}: empty or without columns {missing}")
    absent = sorted(set(params.betas) - set(compression["beta"].unique()))
    if absent:
        raise ValueError(f"{paths.compression}: no rows for beta = {absent}")
    fig = draw(compression, contacts, marginal.iloc[0], params.betas, logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(
            snakemake.input,  # noqa: F821
            snakemake.output.png,  # noqa: F821
            snakemake.output.pdf,  # noqa: F821
            snakemake.params,  # noqa: F821
            log,
        )
