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
import pandas as pd

GREY = "0.55"


def scissor_law(spring: dict, L: float):  # noqa: N803
    """Packed scissor law with k2 = 1 (forces in units of k2)."""
    from restitution.model import laws

    ks_ratio = float(spring["ks_over_k1"]) / float(spring["beta"])
    theta0 = math.radians(float(spring["theta0_deg"]))
    laws.check_ks_ratio(ks_ratio, theta0)
    return laws.scissor_params(1.0, ks_ratio, float(L), theta0, float(spring["corner"]))


def spring_title(spring: dict) -> str:
    return (
        rf"$k_s = {spring['ks_over_k1']:g}\,k_1$, $\theta_0 = {spring['theta0_deg']:g}^\circ$"
        rf", corner {spring['corner']:g}"
    )


def draw_frame(ax, theta_deg: float, label: str) -> None:
    """The scissor frame (upper inset of the paper's Fig. 5(a)): four hinged bars of length L
    at half angle theta, the spring k_s across the side hinges, the load F2 at the corners."""
    from matplotlib.patches import Arc

    t = math.radians(theta_deg)
    h, w = math.cos(t), math.sin(t)
    top, bottom, left, right = (0, h), (0, -h), (-w, 0), (w, 0)
    for a, b in ((top, left), (top, right), (bottom, left), (bottom, right)):
        ax.plot([a[0], b[0]], [a[1], b[1]], color="black", lw=1.0, solid_capstyle="round")
    for x, y in (top, bottom, left, right):
        ax.plot([x], [y], "o", ms=2.2, color="white", mec="black", mew=0.6, zorder=4)
    # Zigzag spring k_s between the side hinges.
    xs = np.linspace(-w + 0.12, w - 0.12, 15)
    ys = 0.06 * np.array([0, 1, -1] * 5)[: len(xs)]
    ys[0] = ys[-1] = 0
    ax.plot([-w, xs[0]], [0, 0], color="0.3", lw=0.6)
    ax.plot([xs[-1], w], [0, 0], color="0.3", lw=0.6)
    ax.plot(xs, ys, color="0.3", lw=0.6)
    ax.text(0, -0.16, r"$k_s$", ha="center", va="top", fontsize=7)
    # Load at the corners and the half angle at the top hinge.
    ax.annotate("", xy=(0, h + 0.35), xytext=(0, h + 0.02),
                arrowprops=dict(arrowstyle="-|>", lw=0.6, color="black"))  # fmt: skip
    ax.annotate("", xy=(0, -h - 0.35), xytext=(0, -h - 0.02),
                arrowprops=dict(arrowstyle="-|>", lw=0.6, color="black"))  # fmt: skip
    ax.text(0.08, h + 0.22, r"$F_2$", fontsize=7, va="center")
    ax.add_patch(Arc(top, 0.5, 0.5, theta1=270 - 0, theta2=270 + theta_deg, lw=0.5))
    ax.text(0.12, h - 0.38, r"$\theta$", fontsize=7)
    ax.text(-w / 2 - 0.18, h / 2 + 0.05, r"$L$", fontsize=7, ha="right")
    ax.text(0, -h - 0.5, label, ha="center", va="top", fontsize=7)
    ax.set_xlim(-1.15, 1.15)
    ax.set_ylim(-h - 0.75, h + 0.45)
    ax.set_aspect("equal")
    ax.axis("off")


