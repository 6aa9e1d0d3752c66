"""Render Fig. 7(d): contact compression omega*s1/V0 against omega*t/(2 pi), one panel per xi.

One trace per alpha. Each legend entry gives the share of the total collision duration t_col
taken by the last contact (from the contact history written by simulate_fig7d), the paper's
point: "the last contact takes the longest time", m1 almost adhered to the wall while m2 is
brought to rest and pushed back.
"""

import numpy as np
import pandas as pd

COLOURS = ["black", "#E69F00", "#0072B2", "#009E73", "#D55E00", "#CC79A7"]
DAMPING = {True: "underdamped", False: "overdamped"}


def draw(traces: pd.DataFrame, contacts: pd.DataFrame, settings: dict, beta: float, logger):
    from restitution import plotting

    xis = sorted(map(float, settings["xis"]))
    alphas = sorted(map(float, settings["alphas"]))
    fig = plotting.new_figure("onehalf", aspect=0.36 * len(xis) + 0.08)
    axes = np.atleast_1d(fig.subplots(len(xis), 1, sharex=True))
    t_max = traces["omega_t"].max() / (2 * np.pi)
    for ax, xi in zip(axes, xis, strict=True):
        for j, alpha in enumerate(alphas):
            sel = (traces["xi"] == xi) & (traces["alpha"] == alpha)
            curve = traces[sel].sort_values("omega_t")
            hist = contacts[(contacts["xi"] == xi) & (contacts["alpha"] == alpha)]
            if curve.empty or hist.empty:
                raise ValueError(f"no trace for xi = {xi}, alpha = {alpha}")
            duration = hist["omega_t_end"] - hist["omega_t_start"]
            t_col = hist["omega_t_end"].iloc[-1] - hist["omega_t_start"].iloc[0]
            share = duration.iloc[-1] / t_col
            label = (
                rf"$\alpha = {alpha:g}$: {len(hist)} contacts, last one "
                rf"{100 * share:.0f}% of $t_\mathrm{{col}}$"
            )
            ax.plot(curve["omega_t"] / (2 * np.pi), curve["s1"], color=COLOURS[j % len(COLOURS)],
                    lw=0.8, zorder=3 - 0.1 * j, label=label)  # fmt: skip
            logger.info(
                "xi %g, alpha %g: %d contacts, omega*t_col %.4f, last contact %.4f = %.1f%%",
                xi, alpha, len(hist), t_col, duration.iloc[-1], 100 * share,
            )  # fmt: skip
        kind = DAMPING[xi < 1] if xi != 1 else "critically damped"
        ax.text(0.99, 0.94, rf"$\xi = {xi:g}$ ({kind}), " + plotting.beta_text(beta),
                transform=ax.transAxes, ha="right", va="top")  # fmt: skip
        ax.set_ylabel(r"$\omega s_1 / V_0$")
        ax.set_ylim(0, None)
        ax.margins(y=0.25)
        ax.set_ylim(0, None)
        ax.legend(loc="upper right", bbox_to_anchor=(1.0, 0.84))
    # A little room left of t = 0, so the first contact (it starts at t = 0) is not hidden by
    # the axis line.
    axes[-1].set_xlim(-0.015 * t_max, t_max * 1.02)
    axes[-1].set_xlabel(r"$\omega t / 2\pi$")
    return fig


def main(traces_path, contacts_path, png_path, pdf_path, params, logger):

    from restitution import plotting
    from restitution.io import read_table

    traces = read_table(traces_path)
    contacts = read_table(contacts_path)
    fig = draw(traces, contacts, params.traces, float(params.beta), logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(
            snakemake.input.traces,  # noqa: F821
            snakemake.input.contacts,  # noqa: F821
            snakemake.output.png,  # noqa: F821
            snakemake.output.pdf,  # noqa: F821
            snakemake.params,  # noqa: F821
            log,
        )
