"""The house rules of every figure, read from the figures' artists (restitution.plotting):

- text at least MIN_TEXT_PT points at the printed size (tick labels, legends, titles, insets);
- one colour, one meaning: an artist that names a beta, xi or alpha (its label) has that value's
  colour, one value has one colour in every figure, and anything else (a design family, a solver,
  a kind of curve) takes no colour of those sets.

save_outputs applies audit_figure to every figure the workflow writes, so a render that breaks a
rule fails its job; here the audit itself is checked, and render functions are run on small
synthetic tables and their artists read back.
"""

import logging
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import load_script
from restitution import plotting

LOG = logging.getLogger("test_figure_rules")


_load = load_script


render_fig7 = _load("render_fig7")
aggregate_fig7 = _load("aggregate_fig7")
render_fig8b = _load("render_fig8b")
workprecision = _load("bench_plot_workprecision")
scaling_plot = _load("bench_plot_scaling")


# --- the audit -----------------------------------------------------------------------------------


def test_named_values_reads_the_house_labels():
    assert plotting.named_values(plotting.beta_text(1e-3)) == [("beta", 1e-3)]
    assert plotting.named_values(plotting.beta_text(0.0)) == [("beta", 0.0)]
    assert plotting.named_values(r"_$\xi = 1.2$") == [("xi", 1.2)]
    assert plotting.named_values(r"mass ratio $\alpha = m_2/m_1$") == []
    assert plotting.named_values(r"$(\alpha^* - 0.4)/(1 + \alpha^*)$ (paper)") == []


def test_audit_flags_text_below_the_minimum():
    fig = plotting.new_figure()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], color="black", label="a")
    ax.legend(fontsize="x-small")  # 0.694 x 8 pt = 5.6 pt
    problems = plotting.audit_figure(fig)
    assert any("'a' is 5.6 pt" in p for p in problems), problems
    ax.legend(fontsize=7)
    assert plotting.audit_figure(fig) == []


def test_audit_flags_small_tick_labels_of_an_inset():
    fig = plotting.new_figure()
    ax = fig.add_subplot()
    inset = ax.inset_axes([0.6, 0.6, 0.3, 0.3])
    inset.tick_params(labelsize=5)
    assert any("5 pt" in p for p in plotting.audit_figure(fig))


def test_audit_flags_a_family_in_a_parameter_colour():
    fig = plotting.new_figure()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], color=plotting.BETA_COLOURS[1e-3], label="free masses")
    problems = plotting.audit_figure(fig)
    assert len(problems) == 1 and "names no beta" in problems[0], problems


def test_audit_flags_a_value_in_another_values_colour():
    fig = plotting.new_figure()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], color=plotting.xi_colour(0.1), label=r"$\xi = 0.3$")
    problems = plotting.audit_figure(fig)
    assert len(problems) == 1 and "xi = 0.3" in problems[0], problems
    ax.lines[0].set_color(plotting.xi_colour(0.3))
    assert plotting.audit_figure(fig) == []


def test_audit_reads_hidden_labels_and_fills():
    """An unlabelled fill in a xi colour breaks the rule; a hidden "_" label that names the xi
    keeps it (Fig. 7(d)'s envelopes)."""
    fig = plotting.new_figure()
    ax = fig.add_subplot()
    ax.fill_between([0, 1], [0, 0], [1, 1], color=plotting.xi_colour(3.0), alpha=0.35)
    assert any("names no xi" in p for p in plotting.audit_figure(fig))
    ax.collections[0].set_label(r"_$\xi = 3$")
    assert plotting.audit_figure(fig) == []


def test_save_outputs_refuses_a_figure_that_breaks_a_rule(tmp_path):
    fig = plotting.new_figure()
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], color=plotting.ALPHA_COLOURS[2.5], label=r"$\beta = 0.1$")
    with pytest.raises(plotting.FigureRuleError, match="beta = 0.1"):
        plotting.save_outputs(fig, tmp_path / "f.png", tmp_path / "f.pdf")
    assert not (tmp_path / "f.png").exists()


