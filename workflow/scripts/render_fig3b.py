"""Render Fig. 3(b): the contact compression against time at alpha = fig3.compression.alpha, one
curve per beta, omega s1/V0 against omega t (the paper's "alpha" axes: a probable misprint).

The compression s1 = -u1 (in units V0/omega) is zero out of contact and drawn positive (the sign
convention of every figure). An inset magnifies the last contact, which
is marginal near beta = 0.1; the exact marginal beta (results/fig3/marginal_beta.csv) is printed
in the panel, so the number comes from the generated file.
"""

import pandas as pd

DASHES = ["-", "--", "-.", ":"]


def draw(compression: pd.DataFrame, contacts: pd.DataFrame, marginal: pd.Series, betas, logger):
    """One panel: the compression omega s1/V0 against omega t, an inset on the last contact.

    The paper's own axes read "alpha t" and "alpha s1/V0", most likely omega misprinted as alpha
    (the referee's reading, issue 26): the caption says so instead of a second panel that repeats
    the same curves on axes rescaled by alpha. Compression
    s1 = -u1 >= 0 is drawn positive, the sign convention of every figure (Fig. 7(d) too).
    """
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=0.9)
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
        inset = ax.inset_axes([0.6, 0.2, 0.37, 0.36])
    for k, beta in enumerate(betas):
        curve = compression[compression["beta"] == beta].sort_values("omega_t")
        n = int((contacts["beta"] == beta).sum())
        cor = float(contacts.loc[contacts["beta"] == beta, "cor"].iloc[0])
        style = dict(color=plotting.beta_colour(beta, betas), ls=DASHES[k % len(DASHES)], lw=1.0)
        label = rf"$\beta = {beta:g}$: {n} contacts, $e = {cor:.3f}$"
        ax.plot(curve["omega_t"], curve["compression"], label=label, **style)
        if inset is not None:
            inset.plot(curve["omega_t"], curve["compression"], label="_" + label, **style)
        logger.info("beta %g: %d contacts, COR %.6f", beta, n, cor)
    top = compression["compression"].max()
    ax.axhline(0.0, color="0.6", lw=0.5, zorder=0)
    ax.set_xlim(compression["omega_t"].min(), compression["omega_t"].max())
    ax.set_ylim(-0.03 * top, 1.7 * top)
    ax.set_xlabel(r"scaled time $\omega t$")
    ax.set_ylabel(plotting.COMPRESSION_LABEL)
    ax.legend(
        loc="upper left",
        title=rf"$\alpha = {alpha:g}$; marginal $\beta^* = {marginal['beta_marginal']:.5f}$ "
        rf"({int(marginal['n_collisions_low'])} $\to$ "
        rf"{int(marginal['n_collisions_high'])} contacts)",
        alignment="left",
    )
    if inset is not None:
        inset.set_xlim(t0 - pad, t1 + pad)
        inset.set_ylim(-0.15 * depth, 1.15 * depth)
        inset.axhline(0.0, color="0.6", lw=0.5, zorder=0)
        inset.tick_params(labelsize=7, length=2)
        inset.minorticks_off()
        inset.set_title(f"contact {most} (magnified)", fontsize=7, pad=2)
        low, high = inset.get_ylim()
        ax.indicate_inset((t0 - pad, low, t1 - t0 + 2 * pad, high - low), edgecolor="0.4", lw=0.5)
    return fig


def main(paths, png_path, pdf_path, params, logger, smk=None):

    from restitution import plotting
    from restitution.tables.io import read_table

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
    if smk is not None:
        from render_caption import write_caption

        m = marginal.iloc[0]
        counts = contacts.groupby("beta")["contact"].max()
        write_caption(smk, {
            "marginal": f"{m['beta_marginal']:.5f}",
            "n_low": int(m["n_collisions_low"]),
            "n_high": int(m["n_collisions_high"]),
            "counts": ", ".join(f"{int(counts[b])}" for b in params.betas),
        }, logger)  # fmt: skip


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
            snakemake,  # noqa: F821
        )