def draw_corners(ax, theta_deg: float, label: str) -> None:
    """The corner contact pairs (lower inset of the paper's Fig. 5(a)): past the compressive lock
    pads at the upper and lower corners touch and stiffen the frame further."""
    from matplotlib.patches import Rectangle

    t = math.radians(theta_deg)
    h, w = math.cos(t), math.sin(t)
    top, bottom, left, right = (0, h), (0, -h), (-w, 0), (w, 0)
    for a, b in ((top, left), (top, right), (bottom, left), (bottom, right)):
        ax.plot([a[0], b[0]], [a[1], b[1]], color="black", lw=1.0, solid_capstyle="round")
    for x, y in (top, bottom, left, right):
        ax.plot([x], [y], "o", ms=2.2, color="white", mec="black", mew=0.6, zorder=4)
    # A pair of pads inside each of the upper and lower corners, touching.
    for sign in (1, -1):
        y = sign * (h - 0.2)
        for side in (-1, 1):
            ax.add_patch(Rectangle((side * 0.11 - 0.055, y - 0.045), 0.11, 0.09,
                                   color="0.6", lw=0))  # fmt: skip
        ax.plot([0, 0], [y - 0.06, y + 0.06], color="black", lw=1.3)
    ax.annotate("", xy=(0, h - 0.02), xytext=(0, h + 0.3),
                arrowprops=dict(arrowstyle="-|>", lw=0.6, color="black"))  # fmt: skip
    ax.annotate("", xy=(0, -h + 0.02), xytext=(0, -h - 0.3),
                arrowprops=dict(arrowstyle="-|>", lw=0.6, color="black"))  # fmt: skip
    ax.text(0, -h - 0.38, label, ha="center", va="top", fontsize=7)
    ax.set_xlim(-1.15, 1.15)
    ax.set_ylim(-h - 0.65, h + 0.35)
    ax.set_aspect("equal")
    ax.axis("off")


def eq24_natural(theta0: float, n: int = 2000):
    """Eq. 24 without cap or corner: (x2/L, F2/(k_s L)) for theta from small to pi/2."""
    theta = np.linspace(math.radians(2.0), math.pi / 2, n)
    x = 2 * (np.cos(theta) - math.cos(theta0))
    f = 2 * np.cos(theta) * (math.sin(theta0) / np.sin(theta) - 1)
    return x, f


