"""Work-precision diagrams: time per scene against COR error, one panel per scene.

One line per method family (its settings joined from loose to tight), the exact solvers as single
points. A red cross marks a result with the wrong number of contacts; errors below the floor
(round-off, exactly 0) are drawn at the floor; the grey band is the reference's own error bound,
below which a measured error only says "at most the bound".
"""

import math
import textwrap

import numpy as np

FLOOR = 1e-17
STYLE = {
    "exact": dict(color="black", marker="*", ms=7, ls="none"),
    "adaptive": dict(color="#0072B2", marker="o", ms=3),
    "verlet": dict(color="#009E73", marker="s", ms=3),
    "RK45": dict(color="#E69F00", marker="v", ms=3),
    "RK23": dict(color="#F0E442", marker="<", ms=3),
    "DOP853": dict(color="#D55E00", marker="^", ms=3),
    "Radau": dict(color="#CC79A7", marker="D", ms=3),
    "BDF": dict(color="#999999", marker=">", ms=3),
    "LSODA": dict(color="#56B4E9", marker="P", ms=3),
}


def draw(records, titles):
    from restitution import plotting

    scenes = list(dict.fromkeys(records["scene"]))
    ncols = 3
    nrows = math.ceil(len(scenes) / ncols)
    fig = plotting.new_figure("double", aspect=0.27 * nrows + 0.1)
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    ok = records[(records["status"] == "ok") & records["cor_error"].notna()]
    for ax, scene in zip(axes, scenes, strict=False):
        sub = ok[ok["scene"] == scene]
        for family, style in STYLE.items():
            g = sub[sub["family"] == family]
            if g.empty:
                continue
            g = g.sort_values("setting", ascending=False)
            err = np.maximum(g["cor_error"].to_numpy(), FLOOR)
            ax.plot(err, g["time_s"], lw=0.8, label=family, **style)
            wrong = ~g["contacts_ok"].to_numpy(bool)
            if wrong.any():
                ax.plot(
                    err[wrong],
                    g["time_s"].to_numpy()[wrong],
                    ls="none",
                    marker="x",
                    color="red",
                    ms=6,
                    mew=1.0,
                    zorder=5,
                )
        bound = records.loc[records["scene"] == scene, "reference_bound"].max()
        if np.isfinite(bound) and bound > 0:
            ax.axvspan(FLOOR / 3, bound, color="0.9", zorder=0, lw=0)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(FLOOR / 3, 1.0)
        ax.set_title(textwrap.fill(titles.get(scene, scene), 44), fontsize="x-small")
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
    from matplotlib.lines import Line2D

    handles.append(Line2D([], [], ls="none", marker="x", color="red", ms=6))
    labels.append("wrong contact count")
    # The house style uses constrained layout: "outside" reserves room below the panels.
    fig.legend(handles, labels, loc="outside lower center", ncol=min(len(labels), 6),
               fontsize="x-small", frameon=False)  # fmt: skip
    return fig


def main(table_path, png_path, pdf_path, logger):
    from restitution import plotting
    from restitution.bench.scenes import SCENES
    from restitution.io import read_table

    records = read_table(table_path)
    titles = {s.name: f"{s.name}: {s.title}" for s in SCENES}
    fig = draw(records, titles)
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
        )
