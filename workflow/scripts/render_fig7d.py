"""Render Fig. 7(d): contact compression omega*s1/V0 against omega*t/(2 pi), a panel per xi, alpha.

One trace per alpha. Each legend entry gives the share of the total collision duration t_col
taken by the last contact (from the contact history written by simulate_fig7d), the paper's
point: "the last contact takes the longest time", m1 almost adhered to the wall while m2 is
brought to rest and pushed back.
"""

import numpy as np
import pandas as pd

DAMPING = {True: "underdamped", False: "overdamped"}
#: Width of the zoomed window (omega t / 2 pi) that resolves the contact-spring ringing.
ZOOM = 0.12


#: Width of the envelope's time bins in periods of m1 ringing on the contact spring, whose
#: period is omega t / 2 pi = sqrt(beta (1 + alpha)/alpha): far too fast to draw as a line.
PERIODS = 1.5


def envelope(t: np.ndarray, s: np.ndarray, width: float):
    """Smallest and largest s in equal time bins about ``width`` wide (empty: NaN), bin centres.

    On the full time axis the contact-spring ringing would draw as a solid band of lines; the
    range it sweeps per bin is what the eye can read, and the insets show the ringing itself.
    """
    bins = max(1, int(np.ceil((t.max() - t.min()) / width)))
    edges = np.linspace(t.min(), t.max(), bins + 1)
    which = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, bins - 1)
    lo = np.full(bins, np.nan)
    hi = np.full(bins, np.nan)
    np.fmin.at(lo, which, s)
    np.fmax.at(hi, which, s)
    return lo, hi, 0.5 * (edges[1:] + edges[:-1])


def trace_stats(hist: pd.DataFrame) -> dict:
    """Contacts, omega t_col, last contact duration and share, longest earlier contact."""
    duration = hist["omega_t_end"] - hist["omega_t_start"]
    t_col = hist["omega_t_end"].iloc[-1] - hist["omega_t_start"].iloc[0]
    return {
        "n": len(hist),
        "t_col": float(t_col),
        "last": float(duration.iloc[-1]),
        "share": float(duration.iloc[-1] / t_col),
        "earlier": float(duration.iloc[:-1].max()) if len(hist) > 1 else 0.0,
        "last_start": float(hist["omega_t_start"].iloc[-1]),
    }


