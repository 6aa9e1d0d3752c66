"""Render Fig. 4(a)-(d) (``params.name``: fig4a, ...): the plastic contact of Section 3.1.

- 4(a): loading-unloading curves F1(x) of one first contact of m1 alone at V0 (no simulation):
  power-law loading kappa*x**eta to (xmax, Fmax), linear unloading with slope k1 down to the
  residual dent xp, for several eta at one DR (kappa from DR, ``laws.plastic_kappa``; forces from
  ``laws.contact_force``). Units: m1 = 1, V0 = 1, k1 = 1 (so x in V0*sqrt(m1/k1), F1 in
  V0*sqrt(m1*k1)); the linear elastic contact F1 = k1*x (eta = 1, DR = 0) for comparison.
- 4(b)-(d): COR against alpha (log axis) from the panel's sweep table, one curve per law, the
  linear elastic contact at the same beta in grey; (c), (d) add the Eq. 23 bound
  sqrt(1 - DR/(1 + alpha)) dashed. Only rows with status "ok" make the curves; any other row is
  drawn as a red cross at its COR and counted in the log and the legend, never silently dropped.
"""

import numpy as np


def first_contact_curve(dr: float, eta: float, n: int = 400):
    """(x, F) of loading to xmax and unloading to the dent, units m1 = V0 = k1 = 1; and xp."""
    from restitution.model import laws

    k1 = 1.0
    kappa = laws.plastic_kappa(dr, eta, k1, v0=1.0)
    cp = laws.contact_params(laws.C_PLASTIC, k1, kappa, eta)
    fmax = np.sqrt(1.0 - dr)  # v0*sqrt((1 - DR)*k1*m1)
    xmax = (fmax / kappa) ** (1.0 / eta)
    xp = xmax - fmax / k1
    load_x = np.linspace(0.0, xmax, n)
    load_f = np.array([laws.contact_force(cp, 1, xmax, fmax, x, 0.0) for x in load_x])
    unload_x = np.linspace(xmax, xp, n // 4)
    unload_f = np.array([laws.contact_force(cp, 0, xmax, fmax, x, 0.0) for x in unload_x])
    if not np.isclose(load_f[-1], fmax, rtol=1e-9):
        raise RuntimeError(f"eta {eta}: loading ends at F = {load_f[-1]!r}, expected {fmax!r}")
    return np.r_[load_x, unload_x], np.r_[load_f, unload_f], xmax, fmax, xp


def draw_a(panel, logger):
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], **plotting.REFERENCE_STYLE, label=r"linear elastic, $k_1 x$")
    for i, eta in enumerate(sorted(panel["etas"])):
        style = plotting.series_style(i)
        colour = style["color"]
        x, f, xmax, fmax, xp = first_contact_curve(panel["dr"], eta)
        # loading stores m1*V0**2/2 = 0.5; the loop encloses the dissipated work DR/2
        n_load = int(np.argmax(x)) + 1
        stored = np.trapezoid(f[:n_load], x[:n_load])
        loop = stored - np.trapezoid(f[n_load:][::-1], x[n_load:][::-1])
        logger.info(
            "eta %g: xmax %.5f, Fmax %.5f, dent xp %.5f, stored %.5f (0.5), loop %.5f (DR/2 = %g)",
            eta, xmax, fmax, xp, stored, loop, panel["dr"] / 2,
        )  # fmt: skip
        ax.plot(x, f, **style, lw=1.1, label=rf"$\eta = {eta:g}$")
        ax.plot([xp], [0.0], "o", ms=3, color=colour, mfc="white", clip_on=False, zorder=4)
        ax.annotate(
            "", xy=(0.5 * (xmax + xp), 0.5 * fmax), xytext=(0.5 * (xmax + xp) + 0.06 * (xmax - xp),
            0.56 * fmax), arrowprops=dict(arrowstyle="-|>", color=colour, lw=0.6,
            mutation_scale=6),
        )  # fmt: skip
    ax.set_xlim(0.0, None)
    ax.set_ylim(0.0, 1.3)  # headroom: the legend sits above the loops (Fmax < 1)
    ax.set_xlabel(r"penetration $x\,\sqrt{k_1/m_1}\,/\,V_0$")
    ax.set_ylabel(r"contact force $F_1 / (V_0\sqrt{m_1 k_1})$")
    ax.legend(loc="upper right", title=rf"$\mathrm{{DR}} = {panel['dr']:g}$")
    ax.text(
        0.03, 0.96, "loading $\\kappa x^\\eta$, unloading slope $k_1$;\n"
        "$\\circ$ residual dent", transform=ax.transAxes, va="top", fontsize=7,
    )  # fmt: skip
    return fig


def curve_label(name, row):
    if row["contact"] == "linear":
        return r"linear elastic contact"
    if name == "b":
        return rf"$\mathrm{{DR}} = {row['dr']:g}$"
    return rf"$\eta = {row['eta']:g}$"