def test_neutral_styles_take_no_parameter_colour():
    """Reference, role, series and marked styles are black or grey (neutral): never a chromatic
    colour, so never a parameter's."""
    styles = [*plotting.SERIES_STYLES, *plotting.MARKED_STYLES, *plotting.ROLE_STYLES.values(),
              plotting.REFERENCE_STYLE]  # fmt: skip
    for style in styles:
        colour = plotting._hex(style["color"])
        assert not plotting._is_chromatic(colour), style


# --- render functions on small synthetic tables ---------------------------------------------------


def _fig7_sweep(xis=(0.1, 0.3, 1.0, 1.2)):
    alpha = np.geomspace(0.1, 1000, 300)
    rows = []
    for k, xi in enumerate(xis):
        # Second contact at 0.7 + 0.1 k (moves right with xi), later steps earlier with xi.
        n = np.where(alpha < 0.7 + 0.1 * k, 1, 1 + np.floor((alpha / (2.0 - 0.3 * k)) ** 0.8) + 1)
        rows.append(pd.DataFrame(dict(alpha=alpha, xi=xi, cor=0.5 + 0.1 * np.sin(alpha) - 0.01 * k,
                                      n_collisions=n.astype(int), omega_t_col=np.sqrt(alpha),
                                      status="ok")))  # fmt: skip
    return pd.concat(rows, ignore_index=True)


FIG7 = {"xis": [0.1, 0.3, 1.0, 1.2], "beta": 1e-3, "alpha_min": 0.1, "alpha_max": 1000.0}


def _fig8b_table():
    rows = []
    for family in render_fig8b.STYLE:
        for n in (2, 3, 4):
            rows.append(dict(family=family, n_masses=n, cor=0.2 - 0.01 * n, worst_cor=0.21,
                             status="ok", bound_active=(family == "masses" and n == 4),
                             start="warm", cor_warm=0.2 - 0.01 * n, cor_cold=0.2 - 0.01 * n,
                             restart_spread=0.0))  # fmt: skip
    table = pd.DataFrame(rows)
    # One design whose cold start ended higher (spread shown as a bar).
    i = table.index[(table["family"] == "uniform") & (table["n_masses"] == 3)][0]
    table.loc[i, ["cor_cold", "restart_spread"]] = [0.3, 0.3 - table.loc[i, "cor"]]
    return table


def _workprecision_records():
    rows = []
    for scene in ("a", "b"):
        for family in ("exact", *workprecision.METHODS):
            for setting in (1e-3, 1e-6, 1e-9):
                rows.append(dict(scene=scene, family=family, setting=setting, status="ok",
                                 cor_error=setting, time_s=1 / setting * 1e-6, contacts_ok=True,
                                 reference_bound=1e-12))  # fmt: skip
    table = pd.DataFrame(rows)
    # The loosest RK45 setting of scene "a" has the wrong contact count; exact errors lie in the
    # reference's band (1e-15 < 1e-12).
    wrong = (table["scene"] == "a") & (table["family"] == "RK45") & (table["setting"] == 1e-3)
    table.loc[wrong, "contacts_ok"] = False
    table.loc[table["family"] == "exact", "cor_error"] = 1e-15
    return table


def _figures():
    figs = {f"fig7{p}": render_fig7.draw(_fig7_sweep(), p, FIG7, LOG) for p in "abc"}
    figs["fig8b"] = render_fig8b.draw(_fig8b_table(), None)
    figs["workprecision"] = workprecision.draw(_workprecision_records(), {}, IVP)
    return figs


IVP = {"methods": ["RK45"], "ivp_rtols": [1e-3, 1e-6], "ivp_atol_over_rtol": 1.0,
       "ivp_steps_per_period": 0, "max_events": 100}  # fmt: skip


@pytest.fixture(scope="module")
def figures():
    return _figures()


