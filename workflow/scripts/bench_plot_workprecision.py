"""Work-precision diagrams: time per scene against COR error, one panel per scene.

One line per method family (its settings joined from loose to tight, through the valid points
only), the exact solvers as single points. A result with the wrong number of contacts is a hollow,
unjoined marker of its method. The grey band (in the legend) is the reference's own error bound:
a measured error inside it only says "at most the bound", so it is drawn at the bound with an
arrow to the left (an upper limit); errors below the floor (round-off, exactly 0) would be drawn at
the floor. The solve_ivp baseline's settings (rtol range, atol, no max_step) are stated above the
legend. Panel titles are mathtext built from each scene's parameters.
"""

import math

import numpy as np

FLOOR = 1e-17
#: A method is none of beta, xi, alpha: greys and black told apart by marker and line style
#: (restitution.plotting.MARKED_STYLES), never a parameter's colour.
METHODS = ("adaptive", "verlet", "RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")


def _styles() -> dict:
    from restitution import plotting

    styles = {"exact": dict(color="black", marker="*", ms=7, ls="none")}
    for index, method in enumerate(METHODS):
        styles[method] = {**plotting.marked_style(index), "ms": 3}  # filled: valid points
    return styles


def draw(records, titles, ivp=None):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from restitution import plotting

    scenes = list(dict.fromkeys(records["scene"]))
    ncols = 3
    nrows = math.ceil(len(scenes) / ncols)
    fig = plotting.new_figure("double", aspect=0.27 * nrows + 0.14)
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    ok = records[(records["status"] == "ok") & records["cor_error"].notna()]
    n_limits = 0
    for ax, scene in zip(axes, scenes, strict=False):
        sub = ok[ok["scene"] == scene]
        bound = records.loc[records["scene"] == scene, "reference_bound"].max()
        bound = bound if np.isfinite(bound) and bound > 0 else 0.0
        for family, style in _styles().items():
            g = sub[sub["family"] == family]
            if g.empty:
                continue
            g = g.sort_values("setting", ascending=False)
            err = np.maximum(g["cor_error"].to_numpy(), FLOOR)
            t = g["time_s"].to_numpy()
            valid = g["contacts_ok"].to_numpy(bool)
            # A measured error inside the reference's band says only "at most the bound": drawn
            # at the bound with an arrow to the left (an upper limit).
            limit = err <= bound
            x = np.where(limit, bound, err)
            # The line joins the valid points only; a point with the wrong contact count is
            # hollow and unjoined (no line implies it belongs to the method's curve).
            ax.plot(x[valid], t[valid], lw=0.8, label=family, **style)
            if (~valid).any():
                ax.plot(x[~valid], t[~valid], ls="none", marker=style["marker"], ms=4,
                        mew=0.9, color=style["color"], mfc="white",
                        label="_wrong contact count")  # fmt: skip
            if limit.any():
                n_limits += int(limit.sum())
                ax.errorbar(x[limit], t[limit], xerr=0.9 * x[limit], xuplims=True, ls="none",
                            color=style["color"], lw=0.6, capsize=2,
                            label="_upper limit")  # fmt: skip
        if bound > 0:
            ax.axvspan(FLOOR / 3, bound, color="0.9", zorder=0, lw=0)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(FLOOR / 3, 1.0)
        ax.set_title(titles.get(scene, scene), fontsize=7)
        ax.grid(True, which="major", lw=0.3, color="0.85")
    for ax in axes[len(scenes) :]:
        ax.set_visible(False)
    for ax in axes[(nrows - 1) * ncols :]:
        ax.set_xlabel("|COR error|")
    for ax in axes[::ncols]:
        ax.set_ylabel("time per scene (s)")
    handles, labels = axes[0].get_legend_handles_labels()
    for ax in axes[1 : len(scenes)]:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    handles.append(Line2D([], [], ls="none", marker="o", ms=4, mew=0.9, color="0.3",
                          mfc="white"))  # fmt: skip
    labels.append("hollow, unjoined: wrong contact count")
    handles.append(Line2D([], [], ls="none", marker=r"$\leftarrow$", ms=8, color="0.3"))
    labels.append("at most the reference's bound")
    handles.append(Patch(color="0.9", lw=0))
    labels.append("below the reference's error bound")
    # The house style uses constrained layout: "outside" reserves room below the panels.
    legend = fig.legend(handles, labels, loc="outside lower center", ncol=min(len(labels), 5),
                        frameon=False)  # fmt: skip
    if ivp is not None:
        legend.set_title(baseline_text(ivp), prop={"size": 7})
    return fig


