"""Figure helpers checked against closed forms and the solver: Fig. 2(b)'s small-alpha limit, the
colour sets of restitution.plotting, and the caption data of Fig. 7(c) on synthetic tables."""

import logging
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_rgb

import restitution
from conftest import load_script
from restitution import plotting
from restitution.analysis.sweeps import local_minima

_load = load_script


render_fig2bcd = _load("render_fig2bcd")
render_fig7 = _load("render_fig7")
aggregate_fig7 = _load("aggregate_fig7")


@pytest.mark.parametrize("beta", [1e-3, 1e-2, 0.1, 1.0])
def test_fig2b_small_alpha_limit_against_the_solver(beta):
    """omega t_col / 2 pi -> (1/2) sqrt(beta (1 + alpha)/alpha): within 1 % at alpha = 1e-4."""
    alpha = 1e-4
    result = restitution.solve(alpha=alpha, beta=beta)
    assert result.status == "ok" and result.n_collisions == 1
    ratio = result.omega_t_col / (2 * math.pi) / render_fig2bcd.small_alpha_limit(alpha, beta)
    assert abs(ratio - 1) < 0.01, ratio


def test_fig2b_limit_is_half_the_contact_period():
    """Closed form: m1 alone on k1 stays in contact pi sqrt(m1/k1), and
    omega^2 = k2 (1 + alpha)/(alpha m1)."""
    m1, k1, beta, alpha = 1.0, 50.0, 0.2, 0.3
    k2 = beta * k1
    omega = math.sqrt(k2 / m1 + k2 / (alpha * m1))
    expected = omega * math.pi * math.sqrt(m1 / k1) / (2 * math.pi)
    assert render_fig2bcd.small_alpha_limit(alpha, beta) == pytest.approx(expected, rel=1e-14)


def test_limit_check_reads_the_smallest_alpha_per_beta():
    alpha = np.array([1e-3, 1e-2])
    rows = []
    for beta in (0.0, 0.1):
        t = 2 * math.pi * render_fig2bcd.small_alpha_limit(alpha, beta) if beta else [0, 0]
        rows += [
            dict(alpha=a, beta=beta, omega_t_col=x, status="ok")
            for a, x in zip(alpha, t, strict=True)
        ]
    check = render_fig2bcd.limit_check(pd.DataFrame(rows))
    assert check["beta"].tolist() == [0.1] and check["alpha"].tolist() == [1e-3]
    assert check["ratio"].iloc[0] == pytest.approx(1.0, rel=1e-14)


def _distance(a, b):
    return math.dist(to_rgb(a), to_rgb(b))


def test_colour_sets_are_disjoint_and_distinct():
    sets = {
        "beta": [*plotting.BETA_COLOURS.values(), *plotting.BETA_EXTRA],
        "xi": [*plotting.XI_COLOURS.values(), *plotting.XI_EXTRA],
        "alpha": [*plotting.ALPHA_COLOURS.values(), *plotting.ALPHA_EXTRA],
    }
    names = list(sets)
    for i, a in enumerate(names):
        assert len(set(sets[a])) == len(sets[a]), a
        for b in names[i + 1 :]:
            shared = {c.lower() for c in sets[a]} & {c.lower() for c in sets[b]}
            assert not shared, (a, b, shared)
    # Within a set, the colours actually used in one panel are far apart in RGB.
    for table in (plotting.BETA_COLOURS, plotting.XI_COLOURS, plotting.ALPHA_COLOURS):
        colours = list(table.values())
        for i, a in enumerate(colours):
            for b in colours[i + 1 :]:
                assert _distance(a, b) > 0.25, (a, b)


def test_colour_of_a_value_is_the_same_everywhere():
    assert plotting.beta_colour(0.01) == plotting.beta_colour(1e-2, [0.0, 0.01, 1.0])
    assert plotting.xi_colour(0.3, [0.1, 0.3]) == plotting.xi_colour(0.3, [0.3, 3.0])
    assert plotting.alpha_colour(7.0, [2.0, 7.0]) == plotting.ALPHA_EXTRA[0]


def test_fig7c_caption_slope_is_fitted_from_the_data():
    """A synthetic omega t_col = 3 alpha^(1/2) must give slope 0.50 and the words 'one half'."""
    alpha = np.geomspace(0.1, 1000, 400)
    sweep = pd.DataFrame(
        dict(alpha=alpha, xi=0.3, status="ok", omega_t_col=3 * np.sqrt(alpha), cor=0.5,
             n_collisions=1)
    )  # fmt: skip
    fig7 = {"xis": [0.3], "alpha_max": 1000.0}
    data = render_fig7.caption_data(sweep, "c", fig7, summary=aggregate_fig7.summarise(sweep))
    assert data["slopes"] == "0.50" and "one half" in data["slope_word"]
    assert data["t_last"] == f"{3 * np.sqrt(1000):.3g}"  # the summary's omega t_col at alpha_max
    linear = sweep.assign(omega_t_col=2 * alpha)
    data = render_fig7.caption_data(linear, "c", fig7, summary=aggregate_fig7.summarise(linear))
    assert data["slopes"] == "1.00" and "linear" in data["slope_word"]


