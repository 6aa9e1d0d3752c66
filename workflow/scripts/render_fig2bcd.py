"""Render Fig. 2(b), 2(c) or 2(d) (``params.panel``: fig2b, ...) from the results/approx tables.

- 2(b): omega t_col / 2 pi and the number of contacts against alpha (from the Fig. 2(a) sweep),
  with the exact unity points alpha#_n and Eq. 19 (paper p = 0.8 and our fit); a third panel
  collects the minima e*_n against alpha*_n with the law e* = (alpha* - c)/(1 + alpha*).
- 2(c): alpha*_n - alpha#_n against n with Eq. 22 (paper q = 0.21 and our fits), residual panel.
- 2(d): exact, paper-approximate and improved-approximate COR, with an error panel.
"""

import json

import numpy as np
import pandas as pd


def small_alpha_limit(alpha, beta):
    """omega t_col / 2 pi of a single contact as alpha -> 0: (1/2) sqrt(beta (1 + alpha)/alpha).

    m1 bounces alone on k1 for half a period pi sqrt(m1/k1); omega^2 = k2 (1 + alpha)/(alpha m1).
    """
    alpha = np.asarray(alpha, dtype=float)
    return 0.5 * np.sqrt(beta * (1 + alpha) / alpha)


def limit_check(sweep) -> pd.DataFrame:
    """Per finite beta: the smallest alpha of the sweep and omega t_col / 2 pi over the limit."""
    rows = []
    for beta in sorted(b for b in sweep["beta"].unique() if b > 0):
        c = sweep[(sweep["beta"] == beta) & (sweep["status"] == "ok")].sort_values("alpha")
        first = c.iloc[0]
        ratio = first["omega_t_col"] / (2 * np.pi) / small_alpha_limit(first["alpha"], beta)
        rows.append({"beta": beta, "alpha": float(first["alpha"]), "ratio": float(ratio)})
    return pd.DataFrame(rows, columns=["beta", "alpha", "ratio"])


def fig2b(sweep, points, fit, plot):
    from restitution import plotting

    fig = plotting.new_figure("single", aspect=1.75)
    ax1, ax2, ax3 = fig.subplots(
        3, 1, sharex=True, gridspec_kw={"hspace": 0.08, "height_ratios": [1.3, 1, 1]}
    )
    betas = sorted(sweep["beta"].unique())
    a = np.geomspace(plot["alpha_min"], plot["alpha_max"], 400)
    for beta in betas:
        c = sweep[(sweep["beta"] == beta) & (sweep["status"] == "ok")].sort_values("alpha")
        colour = plotting.beta_colour(beta, betas)
        t = (c["omega_t_col"] / (2 * np.pi)).where(c["omega_t_col"] > 0)  # log axis: no zeros
        ax1.plot(c["alpha"], t, color=colour, lw=0.8, label=plotting.beta_text(beta))
        if beta > 0:
            ax1.plot(a, small_alpha_limit(a, beta), color=colour, lw=0.6, ls=(0, (2, 2)),
                     label="_" + plotting.beta_text(beta))  # fmt: skip
        if beta == 0:
            # The exact count is the reference the laws are read against: a grey band, so the
            # staircase and the fitted law (black) never share a style.
            ax2.step(c["alpha"], c["n_collisions"], where="post", **plotting.REFERENCE_STYLE,
                     label=r"exact count, $\beta = 0$", zorder=1)  # fmt: skip
    ax1.plot([], [], color="0.3", lw=0.6, ls=(0, (2, 2)),
             label=r"$\frac{1}{2}\sqrt{\beta(1+\alpha)/\alpha}$ ($\alpha \to 0$)")  # fmt: skip
    ax1.set_ylabel(plotting.T_COL_LABELS["2pi"])
    plotting.log_axis(ax1, "y")
    ax1.set_ylim(1e-2, None)
    ax1.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    a = np.geomspace(plot["alpha_min"], plot["alpha_max"], 400)
    p = fit["fits"]["eq19_unity"]["params"]["p"]
    sel = (points["alpha_unity"] >= plot["alpha_min"]) & (
        points["alpha_unity"] <= plot["alpha_max"]
    )
    role = plotting.ROLE_STYLES
    ax2.plot(points["alpha_unity"][sel], points["n"][sel], **role["exact"],
             label=r"unity points $\alpha^\#_n$")  # fmt: skip
    ax2.plot(a, 1 + a**p, **role["fit"], label=rf"Eq. 19, $p = {p:.4f}$ (fit)")
    ax2.plot(a, 1 + a**0.8, **role["paper"], label=r"Eq. 19, $p = 0.8$ (paper)", zorder=3)
    plotting.log_axis(ax2, "y")
    ax2.set_ylabel("number of contacts $n$")
    ax2.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    c_fit = fit["fits"]["minima_c_n1"]["params"]["c"]
    sel = (points["alpha_star"] >= plot["alpha_min"]) & (points["alpha_star"] <= plot["alpha_max"])
    ax3.plot(points["alpha_star"][sel], points["e_star"][sel], **role["exact"],
             label=r"minima $(\alpha^*_n, e^*_n)$")  # fmt: skip
    ax3.plot(a, (a - 0.4) / (1 + a), **role["paper"],
             label=r"$(\alpha^* - 0.4)/(1 + \alpha^*)$ (paper)")  # fmt: skip
    ax3.plot(a, (a - c_fit) / (1 + a), **role["fit"], label=rf"$c = {c_fit:.3f}$ (fit)")
    ax3.set_ylim(0, 1.02)
    ax3.set_ylabel(r"COR minima $e^*_n$")
    ax3.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    plotting.log_axis(ax3, "x")
    ax3.set_xlim(plot["alpha_min"], plot["alpha_max"])
    ax3.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    return fig