def draw_sweep(name, sweep, panel, logger):
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    # eta (panels c, d) takes the line styles, DR (panel b) the marked styles: one style, one
    # meaning across Fig. 4.
    pick = plotting.marked_style if name == "b" else plotting.series_style
    styles = (pick(i) for i in range(len(sweep)))
    n_bad_total = 0
    for _, group in sweep.groupby("curve", sort=True):
        group = group.sort_values("alpha")
        first = group.iloc[0]
        ok = group[group["status"] == "ok"]
        bad = group[group["status"] != "ok"]
        label = curve_label(name, first)
        if ok.empty:
            raise ValueError(f"fig4{name}: no rows with status ok for {label}")
        linear = first["contact"] == "linear"
        style = plotting.REFERENCE_STYLE if linear else {**next(styles), "lw": 1.0}
        if "marker" in style:
            style.update(ms=3, mfc="white", markevery=0.08)
        ax.plot(ok["alpha"], ok["cor"], **style, zorder=2 if linear else 3, label=label)
        if len(bad):
            n_bad_total += len(bad)
            logger.warning(
                "%s: %d rows not ok, drawn as crosses: %s",
                label,
                len(bad),
                bad["status"].value_counts().to_dict(),
            )
            ax.plot(bad["alpha"], bad["cor"].clip(0, 1.02), **plotting.FAIL_STYLE, zorder=5)
        logger.info("%s: %d rows ok, COR min %.5f", label, len(ok), ok["cor"].min())
    if n_bad_total:
        ax.plot([], [], **plotting.FAIL_STYLE, label=f"status not ok ({n_bad_total})")
    a = np.geomspace(sweep["alpha"].min(), sweep["alpha"].max(), 400)
    if name in ("c", "d"):
        ax.plot(
            a,
            np.sqrt(1.0 - panel["dr"] / (1.0 + a)),
            color="black",
            ls=(0, (9, 3)),
            lw=0.7,
            zorder=4,
            label=r"Eq. (23) bound $e_{p\max}$",
        )
    plotting.log_axis(ax, "x")
    ax.set_xlim(sweep["alpha"].min(), sweep["alpha"].max())
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    ax.set_ylabel(plotting.COR_LABEL)
    title = plotting.beta_text(panel["beta"])
    if name == "b":
        title += rf", $\eta = {panel['eta']:g}$"
    else:
        title += rf", $\mathrm{{DR}} = {panel['dr']:g}$"
    ax.legend(loc="lower right", title=title, ncols=1)
    return fig


def caption_data(name: str, sweep, panel: dict, summary) -> dict:
    """Trend words and numbers of panel (b), (c) or (d) from its sweep table and its per-curve
    summary (the minima, as ``simulate_fig4`` listed them)."""
    from render_caption import ordering

    key = "dr" if name == "b" else "eta"
    plastic = sweep[(sweep["contact"] != "linear") & (sweep["status"] == "ok")]
    curves = summary[summary["contact"] != "linear"].set_index(key)
    data = ordering(plastic, key, curves["min1_alpha"], curves["n_minima"])
    if name in ("c", "d"):
        # Where each curve ends: its COR at the largest alpha against its largest COR above a
        # tenth of that alpha (a COR falling again at large alpha shows as a drop).
        top = float(plastic["alpha"].max())
        ends = []
        for eta, curve in plastic.groupby("eta", sort=True):
            upper = curve[curve["alpha"] >= top / 10].sort_values("alpha")
            peak = upper.loc[upper["cor"].idxmax()]
            ends.append(f"eta = {eta:g}: {upper['cor'].iloc[-1]:.3f} at alpha = {top:g}, "
                        f"largest {peak['cor']:.3f} at alpha = {peak['alpha']:.3g}")  # fmt: skip
        data["ends"] = "; ".join(ends)
    return data


def main(sweep_path, png_path, pdf_path, params, logger, smk=None, summary_path=None):

    from restitution import plotting
    from restitution.tables.io import read_table

    # The rule passes the figure name ("fig4c"): a bare letter would be a prefix of input paths
    # such as config/paper_values.yaml, which snakemake --lint reports.
    name, panel = params.name.removeprefix("fig4"), params.panel
    if name == "a":
        fig = draw_a(panel, logger)
    else:
        sweep = read_table(sweep_path)
        expected = len(panel["drs"] if name == "b" else panel["etas"]) + 1
        if (
            sweep["curve"].nunique() != expected
            or not np.isclose(sweep["beta"].unique(), panel["beta"]).all()
        ):
            raise ValueError(
                f"{sweep_path}: {sweep['curve'].nunique()} curves at beta "
                f"{sorted(sweep['beta'].unique())}, expected {expected} at beta {panel['beta']}"
            )
        fig = draw_sweep(name, sweep, panel, logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)
    if smk is not None and "caption" in smk.output.keys():
        from render_caption import write_caption

        summary = read_table(
            summary_path, columns=("contact", "dr", "eta", "min1_alpha", "n_minima")
        )
        write_caption(smk, caption_data(name, sweep, panel, summary), logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(
            snakemake.input.get("sweep"),  # noqa: F821
            snakemake.output.png,  # noqa: F821
            snakemake.output.pdf,  # noqa: F821
            snakemake.params,  # noqa: F821
            log,
            snakemake,  # noqa: F821
            snakemake.input.get("summary"),  # noqa: F821
        )
