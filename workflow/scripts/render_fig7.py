"""Render Fig. 7(a), 7(b) or 7(c) (``params.panel``: fig7a, ...) from the Fig. 7 sweep table.

- 7(a): COR against alpha = m2/m1 (log axis), one curve per damping ratio xi.
- 7(b): number of contacts n_collisions against alpha (a step curve: the count is constant
  between the refined changes).
- 7(c): normalised total duration omega*t_col against alpha, log-log (it spans three decades).

Rows with status "ok" are drawn as curves. Any other row (aggregate_fig7 has already failed the
run if there are more than ``max_not_ok_fraction`` of them) is logged and marked with a red cross
along the bottom of the axes at its alpha, never drawn as data (its values are not final).
"""

import numpy as np
import pandas as pd

PANELS = {
    "a": ("cor", None),  # plotting.COR_LABEL
    "b": ("n_collisions", "number of contacts $n$"),
    "c": ("omega_t_col", None),  # plotting.T_COL_LABELS["omega"], the paper's normalisation
}


def xi_text(xi: float) -> str:
    return rf"$\xi = {xi:g}$"


def mark_not_ok(ax, bad: pd.DataFrame, logger) -> None:
    """Red crosses along the bottom of the axes at the alphas of rows whose status is not ok.

    Their values are not final (e.g. the contact budget ran out), so they are shown where they
    are, never at a value; the log lists them per xi.
    """
    for xi, rows in bad.groupby("xi", sort=True):
        logger.warning(
            "xi %g: %d rows not ok %s, marked at the bottom, not drawn as data, at alpha %s",
            xi,
            len(rows),
            rows["status"].value_counts().to_dict(),
            ", ".join(f"{a:.6g}" for a in rows["alpha"].head(20)),
        )
    if bad.empty:
        return
    from restitution import plotting

    cross = {**plotting.FAIL_STYLE, "ms": 4, "mew": 0.8}
    label = f"status not ok ({len(bad)} rows)"
    ax.plot(bad["alpha"], np.full(len(bad), 0.03), **cross, zorder=5, clip_on=False,
            transform=ax.get_xaxis_transform(), label=label)  # fmt: skip


def draw(sweep: pd.DataFrame, panel: str, fig7: dict, logger):
    """The figure of one panel (a matplotlib Figure on an Agg canvas)."""
    from restitution import plotting

    column, ylabel = PANELS[panel]
    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    for xi in sorted(fig7["xis"]):
        rows = sweep[sweep["xi"] == xi].sort_values("alpha")
        curve = rows[rows["status"] == "ok"]
        if curve.empty:
            raise ValueError(f"no rows with status ok for xi = {xi} in the sweep table")
        colour = plotting.xi_colour(xi, fig7["xis"])
        # Rows not ok become NaN: the curve is broken there instead of bridged across them.
        y = rows[column].where(rows["status"] == "ok").astype(float)
        if panel == "b":
            ax.step(rows["alpha"], y, where="post", color=colour, lw=0.8, label=xi_text(xi))
        else:
            ax.plot(rows["alpha"], y, color=colour, lw=0.8, label=xi_text(xi))
        logger.info(
            "xi %g: %d rows drawn, %s %.5g..%.5g",
            xi,
            len(curve),
            column,
            curve[column].min(),
            curve[column].max(),
        )
    drawn = sweep["xi"].isin([float(xi) for xi in fig7["xis"]])
    mark_not_ok(ax, sweep[drawn & (sweep["status"] != "ok")], logger)
    plotting.log_axis(ax, "x")
    ax.set_xlim(fig7["alpha_min"], fig7["alpha_max"])
    ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    ax.set_ylabel(ylabel or {"a": plotting.COR_LABEL}.get(panel, plotting.T_COL_LABELS["omega"]))
    title = plotting.beta_text(fig7["beta"])
    if panel == "a":
        ax.set_ylim(0.0, 1.02)
        ax.legend(loc="lower right", title=title, ncols=2)
    elif panel == "b":
        # Log count axis: the first steps (1, 2, 3 contacts) stay apart from the peaks.
        plotting.log_axis(ax, "y")
        ax.set_ylim(0.8, None)
        ax.legend(loc="upper left", title=title)
        zoom_counts(ax, sweep, fig7)
    else:
        plotting.log_axis(ax, "y")
        # The fitted large-alpha power law (caption: slope per xi), drawn below the curves.
        # The mean of the slopes as the caption prints them (two decimals).
        slopes = fitted_slopes(curves(sweep, fig7["xis"]), fig7)
        slope = float(np.mean([float(f"{v:.2f}") for v in slopes]))
        hi = float(fig7["alpha_max"])
        a = np.geomspace(hi / 10, hi, 50)
        ref = sweep[(sweep["alpha"] >= hi / 10) & (sweep["status"] == "ok")]["omega_t_col"]
        y0 = float(np.exp(np.log(ref).mean())) / np.sqrt(hi / 10 * hi) ** slope
        ax.plot(a, 0.55 * y0 * a**slope, color="0.35", lw=0.8, ls=(0, (4, 2)),
                label=rf"$\propto \alpha^{{{slope:.2f}}}$ (fit, mean slope)")  # fmt: skip
        ax.legend(loc="lower right", title=title)
    return fig


