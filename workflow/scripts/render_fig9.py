"""Render Fig. 9: the COR against the impact speed V0 with Hertz contact, and its two limits.

Top row: COR against V0 (log axis) for the two-mass chains (a) and the uniform chains (b), each
with its rigid-wall COR as a dashed line (the large-V0 limit) and COR = 1 (the soft-contact
limit) as a dotted one; hollow circles mark the speeds where the contact count changes
(bisected in log V0). Bottom row (c, d): the same rows as 1 - COR on log axes, where the soft
limit shows as its leading-order envelope (dash-dotted, proportional to V0;
``restitution.analysis.speed.soft_limit_envelope``) and the rigid wall as 1 - COR_rigid
(dashed). Only rows with status ok are drawn; on the log axes only where 1 - COR exceeds the
row's error estimate. The caption is written from the tables (``caption_data``): no number in it
is typed.
"""

import math

import numpy as np
import pandas as pd

#: The soft-limit envelope is drawn and checked where q = omega_1 T (slowest mode over the
#: Hertz pulse's time scale) is at least this: there the contact lasts ~ 2 I q / 2 pi > 4
#: periods of the slowest mode and the envelope's O(1/q) corrections are ~ 10 %.
SOFT_Q = 10.0
#: The envelope is drawn down to q = pi / I, where the contact lasts one slowest period
#: (omega_1 t_c = 2 I q = 2 pi; I = restitution.analysis.speed.HERTZ_I = 1.4716).
ENVELOPE_Q_MIN = math.pi / (0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9))


#: Line styles of the limits: the rigid wall, COR = 1, the soft-limit envelope of 1 - COR.
RIGID_LS = (0, (4, 2))
SOFT_LS = (0, (1, 1.2))
ENVELOPE_LS = (0, (6, 1.5, 1, 1.5))
#: Greys of the chains (panel b), from the house series (black, light grey, dark grey), told
#: apart by lightness: the curves are solid, the limits dashed and dotted.
CHAIN_SERIES = (0, 5, 1)


def _styles(limits: pd.DataFrame) -> dict:
    """curve -> (line style, legend label): alpha colours in panel (a), greys in panel (b)."""
    from restitution import plotting

    alphas = limits.loc[limits["panel"] == "a", "alpha"].tolist()
    out, k = {}, 0
    for r in limits.itertuples():
        if r.panel == "a":
            out[r.curve] = ({"color": plotting.alpha_colour(r.alpha, alphas), "ls": "-"},
                            rf"$\alpha = {r.alpha:g}$")  # fmt: skip
        else:  # N is none of beta, xi, alpha: black and greys, solid (dashed: the limits)
            series = plotting.series_style(CHAIN_SERIES[k % len(CHAIN_SERIES)])
            out[r.curve] = ({"color": series["color"], "ls": "-"},
                            rf"$N = {r.n_masses}$")  # fmt: skip
            k += 1
    return out


def _speed_axis(ax, lo, hi, label=True):
    from matplotlib.ticker import LogFormatterMathtext, LogLocator, NullFormatter

    ax.set_xscale("log")
    ax.set_xlim(lo, hi)
    ax.xaxis.set_major_locator(LogLocator(base=100.0, numticks=20))
    ax.xaxis.set_major_formatter(LogFormatterMathtext())
    ax.xaxis.set_minor_locator(LogLocator(base=10.0, subs=(1.0,), numticks=40))
    ax.xaxis.set_minor_formatter(NullFormatter())
    if label:
        ax.set_xlabel(r"impact speed $V_0\,k_h^2/(m_1^2\,\omega^5)$")