def test_fig7a_caption_states_the_order_below_the_first_minimum_from_the_data():
    alpha = np.geomspace(0.1, 10, 200)
    rows = []
    for xi, shift in ((0.1, 0.0), (1.0, 0.02)):
        # COR with a cusp minimum at alpha = 1; below it the damped curve lies higher.
        cor = np.where(alpha < 1, 0.8 + shift - 0.5 * alpha, 0.3 + 0.05 * alpha - shift)
        rows.append(pd.DataFrame(dict(alpha=alpha, xi=xi, cor=cor, status="ok", n_collisions=1,
                                      omega_t_col=1.0)))  # fmt: skip
    sweep = pd.concat(rows, ignore_index=True)
    minima = local_minima(sweep, "alpha", by="xi")  # as aggregate_fig7 lists them
    assert list(minima["alpha"]) == [alpha[alpha < 1][-1]] * 2  # the cusp at alpha = 1
    data = render_fig7.caption_data(sweep, "a", {"xis": [0.1, 1.0], "alpha_max": 10.0}, minima)
    assert data["low_trend"] == "rises"
    assert data["ordered_share"] == "100%"


def _chromatic(colour) -> bool:
    r, g, b = to_rgb(colour)
    return max(r, g, b) - min(r, g, b) > 0.05  # greys and black are neutral


def test_other_quantities_take_no_colour_of_beta_xi_alpha():
    """N, eta, DR and the role of a curve are drawn in greys with line styles; L and V0 have
    sets of their own: no chromatic colour means a beta, xi or alpha in one panel and something
    else in another."""
    taken = {
        c.lower()
        for c in [
            *plotting.BETA_COLOURS.values(), *plotting.BETA_EXTRA,
            *plotting.XI_COLOURS.values(), *plotting.XI_EXTRA,
            *plotting.ALPHA_COLOURS.values(), *plotting.ALPHA_EXTRA,
        ]
    }  # fmt: skip
    others = [s["color"] for s in plotting.SERIES_STYLES]
    others += [s["color"] for s in plotting.ROLE_STYLES.values()]
    others += [plotting.REFERENCE_STYLE["color"]]
    assert not any(_chromatic(c) for c in others), others
    for c in [*plotting.L_COLOURS, *plotting.V0_COLOURS]:
        assert not any(_distance(c, t) < 0.2 for t in taken if _chromatic(t)), c


def test_paper_figure_scripts_define_no_colours_of_their_own():
    """Every colour of Figs. 2-7 comes from restitution.plotting (one place)."""
    import re

    scripts = sorted(Path("workflow/scripts").glob("render_fig[2-7]*.py"))
    assert len(scripts) >= 8
    for path in scripts:
        hexes = re.findall(r"#[0-9A-Fa-f]{6}\b", path.read_text())
        assert not hexes, (path.name, hexes)


# --- Fig. 8(a): resolution mask and smooth minima ---------------------------------------------

curves8a = load_script("simulate_fig8a_curves")
ROOT = Path(__file__).resolve().parents[1]
LOG = logging.getLogger("test_figures")


def test_resolved_limit_ends_at_the_first_close_pair_of_count_steps():
    alpha = np.arange(40, dtype=float)
    # Steps 10 cells apart, then 5, 5, then 2 and 2 apart: unresolved from the step at 29 (the
    # last one before the close pair) on.
    n = np.repeat([1, 2, 3, 4, 5, 6, 7], [10, 10, 5, 5, 2, 2, 6])
    assert curves8a.resolved_limit(alpha, n, min_cells=3) == 29.0
    # One isolated close pair (two curves crossing) does not end the range.
    n = np.repeat([1, 2, 3, 4], [10, 2, 10, 18])
    assert curves8a.resolved_limit(alpha, n, min_cells=3) == math.inf
    # A step of two counts at once is two steps 0 cells apart: with a close one before it, the
    # range ends.
    n = np.repeat([1, 2, 4], [10, 2, 28])
    assert curves8a.resolved_limit(alpha, n, min_cells=3) == 9.0


def test_smooth_minimum_at_beta_1_is_the_papers():
    """The smooth minimum of the COR along alpha at beta = 1, refined from a coarse grid row,
    against the paper's value (config/paper_values.yaml: 0.91 at alpha = 3.42) and a fine grid
    of the solver."""
    import yaml

    paper = yaml.safe_load((ROOT / "config" / "paper_values.yaml").read_text())
    alpha = np.geomspace(1.0, 10.0, 60)
    grid = restitution.solve_many(pd.DataFrame({"alpha": alpha, "beta": 1.0}))
    grid["alpha"], grid["beta"] = alpha, 1.0
    minima = curves8a.smooth_minima(grid, {1.0: math.inf}, LOG)
    near = minima[(minima["alpha"] > 2.5) & (minima["alpha"] < 5.0)]
    assert len(near) == 1
    assert round(near["cor"].iloc[0], 2) == float(paper["beta1_min_cor"])
    assert near["alpha"].iloc[0] == pytest.approx(float(paper["beta1_min_alpha"]), abs=0.02)
    fine = np.linspace(near["alpha"].iloc[0] * 0.99, near["alpha"].iloc[0] * 1.01, 2001)
    cor = restitution.solve_many(pd.DataFrame({"alpha": fine, "beta": 1.0}))["cor"]
    assert near["cor"].iloc[0] <= cor.min() + 1e-12
