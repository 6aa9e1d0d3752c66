"""The minimum-COR design optimiser against closed forms and brute force."""

import math
import re

import numpy as np
import pandas as pd
import pytest

import restitution
from restitution.analysis import design, special_points


@pytest.fixture(scope="module")
def star():
    return special_points.special_points(2).iloc[0]


def test_two_masses_match_the_exact_minimum(star):
    d = design.minimize_cor(2, progress=None)
    assert d.masses[0] == 1.0
    assert d.masses[1] == pytest.approx(star["alpha_star"], abs=1e-9)
    assert d.cor == pytest.approx(star["e_star"], abs=1e-9)
    assert d.cor_check == d.cor
    assert d.n_collisions == 1
    assert d.grazing == (1, "new")
    assert d.bounds_hit == []
    assert "polish" in d.method and d.evaluations > 0


def test_closed_form_of_alpha_star_1(star):
    # Paper Eqs. 10-11, independent of the solvers.
    d = design.minimize_cor(2, progress=None, seed=7)
    assert d.masses[1] == pytest.approx(special_points.alpha_star_1_closed_form(), abs=1e-9)


def test_same_result_for_every_run():
    a = design.minimize_cor(2, progress=None, seed=3)
    b = design.minimize_cor(2, progress=None, seed=3)
    assert a.masses.tolist() == b.masses.tolist() and a.cor == b.cor


def test_same_result_for_any_thread_count():
    import numba

    threads = numba.get_num_threads()
    results = []
    try:
        for n in sorted({1, threads}):
            numba.set_num_threads(n)
            d = design.best_tapered(3, progress=None)
            results.append((d.masses.tolist(), d.cor, d.evaluations))
    finally:
        numba.set_num_threads(threads)
    assert all(r == results[0] for r in results)


def test_progress_lines_are_printed():
    lines = []
    design.minimize_cor(2, progress=lines.append, maxiter=5)
    assert any("generation 1" in s for s in lines)


def test_heartbeat_lines_in_every_long_stage_leave_the_design_unchanged(monkeypatch):
    """The polish and the bound test report progress while they run (every HEARTBEAT s; 0 here:
    a line per evaluation), named after their stage; the design is the one without progress."""
    lines = []
    monkeypatch.setattr(design, "HEARTBEAT", 0.0)
    # Bounds that put the optimum on a bound (0.5 < alpha*_1): the bound test runs too.
    shown = design.minimize_cor(2, bounds=(0.01, 0.5), maxiter=5, progress=lines.append)
    beats = [s for s in lines if re.search(r"\d+ solves(, \d+ grazing evaluations)? so far \(", s)]
    for stage in ("polish", "bound test"):
        assert any(s.startswith(f"masses N=2 {stage}: ") for s in beats), (stage, lines[-5:])
    # The polish's work is mostly grazing evaluations: the heartbeat counts them.
    assert any(s.startswith("masses N=2 polish: ") and "grazing evaluations" in s for s in beats)
    assert not any(" worst case: " in s for s in beats)  # tolerance 0: no worst-case search
    quiet = design.minimize_cor(2, bounds=(0.01, 0.5), maxiter=5, progress=None)
    assert shown.masses.tolist() == quiet.masses.tolist()
    for attr in ("cor", "evaluations", "method", "bounds_hit", "active"):
        assert getattr(shown, attr) == getattr(quiet, attr), attr


def test_heartbeat_waits_for_its_interval():
    """At the default interval a short run prints no heartbeat (only its generation lines)."""
    lines = []
    design.minimize_cor(2, maxiter=5, progress=lines.append)
    assert lines and not any(" so far (" in s for s in lines)


def test_optimum_rides_a_bound_and_says_so():
    # Bounds that exclude alpha*_1 = 0.697 from below: the COR decreases towards it, so the
    # optimum sits on the upper bound 0.5.
    d = design.minimize_cor(2, bounds=(0.01, 0.5), progress=None)
    assert d.masses[1] == pytest.approx(0.5, rel=1e-6)
    assert d.bounds_hit and "at upper bound" in d.bounds_hit[0]
    assert d.cor == pytest.approx(restitution.solve(alpha=0.5).cor, abs=1e-9)
    # The bound is active: the COR falls past it (checked here by the solver alone).
    assert restitution.solve(alpha=0.5 * 1.001).cor < d.cor
    assert d.bound_active and "(active" in d.bounds_hit[0]
    assert d.active == [d.bounds_hit[0]]
    assert d.row()["bound_active"] is True