def fig2c(residuals, fit):
    from restitution import plotting

    fig = plotting.new_figure("onehalf", aspect=0.7)
    ax1, ax2 = fig.subplots(
        2, 1, sharex=True, gridspec_kw={"height_ratios": [2.2, 1], "hspace": 0.08}
    )
    n = residuals["n"].to_numpy(dtype=float)
    gap = residuals["gap"].to_numpy()
    q = fit["fits"]["eq22_gap_n1"]["params"]["q"]
    qs = fit["fits"]["eq22_gap_scaled_n2"]["params"]
    nn = np.linspace(1, n.max(), 400)
    role = plotting.ROLE_STYLES
    ax1.plot(n, gap, **role["exact"], label="exact")
    ax1.plot(nn, nn**q, **role["fit"], label=rf"$n^{{{q:.4f}}}$ (fit)")
    ax1.plot(nn, nn**0.21, **role["paper"], label=r"$n^{0.21}$ (paper)", zorder=3)
    ax1.plot(nn, qs["A"] * nn ** qs["q"], **role["fit_alt"],
             label=rf"${qs['A']:.3f}\,n^{{{qs['q']:.4f}}}$ (fit, $n \geq 2$)")  # fmt: skip
    ax1.set_ylabel(r"$\alpha^*_n - \alpha^\#_n$")
    ax1.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    ax2.axhline(0, color="0.6", lw=0.5)
    ax2.plot(n, n**0.21 - gap, marker="o", ms=2, mfc="white", lw=0.6, color=role["paper"]["color"],
             ls=role["paper"]["ls"], label="paper law - exact")  # fmt: skip
    ax2.plot(n, n**q - gap, marker="s", ms=2, lw=0.6, color=role["fit"]["color"],
             label="fitted law - exact")  # fmt: skip
    ax2.set_ylabel("residual")
    ax2.set_xlabel("number of contacts $n$")
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter

    ax2.set_xscale("log")
    ticks = [t for t in (1, 2, 5, 10, 20, 50, 100, 200, 500) if t <= n.max()]
    ax2.xaxis.set_major_locator(FixedLocator(ticks))
    ax2.xaxis.set_major_formatter(FuncFormatter(lambda v, _p: f"{v:g}"))
    ax2.xaxis.set_minor_formatter(NullFormatter())
    ax2.set_xlim(0.9, n.max() * 1.1)
    ax2.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return fig


def fig2d(curves, errors, plot):
    from restitution import plotting

    fig = plotting.new_figure("onehalf", aspect=0.85)
    ax1, ax2 = fig.subplots(
        2, 1, sharex=True, gridspec_kw={"height_ratios": [1.6, 1], "hspace": 0.08}
    )
    c = curves[(curves["alpha"] >= plot["alpha_min"]) & (curves["alpha"] <= plot["alpha_max"])]
    e = {r.model: r for r in errors.itertuples()}
    role = plotting.ROLE_STYLES
    # The paper's model read two ways below alpha*_1: Eq. 21 literally (its falling branch from
    # alpha = 0) or the exact single-contact branch (1 - alpha)/(1 + alpha) of Eq. 1 there.
    styles = [
        ("paper", role["paper"], r"paper, Eq. 21 below $\alpha^*_1$"),
        ("paper_exact_first_branch", role["paper_alt"], r"paper, Eq. 1 below $\alpha^*_1$"),
        ("improved", role["fit"], "improved (sqrt cusp)"),
    ]
    ax1.plot(c["alpha"], c["exact"], **plotting.REFERENCE_STYLE, label="exact", zorder=1)
    for name, style, text in styles:
        ax1.plot(c["alpha"], c[name], **{**style, "lw": 0.8}, label=text, zorder=2)
    ax1.set_ylim(0, 1.02)
    ax1.set_ylabel(plotting.COR_LABEL)
    ax1.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    styles_err = styles + [
        ("improved_universal", role["fit_alt"], "improved, one shape for all $n$")
    ]
    for name, style, text in styles_err:
        err = np.abs(c[name] - c["exact"]).clip(lower=1e-12)
        ax2.plot(c["alpha"], err, **{**style, "lw": 0.7},
                 label=f"{text}: max {e[name].max_abs_error:.1e}")  # fmt: skip
    ax2.set_yscale("log")
    ax2.set_ylim(1e-8, 1)
    ax2.set_ylabel("|approx - exact|")
    ax2.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), ncols=1)
    plotting.log_axis(ax2, "x")
    ax2.set_xlim(plot["alpha_min"], plot["alpha_max"])
    ax2.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
    return fig


