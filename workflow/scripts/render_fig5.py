"""Render Fig. 5(a) or 5(b) (``params.name``): the scissor structural spring of Section 3.2.

- 5(a): force-displacement curves F2(x2) of the scissor spring (Eq. 24, ``laws.structure_force``)
  for a few bar lengths L, with the linear spring k2*x2 for comparison. F2 in units of k2*V0/omega,
  x2 (extension > 0) in V0/omega; the curves do not depend on alpha in these units. Marked: the
  compressive lock (sin(theta)**3 = sin(theta0), slope 0) and the points where the slope reaches
  the cap k2 (in tension, and in compression when the corner stiffening has taken the stroke).
- 5(b): COR against alpha (log axis) from the sweep table, one curve per L, the linear structural
  spring at the same beta in grey. Rows not "ok" are drawn as red crosses and counted in the log.
"""

import math

import numpy as np

GREY = "0.55"
RED = "#D55E00"
COLOURS = ["#0072B2", "#E69F00", "#009E73", "#CC79A7", "#56B4E9", "#F0E442", "#000000"]


def scissor_law(spring: dict, L: float):  # noqa: N803
    """Packed scissor law with k2 = 1 (forces in units of k2)."""
    from restitution import laws

    ks_ratio = float(spring["ks_over_k1"]) / float(spring["beta"])
    theta0 = math.radians(float(spring["theta0_deg"]))
    laws.check_ks_ratio(ks_ratio, theta0)
    return laws.scissor_params(1.0, ks_ratio, float(L), theta0, float(spring["corner"]))


def spring_title(spring: dict) -> str:
    return (
        rf"$k_s = {spring['ks_over_k1']:g}\,k_1$, $\theta_0 = {spring['theta0_deg']:g}^\circ$"
        rf", corner {spring['corner']:g}"
    )


def draw_a(spring, panel, logger):
    from restitution import laws, plotting

    fig = plotting.new_figure("single", aspect=0.78)
    ax = fig.add_subplot()
    x = np.linspace(panel["x_min"], panel["x_max"], 2001)
    ax.plot(x, x, color=GREY, lw=0.9, ls="--", label=r"linear, $k_2 x_2$")
    for colour, L in zip(COLOURS, sorted(panel["Ls"]), strict=False):  # noqa: N806
        sp = scissor_law(spring, L)
        f = np.array([laws.structure_force(sp, xi) for xi in x])
        slope = np.array([laws.structure_slope(sp, xi) for xi in x])
        if slope.max() > 1.0 + 1e-9:
            raise RuntimeError(f"L = {L}: slope {slope.max()} exceeds the cap k2")
        ax.plot(x, f, color=colour, lw=1.1, label=rf"$L = {L:g}$")
        x_lock, f_lock = sp[laws.SP_XLOCK], sp[laws.SP_FLOCK]
        x_cap, f_cap = sp[laws.SP_XCAP], sp[laws.SP_FCAP]
        x_flat = x_lock - sp[laws.SP_DC]
        f_flat = laws.structure_force(sp, x_flat)
        logger.info(
            "L %g: lock x2 %.4f F2/k2 %.5f; tension cap x2 %.4f F2/k2 %.5f; "
            "compressive cap x2 %.4f F2/k2 %.5f",
            L, x_lock, f_lock, x_cap, f_cap, x_flat, f_flat,
        )  # fmt: skip
        for xs, fs, marker in ((x_lock, f_lock, "o"), (x_cap, f_cap, "s"), (x_flat, f_flat, "s")):
            if panel["x_min"] <= xs <= panel["x_max"]:
                ax.plot([xs], [fs], marker, ms=3.2, color=colour, mfc="white", mew=0.8, zorder=4)
    ax.plot([], [], "o", ms=3.2, color="black", mfc="white", mew=0.8,
            label=r"lock, $\sin^3\theta = \sin\theta_0$")  # fmt: skip
    ax.plot([], [], "s", ms=3.2, color="black", mfc="white", mew=0.8,
            label=r"slope reaches cap $k_2$")  # fmt: skip
    ax.axhline(0.0, color="0.8", lw=0.5, zorder=0)
    ax.axvline(0.0, color="0.8", lw=0.5, zorder=0)
    ax.set_xlim(panel["x_min"], panel["x_max"])
    lim = 1.05 * max(abs(panel["x_min"]), abs(panel["x_max"]))
    ax.set_ylim(-lim, lim)
    ax.set_xlabel(r"extension $x_2\,\omega / V_0$ (tension > 0)")
    ax.set_ylabel(r"spring force $F_2\,\omega / (k_2 V_0)$")
    title = plotting.beta_text(spring["beta"]) + ", " + spring_title(spring)
    ax.legend(loc="upper left", title=title, fontsize=6.5, title_fontsize=6.5)
    return fig


def draw_b(sweep, spring, panel, logger):
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    colours = iter(COLOURS)
    n_bad_total = 0
    for _, group in sweep.groupby("curve", sort=True):
        group = group.sort_values("alpha")
        first = group.iloc[0]
        linear = first["structure"] == "linear"
        label = "linear spring" if linear else rf"$L = {first['L']:g}$"
        ok = group[group["status"] == "ok"]
        bad = group[group["status"] != "ok"]
        if ok.empty:
            raise ValueError(f"fig5b: no rows with status ok for {label}")
        ax.plot(
            ok["alpha"],
            ok["cor"],
            color=GREY if linear else next(colours),
            lw=0.8 if linear else 1.0,
            zorder=2 if linear else 3,
            label=label,
        )
        if len(bad):
            n_bad_total += len(bad)
            logger.warning(
                "%s: %d rows not ok, drawn as crosses: %s",
                label,
                len(bad),
                bad["status"].value_counts().to_dict(),
            )
            ax.plot(bad["alpha"], bad["cor"].clip(0, 1.02), "x", color=RED, ms=3, zorder=5)
        i = ok["cor"].idxmin()
        logger.info(
            "%s: %d rows ok, COR min %.5f at alpha %.5g",
            label,
            len(ok),
            ok.loc[i, "cor"],
            ok.loc[i, "alpha"],
        )
    if n_bad_total:
        ax.plot([], [], "x", color=RED, ms=3, label=f"status not ok ({n_bad_total})")
    plotting.log_axis(ax, "x")
    ax.set_xlim(sweep["alpha"].min(), sweep["alpha"].max())
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    ax.set_ylabel("coefficient of restitution $e$")
    title = plotting.beta_text(spring["beta"]) + ", " + spring_title(spring)
    title += rf", $v_0 = {panel['v0']:g}$"
    ax.legend(loc="lower right", title=title, ncols=2, fontsize=6.5, title_fontsize=6.5)
    return fig


def main(sweep_path, png_path, pdf_path, params, logger):

    from restitution import plotting
    from restitution.io import read_table

    if params.name == "a":
        fig = draw_a(params.spring, params.panel, logger)
    else:
        sweep = read_table(sweep_path)
        expected = len(params.panel["Ls"]) + 1
        if sweep["curve"].nunique() != expected:
            raise ValueError(
                f"{sweep_path}: {sweep['curve'].nunique()} curves, expected {expected} "
                f"(fig5.b.Ls plus the linear spring)"
            )
        fig = draw_b(sweep, params.spring, params.panel, logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)


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
        )