def test_free_optimum_has_no_active_bound_and_names_its_cusp():
    d = design.minimize_cor(2, progress=None)
    assert not d.bound_active and d.bounds_hit == []
    assert d.active == ["grazing new n=1"]
    assert d.row()["active"] == "grazing new n=1"


def test_bound_near_but_not_active_is_told_apart():
    # Upper bound just (0.5 %) above alpha*_1: the optimum is the free cusp inside the bound, and
    # past the bound the COR rises (the square-root side of the cusp).
    star = special_points.special_points(1)["alpha_star"][0]
    d = design.minimize_cor(2, bounds=(0.01, star * 1.005), progress=None)
    assert d.masses[1] == pytest.approx(star, abs=1e-9)
    assert d.bounds_hit and "not active" in d.bounds_hit[0]
    assert not d.bound_active
    assert restitution.solve(alpha=star * 1.005 * 1.001).cor > d.cor


def test_warm_start_bounds_the_search_by_the_contained_family():
    """With the uniform optimum in its first population, a tiny search cannot end above it."""
    u = design.best_uniform(4, progress=None)
    d = design.minimize_cor(4, popsize=2, maxiter=1, polish=False, progress=None,
                            warm_starts=[u])  # fmt: skip
    assert d.warm_starts == 1
    assert d.cor <= u.cor + 1e-15
    with pytest.raises(ValueError, match="warm_starts"):
        design.minimize_cor(4, progress=None, warm_starts=[([1.0, 0.5], None)])
    with pytest.raises(ValueError, match="warm_starts"):
        design.minimize_cor(4, progress=None, warm_starts=5)


def test_split_warm_start_keeps_the_shorter_designs_cor(tmp_path):
    """A free-spring design of N - 1 masses with light masses of its own (as the optima are):
    an end mass at the lower bound is no small change to it, one of its masses halved into two
    on the stiffest spring is. The script offers the splits whose halves stay in the bounds."""
    from conftest import load_script
    from restitution.tables.io import write_table

    script = load_script("design_fig8b")
    masses, springs = np.array([1.0, 0.6, 0.04, 0.13]), np.array([1.0, 0.4, 0.07])

    def cor(m, k):
        mm, kk, kc = design.scaled_chain(m, k, 0.0)
        return restitution.solve(masses=list(mm), springs=list(kk), k_contact=kc).cor

    base = cor(masses, springs)
    ends = [abs(cor(*script.extend(masses, springs, 5, e)) - base) for e in (None, 0.01)]
    splits = [abs(cor(*script.split(masses, springs, j, 100.0)) - base) for j in (1, 2, 3)]
    assert min(splits) < 0.1 * min(ends)
    row = {"family": "masses_springs", "n_masses": 4, "masses": masses, "springs": springs}
    write_table(pd.DataFrame([row]), tmp_path / "ms4.parquet")
    (given,) = script.known_designs([tmp_path / "ms4.parquet"]).values()
    starts, sources = script.warm_starts([given], 5, 0.01, 100.0)
    assert sources[2:] == [f"masses_springs N=4 split at m_{j}" for j in (2, 3, 4)]
    for m, k in starts:
        assert len(m) == 5 and len(k) == 4 and m.min() >= 0.01 and k.max() <= 100.0
    starts, sources = script.warm_starts([given], 5, 0.03, 100.0)
    assert len(starts) == 2 + 2  # m_3 / 2 = 0.02 would leave the bounds: no split there


def test_long_tapered_chain_is_not_cut_off_by_its_end_mass():
    """Issue 26: bounding the end mass r**(N-1) by 0.01 made r >= 0.464 at N = 7, so the
    decreasing chain lost the first cusp (COR 0.39 instead of ~0.14). The step ratio is bounded
    now; a fine grid of r (independent of the optimiser) confirms the optimum."""
    d = design.best_tapered(7, direction="decreasing", progress=None)
    r = np.geomspace(1e-8 ** (1 / 6), 1.0, 6001)
    chains = [design.scaled_chain(x ** np.arange(7), np.ones(6), 0.0) for x in r]
    frame = pd.DataFrame({"masses": [list(c[0]) for c in chains],
                          "springs": [list(c[1]) for c in chains],
                          "k_contact": [c[2] for c in chains]})  # fmt: skip
    grid = restitution.solve_many(frame)["cor"].min()
    assert d.cor <= grid + 1e-12
    assert d.parameter < 0.01 ** (1 / 6)  # the taper the old bound excluded
    assert d.cor < 0.2


