"""Scaling diagrams: time per scene vs alpha (with the contact count), vs chain length N, and the
solve_many sweep time vs number of scenes on 1 and 2 threads. solve_ivp is timed at matched
accuracy (the loosest rtol within ``match_error`` of the exact COR; hollow where none is). Each
fitted power law is drawn over its fit range, its exponent +- standard error and range in the
legend.
"""

import math

import numpy as np

# A method or a thread count is none of beta, xi, alpha: black and a grey with its own marker and
# line style (restitution.plotting's rule), never a parameter's colour.
FIRST = dict(color="black", marker="o", ls="-")
OTHER = dict(color="#6E6E6E", marker="s", mfc="white", ls=(0, (4, 1.5)))


def _fit(fits, kind, family, threads=1, quantity="time_s"):
    f = fits[
        (fits["kind"] == kind)
        & (fits["family"] == family)
        & (fits["threads"] == threads)
        & (fits["quantity"] == quantity)
    ]
    if f.empty or not np.isfinite(f["exponent"].iloc[0]):
        return None
    return f.iloc[0]


def _range(value: float) -> str:
    """A fit-range end: plain below 1000, a power of ten as 10^k, else 3 digits."""
    if value >= 1000:
        k = math.log10(value)
        return rf"$10^{{{round(k)}}}$" if abs(k - round(k)) < 1e-9 else f"{value:.3g}"
    return f"{value:g}"


def _label(fits, kind, family, threads=1, quantity="time_s"):
    """Legend text of a fitted power law: exponent, its standard error and the fit range."""
    f = _fit(fits, kind, family, threads, quantity)
    if f is None:
        return ""
    power = rf"$\propto x^{{{f['exponent']:.2f} \pm {f['stderr']:.2f}}}$"
    return "\n" + f"{power}, fit {_range(f['x_min'])}..{_range(f['x_max'])}"


def _fit_line(ax, fits, kind, family, threads=1, quantity="time_s", **style):
    """The fitted power law drawn over its fit range (thin, grey, dashed)."""
    f = _fit(fits, kind, family, threads, quantity)
    if f is None:
        return
    x = np.geomspace(f["x_min"], f["x_max"], 50)
    ax.plot(x, f["prefactor"] * x ** f["exponent"], **{**FIT, **style}, label="_fit")


IVP_WORD = "solve_ivp timed at matched accuracy:"
#: Each panel's legend below its axes (inside, the long fit texts would cover the data).
BELOW = dict(loc="upper left", bbox_to_anchor=(0.0, -0.2), fontsize=7, frameon=False)
POINTS = dict(ms=3, lw=0.8)  # every measured series: points joined by thin lines
FIT = dict(color="0.55", lw=2.2, ls="-", alpha=0.45, zorder=1)  # fitted law under the points


def draw(table, fits, match_error=None):
    from matplotlib.lines import Line2D

    from restitution import plotting

    fig = plotting.new_figure("double", aspect=0.5)
    ax_a, ax_n, ax_s = fig.subplots(1, 3)
    ok = table[table["status"] == "ok"]
    a = table[table["kind"] == "alpha"]
    for family, g in a.groupby("family"):
        style = FIRST if family == "exact" else OTHER
        good = g[g["status"] == "ok"]
        ax_a.plot(good["x"], good["time_s"], **POINTS, **style,
                  label=f"{family}{_label(fits, 'alpha', family)}")  # fmt: skip
        bad = g[g["status"] != "ok"]
        if len(bad):  # not matched (or failed): hollow, unjoined
            ax_a.plot(bad["x"], bad["time_s"], ls="none", marker=style["marker"], ms=4,
                      color=style["color"], mfc="white", label="_unmatched")  # fmt: skip
        _fit_line(ax_a, fits, "alpha", family)
    ex = ok[(ok["kind"] == "alpha") & (ok["family"] == "exact")]
    twin = ax_a.twinx()
    contacts = _label(fits, "alpha", "exact", quantity="n_collisions")
    twin.plot(ex["x"], ex["n_collisions"], ls=":", color="0.5", lw=0.8,
              label=f"contacts{contacts}")  # fmt: skip
    twin.set_yscale("log")
    twin.set_ylabel("contacts", color="0.4")
    ax_a.set_xlabel(r"mass ratio $\alpha$")
    ax_a.set_ylabel("time per scene (s)")
    if match_error is not None:
        ax_a.set_title(rf"{IVP_WORD} |COR error| $\leq$ {match_error:g}", fontsize=7)
    lines = ax_a.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    handles = lines[0] + more[0] + [Line2D([], [], **FIT)]
    labels = lines[1] + more[1] + ["power-law fit over its range"]
    if (a["status"] != "ok").any():
        handles.append(Line2D([], [], ls="none", marker="s", ms=4, color=OTHER["color"],
                              mfc="white"))  # fmt: skip
        labels.append("no rtol matched (hollow)")
    ax_a.legend(handles, labels, **BELOW)
    c = ok[ok["kind"] == "chain"]
    ax_n.plot(c["x"], c["time_s"], **POINTS, **FIRST,
              label=f"exact{_label(fits, 'chain', 'exact')}")  # fmt: skip
    _fit_line(ax_n, fits, "chain", "exact")
    ax_n.set_xlabel("number of masses N")
    ax_n.set_ylabel("time per scene (s)")
    ax_n.legend(**BELOW)
    s = table[table["kind"] == "sweep"]
    for threads, g in s.groupby("threads"):
        fitted = _label(fits, "sweep", "solve_many", threads)
        ax_s.plot(g["x"], g["time_s"], **POINTS, **(FIRST if threads == 1 else OTHER),
                  label=f"{threads} thread(s){fitted}")  # fmt: skip
        _fit_line(ax_s, fits, "sweep", "solve_many", threads)
    ax_s.set_xlabel("scenes in one solve_many call")
    ax_s.set_ylabel("time per sweep (s)")
    ax_s.legend(**BELOW)
    for ax in (ax_a, ax_n, ax_s):
        plotting.log_axis(ax, "x")
        ax.set_yscale("log")
        ax.grid(True, which="major", lw=0.3, color="0.85")
    return fig


def main(table_path, fits_path, png_path, pdf_path, logger, match_error=None):
    from restitution import plotting
    from restitution.tables.io import read_table

    fig = draw(read_table(table_path), read_table(fits_path), match_error)
    plotting.save_outputs(fig, png_path, pdf_path, logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(
            snakemake.input.table,  # noqa: F821
            snakemake.input.exponents,  # noqa: F821
            snakemake.output.png,  # noqa: F821
            snakemake.output.pdf,  # noqa: F821
            log,
            match_error=snakemake.params.match_error,  # noqa: F821
        )