def test_fig8b_marks_bound_active_designs_hollow_and_shows_restart_spread(figures):
    ax = figures["fig8b"].axes[0]
    marks = [ln for ln in ax.lines if ln.get_linestyle() == "None"]
    hollow = [ln for ln in marks if ln.get_markerfacecolor() in ("white", (1.0, 1.0, 1.0, 1.0))
              and len(ln.get_xdata()) and ln.get_label().endswith("(bound active)")]  # fmt: skip
    # Exactly the one bound-active design (free masses, N = 4) is hollow.
    assert [(list(ln.get_xdata()), list(ln.get_ydata())) for ln in hollow] == [([4], [0.16])]
    # The restart spread: a vertical bar from 0.17 to the other start's 0.3 at N = 3.
    bars = [ln for ln in ax.lines if list(ln.get_xdata()) == [3, 3]]
    assert bars and sorted(bars[0].get_ydata()) == pytest.approx([0.17, 0.3])
    # y-axis on the data (log), not 0..1.
    lo, hi = ax.get_ylim()
    assert ax.get_yscale() == "log" and 0.16 / 1.2 < lo < 0.16 and 0.3 < hi < 0.3 * 1.2


def test_workprecision_invalid_points_hollow_unjoined_and_in_band_as_upper_limits(figures):
    ax = figures["workprecision"].axes[0]  # scene "a"
    rk45 = [ln for ln in ax.lines if ln.get_label() == "RK45"][0]
    # The joined line holds only the two valid settings (1e-6, 1e-9), not the wrong-count one.
    assert sorted(rk45.get_xdata()) == pytest.approx([1e-9, 1e-6])
    wrong = [ln for ln in ax.lines if ln.get_label() == "_wrong contact count"]
    assert len(wrong) == 1 and list(wrong[0].get_xdata()) == pytest.approx([1e-3])
    assert wrong[0].get_linestyle() == "None" and wrong[0].get_markerfacecolor() == "white"
    # Exact errors (1e-15) inside the band (1e-12) are drawn at the bound with an upper-limit
    # arrow, never at the measured value.
    exact = [ln for ln in ax.lines if ln.get_label() == "exact"][0]
    assert set(exact.get_xdata()) == {1e-12}
    assert any(c.get_label() == "_upper limit" for c in ax.containers)
    # The baseline's settings are stated on the figure.
    title = figures["workprecision"].legends[0].get_title().get_text()
    assert "no max_step" in title and "RK45" in title and "atol = 1 rtol" in title


def test_scaling_plot_draws_fit_lines_over_their_ranges():
    table = pd.DataFrame([
        dict(kind="alpha", family=f, x=x, threads=1, n_scenes=1, n_collisions=int(x),
             time_s=x * (1e-6 if f == "exact" else 1e-3), status="ok")
        for f in ("exact", "DOP853") for x in (1.0, 10.0, 100.0)
    ] + [dict(kind="alpha", family="DOP853", x=1000.0, threads=1, n_scenes=1, n_collisions=1000,
              time_s=1.0, status="not_matched")] + [
        dict(kind=k, family=f, x=x, threads=1, n_scenes=1, n_collisions=1, time_s=x * 1e-5,
             status="ok")
        for k, f in (("chain", "exact"), ("sweep", "solve_many")) for x in (2.0, 8.0, 32.0)
    ])  # fmt: skip
    fits = pd.DataFrame([dict(kind="alpha", family=f, threads=1, quantity="time_s", exponent=1.0,
                              stderr=0.01, prefactor=p, x_min=10.0, x_max=100.0, n_points=2)
                         for f, p in (("exact", 1e-6), ("DOP853", 1e-3))])  # fmt: skip
    fig = scaling_plot.draw(table, fits, match_error=1e-6)
    ax = fig.axes[0]
    lines = [ln for ln in ax.lines if ln.get_label() == "_fit"]
    assert len(lines) == 2
    for ln in lines:
        assert min(ln.get_xdata()) == pytest.approx(10.0) and max(ln.get_xdata()) == 100.0
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("fit 10..100" in t for t in labels)  # the fit range in the legend
    # The unmatched point: hollow, unjoined; the joined DOP853 line stops at alpha = 100.
    joined = [ln for ln in ax.lines if ln.get_label().startswith("DOP853")][0]
    assert max(joined.get_xdata()) == 100.0
    hollow = [ln for ln in ax.lines if ln.get_label() == "_unmatched"]
    assert list(hollow[0].get_xdata()) == [1000.0] and hollow[0].get_markerfacecolor() == "white"
    assert "matched accuracy" in ax.get_title()
    assert plotting.audit_figure(fig) == []