def test_finite_beta_optimum_beats_a_fine_grid():
    # At beta = 0.01 the smallest COR is a smooth minimum just past the count step (the grazing
    # contact's impulse grows smoothly through a contact spring). Independent: a coarse grid,
    # then a fine grid around its lowest point.
    beta = 0.01
    d = design.minimize_cor(2, beta=beta, progress=None)
    a = np.geomspace(0.3, 1.5, 4001)
    res = restitution.solve_many(pd.DataFrame({"alpha": a, "beta": beta}))
    i = int(res["cor"].idxmin())
    fine = np.linspace(a[i - 1], a[i + 1], 20001)
    cor = restitution.solve_many(pd.DataFrame({"alpha": fine, "beta": beta}))["cor"].min()
    assert cor - 1e-10 <= d.cor <= cor + 1e-13
    assert d.cor_check == d.cor


def test_uniform_chain_beats_a_fine_grid():
    for n in (3, 4):
        d = design.best_uniform(n, progress=None)
        a = np.geomspace(0.01, 100, 20001)
        res = restitution.solve_many(pd.DataFrame({"alpha": a, "n_masses": n}))
        assert d.cor <= res["cor"].min() + 1e-12
        assert d.cor_check == pytest.approx(d.cor, abs=1e-12)
        assert d.grazing is not None


def test_robust_worst_case_is_the_worst_over_the_error_band():
    tol = 0.01
    d = design.minimize_cor(2, tolerance=tol, popsize=8, maxiter=25, progress=None)
    r = d.masses[1]
    # Two masses: the errors act only through m2(1 + d2) / (m1 (1 + d1)); brute force the band.
    band = np.linspace(r * (1 - tol) / (1 + tol), r * (1 + tol) / (1 - tol), 4001)
    worst = restitution.solve_many(pd.DataFrame({"alpha": band}))["cor"].max()
    assert d.worst_cor == pytest.approx(worst, abs=1e-5)
    assert d.worst_cor >= d.cor
    # Robustness costs COR: the nominal optimum's worst case is worse than the robust design's.
    star = special_points.special_points(1)["alpha_star"][0]
    band0 = np.linspace(star * (1 - tol) / (1 + tol), star * (1 + tol) / (1 - tol), 4001)
    worst0 = restitution.solve_many(pd.DataFrame({"alpha": band0}))["cor"].max()
    assert d.worst_cor < worst0


@pytest.mark.parametrize(
    "kwargs, word",
    [
        (dict(n_masses=1), "n_masses"),
        (dict(n_masses=2, beta=-1.0), "beta"),
        (dict(n_masses=2, bounds=(1.0, 0.5)), "bounds"),
        (dict(n_masses=2, tolerance=-0.1), "tolerance"),
        (dict(n_masses=2, vary="springs"), "vary"),
        # issue 29: out of range or of the wrong type (scipy raised RuntimeError, TypeError)
        (dict(n_masses=2, bounds=(1e-10, 1.0)), "bounds"),
        (dict(n_masses=2, bounds=(1.0, 1e9)), "bounds"),
        (dict(n_masses=2, bounds=(0.5,)), "bounds"),
        (dict(n_masses=2, bounds="ab"), "bounds"),
        (dict(n_masses=2, beta=1j), "beta"),
        (dict(n_masses=True), "n_masses"),
        (dict(n_masses=2, popsize=0), "popsize"),
        (dict(n_masses=2, maxiter=0), "maxiter"),
        (dict(n_masses=2, seed=-1), "seed"),
        (dict(n_masses=2, max_events=0), "max_events"),
        (dict(n_masses=2, polish="yes"), "polish"),
    ],
)
def test_bad_input_is_refused_before_work(kwargs, word):
    with pytest.raises(ValueError, match=word):
        design.minimize_cor(progress=None, **kwargs)