def draw(traces: pd.DataFrame, contacts: pd.DataFrame, settings: dict, beta: float, logger):
    """One panel per (xi, alpha): rows xi, columns alpha, a shared compression axis.

    The contact spring rings at about 1/sqrt(beta) times the structural frequency, far too fast
    to resolve across the whole sequence, so each panel carries an inset that magnifies a short
    window (the start of the last contact, or the first contacts) where the ringing is visible.
    """
    from restitution import plotting

    xis = sorted(map(float, settings["xis"]))
    alphas = sorted(map(float, settings["alphas"]))
    fig = plotting.new_figure("double", aspect=0.3 * len(xis) + 0.06)
    axes = np.atleast_2d(fig.subplots(len(xis), len(alphas), sharey=True, squeeze=False))
    top = float(traces["s1"].max()) * 1.05
    stats = {}
    for r, xi in enumerate(xis):
        kind = DAMPING[xi < 1] if xi != 1 else "critically damped"
        for c, alpha in enumerate(alphas):
            ax = axes[r, c]
            sel = (traces["xi"] == xi) & (traces["alpha"] == alpha)
            curve = traces[sel].sort_values("omega_t")
            hist = contacts[(contacts["xi"] == xi) & (contacts["alpha"] == alpha)]
            if curve.empty or hist.empty:
                raise ValueError(f"no trace for xi = {xi}, alpha = {alpha}")
            st = stats[(xi, alpha)] = trace_stats(hist)
            # Coloured by xi, as in Fig. 7(a)-(c); alpha is the column (named in each panel).
            colour = plotting.xi_colour(xi, xis)
            named = rf"_$\xi = {xi:g}$"  # hidden label: names the colour's meaning
            t = curve["omega_t"].to_numpy() / (2 * np.pi)
            ring = np.sqrt(beta * (1 + alpha) / alpha)  # ringing period, omega t / 2 pi
            lo, hi, centres = envelope(t, curve["s1"].to_numpy(), PERIODS * ring)
            ax.fill_between(centres, lo, hi, color=colour, alpha=0.35, lw=0, label=named)
            ax.plot(centres, hi, color=colour, lw=0.6, label=named)
            ax.set_xlim(-0.02 * t.max(), t.max() * 1.02)
            ax.set_ylim(0, top * 1.45)
            ax.text(0.02, 0.97, rf"$\xi = {xi:g}$ ({kind}), $\alpha = {alpha:g}$"
                    "\n" rf"{st['n']} contacts; last one {100 * st['share']:.0f}% of "
                    r"$t_\mathrm{col}$", transform=ax.transAxes, ha="left", va="top",
                    fontsize=7)  # fmt: skip
            # Inset: a short window in which the ringing is resolved.
            t0 = st["last_start"] / (2 * np.pi) if xi < 1 else 0.0
            window = (t >= t0) & (t <= t0 + ZOOM)
            inset = ax.inset_axes([0.62, 0.55, 0.36, 0.36])
            inset.plot(t[window], curve["s1"].to_numpy()[window], color=colour, lw=0.6, label=named)
            inset.set_xlim(t0, t0 + ZOOM)
            inset.set_ylim(0, None)
            inset.tick_params(labelsize=7, length=1.5, which="both")
            inset.minorticks_off()
            # Only the frame of the magnified window: connector lines would cross the trace.
            low, high = inset.get_ylim()
            ax.indicate_inset((t0, low, ZOOM, high - low), edgecolor="0.4", lw=0.5)
            if c == 0:
                ax.set_ylabel(plotting.COMPRESSION_LABEL)
            if r == len(xis) - 1:
                ax.set_xlabel(r"scaled time $\omega t / 2\pi$")
            logger.info(
                "xi %g, alpha %g: %d contacts, omega*t_col %.4f, last contact %.4f = %.1f%%",
                xi, alpha, st["n"], st["t_col"], st["last"], 100 * st["share"],
            )  # fmt: skip
    fig.suptitle(plotting.beta_text(beta), fontsize=8)
    return fig, stats


def caption_data(stats: dict) -> dict:
    """Per-trace sentences of the caption from the contact histories."""
    parts = [
        f"omega t = {v['last']:.3g} of {v['t_col']:.3g} ({100 * v['share']:.0f}%) for "
        f"xi = {xi:g}, alpha = {alpha:g}"
        for (xi, alpha), v in sorted(stats.items())
    ]
    earlier = max(v["earlier"] for v in stats.values())
    growth = []
    for xi in sorted({xi for xi, _ in stats}):
        runs = sorted((a, v["last"]) for (x, a), v in stats.items() if x == xi)
        if len(runs) > 1:
            growth.append(f"{runs[-1][1] / runs[0][1]:.2f} (xi = {xi:g})")
    return {
        "last_contacts": "; ".join(parts),
        "longest_earlier": f"{earlier:.2g}",
        "growth": ", ".join(growth) if growth else "not measured (one alpha only)",
        "zoom": f"{ZOOM:g}",
        "periods": f"{PERIODS:g}",
    }


def main(traces_path, contacts_path, png_path, pdf_path, params, logger, smk=None):

    from restitution import plotting
    from restitution.tables.io import read_table

    traces = read_table(traces_path)
    contacts = read_table(contacts_path)
    fig, stats = draw(traces, contacts, params.traces, float(params.beta), logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)
    if smk is not None:
        from render_caption import write_caption

        write_caption(smk, caption_data(stats), logger)


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
            snakemake,  # noqa: F821
        )
