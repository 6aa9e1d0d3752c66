"""Render Fig. 8(b): the smallest COR against the number of masses N, one line per design family.

From results/design/designs.parquet only (every design re-solved there). Log COR axis on the
data. Filled markers: free optima; hollow: a bound is active (the COR falls when it is relaxed).
Robust designs are drawn with their worst COR over the mass errors and, dotted, their nominal COR.
Where a design's two independent starts differ by more than ``SPREAD_SHOWN``, a bar reaches the
other start's value. The caption is written from the table by ``render_fig8a.write_caption`` (no
number typed).
"""

import numpy as np
import pandas as pd

#: Two starts "agree" when their objectives differ by at most this (the polish resolves a cusp to
#: round-off; a larger spread is drawn and listed).
SPREAD_SHOWN = 1e-6

#: Design families in the order drawn, with their legend text. A family is none of beta, xi,
#: alpha: it is drawn in greys with a marker and a line style each (restitution.plotting's rule).
STYLE = {
    "uniform": "uniform chain (Fig. 6), best alpha",
    "tapered_decreasing": "tapered, masses decreasing",
    "tapered_increasing": "tapered, masses increasing",
    "masses": "free masses",
    "masses_springs": "free masses and springs",
    "robust": "robust (worst case)",
}
LABEL = dict(STYLE)


def _objective(rows: pd.DataFrame) -> pd.Series:
    """What each family minimises: a robust design's worst COR, every other design's COR."""
    return rows["worst_cor"].where(rows["family"] == "robust", rows["cor"])


def _column(table: pd.DataFrame, name: str, default):
    return table[name] if name in table else pd.Series(default, index=table.index)


def draw(table: pd.DataFrame, params):
    """Filled markers: free optima; hollow: a bound is active (the COR falls past it). A
    vertical bar from a marker: the other start's value where the two starts differ."""
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter

    from restitution import plotting

    fig = plotting.new_figure("onehalf", aspect=0.75)
    ax = fig.add_subplot()
    ok = table[table["status"] == "ok"].copy()
    ok["y"] = _objective(ok)
    active = _column(ok, "bound_active", False).astype(bool)
    spread = _column(ok, "restart_spread", 0.0).astype(float)
    other = np.where(_column(ok, "start", "warm") == "warm", _column(ok, "cor_cold", np.nan),
                     _column(ok, "cor_warm", np.nan))  # fmt: skip
    ys = [ok["y"].to_numpy()]
    handles, labels = [], []
    for index, (family, label) in enumerate(STYLE.items()):
        style = {**plotting.marked_style(index), "ms": 4.5}
        rows = ok[ok["family"] == family].sort_values("n_masses")
        if rows.empty:
            continue
        ax.plot(rows["n_masses"], rows["y"], **{**style, "marker": "none"}, lw=1.0,
                label=f"_{label} (line)")  # fmt: skip
        free = ~active[rows.index]
        ax.plot(rows["n_masses"][free], rows["y"][free], **{**style, "ls": "none"},
                label=f"_{label}")  # fmt: skip
        ax.plot(rows["n_masses"][~free], rows["y"][~free], **{**style, "ls": "none", "ms": 6},
                mfc="white", mew=1.3, zorder=4, label=f"_{label} (bound active)")  # fmt: skip
        handles.append(Line2D([], [], **style, lw=1.0))
        labels.append(label)
        if family == "robust":
            ys.append(rows["cor"].to_numpy())
            nominal = {**style, "ls": ":", "ms": 2.5}  # small, filled: not "bound active"
            ax.plot(rows["n_masses"], rows["cor"], **nominal, lw=0.6, label="_robust (nominal)")
            handles.append(Line2D([], [], **nominal, lw=0.6))
            labels.append("robust (nominal)")
        differs = rows.index[(spread[rows.index] > SPREAD_SHOWN).to_numpy()]
        for i in differs:
            o = other[ok.index.get_loc(i)]
            ax.plot([rows.at[i, "n_masses"]] * 2, [rows.at[i, "y"], o], color=style["color"],
                    lw=0.8, marker="_", ms=6, label="_")  # fmt: skip
            ys.append(np.array([o]))
    y = np.concatenate(ys)
    y = y[np.isfinite(y)]
    lo, hi = y.min() / 1.15, y.max() * 1.15
    ax.set_yscale("log")
    ax.set_ylim(lo, hi)
    ticks = [
        t for t in (0.02, 0.03, 0.05, 0.07, 0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1.0) if lo <= t <= hi
    ]
    ax.yaxis.set_major_locator(FixedLocator(ticks))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _pos: f"{value:g}"))
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.set_xticks(sorted(ok["n_masses"].unique()))
    ax.set_xlabel("number of masses N")
    ax.set_ylabel("smallest " + plotting.COR_LABEL)
    grey = dict(color="0.3", ls="none", marker="o", ms=4.5)
    handles += [Line2D([], [], **grey), Line2D([], [], **{**grey, "ms": 6}, mfc="white", mew=1.3),
                Line2D([], [], color="0.3", lw=0.8, marker="_", ms=6)]  # fmt: skip
    labels += ["free optimum", "a bound is active", "other start (where they differ)"]
    ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return fig