def test_polish_keeps_to_the_search_budget():
    """The polish may spend what the global search may: its population times (maxiter + 1)
    evaluations (issue 29: minimize_cor(16, popsize=4, maxiter=3) polished for 454 s)."""
    popsize, maxiter, n = 2, 1, 6
    budget = max(5, popsize * (n - 1)) * (maxiter + 1)
    d = design.minimize_cor(n, popsize=popsize, maxiter=maxiter, progress=None)
    # solves: the search's population per generation, the polish's share, the final solve
    assert d.evaluations <= 2 * budget + 1, d.evaluations
    assert f"stopped at its budget of {budget}" in d.method


def test_three_masses_free_beats_uniform_and_rechecks():
    u = design.best_uniform(3, progress=None)
    d = design.minimize_cor(3, progress=None)
    assert d.cor <= u.cor + 1e-12
    assert d.cor_check == pytest.approx(d.cor, abs=1e-12)
    m, k, kc = design.scaled_chain(d.masses, d.springs, 0.0)
    assert restitution.solve(masses=list(m), springs=list(k), k_contact=kc).cor == pytest.approx(
        d.cor, abs=1e-12
    )


def test_tapered_chain_both_directions():
    dec = design.best_tapered(4, direction="decreasing", progress=None)
    inc = design.best_tapered(4, direction="increasing", progress=None)
    assert dec.parameter <= 1.0 <= inc.parameter
    for d in (dec, inc):
        assert d.cor_check == pytest.approx(d.cor, abs=1e-12)
        # The masses form the geometric progression of the reported ratio.
        np.testing.assert_allclose(d.masses, d.parameter ** np.arange(4), rtol=1e-12)
    assert math.isfinite(dec.cor) and math.isfinite(inc.cor)


def test_manifold_point_outside_the_solvers_ranges_is_no_point():
    """The polish's unbounded steps (Nelder-Mead, secant) can leave the ratios the solvers handle
    (m_3/m_1 = 6.2e-9 in Fig. 8(b)'s masses search, N = 4, which then crashed the job): the
    grazing value there is NaN (no manifold point), not a SceneError."""
    from restitution.analysis.design import _grazing_value, family

    fam = family("masses", 4)
    inside = _grazing_value(fam, 0.0, np.log([2.0, 0.5, 3.0]), 2, "new")
    outside = _grazing_value(fam, 0.0, np.log([2.0, 6.2e-9, 3.0]), 2, "new")
    assert math.isfinite(inside)
    assert math.isnan(outside)


def test_a_candidate_over_the_contact_budget_counts_as_unfinished():
    """max_events is the budget of every solve of a search (fig8.design.max_events): a chain
    that needs more contacts is no minimum, however low its COR would be; within the budget
    the objective is the COR itself. best_uniform and best_tapered take it as minimize_cor."""
    fam = design.family("tapered", 4)
    x = np.log([1.9])  # an increasing taper of 4 masses: several contacts
    m, k = fam.chain(x)
    ms, ks, kc = design.scaled_chain(m, k, 0.0)
    full = restitution.solve(masses=list(ms), springs=list(ks), k_contact=kc)
    assert full.success and full.n_collisions >= 3
    enough = design._Objective(fam, 0.0, 0.0, full.n_collisions, None)
    short = design._Objective(fam, 0.0, 0.0, full.n_collisions - 1, None)
    assert enough.cor(x) == full.cor
    assert short.cor(x) == design._BAD
    assert short.batch(x[:, None])[0] == design._BAD
    for search in (design.best_uniform, design.best_tapered):
        with pytest.raises(ValueError, match="max_events"):
            search(3, max_events=0, progress=None)


def test_a_design_s_error_estimate_bounds_its_cor_against_mpmath():
    """A design carries its checked solve's error estimate (the table's error_estimate): on a
    grazing cusp, where the replica runs straddle the cusp, it is not round-off, and it must
    still bound the COR's error against the 40-digit solve."""
    d = design.minimize_cor(3, progress=None)
    assert d.row()["error_estimate"] == d.error_estimate
    assert 0.0 <= d.error_estimate < 1e-4
    m, k, kc = design.scaled_chain(d.masses, d.springs, 0.0)
    precise = restitution.solve(masses=list(m), springs=list(k), k_contact=kc, method="precise")
    assert abs(d.cor - precise.cor) <= d.error_estimate