def draw_a(spring, panel, logger):
    """Left: F2 against x2 over the stroke an impact explores, with the two insets (the frame
    and the corner contact pairs). Right: the same curves in Eq. 24's own units, F2/(k_s L)
    against x2/L, where the compressive force limit and the steep stiffening in tension show
    (at k_s/k2 = 0.01 they are invisible on the left's scale)."""
    from restitution import plotting
    from restitution.model import laws

    fig = plotting.new_figure("double", aspect=0.42)
    ax, zoom = fig.subplots(1, 2)
    x = np.linspace(panel["x_min"], panel["x_max"], 2001)
    ax.plot(x, x, color=GREY, lw=0.9, ls="--", label=r"linear, $k_2 x_2$")
    ks = float(spring["ks_over_k1"]) / float(spring["beta"])
    theta0 = math.radians(float(spring["theta0_deg"]))
    xe, fe = eq24_natural(theta0)
    zoom.plot(xe, fe, color="black", lw=0.7, ls=(0, (3, 2)), zorder=5,
              label="Eq. 24 alone (no cap, no corners)")  # fmt: skip
    locks = []
    for colour, L in zip(plotting.L_COLOURS, sorted(panel["Ls"]), strict=False):  # noqa: N806
        sp = scissor_law(spring, L)
        f = np.array([laws.structure_force(sp, xi) for xi in x])
        slope = np.array([laws.structure_slope(sp, xi) for xi in x])
        if slope.max() > 1.0 + 1e-9:
            raise RuntimeError(f"L = {L}: slope {slope.max()} exceeds the cap k2")
        ax.plot(x, f, color=colour, lw=1.1, label=rf"$L = {L:g}$")
        xn = np.linspace(-1.6 * L, 0.7 * L, 3001)
        fn = np.array([laws.structure_force(sp, xi) for xi in xn]) / (ks * L)
        zoom.plot(xn / L, fn, color=colour, lw=1.1, label=rf"$L = {L:g}$")
        x_lock, f_lock = sp[laws.SP_XLOCK], sp[laws.SP_FLOCK]
        x_cap, f_cap = sp[laws.SP_XCAP], sp[laws.SP_FCAP]
        x_flat = x_lock - sp[laws.SP_DC]
        f_flat = laws.structure_force(sp, x_flat)
        locks.append(f_lock / (ks * L))
        logger.info(
            "L %g: lock x2 %.4f F2/k2 %.5f; tension cap x2 %.4f F2/k2 %.5f; "
            "compressive cap x2 %.4f F2/k2 %.5f",
            L, x_lock, f_lock, x_cap, f_cap, x_flat, f_flat,
        )  # fmt: skip
        for xs, fs, marker in ((x_lock, f_lock, "o"), (x_cap, f_cap, "s"), (x_flat, f_flat, "s")):
            if panel["x_min"] <= xs <= panel["x_max"]:
                ax.plot([xs], [fs], marker, ms=3.2, color=colour, mfc="white", mew=0.8, zorder=4)
            zoom.plot([xs / L], [fs / (ks * L)], marker, ms=3.2, color=colour, mfc="white",
                      mew=0.8, zorder=6, clip_on=True)  # fmt: skip
    for axis in (ax, zoom):
        axis.plot([], [], "o", ms=3.2, color="black", mfc="white", mew=0.8,
                  label=r"lock, $\sin^3\theta = \sin\theta_0$")  # fmt: skip
        axis.plot([], [], "s", ms=3.2, color="black", mfc="white", mew=0.8,
                  label=r"slope reaches cap $k_2$")  # fmt: skip
        axis.axhline(0.0, color="0.8", lw=0.5, zorder=0)
        axis.axvline(0.0, color="0.8", lw=0.5, zorder=0)
    ax.set_xlim(panel["x_min"], panel["x_max"])
    lim = 1.05 * max(abs(panel["x_min"]), abs(panel["x_max"]))
    ax.set_ylim(-lim, lim)
    ax.set_xlabel(r"extension $x_2\,\omega / V_0$ (tension > 0)")
    ax.set_ylabel(r"spring force $F_2\,\omega / (k_2 V_0)$")
    title = plotting.beta_text(spring["beta"]) + ", " + spring_title(spring)
    fig.suptitle(title, fontsize=7)
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7)
    # Insets in the two empty quadrants: the frame (upper left), the corner pairs (lower right).
    upper = ax.inset_axes([0.09, 0.52, 0.34, 0.46])
    draw_frame(upper, float(spring["theta0_deg"]), r"frame at rest, $\theta = \theta_0$")
    lower = ax.inset_axes([0.57, 0.04, 0.34, 0.46])
    theta_lock = math.degrees(math.asin(math.sin(theta0) ** (1 / 3)))
    draw_corners(lower, max(theta_lock + 10, 80.0), "corner contact pairs")
    zoom.set_xlim(-1.6, 0.7)
    low = min(locks)
    zoom.set_ylim(6 * low, -30 * low)
    zoom.set_xlabel(r"$x_2 / L$ (Eq. 24's units)")
    zoom.set_ylabel(r"$F_2 / (k_s L)$")
    zoom.legend(loc="upper left", fontsize=7)
    zoom.text(0.98, 0.03, "Eq. 24 is homogeneous in $L$:\nthe curves of every $L$ coincide",
              transform=zoom.transAxes, ha="right", va="bottom", fontsize=7)  # fmt: skip
    return fig