def draw(table: pd.DataFrame, limits: pd.DataFrame, changes: pd.DataFrame, logger=None):
    """The Fig. 9 figure (a matplotlib Figure on an Agg canvas)."""
    from matplotlib.lines import Line2D
    from matplotlib.ticker import LogFormatterMathtext, LogLocator, NullFormatter

    from restitution import plotting

    fig = plotting.new_figure("double", aspect=0.78)
    axes = fig.subplots(2, 2, sharex=True)
    styles = _styles(limits)
    lo, hi = table["v0"].min(), table["v0"].max()
    mid = math.sqrt(lo * hi)  # the limits are drawn on their side of the axis only
    ok = table[table["status"] == "ok"]
    if logger is not None and len(ok) < len(table):
        logger.warning("%d rows not ok: not drawn", len(table) - len(ok))
    grey = {"color": "0.35"}
    for col, panel in enumerate("ab"):
        top, bottom = axes[0, col], axes[1, col]
        floor = []
        for r in limits[limits["panel"] == panel].itertuples():
            style, label = styles[r.curve]
            rows = ok[ok["curve"] == r.curve].sort_values("v0")
            top.plot(rows["v0"], rows["cor"], **style, lw=1.0, zorder=3, label=label)
            top.plot([mid, hi], [r.rigid_cor] * 2, **{**style, "ls": RIGID_LS}, lw=0.8,
                     zorder=2, label=f"_rigid wall, {label}")  # fmt: skip
            ch = changes[changes["curve"] == r.curve]
            top.plot(ch["v0"], ch["cor_lo"], **{**style, "ls": "none"}, marker="o", ms=3.5,
                     mfc="white", mew=0.9, zorder=4, label=f"_count change, {label}")  # fmt: skip
            # 1 - COR where it exceeds the row's error estimate (finite estimates only).
            loss = 1.0 - rows["cor"]
            shown = rows[(loss > rows["error_estimate"]) & np.isfinite(rows["error_estimate"])]
            floor.append((1.0 - shown["cor"]).min())
            bottom.plot(shown["v0"], 1.0 - shown["cor"], **style, lw=0.8, zorder=3,
                        label=f"_{label}")  # fmt: skip
            bottom.plot([mid, hi], [1.0 - r.rigid_cor] * 2, **{**style, "ls": RIGID_LS},
                        lw=0.8, zorder=2, label=f"_rigid wall, {label}")  # fmt: skip
            soft = rows[rows["q"] >= ENVELOPE_Q_MIN]
            bottom.plot(soft["v0"], soft["soft_envelope"], **{**style, "ls": ENVELOPE_LS},
                        lw=1.0, zorder=4, label=f"_soft-limit envelope, {label}")  # fmt: skip
        top.plot([lo, mid], [1.0, 1.0], **grey, ls=SOFT_LS, lw=0.8, zorder=1,
                 label="_soft limit COR = 1")  # fmt: skip
        top.legend(loc="center left")
        top.set_ylabel(plotting.COR_LABEL)
        _speed_axis(top, lo, hi, label=False)
        low = min(limits.loc[limits["panel"] == panel, "rigid_cor"].min(),
                  ok.loc[ok["panel"] == panel, "cor"].min())  # fmt: skip
        top.set_ylim(low - 0.05 * (1.0 - low), 1.0 + 0.04 * (1.0 - low))
        bottom.set_yscale("log")
        bottom.yaxis.set_major_locator(LogLocator(base=100.0, numticks=20))
        bottom.yaxis.set_major_formatter(LogFormatterMathtext())
        bottom.yaxis.set_minor_locator(LogLocator(base=10.0, subs=(1.0,), numticks=40))
        bottom.yaxis.set_minor_formatter(NullFormatter())
        bottom.set_ylabel(r"$1 - e$")
        bottom.set_ylim(10.0 ** math.floor(math.log10(max(min(floor), 1e-14))), 2.0)
        _speed_axis(bottom, lo, hi)
    for ax, letter in zip(axes.flat, "abcd", strict=True):
        ax.text(0.015, 0.97, f"({letter})", transform=ax.transAxes, ha="left", va="top",
                fontsize=9, fontweight="bold")  # fmt: skip
    key = [
        (Line2D([], [], **grey, ls=RIGID_LS, lw=0.8),
         r"rigid wall: $e_\mathrm{rigid}$ (large $V_0$)"),
        (Line2D([], [], **grey, ls=SOFT_LS, lw=0.8), "soft contact: $e = 1$ (small $V_0$)"),
        (Line2D([], [], **grey, ls=ENVELOPE_LS, lw=1.0), "soft contact: envelope of $1 - e$"),
        (Line2D([], [], **grey, ls="none", marker="o", ms=3.5, mfc="white", mew=0.9),
         "contact count changes"),
    ]  # fmt: skip
    fig.legend(*zip(*key, strict=True), loc="outside lower center", ncol=4)
    axes[0, 0].set_title(r"two masses, $\alpha = m_2/m_1$")
    n_alpha = limits.loc[limits["panel"] == "b", "alpha"]
    axes[0, 1].set_title(rf"uniform chains, $m_i/m_1 = {n_alpha.iloc[0]:g}$" if len(n_alpha)
                         else "uniform chains")  # fmt: skip
    return fig


# ---------------------------------------------------------------------------------------------
# Caption numbers, all from the tables
# ---------------------------------------------------------------------------------------------
def fmt(x, digits=3) -> str:
    return f"{float(x):.{digits}g}"


def _exp(x) -> str:
    """x with two significant digits, exponents without padding (1.2e-07 -> 1.2e-7)."""
    text = f"{float(x):.2g}"
    if "e" not in text:
        return text
    mantissa, exponent = text.split("e")
    return f"{mantissa}e{int(exponent)}"