#: The inset of Fig. 7(b): the first steps of the count, alpha in ZOOM_ALPHA, counts 1..ZOOM_N.
ZOOM_ALPHA = (0.6, 2.2)
ZOOM_N = 4


def zoom_counts(ax, sweep: pd.DataFrame, fig7: dict) -> None:
    """Inset of Fig. 7(b) on linear axes: where the second, third and fourth contacts appear.

    The step curves would cover one another on the same count; each xi is drawn a little higher
    than the previous (by 0.06 of a contact, stated in the caption) so every step stays visible.
    """
    from restitution import plotting

    inset = ax.inset_axes([0.57, 0.11, 0.41, 0.27])
    xis = sorted(fig7["xis"])
    for k, xi in enumerate(xis):
        rows = sweep[(sweep["xi"] == xi) & (sweep["status"] == "ok")].sort_values("alpha")
        offset = ZOOM_OFFSET * (k - (len(xis) - 1) / 2)
        inset.step(rows["alpha"], rows["n_collisions"] + offset, where="post", lw=0.8,
                   color=plotting.xi_colour(xi, fig7["xis"]), label="_" + xi_text(xi))  # fmt: skip
    inset.set_xlim(*ZOOM_ALPHA)
    inset.set_ylim(0.6, ZOOM_N + 0.4)
    inset.set_yticks(range(1, ZOOM_N + 1))
    inset.set_xticks([1.0, 1.5, 2.0], ["1", "1.5", "2"])
    inset.minorticks_off()
    inset.tick_params(labelsize=7, length=2, which="both")
    inset.set_facecolor("white")


#: Vertical offset between the xi curves in the inset of Fig. 7(b), in contacts.
ZOOM_OFFSET = 0.06


def _fmt(value, digits=3):
    return f"{float(value):.{digits}g}"


def curves(sweep: pd.DataFrame, xis) -> dict:
    """The ok rows of each xi, sorted by alpha."""
    out = {}
    for xi in sorted(map(float, xis)):
        rows = sweep[(sweep["xi"] == xi) & (sweep["status"] == "ok")]
        out[xi] = rows.sort_values("alpha").reset_index(drop=True)
    return out


def first_reach(curve: pd.DataFrame, n: int) -> float:
    """The smallest alpha at which the contact count of ``curve`` is at least ``n`` (NaN: never)."""
    hit = curve.loc[curve["n_collisions"] >= n, "alpha"]
    return float(hit.iloc[0]) if len(hit) else float("nan")