def draw_b(sweep, spring, panel, logger):
    """Left: COR against alpha per bar length L at v0 (and the linear spring). Right: per impact
    speed v0 at the fixed L of panel.velocity (the velocity dependence)."""
    from restitution import plotting

    has_v0 = "series" in sweep and (sweep["series"] == "v0").any()
    fig = plotting.new_figure("double" if has_v0 else "single", aspect=0.4 if has_v0 else 0.72)
    axes = fig.subplots(1, 2 if has_v0 else 1, sharey=True, squeeze=False)[0]
    n_bad_total = 0
    series = (
        sweep["series"]
        if "series" in sweep
        else np.where(sweep["structure"] == "linear", "linear", "L")
    )
    sweep = sweep.assign(series=series)
    for _, group in sweep.groupby("curve", sort=True):
        group = group.sort_values("alpha")
        first = group.iloc[0]
        kind = first["series"]
        linear = kind == "linear"
        ax = axes[1] if kind == "v0" else axes[0]
        if linear:
            label, colour = "linear spring", GREY
        elif kind == "L":
            label = rf"$L = {first['L']:g}$"
            colour = plotting.L_COLOURS[
                sorted(panel["Ls"]).index(first["L"]) % len(plotting.L_COLOURS)
            ]
        else:
            label = rf"$v_0 = {first['v0']:g}$"
            v0s = sorted(panel["velocity"]["v0s"])
            colour = plotting.V0_COLOURS[v0s.index(first["v0"]) % len(plotting.V0_COLOURS)]
            length = float(panel["velocity"]["L"])
            if np.isclose(first["v0"], panel["v0"]) and length in map(float, panel["Ls"]):
                # The same curve as L = length on the left: the same colour, said so.
                colour = plotting.L_COLOURS[
                    sorted(map(float, panel["Ls"])).index(length) % len(plotting.L_COLOURS)
                ]
                label += rf" (left: $L = {length:g}$)"
        ok = group[group["status"] == "ok"]
        bad = group[group["status"] != "ok"]
        if ok.empty:
            raise ValueError(f"fig5b: no rows with status ok for {label}")
        ax.plot(ok["alpha"], ok["cor"], color=colour, lw=0.8 if linear else 1.0,
                zorder=2 if linear else 3, label=label)  # fmt: skip
        if len(bad):
            n_bad_total += len(bad)
            logger.warning("%s: %d rows not ok, drawn as crosses: %s", label, len(bad),
                           bad["status"].value_counts().to_dict())  # fmt: skip
            ax.plot(bad["alpha"], bad["cor"].clip(0, 1.02), **plotting.FAIL_STYLE, zorder=5)
        i = ok["cor"].idxmin()
        logger.info("%s: %d rows ok, COR min %.5f at alpha %.5g", label, len(ok),
                    ok.loc[i, "cor"], ok.loc[i, "alpha"])  # fmt: skip
    if n_bad_total:
        axes[0].plot([], [], **plotting.FAIL_STYLE, label=f"status not ok ({n_bad_total})")
    for ax in axes:
        plotting.log_axis(ax, "x")
        ax.set_xlim(sweep["alpha"].min(), sweep["alpha"].max())
        ax.set_ylim(0.0, 1.02)
        ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    axes[0].set_ylabel(plotting.COR_LABEL)
    title = plotting.beta_text(spring["beta"]) + ", " + spring_title(spring)
    axes[0].legend(loc="lower right", title=rf"$v_0 = {panel['v0']:g}$", ncols=2, fontsize=7,
                   title_fontsize=7)  # fmt: skip
    if has_v0:
        axes[1].legend(loc="lower right", title=rf"$L = {panel['velocity']['L']:g}$",
                       fontsize=7, title_fontsize=7)  # fmt: skip
    fig.suptitle(title, fontsize=7)
    return fig


def trend(sweep, key: str, series: str) -> dict:
    """How the COR orders with ``key`` (L or v0) within ``series``, on the common grid alphas."""
    sub = sweep[(sweep["series"] == series) & (sweep["status"] == "ok")]
    values = sorted(sub[key].unique())
    table = sub.pivot_table(index="alpha", columns=key, values="cor").dropna()
    if len(values) < 2 or table.empty:
        return {"share": "-", "n": 0, "means": "-"}
    falls = np.all(np.diff(table[values].to_numpy(), axis=1) < 0, axis=1)
    means = table[values].mean()
    return {
        "share": f"{100 * falls.mean():.0f}%",
        "n": len(table),
        "means": ", ".join(f"{means[v]:.3f}" for v in values),
        "values": ", ".join(f"{v:g}" for v in values),
        "mean_trend": "falls"
        if np.all(np.diff(means.to_numpy()) < 0)
        else ("rises" if np.all(np.diff(means.to_numpy()) > 0) else "is not monotonic"),
    }