def rigid_order(rows: pd.DataFrame, rigid_cor: float) -> tuple[float, float, float]:
    """(difference at the largest V0, omega t_c there, observed order p): the difference to the
    rigid-wall COR against omega t_c over the last decade of V0 of the ok rows,
    d ~ (omega t_c)**p."""
    rows = rows.sort_values("v0")
    top = rows.iloc[-1]
    below = rows[rows["v0"] <= top["v0"] / 10.0 * (1 + 1e-9)].iloc[-1]
    d_top, d_below = abs(top["cor"] - rigid_cor), abs(below["cor"] - rigid_cor)
    p = math.log(d_below / d_top) / math.log(below["omega_tc"] / top["omega_tc"])
    return top["cor"] - rigid_cor, top["omega_tc"], p


def caption_data(table: pd.DataFrame, limits: pd.DataFrame, changes: pd.DataFrame) -> dict:
    ok = table[table["status"] == "ok"]
    finite = ok[np.isfinite(ok["error_estimate"])]
    rigid, soft, counts = [], [], []
    ratios = []
    for r in limits.itertuples():
        rows = ok[ok["curve"] == r.curve].sort_values("v0")
        d, tc, p = rigid_order(rows, r.rigid_cor)
        plural = "" if r.rigid_n_collisions == 1 else "s"
        rigid.append(f"{r.curve}: {fmt(r.rigid_cor, 4)} ({r.rigid_n_collisions} contact{plural}), "
                     f"{fmt(d, 2)} at omega t_c = {fmt(tc, 2)}, p = {p:.2f}")  # fmt: skip
        first = rows.iloc[0]
        soft.append(f"{r.curve}: {_exp(1.0 - first['cor'])} (envelope "
                    f"{_exp(first['soft_envelope'])}, q = {first['q']:.0f})")  # fmt: skip
        q = rows[(rows["q"] >= SOFT_Q) & np.isfinite(rows["error_estimate"])]
        ratios.append(((1.0 - q["cor"] - q["error_estimate"]) / q["soft_envelope"]).max())
        ch = changes[changes["curve"] == r.curve]
        listed = ", ".join(f"{fmt(c.v0, 4)} ({c.n_lo} to {c.n_hi})" for c in ch.itertuples())
        counts.append(f"{r.curve}: {listed or 'none'}")
    n_soft_rows = int(((ok["q"] >= SOFT_Q) & np.isfinite(ok["error_estimate"])).sum())
    hidden = ok[~((1.0 - ok["cor"] > ok["error_estimate"]) & np.isfinite(ok["error_estimate"]))]
    statuses = table.loc[table["status"] != "ok", "status"].value_counts().sort_index()
    jumps = (changes["cor_hi"] - changes["cor_lo"]).abs()
    return dict(
        spectrum=f"(5/2) Gamma(5/2) q^-2.5 = {2.5 * math.gamma(2.5):.4g} q^-2.5",
        n_rows=len(table),
        n_refined=int(table["refined"].sum()),
        n_not_ok=int((table["status"] != "ok").sum()),
        not_ok_statuses=", ".join(f"{k}: {v}" for k, v in statuses.items()) or "none",
        max_error=_exp(finite["error_estimate"].max()),
        methods=", ".join(sorted(ok["method"].unique())),
        rigid_methods=", ".join(sorted(limits["rigid_method"].unique())),
        rigid=". ".join(rigid),
        soft=". ".join(soft),
        soft_q=f"{SOFT_Q:g}",
        soft_rows=n_soft_rows,
        soft_ratio=f"{max(ratios):.3f}",
        n_hidden=len(hidden),
        changes=". ".join(counts),
        n_changes=len(changes),
        n_unresolved=int((~changes["resolved"].astype(bool)).sum()),
        width=_exp(changes["width"].max()) if len(changes) else "none",
        change_min=fmt(changes["v0"].min(), 3) if len(changes) else "none",
        change_max=fmt(changes["v0"].max(), 3) if len(changes) else "none",
        cor_jump=_exp(jumps.max()) if len(changes) else "none",
    )


def main(smk, logger):
    from render_caption import write_caption

    from restitution import plotting
    from restitution.tables.io import read_table

    table = read_table(smk.input.table)
    limits = read_table(smk.input.limits)
    changes = read_table(smk.input.changes)
    fig = draw(table, limits, changes, logger)
    plotting.save_outputs(fig, smk.output.png, smk.output.pdf, logger)
    write_caption(smk, caption_data(table, limits, changes), logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(snakemake, log)  # noqa: F821