def fmt(x, digits=3) -> str:
    return f"{float(x):.{digits}g}"


def caption_data(table: pd.DataFrame) -> dict:
    ok = table[table["status"] == "ok"].copy()
    ok["y"] = _objective(ok)
    best = ok.loc[ok["cor"].idxmin()]
    two = ok[(ok["n_masses"] == 2) & (ok["family"] == "masses")]
    per_family = []
    for family in STYLE:
        rows = ok[ok["family"] == family].sort_values("n_masses")
        if rows.empty:
            continue
        y = rows["y"]
        first, last = rows.iloc[0], rows.iloc[-1]
        if len(rows) == 1:
            per_family.append(
                f"{LABEL[family]}: {fmt(y.iloc[0], 4)} at N = {int(first['n_masses'])}"
            )
            continue
        trend = "falls" if y.iloc[-1] < y.iloc[0] else "rises"
        low = rows.iloc[int(y.to_numpy().argmin())]
        per_family.append(
            f"{LABEL[family]}: {fmt(y.iloc[0], 4)} at N = {int(first['n_masses'])} to "
            f"{fmt(y.iloc[-1], 4)} at N = {int(last['n_masses'])} ({trend}; lowest "
            f"{fmt(y.min(), 4)} at N = {int(low['n_masses'])})"
        )
    active = ok[ok["bound_active"].astype(bool)]
    near = ok[(ok["bounds_hit"].str.len() > 0) & ~ok["bound_active"].astype(bool)]
    robust = ok[ok["family"] == "robust"]
    recheck = (ok["cor_resolved"] - ok["cor"]).abs().max()
    # The solver's COR error estimates of the designs (largest on a grazing cusp).
    err = _column(ok, "error_estimate", np.nan).astype(float)
    err_max, err_where = "not recorded", ""
    if err.notna().any():
        worst = ok.loc[err.idxmax()]
        err_max = f"{err.max():.1e}"
        err_where = f" ({LABEL[worst['family']]} N = {int(worst['n_masses'])})"
    differ = ok[ok["restart_spread"] > SPREAD_SHOWN].sort_values(["family", "n_masses"])
    cold_better = ok[(ok["start"] == "cold") & (ok["restart_spread"] > SPREAD_SHOWN)]
    warm_better = ok[(ok["start"] == "warm") & (ok["restart_spread"] > SPREAD_SHOWN)]
    grazing = ok[ok["grazing"].str.len() > 0]
    return dict(
        n_designs=len(table),
        n_not_ok=int((table["status"] != "ok").sum()),
        n_range=f"{int(ok['n_masses'].min())}..{int(ok['n_masses'].max())}",
        best_cor=fmt(best["cor"], 4),
        best_family=LABEL[best["family"]],
        best_n=int(best["n_masses"]),
        best_masses=", ".join(fmt(m, 3) for m in best["masses"]),
        best_active=best["active"],
        two_alpha=fmt(two["masses"].iloc[0][1], 10) if len(two) else "not run",
        two_cor=fmt(two["cor"].iloc[0], 10) if len(two) else "not run",
        per_family="; ".join(per_family),
        n_active=len(active),
        active_list="; ".join(
            f"{LABEL[r.family]} N = {r.n_masses}: {r.bounds_hit}" for r in active.itertuples()
        ),
        n_near=len(near),
        n_grazing=len(grazing),
        n_agree=int((ok["restart_spread"] <= SPREAD_SHOWN).sum()),
        spread_shown=f"{SPREAD_SHOWN:g}",
        spread_max=fmt(ok["restart_spread"].max(), 2),
        differ_list="; ".join(
            f"{LABEL[r.family]} N = {r.n_masses}: warm {fmt(r.cor_warm, 6)}, cold "
            f"{fmt(r.cor_cold, 6)}"
            for r in differ.itertuples()
        )
        or "none",  # fmt: skip
        n_cold_better=len(cold_better),
        n_warm_better=len(warm_better),
        robust_price=(
            ", ".join(
                f"N = {int(r.n_masses)}: {fmt(r.worst_cor - r.cor, 2)}" for r in robust.itertuples()
            )
            or "not run"  # fmt: skip
        ),
        recheck=f"{recheck:.1e}",
        err_max=err_max,
        err_where=err_where,
        n_err_tiny=int((err <= 1e-12).sum()),
        evaluations=int(ok["evaluations"].sum()),
        y_min=fmt(ok["y"].min(), 3),
        y_max=fmt(ok["y"].max(), 3),
    )


def main(smk, logger):
    from render_fig8a import write_caption

    from restitution import plotting
    from restitution.tables.io import read_table

    table = read_table(smk.input.table)
    fig = draw(table, smk.params)
    plotting.save_outputs(fig, smk.output.png, smk.output.pdf, logger)
    write_caption(smk, caption_data(table), logger)


if __name__ == "__main__":
    from _common import setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    main(snakemake, log)  # noqa: F821
