"""solve_many's method=, rtol= and step= keywords: a setting for every row, as its column."""

import numpy as np
import pandas as pd
import pytest

import restitution
from restitution import SceneError

PAPER = pd.DataFrame({"alpha": [0.5, 2.0, 7.0], "beta": [0.0, 0.01, 0.1]})


def _same(a: pd.DataFrame, b: pd.DataFrame, columns) -> None:
    for c in columns:
        x, y = a[c].to_numpy(), b[c].to_numpy()
        if x.dtype.kind == "f":
            assert np.array_equal(x, y, equal_nan=True), c
        else:
            assert list(x) == list(y), c


def test_keywords_equal_the_columns():
    cols = ["cor", "n_collisions", "error_estimate", "method", "status"]
    by_kw = restitution.solve_many(PAPER, method="adaptive", rtol=1e-9)
    by_col = restitution.solve_many(PAPER.assign(method="adaptive", rtol=1e-9))
    _same(by_kw, by_col, cols)
    assert set(by_kw["method"]) == {"adaptive"}
    # and the setting did something: the exact default differs from the integrated rows
    exact = restitution.solve_many(PAPER)
    assert set(exact["method"]) != {"adaptive"}
    assert np.all(np.abs(exact["cor"] - by_kw["cor"]) <= by_kw["error_estimate"] + 1e-15)
    soft = PAPER[PAPER["beta"] > 0]  # Verlet needs a finite contact
    verlet = restitution.solve_many(soft, method="verlet", step=0.01)
    _same(verlet, restitution.solve_many(soft.assign(method="verlet", step=0.01)), cols)


def test_keyword_and_column_together_are_refused():
    with pytest.raises(SceneError, match="method is given twice"):
        restitution.solve_many(PAPER.assign(method="auto"), method="adaptive")
    with pytest.raises(SceneError, match="rtol is given twice"):
        restitution.solve_many(PAPER.assign(method="adaptive", rtol=1e-8), rtol=1e-9)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"method": "rk4"}, "method must be one of auto, "),
        ({"method": 3}, "method must be one of"),
        ({"method": "adaptive", "rtol": 0.5}, r"rtol must be in \[1e-14, 1e-2\]"),
        ({"method": "adaptive", "rtol": "1e-8"}, "rtol must be"),
        ({"method": "verlet", "step": 0.0}, r"step must be in \(0, 0.25\]"),
    ],
)
def test_bad_keywords_name_the_parameter(kwargs, message):
    with pytest.raises(SceneError, match=message):
        restitution.solve_many(PAPER, **kwargs)


def test_rtol_on_exact_rows_is_refused_as_a_column_would_be():
    with pytest.raises(SceneError, match="rtol"):
        restitution.solve_many(PAPER, rtol=1e-9)


def test_rtol_keyword_on_a_general_table():
    frame = pd.DataFrame(
        {
            "masses": [[1.0, 2.0], [1.0, 0.5, 2.0]],
            "springs": [[1.0], [0.3, 1.2]],
            "contact": [{"law": "hertz", "k": 30.0}, {"law": "hertz", "k": 50.0}],
        }
    )
    loose = restitution.solve_many(frame, rtol=1e-6)
    tight = restitution.solve_many(frame, rtol=1e-11)
    assert list(tight["rtol"]) == [1e-11, 1e-11]
    assert (tight["error_estimate"] < loose["error_estimate"]).all()
    assert np.all(np.abs(tight["cor"] - loose["cor"]) <= loose["error_estimate"])
