"""Render Fig. 8(a): the (alpha, beta) plane coloured by the COR, with the exact count-step curves.

The beta axis is symmetric-log (linear below ``beta_min`` of the map's grid, so the rigid wall
beta = 0 is a strip at the bottom and 1e-3, 1e-2 stay visible). Curves: solid where a new contact
grazes after a separation (from the rigid-wall points alpha*_n), dashed where a contact splits in
two. Thin lines: the cuts drawn in Fig. 2(a) (fixed beta) and Fig. 3(a) (fixed alpha). The caption
is written from the tables (``write_caption``): no number in it is typed.
"""

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd

# Kinds of curve are none of beta, xi, alpha: black, told apart by line style (no colour of theirs).
COLOURS = {"new": "#000000", "split": "#000000"}


def write_caption(smk, data: dict, logger=None) -> Path:
    """Render the Jinja template ``smk.input.template`` with the config, params and ``data``.

    Undefined names fail (a caption never silently loses a value); written to
    ``smk.output.caption``, the file the rule's ``report(caption=...)`` points at.
    """
    from jinja2 import Environment, StrictUndefined

    env = Environment(trim_blocks=True, lstrip_blocks=True, undefined=StrictUndefined)
    snakemake = SimpleNamespace(config=smk.config, params=smk.params)
    text = env.from_string(Path(smk.input.template).read_text()).render(
        snakemake=snakemake, data=data
    )
    out = Path(smk.output.caption)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    if logger is not None:
        logger.info("caption %s with data %s", out, data)
    return out


def fmt(x, digits=3) -> str:
    return f"{float(x):.{digits}g}"


#: Overlays on the map: black lines with a white halo, visible on every colour of the map.
HALO = 1.6


def _halo(lw: float):
    from matplotlib import patheffects

    return [patheffects.withStroke(linewidth=lw + HALO, foreground="white")]


def one_minus_cor(grid: pd.DataFrame, limits: dict) -> pd.DataFrame:
    """(beta x alpha) table of 1 - COR: NaN where a scene is not ok or beyond its row's
    resolved range (there the grid cannot resolve the cusps)."""
    keep = (grid["status"] == "ok") & (grid["alpha"] <= grid["beta"].map(limits))
    table = grid.assign(value=(1.0 - grid["cor"]).where(keep))
    return table.pivot_table(index="beta", columns="alpha", values="value", dropna=False)


def count_labels(grid: pd.DataFrame, limits: dict, n_max: int, min_width: float = 0.2):
    """[(n, alpha, beta)]: where to write each count n <= n_max, the middle (in ln alpha) of its
    widest run along one row of beta in [1e-3, 0.05] inside the resolved range, when at least
    ``min_width`` wide in ln alpha."""
    best = {}
    rows = grid[(grid["beta"] >= 1e-3) & (grid["beta"] <= 0.05) & (grid["status"] == "ok")]
    for beta, row in rows.groupby("beta"):
        row = row[row["alpha"] <= limits[beta]].sort_values("alpha")
        a, n = np.log(row["alpha"].to_numpy()), row["n_collisions"].to_numpy()
        edges = np.r_[0, np.flatnonzero(np.diff(n) != 0) + 1, n.size]
        for i, j in zip(edges[:-1], edges[1:], strict=True):
            width = a[j - 1] - a[i]
            if n[i] <= n_max and width >= min_width and width > best.get(n[i], (0.0,))[0]:
                best[int(n[i])] = (width, math.exp(0.5 * (a[i] + a[j - 1])), beta)
    return [(n, alpha, beta) for n, (_, alpha, beta) in sorted(best.items())]


