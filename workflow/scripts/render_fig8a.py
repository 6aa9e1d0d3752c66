"""Render Fig. 8(a): the (alpha, beta) plane coloured by the COR, with the exact count-step curves.

The beta axis is symmetric-log (linear below ``beta_min`` of the map's grid, so the rigid wall
beta = 0 is a strip at the bottom and 1e-3, 1e-2 stay visible). Curves: solid where a new contact
grazes after a separation (from the rigid-wall points alpha*_n), dashed where a contact splits in
two. Thin lines: the cuts drawn in Fig. 2(a) (fixed beta) and Fig. 3(a) (fixed alpha). The caption
is written from the tables (``write_caption``): no number in it is typed.
"""

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


def draw(grid: pd.DataFrame, curves: pd.DataFrame, params, logger):
    from restitution import plotting

    fig = plotting.new_figure("double", aspect=0.55)
    ax = fig.add_subplot()
    ok = grid[grid["status"] == "ok"]
    if len(ok) < len(grid):
        logger.warning("%d map scenes not ok: drawn blank", len(grid) - len(ok))
    table = grid.assign(cor=grid["cor"].where(grid["status"] == "ok"))
    pivot = table.pivot_table(index="beta", columns="alpha", values="cor", dropna=False)
    mesh = ax.pcolormesh(pivot.columns, pivot.index, pivot.to_numpy(), shading="nearest",
                         cmap="viridis", vmin=0.0, vmax=1.0, rasterized=True)  # fmt: skip
    linthresh = params.map["beta_min"]
    ax.set_xscale("log")
    ax.set_yscale("symlog", linthresh=linthresh, linscale=0.5)
    ax.axhline(linthresh / 2, color="white", lw=0.4)
    ax.text(params.map["alpha_max"] / 1.15, linthresh / 5, r"rigid wall $\beta = 0$", color="white",
            ha="right", va="center", fontsize=7)  # fmt: skip
    for _, c in curves.groupby("curve"):
        kind = c["kind"].iloc[0]
        ax.plot(c["alpha"], c["beta"], color=COLOURS[kind], lw=0.9,
                ls="-" if kind == "new" else "--")  # fmt: skip
    for beta in params.fig2a_betas:
        ax.axhline(beta, color="white", lw=0.6, ls=":")
    for alpha in params.fig3_alphas:
        ax.plot([alpha, alpha], [params.fig3_beta_min, params.map["beta_max"]], color="white",
                lw=0.6, ls=":")  # fmt: skip
    ax.set_xlim(params.map["alpha_min"], params.map["alpha_max"])
    ax.set_ylim(0.0, params.map["beta_max"])
    ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    ax.set_ylabel(r"stiffness ratio $\beta = k_2/k_1$")
    ax.plot([], [], color=COLOURS["new"], label="new contact grazes")
    ax.plot([], [], color=COLOURS["split"], ls="--", label="contact splits")
    ax.plot([], [], color="0.5", ls=":", label="Fig. 2(a), 3(a) cuts")
    ax.legend(loc="upper left", fontsize=7, framealpha=0.8)
    fig.colorbar(mesh, ax=ax, label=plotting.COR_LABEL, pad=0.02)
    return fig


def caption_data(grid, curves, coverage) -> dict:
    ok = grid[grid["status"] == "ok"]
    i = ok["cor"].idxmin()
    kinds = curves.groupby("curve")["kind"].first()
    new = curves[curves["kind"] == "new"]
    starts = new.groupby("curve").first()
    ends = new.groupby("curve").last()
    rigid = ok[ok["beta"] == 0.0]
    soft = ok[ok["beta"] == ok["beta"].max()]
    return dict(
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
    )


def main(smk, logger):
    from restitution import plotting
    from restitution.tables.io import read_provenance, read_table

    grid = pd.concat([read_table(p) for p in smk.input.maps], ignore_index=True)
    curves = read_table(smk.input.curves)
    coverage = float(read_provenance(smk.input.curves).get("coverage", float("nan")))
    fig = draw(grid, curves, smk.params, logger)
    plotting.save_outputs(fig, smk.output.png, smk.output.pdf, logger)
    write_caption(smk, caption_data(grid, curves, coverage), logger)


if __name__ == "__main__":
    from _common import setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    main(snakemake, log)  # noqa: F821
