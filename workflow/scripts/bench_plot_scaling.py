"""Scaling diagrams: time per scene vs alpha (with the contact count), vs chain length N, and the
solve_many sweep time vs number of scenes on 1 and 2 threads; fitted exponents in the legends.
"""

import numpy as np

# A method or a thread count is none of beta, xi, alpha: black and a grey with its own marker and
# line style (restitution.plotting's rule), never a parameter's colour.
FIRST = dict(color="black", marker="o", ls="-")
OTHER = dict(color="#6E6E6E", marker="s", mfc="white", ls=(0, (4, 1.5)))


def _label(fits, kind, family, threads=1, quantity="time_s"):
    f = fits[
        (fits["kind"] == kind)
        & (fits["family"] == family)
        & (fits["threads"] == threads)
        & (fits["quantity"] == quantity)
    ]
    if f.empty or not np.isfinite(f["exponent"].iloc[0]):
        return ""
    return rf" ($\propto x^{{{f['exponent'].iloc[0]:.2f}}}$)"


POINTS = dict(ms=3, lw=0.8)  # every measured series: points joined by thin lines


def draw(table, fits):
    from restitution import plotting

    fig = plotting.new_figure("double", aspect=0.3)
    ax_a, ax_n, ax_s = fig.subplots(1, 3)
    ok = table[table["status"] == "ok"]
    a = ok[ok["kind"] == "alpha"]
    for family, g in a.groupby("family"):
        ax_a.plot(
            g["x"],
            g["time_s"],
            **POINTS,
            **(FIRST if family == "exact" else OTHER),
            label=f"{family}{_label(fits, 'alpha', family)}",
        )
    ex = a[a["family"] == "exact"]
    twin = ax_a.twinx()
    twin.plot(
        ex["x"],
        ex["n_collisions"],
        ls=":",
        color="0.5",
        lw=0.8,
        label=f"contacts{_label(fits, 'alpha', 'exact', quantity='n_collisions')}",
    )
    twin.set_yscale("log")
    twin.set_ylabel("contacts", color="0.4")
    ax_a.set_xlabel(r"mass ratio $\alpha$")
    ax_a.set_ylabel("time per scene (s)")
    lines = ax_a.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    ax_a.legend(lines[0] + more[0], lines[1] + more[1], loc="best")
    c = ok[ok["kind"] == "chain"]
    ax_n.plot(
        c["x"],
        c["time_s"],
        **POINTS,
        **FIRST,
        label=f"exact{_label(fits, 'chain', 'exact')}",
    )
    ax_n.set_xlabel("number of masses N")
    ax_n.legend(loc="best")
    s = table[table["kind"] == "sweep"]
    for threads, g in s.groupby("threads"):
        ax_s.plot(
            g["x"],
            g["time_s"],
            **POINTS,
            **(FIRST if threads == 1 else OTHER),
            label=f"{threads} thread(s){_label(fits, 'sweep', 'solve_many', threads)}",
        )
    ax_s.set_xlabel("scenes in one solve_many call")
    ax_s.set_ylabel("time per sweep (s)")
    ax_s.legend(loc="best")
    for ax in (ax_a, ax_n, ax_s):
        plotting.log_axis(ax, "x")
        ax.set_yscale("log")
        ax.grid(True, which="major", lw=0.3, color="0.85")
    return fig


def main(table_path, fits_path, png_path, pdf_path, logger):
    from restitution import plotting
    from restitution.tables.io import read_table

    fig = draw(read_table(table_path), read_table(fits_path))
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
        )