def caption_data(panel, inp, fit) -> dict:
    """Numbers of the caption of ``panel`` from the tables just drawn."""
    from restitution.tables.io import read_table

    fits = fit["fits"]
    if panel == "b":
        check = limit_check(read_table(inp.sweep))
        worst = float((check["ratio"] - 1).abs().max()) if len(check) else float("nan")
        return {
            "p_fit": f"{fits['eq19_unity']['params']['p']:.4f}",
            "c_fit": f"{fits['minima_c_n1']['params']['c']:.3f}",
            "limit_alpha": f"{check['alpha'].min():g}" if len(check) else "-",
            "limit_ratios": ", ".join(f"{r:.4f}" for r in check["ratio"]),
            "limit_betas": ", ".join(f"{b:g}" for b in check["beta"]),
            "limit_worst": f"{100 * worst:.1f}%",
        }
    if panel == "c":
        qs = fits["eq22_gap_scaled_n2"]["params"]
        return {
            "n_plotted": int(read_table(inp.residuals)["n"].max()),
            "q_fit": f"{fits['eq22_gap_n1']['params']['q']:.4f}",
            "A_fit": f"{qs['A']:.3f}",
            "q2_fit": f"{qs['q']:.4f}",
        }
    from restitution.analysis.approx import PAPER

    errors = read_table(inp.errors).set_index("model")
    curves = read_table(inp.curves)
    below = curves[curves["alpha"] < PAPER["alpha_star_1"]]
    eq1_below = (below["paper_exact_first_branch"] - below["exact"]).abs().max()
    paper = float(errors.loc["paper", "max_abs_error"])
    eq1 = errors.loc["paper_exact_first_branch"]
    improved = float(errors.loc["improved", "max_abs_error"])
    universal = float(errors.loc["improved_universal", "max_abs_error"])
    return {
        "paper_max": f"{paper:.2f}",
        "paper_max_alpha": f"{float(errors.loc['paper', 'alpha_at_max']):.3g}",
        "eq1_max": f"{float(eq1['max_abs_error']):.2f}",
        "eq1_max_alpha": f"{float(eq1['alpha_at_max']):.3g}",
        "eq1_ratio": f"{float(eq1['max_abs_error']) / improved:.0f}",
        "alpha_star_1": f"{PAPER['alpha_star_1']:g}",
        "below_lo": f"{float(below['alpha'].min()):.3g}",
        "below_paper": f"{float((below['paper'] - below['exact']).abs().max()):.2f}",
        "below_eq1": "0 (exact there)" if eq1_below == 0 else f"{float(eq1_below):.1e}",
        "improved_max": f"{improved:.1e}",
        "ratio": f"{paper / improved:.0f}",
        "universal_max": f"{universal:.1e}",
        "universal_ratio": f"{paper / universal:.0f}",
    }


def main(inp, out, params, logger, smk=None):

    from restitution import plotting
    from restitution.tables.io import read_table

    plot = {
        "alpha_min": params.approx["plot_alpha_min"],
        "alpha_max": params.approx["plot_alpha_max"],
    }
    with open(inp.fit) as fh:
        fit = json.load(fh)
    # The rule passes the figure name ("fig2c"): a bare letter would be a prefix of input paths
    # such as config/paper_values.yaml, which snakemake --lint reports.
    panel = params.panel.removeprefix("fig2")
    if panel == "b":
        sweep = read_table(inp.sweep)
        fig = fig2b(sweep, read_table(inp.points), fit, plot)
    elif panel == "c":
        fig = fig2c(read_table(inp.residuals), fit)
    elif panel == "d":
        fig = fig2d(read_table(inp.curves), read_table(inp.errors), plot)
    else:
        raise ValueError(f"unknown panel {params.panel!r}; expected 'b', 'c' or 'd'")
    plotting.save_outputs(fig, out.png, out.pdf, logger)
    if smk is not None:
        from render_caption import write_caption

        write_caption(smk, caption_data(panel, inp, fit), logger)


if __name__ == "__main__":
    from _common import Timer, setup

    smk = snakemake  # noqa: F821 (injected by Snakemake)
    log = setup(smk, numba=False)
    with Timer(log, f"render {smk.params.panel}"):
        main(smk.input, smk.output, smk.params, log, smk)