def _ranges(values: list[int]) -> str:
    """Integers as runs: [2, 4, 5, 6, 9] -> 'n = 2, 4-6, 9' ('no n' if empty)."""
    if not values:
        return "no n"
    runs, start = [], values[0]
    for a, b in zip(values, [*values[1:], None], strict=True):
        if b != a + 1:
            runs.append(f"{start}" if start == a else f"{start}-{a}")
            start = b
    return "n = " + ", ".join(runs)


def count_order(by_xi: dict, fig7: dict) -> dict:
    """How the contact count orders with xi, as caption words and numbers (Fig. 7(b)).

    - Where the count first reaches n, per xi, for every n that every curve reaches: the n whose
      first alpha moves right (to larger alpha) as xi grows, left, or neither. n = 2 is where the
      second contact appears, the first COR minimum of Fig. 7(a).
    - On a log grid of alpha: the share where the count rises with xi (never falls from one xi to
      the next and is not the same for all), falls with xi, is the same, or neither; and the
      first alpha of the grid where it falls with xi, with its counts.
    """
    xis = list(by_xi)
    top = min(int(c["n_collisions"].max()) for c in by_xi.values())
    right, left, neither = [], [], []
    reach = {}
    for n in range(2, top + 1):
        alphas = [first_reach(c, n) for c in by_xi.values()]
        reach[n] = alphas
        steps = np.diff(alphas)
        (right if np.all(steps > 0) else left if np.all(steps < 0) else neither).append(n)
    grid = np.geomspace(fig7["alpha_min"], fig7["alpha_max"], 4000)
    counts = np.array(
        [
            c["n_collisions"].to_numpy()[
                np.clip(np.searchsorted(c["alpha"].to_numpy(), grid, side="right") - 1, 0, None)
            ]
            for c in by_xi.values()
        ]
    )
    d = np.diff(counts, axis=0)
    same = np.all(d == 0, axis=0)
    rises = np.all(d >= 0, axis=0) & ~same
    falls = np.all(d <= 0, axis=0) & ~same
    first_fall = int(np.argmax(falls)) if falls.any() else None
    left_example = left[len(left) // 2] if left else None
    return {
        "reach2": ", ".join(_fmt(a) for a in reach.get(2, [])) or "-",
        "reach2_word": "moves to larger"
        if 2 in right
        else (
            "moves to smaller" if 2 in left else "does not move monotonically to larger or smaller"
        ),
        "n_common": top,
        "n_right": _ranges(right),
        "n_left": _ranges(left),
        "n_neither": _ranges(neither),
        "left_n": left_example if left_example is not None else "-",
        "left_alphas": ", ".join(_fmt(a) for a in reach[left_example]) if left else "-",
        "share_rises": f"{100 * rises.mean():.0f}%",
        "share_falls": f"{100 * falls.mean():.0f}%",
        "share_same": f"{100 * same.mean():.0f}%",
        "share_neither": f"{100 * (1 - rises.mean() - falls.mean() - same.mean()):.0f}%",
        "rise_lo": _fmt(grid[rises][0]) if rises.any() else "-",
        "rise_hi": _fmt(grid[rises][-1]) if rises.any() else "-",
        "fall_alpha": _fmt(grid[first_fall]) if first_fall is not None else "-",
        "fall_counts": ", ".join(str(int(v)) for v in counts[:, first_fall])
        if first_fall is not None
        else "-",
        "n_grid": len(grid),
        "xi_word": ", ".join(f"{xi:g}" for xi in xis),
    }


def fitted_slopes(by_xi: dict, fig7: dict) -> list[float]:
    """Slope of log(omega t_col) against log(alpha) over the top decade of alpha, per curve."""
    lo = float(fig7["alpha_max"]) / 10
    slopes = []
    for c in by_xi.values():
        sel = c["alpha"] >= lo
        slope = np.polyfit(np.log(c.loc[sel, "alpha"]), np.log(c.loc[sel, "omega_t_col"]), 1)
        slopes.append(float(slope[0]))
    return slopes


def caption_data(sweep: pd.DataFrame, panel: str, fig7: dict, minima=None, summary=None) -> dict:
    """Numbers and words of the caption of ``panel``, computed from the sweep table and read from
    what ``aggregate_fig7`` listed: panel (a) from its minima table (minima.csv: xi, minimum,
    alpha, cor), panels (b) and (c) from its per-xi summary (summary.csv: peak_collisions,
    peak_alpha_min, collisions_at_alpha_max, omega_t_col_at_alpha_max).
    """
    if panel in ("b", "c"):
        if summary is None:
            raise ValueError(f"the caption of Fig. 7({panel}) needs the summary of aggregate_fig7")
        summary = summary.set_index("xi")
    by_xi = curves(sweep, fig7["xis"])
    xis = list(by_xi)
    xi_list = ", ".join(f"{xi:g}" for xi in xis)
    data = {"xi_list": xi_list}
    if panel == "a":
        if minima is None:
            raise ValueError("the caption of Fig. 7(a) needs the minima table of aggregate_fig7")
        minima = {xi: minima[minima["xi"] == xi].sort_values("minimum") for xi in by_xi}
        first = {xi: m.iloc[0] for xi, m in minima.items() if len(m)}
        second = {xi: m.iloc[1] for xi, m in minima.items() if len(m) > 1}
        low = {xi: c.iloc[0] for xi, c in by_xi.items()}
        low_cor = [float(low[xi]["cor"]) for xi in xis]
        rising = all(b > a for a, b in zip(low_cor, low_cor[1:], strict=False))
        falling = all(b < a for a, b in zip(low_cor, low_cor[1:], strict=False))
        # Above the largest first minimum: on a common log grid, where is COR falling with xi?
        start = max(float(first[xi]["alpha"]) for xi in first)
        grid = np.geomspace(start * 1.0001, fig7["alpha_max"], 2000)
        values = np.array(
            [np.interp(np.log(grid), np.log(c["alpha"]), c["cor"]) for c in by_xi.values()]
        )
        ordered = np.all(np.diff(values, axis=0) < 0, axis=0)
        data.update(
            alpha_low=_fmt(low[xis[0]]["alpha"]),
            low_values=", ".join(_fmt(v) for v in low_cor),
            low_trend="rises" if rising else ("falls" if falling else "is not monotonic"),
            first_minima=", ".join(
                f"{_fmt(first[xi]['alpha'])} (COR {_fmt(first[xi]['cor'], 2)})" for xi in first
            ),
            first_min_max=_fmt(start),
            second_minima=", ".join(_fmt(second[xi]["alpha"]) for xi in second),
            second_xis=", ".join(f"{xi:g}" for xi in second),
            second_trend="moves to smaller alpha"
            if all(
                b < a
                for a, b in zip(
                    [second[x]["alpha"] for x in second],
                    [second[x]["alpha"] for x in second][1:],
                    strict=False,
                )
            )
            else "does not move monotonically",
            ordered_share=f"{100 * ordered.mean():.0f}%",
        )
    elif panel == "b":
        rows = summary.loc[xis]
        parts = [
            f"{int(r.peak_collisions)} at alpha = {_fmt(r.peak_alpha_min)} (xi = {xi:g})"
            for xi, r in rows.iterrows()
        ]
        ends = [str(int(n)) for n in rows["collisions_at_alpha_max"]]
        peaks = [int(n) for n in rows["peak_collisions"]]
        steps = np.diff(peaks)
        data.update(
            peaks="; ".join(parts),
            ends=", ".join(ends),
            peak_word="falls"
            if np.all(steps < 0)
            else "rises"
            if np.all(steps > 0)
            else "does not change monotonically",
        )
        data.update(count_order(by_xi, fig7))
        data.update(zoom_lo=f"{ZOOM_ALPHA[0]:g}", zoom_hi=f"{ZOOM_ALPHA[1]:g}",
                    zoom_offset=f"{ZOOM_OFFSET:g}")  # fmt: skip
    elif panel == "c":
        hi = float(fig7["alpha_max"])
        lo = hi / 10
        slopes = fitted_slopes(by_xi, fig7)
        mean = float(np.mean(slopes))
        # Where omega t_col falls between its jumps (grid steps at the same contact count).
        single, jumps, falls_small, falls_large = [], [], [], []
        for c in by_xi.values():
            a = c["alpha"].to_numpy()
            t = c["omega_t_col"].to_numpy()
            n = c["n_collisions"].to_numpy()
            j = int(np.argmax(n > 1))
            single.append(float(t[:j].min()) if j > 0 else float("nan"))
            jumps.append(float(a[j]))
            same = n[1:] == n[:-1]
            fall = t[1:] < t[:-1]
            small = same & (a[1:] >= 1.0) & (a[1:] < 10.0)
            large = same & (a[1:] >= lo)
            falls_small.append(f"{100 * fall[small].mean():.0f}%" if small.any() else "-")
            falls_large.append(f"{100 * fall[large].mean():.0f}%" if large.any() else "-")
        first = min(float(c["omega_t_col"].iloc[0]) for c in by_xi.values())
        last = [float(t) for t in summary.loc[xis, "omega_t_col_at_alpha_max"]]
        data.update(
            fit_lo=f"{lo:g}",
            fit_hi=f"{hi:g}",
            slopes=", ".join(f"{v:.2f}" for v in slopes),
            slope_word=(
                "close to one half, so omega t_col grows about as the square root of alpha, "
                "not linearly"
                if abs(mean - 0.5) < 0.1
                else (
                    "close to one: about linear"
                    if abs(mean - 1) < 0.1
                    else "neither one half nor one"
                )
            ),
            t_single=", ".join(_fmt(v, 2) for v in single),
            first_jumps=", ".join(_fmt(v) for v in jumps),
            falls_small=", ".join(falls_small),
            falls_large=", ".join(falls_large),
            t_first=_fmt(first, 2),
            t_last=", ".join(_fmt(v) for v in last),
        )
    return data


def main(
    sweep_path, png_path, pdf_path, params, logger, smk=None, minima_path=None, summary_path=None
):

    from restitution import plotting
    from restitution.tables.io import read_table

    # The rule passes the figure name ("fig7c"): a bare letter would be a prefix of input paths
    # such as config/paper_values.yaml, which snakemake --lint reports.
    panel = params.panel.removeprefix("fig7")
    if panel not in PANELS:
        raise ValueError(f"panel must be one of fig7{sorted(PANELS)}, got {params.panel!r}")
    sweep = read_table(sweep_path)
    missing = sorted(set(map(float, params.fig7["xis"])) - set(sweep["xi"].unique()))
    if missing:
        raise ValueError(f"{sweep_path}: no rows for xi = {missing}")
    fig = draw(sweep, panel, params.fig7, logger)
    plotting.save_outputs(fig, png_path, pdf_path, logger)
    if smk is not None:
        from render_caption import write_caption

        minima = summary = None
        if minima_path is not None:
            minima = read_table(minima_path, columns=("xi", "minimum", "alpha", "cor"))
        if summary_path is not None:
            summary = read_table(summary_path, columns=("xi", "peak_collisions"))
        write_caption(smk, caption_data(sweep, panel, params.fig7, minima, summary), logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(
            snakemake.input.sweep,  # noqa: F821
            snakemake.output.png,  # noqa: F821
            snakemake.output.pdf,  # noqa: F821
            snakemake.params,  # noqa: F821
            log,
            snakemake,  # noqa: F821
            snakemake.input.get("minima"),  # noqa: F821
            snakemake.input.get("summary"),  # noqa: F821
        )