def test_manifold_solve_stops_at_the_grazing_gaps_round_off(monkeypatch):
    """The polish's root solve of G = 0 (``_solve_on_manifold``) on a 7-mass chain of Fig. 8(b)'s
    free masses-and-springs polish where the old secant (xtol 1e-15) chased G's round-off to its
    iteration limit (56 grazing evaluations): it lands on the side without the grazing contact,
    within a few ROOT_XTOL of the root Brent's method finds at 1e-15 on a bracket, and stops there
    (at most 20 evaluations)."""
    from scipy.optimize import brentq

    fam = design.family("masses+springs", 7)
    x = np.array([-0.4442409082353475, -4.568325688823292, -2.0075638110388696,
                  -3.8785560379490476, -3.8785560379490476, -2.0469716768583304,
                  -0.8790323738282037, -1.2545061389646015, -2.724219847149873,
                  4.605170185988092, -4.60517018598809])  # fmt: skip
    calls = []
    value = design._grazing_value
    monkeypatch.setattr(design, "_grazing_value", lambda *a, **k: calls.append(1) or value(*a, **k))
    y = design._solve_on_manifold(fam, 0.0, x, 0, 1, "new")
    assert y is not None and len(calls) <= 20
    np.testing.assert_array_equal(np.delete(y, 0), np.delete(x, 0))  # only coordinate 0 moves

    def g(t):
        return value(fam, 0.0, np.concatenate([[t], x[1:]]), 1, "new")

    assert 0.0 <= g(y[0]) <= 1e-9
    root = brentq(g, y[0] - 1e-6, y[0] + 1e-6, xtol=1e-15, rtol=4 * np.finfo(float).eps)
    assert abs(y[0] - root) <= 4 * design.ROOT_XTOL


def test_safe_side_step_from_a_root_at_zero():
    """``_to_safe_side`` climbs to the side G >= 0 by doubling steps; from a root estimate at
    exactly 0 (a unit ratio, log 1) it starts at 1e-18, not at 5e-324's 1,000 doublings, and
    ends at most about twice as far in as the first safe point."""
    calls = []

    def g(t):
        calls.append(t)
        return t - 3e-13

    y = design._to_safe_side(g, 0.0, np.zeros(2), 1)
    assert y is not None and y[0] == 0.0
    assert 3e-13 <= y[1] <= 6e-13 + 1e-18 and len(calls) <= 24


def test_family_job_designs_its_n_in_turn_each_warm_started_from_the_last(tmp_path, capsys):
    """One job designs a family's N smallest first: N warm-starts from the contained family's
    table (given) and from its own N - 1 (designed in the same job), in the order the per-design
    jobs had (contained families first); the table is written once, with every N."""
    import logging
    from types import SimpleNamespace

    from conftest import load_script
    from restitution.tables.io import read_table

    script = load_script("design_fig8b")
    d = {"beta": 0.0, "bounds": [0.01, 100.0], "tolerance": 0.01, "seed": 1, "restart_seed": 2,
         "popsize": 3, "maxiter": 3, "robust_popsize": 2, "robust_maxiter": 2,
         "max_events": 10000}  # fmt: skip
    log = logging.getLogger("test")
    uniform = SimpleNamespace(design=d, ns=[3, 2], contains=[])
    script.main(uniform, tmp_path / "uniform.parquet", "uniform", log, progress=True)
    assert "design uniform" in capsys.readouterr().err  # the bar over its N
    masses = SimpleNamespace(design=d, ns=[2, 3], contains=["uniform", "tapered_decreasing"])
    script.main(masses, tmp_path / "masses.parquet", "masses", log, [tmp_path / "uniform.parquet"])
    u, m = read_table(tmp_path / "uniform.parquet"), read_table(tmp_path / "masses.parquet")
    assert list(u["n_masses"]) == [2, 3] and list(m["n_masses"]) == [2, 3]
    assert list(u["warm_from"]) == ["", ""]
    assert list(m["warm_from"]) == [
        "uniform N=2",
        "uniform N=3; masses N=2 + last mass repeated; masses N=2 + end mass 0.01",
    ]
    assert (m["cor"].to_numpy() <= u["cor"].to_numpy() + 1e-15).all()
    assert (m["status"] == "ok").all()