@pytest.mark.parametrize("name", ["fig7a", "fig7b", "fig7c", "fig8b", "workprecision"])
def test_rendered_figure_keeps_the_rules(figures, name):
    assert plotting.audit_figure(figures[name]) == []


def test_one_value_one_colour_across_figures(figures):
    """Every artist that names a parameter value has one colour for it in all figures, and the
    families and methods (they name none) use none of the parameter colours."""
    seen = {}
    for fig in figures.values():
        for ax in fig.axes:
            for artist in [*ax.lines, *ax.collections]:
                colours = {c for c in plotting._artist_colours(artist) if plotting._is_chromatic(c)}
                for key in plotting.named_values(artist.get_label()):
                    seen.setdefault(key, set()).update(colours)
    assert {k for k in seen if k[0] == "xi"} == {("xi", xi) for xi in FIG7["xis"]}
    for key, colours in seen.items():
        assert len(colours) == 1, (key, colours)


def test_fig7b_counts_are_drawn_on_a_log_axis_with_an_inset(figures):
    ax = figures["fig7b"].axes[0]
    assert ax.get_yscale() == "log"
    assert ax.child_axes and ax.child_axes[0].get_yscale() == "linear"


def test_fig7b_caption_states_where_each_count_first_appears():
    """Synthetic counts: the second contact moves right with xi, every later count left."""
    sweep = _fig7_sweep()
    data = render_fig7.caption_data(sweep, "b", FIG7, summary=aggregate_fig7.summarise(sweep))
    assert data["reach2_word"] == "moves to larger"
    assert data["n_right"] == "n = 2"
    assert data["n_left"].startswith("n = 3")
    # Just above the undamped onset the least damped curve has more contacts than the others.
    counts = [int(v) for v in data["fall_counts"].split(", ")]
    assert counts[0] > counts[-1]
    # Reversed order of the onset: the words follow the data.
    flipped = _fig7_sweep(xis=(1.2, 1.0, 0.3, 0.1))
    summary = aggregate_fig7.summarise(flipped)
    assert render_fig7.caption_data(flipped, "b", FIG7, summary=summary)["reach2_word"] == (
        "moves to smaller"
    )


def test_study_plot_colours_a_xi_curve_by_its_xi():
    """A user study's curves per xi (config/study-example.yaml) take the xi colours, so its plots
    pass the audit save_outputs applies."""
    import yaml

    from restitution_workflow.study import check_study

    study_plot = _load("study_plot")
    example = Path(__file__).resolve().parents[1] / "config" / "study-example.yaml"
    study = check_study(yaml.safe_load(example.read_text()))
    alpha = np.geomspace(0.1, 100, 20)
    table = pd.concat(
        pd.DataFrame(
            dict(alpha=alpha, cor=0.5, n_collisions=1, curve=xi, curve_index=i, status="ok")
        )  # fmt: skip
        for i, xi in enumerate([0.0, 0.1, 0.3, 1.0])
    )
    fig = study_plot.draw(table, study, "cor", LOG)
    assert plotting.audit_figure(fig) == []
    colours = {line.get_label(): line.get_color() for line in fig.axes[0].lines}
    assert colours[r"$\xi = 0.3$"] == plotting.xi_colour(0.3)
