"""Render Fig. 8(b): the smallest COR against the number of masses N, one line per design family.

From results/design/designs.parquet only (every design re-solved there). Robust designs are drawn
with their worst COR over the mass errors (filled) and their nominal COR (open). The caption is
written from the table by ``render_fig8a.write_caption`` (no number typed).
"""

import pandas as pd

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


def draw(table: pd.DataFrame, params):
    from restitution import plotting

    fig = plotting.new_figure("onehalf", aspect=0.7)
    ax = fig.add_subplot()
    for index, (family, label) in enumerate(STYLE.items()):
        style = {**plotting.marked_style(index), "ms": 4, "mfc": "white"}
        rows = table[(table["family"] == family) & (table["status"] == "ok")]
        if rows.empty:
            continue
        rows = rows.sort_values("n_masses")
        y = rows["worst_cor"] if family == "robust" else rows["cor"]
        ax.plot(rows["n_masses"], y, **{**style, "mfc": style["color"]}, lw=1.0, label=label)
        if family == "robust":
            ax.plot(rows["n_masses"], rows["cor"], **{**style, "ls": ":"}, lw=0.6,
                    label="robust (nominal)")  # fmt: skip
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel("number of masses N")
    ax.set_ylabel("smallest " + plotting.COR_LABEL)
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return fig


def fmt(x, digits=3) -> str:
    return f"{float(x):.{digits}g}"


def caption_data(table: pd.DataFrame) -> dict:
    ok = table[table["status"] == "ok"]
    best = ok.loc[ok["cor"].idxmin()]
    two = ok[(ok["n_masses"] == 2) & (ok["family"] == "masses")]
    per_family = []
    for family in STYLE:
        rows = ok[ok["family"] == family].sort_values("n_masses")
        if rows.empty:
            continue
        y = rows["worst_cor"] if family == "robust" else rows["cor"]
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
    hits = ok[ok["bounds_hit"].str.len() > 0]
    robust = ok[ok["family"] == "robust"]
    recheck = (ok["cor_resolved"] - ok["cor"]).abs().max()
    return dict(
        n_designs=len(table),
        n_not_ok=int((table["status"] != "ok").sum()),
        best_cor=fmt(best["cor"], 4),
        best_family=LABEL[best["family"]],
        best_n=int(best["n_masses"]),
        best_masses=", ".join(fmt(m, 3) for m in best["masses"]),
        two_alpha=fmt(two["masses"].iloc[0][1], 10) if len(two) else "not run",
        two_cor=fmt(two["cor"].iloc[0], 10) if len(two) else "not run",
        per_family="; ".join(per_family),
        n_bound=len(hits),
        bound_list="; ".join(
            f"{LABEL[r.family]} N = {r.n_masses}: {r.bounds_hit}" for r in hits.itertuples()
        )
        or "none",  # fmt: skip
        robust_price=(
            ", ".join(
                f"N = {int(r.n_masses)}: {fmt(r.worst_cor - r.cor, 2)}" for r in robust.itertuples()
            )
            or "not run"  # fmt: skip
        ),
        recheck=f"{recheck:.1e}",
        evaluations=int(ok["evaluations"].sum()),
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
