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
                             status="ok"))  # fmt: skip
    return pd.DataFrame(rows)


def _workprecision_records():
    rows = []
    for scene in ("a", "b"):
        for family in ("exact", *workprecision.METHODS):
            for setting in (1e-3, 1e-6):
                rows.append(dict(scene=scene, family=family, setting=setting, status="ok",
                                 cor_error=setting, time_s=1 / setting * 1e-6, contacts_ok=True,
                                 reference_bound=1e-12))  # fmt: skip
    return pd.DataFrame(rows)


def _figures():
    figs = {f"fig7{p}": render_fig7.draw(_fig7_sweep(), p, FIG7, LOG) for p in "abc"}
    figs["fig8b"] = render_fig8b.draw(_fig8b_table(), None)
    figs["workprecision"] = workprecision.draw(_workprecision_records(), {})
    return figs


@pytest.fixture(scope="module")
def figures():
    return _figures()


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