def baseline_text(ivp: dict) -> str:
    """The solve_ivp baseline's settings in words (stated on the figure)."""
    rtols = sorted(float(v) for v in ivp["ivp_rtols"])
    methods = ", ".join(ivp.get("methods", [])) or "none run"
    step = ivp["ivp_steps_per_period"]
    step_text = (f"max_step = shortest period / {step:g}" if step else
                 "no max_step (events checked at its own step ends)")  # fmt: skip
    return (f"solve_ivp baseline ({methods}): rtol {rtols[0]:g}..{rtols[-1]:g}, "
            f"atol = {float(ivp['ivp_atol_over_rtol']):g} rtol, {step_text}, terminal events "
            f"for every contact switch")  # fmt: skip


def tex_number(value: float) -> str:
    """Mathtext of a number: powers of ten as 10^{k}, others with four significant digits."""
    if value == 0:
        return "0"
    exponent = math.log10(abs(value))
    if abs(exponent - round(exponent)) < 1e-6 and abs(round(exponent)) >= 2:
        return rf"10^{{{round(exponent)}}}"
    return f"{value:.4g}"


def scene_title(scene, scenes=()) -> str:
    """Panel title in mathtext from the scene's parameters (name, alpha, beta, xi, N, law).

    A grazing scene "grazeN" sits at alpha*_N; "grazeN_past" is given relative to it.
    """
    alpha = rf"\alpha = {tex_number(scene.alpha)}"
    base = scene.name.removesuffix("_past")
    if base.startswith("graze") and base[5:].isdigit():
        star = rf"\alpha^*_{{{base[5:]}}}"
        alpha = rf"\alpha = {star}"
        ref = {s.name: s for s in scenes}.get(base)
        if scene.name != base and ref is not None:
            alpha += rf"(1 + {tex_number(scene.alpha / ref.alpha - 1)})"
    parts = [alpha, rf"\beta = {tex_number(scene.beta)}"]
    if scene.xi:
        parts.append(rf"\xi = {tex_number(scene.xi)}")
    if scene.n_masses != 2:
        parts.append(rf"N = {scene.n_masses}")
    symbols = {"eta": r"\eta", "dr": r"\mathrm{DR}", "ks_ratio": r"k_s/k_1", "L": "L"}
    for key, value in scene.law.items():
        if key in symbols:
            parts.append(rf"{symbols[key]} = {tex_number(value)}")
    kind = scene.law.get("contact") or scene.law.get("structure") or ""
    kind = f" ({kind})" if kind and kind != scene.name else ""
    return f"{scene.name}{kind}: " + "$" + ",\\ ".join(parts) + "$"


def main(table_path, png_path, pdf_path, logger, ivp=None):
    from restitution import plotting
    from restitution.tables.io import read_table
    from restitution_workflow.bench.scenes import SCENES

    records = read_table(table_path)
    titles = {s.name: scene_title(s, SCENES) for s in SCENES}
    fig = draw(records, titles, ivp)
    plotting.save_outputs(fig, png_path, pdf_path, logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(
            snakemake.input.table,  # noqa: F821
            snakemake.output.png,  # noqa: F821
            snakemake.output.pdf,  # noqa: F821
            log,
            ivp=dict(snakemake.params.ivp),  # noqa: F821
        )