def draw(grid, curves, params, logger, untraced=None, minima=None, limits=None):
    from matplotlib.colors import LogNorm
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from restitution import plotting

    limits = limits or {b: math.inf for b in grid["beta"].unique()}
    fig = plotting.new_figure("double", aspect=0.6)
    ax = fig.add_subplot()
    n_bad = int((grid["status"] != "ok").sum())
    if n_bad:
        logger.warning("%d map scenes not ok: drawn blank", n_bad)
    pivot = one_minus_cor(grid, limits)
    cmap = plotting_cmap()
    mesh = ax.pcolormesh(pivot.columns, pivot.index, pivot.to_numpy(), shading="nearest",
                         cmap=cmap, norm=LogNorm(vmin=VMIN, vmax=1.0),
                         rasterized=True)  # fmt: skip
    linthresh = params.map["beta_min"]
    ax.set_xscale("log")
    ax.set_yscale("symlog", linthresh=linthresh, linscale=0.5)
    ax.axhline(linthresh / 2, color="black", lw=0.5)
    ax.text(0.06, linthresh / 5, r"rigid wall $\beta = 0$", color="black", ha="left",
            va="center", fontsize=7, path_effects=_halo(0.5))  # fmt: skip
    for _, c in curves.groupby("curve"):
        kind = c["kind"].iloc[0]
        ax.plot(c["alpha"], c["beta"], color=COLOURS[kind], lw=0.9,
                ls="-" if kind == "new" else "--", path_effects=_halo(0.9))  # fmt: skip
    if minima is not None and len(minima):
        for _, c in minima.groupby("curve"):
            if len(c) >= 2:
                ax.plot(c["alpha"], c["beta"], color="black", lw=0.9, ls=MIN_LS,
                        path_effects=_halo(0.9))  # fmt: skip
            else:
                ax.plot(c["alpha"], c["beta"], color="black", ls="none", marker="o", ms=2,
                        path_effects=_halo(0.5))  # fmt: skip
    if untraced is not None and len(untraced):
        shown = untraced[untraced["resolved"] & (untraced["beta"] > 0)]
        ax.plot(shown["alpha"], shown["beta"], **UNTRACED, label="_untraced")
    cut = dict(color="0.25", lw=0.6, ls=":")
    for beta in params.fig2a_betas:
        ax.axhline(beta, **cut, path_effects=_halo(0.6))
    for alpha in params.fig3_alphas:
        ax.plot([alpha, alpha], [params.fig3_beta_min, params.map["beta_max"]], **cut,
                path_effects=_halo(0.6))  # fmt: skip
    for n, alpha, beta in count_labels(grid, limits, N_LABELS):
        ax.text(alpha, beta, f"{n}", ha="center", va="center", fontsize=8, color="black",
                path_effects=_halo(0.5))  # fmt: skip
    ax.set_xlim(params.map["alpha_min"], params.map["alpha_max"])
    ax.set_ylim(0.0, params.map["beta_max"])
    ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    ax.set_ylabel(r"stiffness ratio $\beta = k_2/k_1$")
    handles = [
        Line2D([], [], color="black", lw=0.9, path_effects=_halo(0.9)),
        Line2D([], [], color="black", lw=0.9, ls="--", path_effects=_halo(0.9)),
        Line2D([], [], color="black", lw=0.9, ls=MIN_LS, path_effects=_halo(0.9)),
        Line2D([], [], **{**UNTRACED, "ms": 3}),
        Line2D([], [], **cut),
        Patch(facecolor=MASK_GREY, edgecolor="none"),
    ]
    labels = ["new contact grazes", "contact splits", r"smooth COR minimum ($\beta > 0$)",
              "count step no curve traces", "Fig. 2(a), 3(a) cuts",
              "grid cannot resolve the cusps"]  # fmt: skip
    # Below the map (constrained layout reserves the room): inside, it would hide data.
    fig.legend(handles, labels, loc="outside lower center", ncol=3, fontsize=7, frameon=False)
    ax.set_facecolor(MASK_GREY)
    bar = fig.colorbar(mesh, ax=ax, pad=0.02, extend="min")
    bar.set_label(r"$1 - e$ (log scale; numbers on the map: contacts)")
    return fig


#: The caption's measure of how a linear COR scale saturates: the share of the grid above
#: SATURATED_COR (and of its part beyond SATURATED_ALPHA, the comb of many contacts).
SATURATED_COR = 0.9
SATURATED_ALPHA = 3.0
#: 1 - COR below this is drawn in the colour map's lowest colour (colour bar extends "min").
VMIN = 1e-3
#: The grid's count steps no traced curve explains: small open circles (visible on any colour).
UNTRACED = dict(ls="none", marker="o", ms=1.8, mfc="white", mec="black", mew=0.3)
#: Counts labelled on the map (regions wide enough for the number).
N_LABELS = 12
#: Line style of the smooth minima; grey behind masked cells and unfinished scenes.
MIN_LS = (0, (3, 1, 1, 1))
MASK_GREY = "#C8C8C8"