WORDS = {"falls": "a smaller", "rises": "a larger"}


def caption_b(sweep, panel, scan) -> dict:
    sweep = sweep.assign(series=sweep["series"])
    by_l = trend(sweep, "L", "L")
    by_v = trend(sweep, "v0", "v0")
    # Similarity: the law is homogeneous in L, so (L, v0) and (L/v0, 1) must give the same COR.
    ok = sweep[sweep["status"] == "ok"]
    worst = 0.0
    pairs = []
    for v0 in panel.get("velocity", {}).get("v0s", []):
        ratio = panel["velocity"]["L"] / v0
        a = ok[(ok["series"] == "v0") & np.isclose(ok["v0"], v0)].set_index("alpha")["cor"]
        b = ok[(ok["series"] == "L") & np.isclose(ok["L"], ratio)].set_index("alpha")["cor"]
        common = a.index.intersection(b.index)
        if len(common):
            worst = max(worst, float((a[common] - b[common]).abs().max()))
            pairs.append(f"{ratio:g}")
    falls = scan.drop_duplicates(["theta0_deg", "corner"])["mean_cor_falls_with_L"]
    lin = ok[ok["series"] == "linear"]
    lin_min = lin.loc[lin["cor"].idxmin()] if len(lin) else None
    return {
        "L_share": by_l["share"], "L_n": by_l["n"], "L_means": by_l["means"],
        "L_values": by_l.get("values", "-"), "L_trend": by_l.get("mean_trend", "-"),
        "v_share": by_v["share"], "v_means": by_v["means"], "v_values": by_v.get("values", "-"),
        "v_trend": by_v.get("mean_trend", "-"),
        "similarity": f"{worst:.1e}" if pairs else "not checked (no matching L)",
        "similarity_L": ", ".join(pairs) or "-",
        "linear_min": f"{lin_min['cor']:.3f}" if lin_min is not None else "-",
        "linear_alpha": f"{lin_min['alpha']:.3g}" if lin_min is not None else "-",
        "scan_falls": int(falls.sum()), "scan_cases": len(falls),
        "L_word": WORDS.get(by_l.get("mean_trend"), "no ordered"),
        "v_word": WORDS.get(by_v.get("mean_trend"), "no ordered"),
        "later_claim": "borne out"
        if (by_l.get("mean_trend"), by_v.get("mean_trend")) == ("rises", "falls")
        else "not borne out",
    }  # fmt: skip


def main(inp, png_path, pdf_path, params, logger, smk=None):

    from restitution import plotting
    from restitution.tables.io import read_table

    if params.name == "a":
        fig = draw_a(params.spring, params.panel, logger)
        data = {}
    else:
        sweep = read_table(inp.sweep)
        velocity = params.panel.get("velocity") or {}
        expected = len(params.panel["Ls"]) + 1 + len(velocity.get("v0s", []))
        if sweep["curve"].nunique() != expected:
            raise ValueError(
                f"{inp.sweep}: {sweep['curve'].nunique()} curves, expected {expected} "
                f"(fig5.b.Ls, fig5.b.velocity.v0s and the linear spring)"
            )
        fig = draw_b(sweep, params.spring, params.panel, logger)
        data = caption_b(sweep, params.panel, pd.read_csv(inp.scan))
    plotting.save_outputs(fig, png_path, pdf_path, logger)
    if smk is not None:
        from render_caption import write_caption

        write_caption(smk, data, logger)


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
