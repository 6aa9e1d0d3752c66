"""Render Fig. 3(b): the contact compression against time at alpha = fig3.compression.alpha, one
curve per beta, on the paper's axes (alpha s1/V0 against alpha t) and omega-scaled.

The compression s1 = -u1 (in units V0/omega) is zero out of contact and drawn positive (the sign
convention of every figure). An inset in the omega-scaled panel magnifies the last contact, which
is marginal near beta = 0.1; the exact marginal beta (results/fig3/marginal_beta.csv) is printed
in the panel, so the number comes from the generated file.
"""

import pandas as pd

DASHES = ["-", "--", "-.", ":"]


def draw(compression: pd.DataFrame, contacts: pd.DataFrame, marginal: pd.Series, betas, logger):
    """Two panels: the paper's axes (alpha s1/V0 against alpha t) and the omega-scaled view.

    Units are m1 = V0 = omega = 1, so the paper's "alpha t" is alpha times omega t and its
    "alpha s1/V0" is alpha times omega s1/V0. Compression s1 = -u1 >= 0 is drawn positive, the
    sign convention of every figure (Fig. 7(d) too).
    """
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=1.45)
    paper_ax, ax = fig.subplots(2, 1)
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
        inset = ax.inset_axes([0.64, 0.52, 0.34, 0.42])
    for k, beta in enumerate(betas):
        curve = compression[compression["beta"] == beta].sort_values("omega_t")
        n = int((contacts["beta"] == beta).sum())
        cor = float(contacts.loc[contacts["beta"] == beta, "cor"].iloc[0])
        style = dict(color=plotting.beta_colour(beta, betas), ls=DASHES[k % len(DASHES)], lw=1.0)
        label = rf"$\beta = {beta:g}$: {n} contacts, $e = {cor:.3f}$"
        paper_ax.plot(alpha * curve["omega_t"], alpha * curve["compression"], label=label, **style)
        ax.plot(curve["omega_t"], curve["compression"], **style)
        if inset is not None:
            inset.plot(curve["omega_t"], curve["compression"], **style)
        logger.info("beta %g: %d contacts, COR %.6f", beta, n, cor)
    top = compression["compression"].max()
    for axis, scale in ((paper_ax, alpha), (ax, 1.0)):
        axis.axhline(0.0, color="0.6", lw=0.5, zorder=0)
        axis.set_xlim(scale * compression["omega_t"].min(), scale * compression["omega_t"].max())
        axis.set_ylim(-0.03 * scale * top, 1.75 * scale * top)
    paper_ax.set_xlabel(r"$\alpha t$ (paper's axes; $\alpha\,\omega t$ here)")
    paper_ax.set_ylabel(r"$\alpha s_1 / V_0$")
    ax.set_xlabel(r"scaled time $\omega t$")
    ax.set_ylabel(plotting.COMPRESSION_LABEL)
    paper_ax.legend(
        loc="upper right",
        fontsize=6.5,
        title=rf"$\alpha = {alpha:g}$; marginal $\beta^* = {marginal['beta_marginal']:.5f}$ "
        rf"({int(marginal['n_collisions_low'])} $\to$ "
        rf"{int(marginal['n_collisions_high'])} contacts)",
        title_fontsize=6.5,
        alignment="left",
    )
    if inset is not None:
        inset.set_xlim(t0 - pad, t1 + pad)
        inset.set_ylim(-0.15 * depth, 1.15 * depth)
        inset.axhline(0.0, color="0.6", lw=0.5, zorder=0)
        inset.tick_params(labelsize=6, length=2)
        inset.set_title(f"contact {most} (magnified)", fontsize=6, pad=2)
        low, high = inset.get_ylim()
        ax.indicate_inset((t0 - pad, low, t1 - t0 + 2 * pad, high - low), edgecolor="0.4", lw=0.5)
    return fig


def main(paths, png_path, pdf_path, params, logger, smk=None):

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
