"""Approximate COR models and the least-squares fits (restitution.analysis.approx,
restitution.analysis.fitting)."""

import numpy as np
import pandas as pd
import pytest

import restitution
from restitution.analysis import approx, fitting


@pytest.fixture(scope="module")
def table():
    return approx.shape_table(60.0)


# ---------------------------------------------------------------------------------------------
# Fitting machinery: known answers
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("p", [0.21, 0.8, 1.25])
def test_power_law_exponent_recovered_from_noiseless_data(p):
    x = np.linspace(1.0, 80.0, 40)
    fit = fitting.fit_power(x, x**p, p0=0.5)
    assert fit.params["p"] == pytest.approx(p, abs=1e-10)
    assert fit.stderr["p"] < 1e-10 and fit.r2 == pytest.approx(1.0, abs=1e-12)


def test_scaled_power_law_recovered():
    x = np.geomspace(0.5, 300.0, 50)
    fit = fitting.fit_power(x, 2.5 * x**0.42, scale=True, p0=1.0)
    assert fit.params["A"] == pytest.approx(2.5, rel=1e-9)
    assert fit.params["p"] == pytest.approx(0.42, abs=1e-10)


def test_standard_errors_match_linear_regression():
    """For a straight line the Jacobian s.e. must equal the textbook OLS formula."""
    rng = np.random.default_rng(7)
    x = np.linspace(0, 10, 60)
    y = 1.5 + 0.3 * x + rng.normal(0, 0.2, x.size)
    fit = fitting.least_squares_fit("line", lambda t: t[0] + t[1] * x - y, [0, 0], ["a", "b"], y)
    X = np.column_stack([np.ones_like(x), x])
    beta, ssr, *_ = np.linalg.lstsq(X, y, rcond=None)
    cov = ssr[0] / (x.size - 2) * np.linalg.inv(X.T @ X)
    assert fit.params["b"] == pytest.approx(beta[1], rel=1e-8)
    assert fit.stderr["a"] == pytest.approx(np.sqrt(cov[0, 0]), rel=1e-6)
    assert fit.stderr["b"] == pytest.approx(np.sqrt(cov[1, 1]), rel=1e-6)
    r2 = 1 - ssr[0] / np.sum((y - y.mean()) ** 2)
    assert fit.r2 == pytest.approx(r2, rel=1e-10)


def test_paper_laws_refit_near_paper_values(table):
    pts = table[table.alpha_star <= 60.0]
    assert fitting.fit_unity_law(pts).params["p"] == pytest.approx(0.8, abs=0.03)
    assert fitting.fit_gap_law(pts).params["q"] == pytest.approx(0.21, abs=0.02)
    assert fitting.fit_minima_law(pts).params["c"] == pytest.approx(0.4, abs=0.06)


# ---------------------------------------------------------------------------------------------
# Models: exact where they were built, errors against the project's solver
# ---------------------------------------------------------------------------------------------
def test_improved_exact_at_its_points(table):
    star, unity, e_star = (table[c].to_numpy() for c in ("alpha_star", "alpha_unity", "e_star"))
    inside = star < 59.0
    np.testing.assert_allclose(approx.improved_cor(star[inside], table), e_star[inside], atol=1e-12)
    # From the left of each minimum too (end of the falling branch).
    left = star[inside] * (1 - 1e-15)
    np.testing.assert_allclose(approx.improved_cor(left, table), e_star[inside], atol=1e-12)
    np.testing.assert_allclose(approx.improved_cor(unity[1:][inside[1:]], table), 1.0, atol=1e-14)
    for shape in (approx.UNIVERSAL_SHAPE, (0, 0, 0, 1, 0, 0)):
        np.testing.assert_allclose(
            approx.improved_cor(star[inside], table, shape=shape), e_star[inside], atol=1e-12
        )


def test_improved_single_contact_branch_exact(table):
    a = np.geomspace(1e-3, table.alpha_star[0] * (1 - 1e-12), 500)
    np.testing.assert_allclose(approx.improved_cor(a, table), (1 - a) / (1 + a), atol=1e-15)


def test_paper_model_exact_at_its_law_points():
    pts = approx.law_points(40)
    star, unity = pts.alpha_star.to_numpy(), pts.alpha_unity.to_numpy()
    np.testing.assert_allclose(approx.paper_cor(unity[1:30]), 1.0, atol=1e-14)
    expect = 1 - 2 * 0.6971 / (1 + star[:30])  # gamma* = alpha*_1 at every minimum (Eq. 20)
    np.testing.assert_allclose(approx.paper_cor(star[:30]), expect, atol=1e-14)
    # The paper's value: alpha#_2 = 1 from Eq. 19.
    assert float(approx.paper_cor(1.0)) == pytest.approx(1.0, abs=1e-14)


def test_vectorised_shapes(table):
    a = np.array([[0.5, 1.0], [3.0, 20.0]])
    for f in (approx.paper_cor, lambda x: approx.improved_cor(x, table)):
        out = f(a)
        assert out.shape == a.shape
        assert np.ndim(f(2.0)) == 0


@pytest.mark.slow
def test_improved_error_ten_times_smaller_than_paper():
    """Max error over alpha in [0.01, 200] against restitution.solve_many (kernel), not our code."""
    a = approx.error_grid(0.01, 200.0, 40_001)
    exact = restitution.solve_many(pd.DataFrame({"alpha": a}))["cor"].to_numpy()
    err = approx.errors(
        {"paper": approx.paper_cor, "improved": approx.improved_cor,
         "universal": lambda x: approx.improved_cor(x, shape=approx.UNIVERSAL_SHAPE)},
        a, exact,
    )  # fmt: skip
    e = dict(zip(err.model, err.max_abs_error, strict=True))
    assert e["improved"] * 10 < e["paper"]
    assert e["universal"] * 10 < e["paper"]
    assert e["improved"] < 2e-3