def plotting_cmap():
    """Sequential, perceptually uniform map of 1 - COR (bright: little rebound)."""
    from matplotlib import colormaps

    return colormaps["viridis"]


def caption_data(grid, curves, coverage, untraced=None, minima=None, limits=None) -> dict:
    ok = grid[grid["status"] == "ok"]
    i = ok["cor"].idxmin()
    kinds = curves.groupby("curve")["kind"].first()
    new = curves[curves["kind"] == "new"]
    starts = new.groupby("curve").first()
    ends = new.groupby("curve").last()
    rigid = ok[ok["beta"] == 0.0]
    soft = ok[ok["beta"] == ok["beta"].max()]
    limits = limits or {b: math.inf for b in grid["beta"].unique()}
    lim = pd.Series(limits)
    masked = grid["alpha"] > grid["beta"].map(limits)
    above = ok[ok["alpha"] > SATURATED_ALPHA]
    data = dict(
        n_scenes=len(grid),
        n_not_ok=int((grid["status"] != "ok").sum()),
        cor_min=fmt(ok["cor"][i], 4),
        cor_min_alpha=fmt(ok["alpha"][i], 4),
        cor_min_beta=fmt(ok["beta"][i], 3),
        n_curves=int(kinds.size),
        n_new=int((kinds == "new").sum()),
        n_split=int((kinds == "split").sum()),
        n_points=len(curves),
        residual=f"{np.nanmax(np.abs(curves['residual'])):.1e}",
        alpha_star_first=fmt(starts["alpha"].min(), 4),
        new_end_beta_min=fmt(ends["beta"].min(), 3),
        new_end_beta_max=fmt(ends["beta"].max(), 3),
        coverage=f"{100 * coverage:.1f}",
        max_count_rigid=int(rigid["n_collisions"].max()),
        max_count_soft=int(soft["n_collisions"].max()),
        beta_soft=fmt(soft["beta"].iloc[0]),
        share_above_09=f"{100 * (ok['cor'] > SATURATED_COR).mean():.0f}",
        share_above_09_a3=f"{100 * (above['cor'] > SATURATED_COR).mean():.0f}",
        saturated_cor=f"{SATURATED_COR:g}",
        saturated_alpha=f"{SATURATED_ALPHA:g}",
        masked=f"{100 * masked.mean():.0f}",
        limit_rigid=fmt(limits.get(0.0, math.inf), 3),
        limit_min=fmt(lim.min(), 3),
        limit_max=fmt(lim[np.isfinite(lim)].max(), 3) if np.isfinite(lim).any() else "inf",
        n_unresolved_rows=int(np.isfinite(lim).sum()),
        n_rows=len(lim),
        vmin=f"{VMIN:g}",
        below_vmin=f"{100 * ((1 - ok['cor']) < VMIN).mean():.1f}",
    )
    if untraced is not None:
        data["n_untraced"] = len(untraced)
        data["n_untraced_shown"] = int((untraced["resolved"] & (untraced["beta"] > 0)).sum())
    if minima is not None:
        top = minima[minima["beta"] == minima["beta"].max()].sort_values("alpha")
        data["n_minima"] = len(minima)
        data["n_minima_curves"] = int(minima["curve"].nunique()) if len(minima) else 0
        data["minima_top_beta"] = fmt(top["beta"].iloc[0]) if len(top) else "none"
        data["minima_top"] = (
            ", ".join(f"{fmt(r.cor, 3)} at alpha = {fmt(r.alpha, 3)}" for r in top.itertuples())
            or "none"
        )
    return data


def main(smk, logger):
    from simulate_fig8a_curves import resolved_limits

    from restitution import plotting
    from restitution.tables.io import read_provenance, read_table

    grid = pd.concat([read_table(p) for p in smk.input.maps], ignore_index=True)
    curves = read_table(smk.input.curves)
    untraced = read_table(smk.input.untraced)
    minima = read_table(smk.input.minima)
    limits = resolved_limits(grid, smk.params.curves["min_cells"])
    coverage = float(read_provenance(smk.input.curves).get("coverage", float("nan")))
    fig = draw(grid, curves, smk.params, logger, untraced, minima, limits)
    plotting.save_outputs(fig, smk.output.png, smk.output.pdf, logger)
    data = caption_data(grid, curves, coverage, untraced, minima, limits)
    write_caption(smk, data, logger)


if __name__ == "__main__":
    from _common import setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    main(snakemake, log)  # noqa: F821
