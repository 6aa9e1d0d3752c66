"""The public API: validation before work, method choice, solve_many contract and determinism."""

import math

import numba
import numpy as np
import pandas as pd
import pytest

import restitution
from restitution import SceneError, solve, solve_many
from restitution.solvers.result import RESULT_COLUMNS


@pytest.mark.parametrize(
    "kwargs, name, allowed",
    [
        ({"alpha": 0.0}, "alpha", "[1e-8, 1e8]"),
        ({"alpha": -1.0}, "alpha", "[1e-8, 1e8]"),
        ({"alpha": math.nan}, "alpha", "[1e-8, 1e8]"),
        ({"alpha": "heavy"}, "alpha", "[1e-8, 1e8]"),
        ({"alpha": 1.0, "beta": -1e-3}, "beta", "[0, 1e6]"),
        ({"alpha": 1.0, "xi": -0.1}, "xi", "[0, 1e3]"),
        ({"alpha": 1.0, "xi": math.inf}, "xi", "[0, 1e3]"),
        ({"alpha": 1.0, "n_masses": 1}, "n_masses", "[2, 512]"),
        ({"alpha": 1.0, "n_masses": 2.5}, "n_masses", "[2, 512]"),
        ({"alpha": 1.0, "method": "euler"}, "method", "auto, impulsive, piecewise"),
    ],
)
def test_invalid_scene_names_parameter_and_range(kwargs, name, allowed):
    with pytest.raises(SceneError) as err:
        solve(**kwargs)
    assert name in str(err.value)
    assert allowed in str(err.value)


def test_forced_method_must_fit_the_scene():
    with pytest.raises(SceneError, match="'impulsive' needs beta = 0"):
        solve(alpha=1.0, beta=0.1, method="impulsive")
    with pytest.raises(SceneError, match="'piecewise' needs beta > 0"):
        solve(alpha=1.0, beta=0.0, method="piecewise")


def test_auto_records_the_method_the_scene_needs():
    assert solve(alpha=0.5).method == "impulsive"
    assert solve(alpha=0.5, beta=0.01).method == "piecewise"
    assert solve(alpha=0.5, n_masses=4).method == "impulsive"


def test_solve_single_contact_closed_form():
    # Below alpha*_1 = 0.6971 one impulsive contact: COR = (1 - alpha)/(1 + alpha) (Eq. 1).
    r = solve(alpha=0.3)
    assert r.success and r.n_collisions == 1
    assert r.cor == pytest.approx((1 - 0.3) / 1.3, abs=1e-14)
    assert r.e_translational + r.e_vibrational + r.e_dissipated == pytest.approx(1.0, abs=1e-12)


def test_history_has_one_row_per_contact():
    r = solve(alpha=5.0, history=True)
    assert len(r.history) == r.n_collisions > 1
    assert (r.history["v1_in"] <= 0).all() and (r.history["v1_out"] >= 0).all()
    assert np.all(np.diff(r.history["omega_t_start"]) > 0)
    assert r.history["omega_t_end"].iloc[-1] == pytest.approx(r.omega_t_col, abs=1e-12)


def test_solve_many_matches_solve_and_keeps_input_columns():
    frame = pd.DataFrame(
        {
            "alpha": [0.3, 2.0, 5.0, 1.5, 3.0],
            "beta": [0.0, 0.0, 0.01, 0.1, 0.0],
            "xi": [0.0, 0.2, 0.0, 0.5, 0.0],
            "n_masses": [2, 2, 2, 3, 4],
            "label": list("abcde"),
        },
        index=[10, 11, 12, 13, 14],
    )
    out = solve_many(frame, keep=["label"])
    assert list(out.index) == list(frame.index)
    assert list(out["label"]) == list("abcde")
    for c in RESULT_COLUMNS:
        assert c in out
    for (_, row), (_, res) in zip(frame.iterrows(), out.iterrows(), strict=True):
        r = solve(row.alpha, row.beta, row.xi, int(row.n_masses))
        assert res.cor == r.cor  # the batch and scalar paths run the same kernels
        assert res.n_collisions == r.n_collisions
        assert res.method == r.method and res.status == r.status


@pytest.mark.parametrize("n_masses", [[2, 2, 3], [2.0, 2.0, 3.0]])  # kept / converted column
def test_solve_many_result_and_input_never_write_into_each_other(n_masses):
    """The result shares no writable memory with the user's frame: writing into either leaves
    the other as it was (columns carried through, columns converted, result columns)."""
    frame = pd.DataFrame(
        {"alpha": [1.0, 2.0, 3.0], "beta": [0.0, 0.1, 0.0], "xi": [0.0, 0.2, 0.0]}
    ).assign(n_masses=n_masses)
    before = frame.copy()
    out = solve_many(frame)
    expected = out.copy()
    out.loc[0, ["alpha", "beta", "xi", "n_masses", "cor"]] = [9.0, 7.0, 5.0, 4, 3.0]
    out["xi"] *= 2.0
    pd.testing.assert_frame_equal(frame, before)
    frame.loc[1, ["alpha", "beta", "xi"]] = [8.0, 0.5, 0.5]
    frame.loc[2, "n_masses"] = 6
    assert out.loc[1, "alpha"] == expected.loc[1, "alpha"] == 2.0
    assert out.loc[1, "beta"] == expected.loc[1, "beta"] == 0.1
    assert out.loc[2, "n_masses"] == expected.loc[2, "n_masses"] == 3


def test_solve_many_progress_bar_counts_every_row_and_changes_nothing(capsys):
    """progress=True draws a tqdm bar on stderr that reaches every row (exact rows in blocks,
    numerical rows one by one) and gives the same table as without it."""
    frame = pd.DataFrame(
        {
            "alpha": np.geomspace(0.1, 20.0, 300),
            "beta": np.tile([0.0, 0.01, 0.1], 100),
            "method": ["auto"] * 298 + ["adaptive", "adaptive"],
        }
    )
    quiet = solve_many(frame)
    assert capsys.readouterr().err == ""
    shown = solve_many(frame, progress=True)
    err = capsys.readouterr().err
    assert "solve_many" in err and "300/300" in err
    pd.testing.assert_frame_equal(quiet, shown, check_exact=True)


@pytest.mark.parametrize("n", [0, 1, 100, 2500])
def test_solve_many_column_types_do_not_depend_on_the_table_size(n):
    out = solve_many(pd.DataFrame({"alpha": np.linspace(0.5, 5.0, n)}))
    assert out.dtypes.astype(str).to_dict() == {
        "alpha": "float64", "beta": "float64", "xi": "float64", "n_masses": "int64",
        "cor": "float64", "n_collisions": "int64", "omega_t_col": "float64",
        "e_translational": "float64", "e_vibrational": "float64", "e_dissipated": "float64",
        "method": "str", "status": "str", "error_estimate": "float64",
    }  # fmt: skip


@pytest.mark.parametrize("n", [0, 1, 3])
def test_general_table_column_types_do_not_depend_on_the_table_size(n):
    frame = pd.DataFrame(
        {"masses": [[1.0, 2.0]] * n, "springs": [[1.0]] * n, "dashpots": [[0.1]] * n}
    )
    out = solve_many(frame)
    types = out.dtypes.astype(str).to_dict()
    assert types["masses"] == types["springs"] == types["dashpots"] == "object"
    assert types["method"] == types["status"] == "str"
    assert all(types[c] == "float64" for c in ("cor", "t_col", "omega_t_col", "error_estimate"))
    assert types["n_collisions"] == "int64"
    assert all(type(v) is list for v in out["masses"])


def test_solve_many_validates_every_row_before_work():
    frame = pd.DataFrame({"alpha": [1.0, 2.0, -3.0], "beta": [0.0, 0.0, 0.0]})
    with pytest.raises(SceneError, match=r"alpha must be in \[1e-8, 1e8\]; got -3.0 \(row 2\)"):
        solve_many(frame)
    with pytest.raises(SceneError, match="needs a column 'alpha'"):
        solve_many(pd.DataFrame({"beta": [0.0]}))
    with pytest.raises(SceneError, match="method"):
        solve_many(pd.DataFrame({"alpha": [1.0], "method": ["rk4"]}))


def test_solve_many_bit_identical_for_any_thread_count():
    rng = np.random.default_rng(7)
    frame = pd.DataFrame(
        {
            "alpha": 10 ** rng.uniform(-2, 2.3, 300),
            "beta": np.where(rng.random(300) < 0.5, 0.0, 10 ** rng.uniform(-3, 0, 300)),
            "xi": np.where(rng.random(300) < 0.5, 0.0, rng.uniform(0, 2, 300)),
        }
    )
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = solve_many(frame)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = solve_many(frame)
    finally:
        numba.set_num_threads(before)
    pd.testing.assert_frame_equal(one, many, check_exact=True)


def test_event_budget_is_reported_not_hidden():
    r = solve(alpha=100.0, max_events=3)
    assert r.status == "event_budget_exhausted" and not r.success
    assert "NOT finished" in r.message


def test_version_is_exposed():
    assert restitution.__version__ != ""


def test_nonlinear_laws_go_through_solve_and_record_their_method():
    r = solve(alpha=2.0, beta=0.01, contact="plastic", eta=0.5, dr=0.5)
    assert r.success and r.method == "adaptive" and 0 < r.cor <= math.sqrt(1 - 0.5 / 3.0)
    assert r.error_estimate > 0  # the adaptive method reports its own error estimate
    # chains with nonlinear links go to the general nonlinear kernel
    chain = solve(alpha=2.0, beta=0.01, n_masses=3, structure="scissor")
    assert chain.success and chain.method == "adaptive" and chain.n_masses == 3
    with pytest.raises(SceneError, match="'reference'.*two masses only"):
        solve(alpha=2.0, beta=0.01, n_masses=3, method="reference")
    with pytest.raises(SceneError, match="unknown scene parameter"):
        solve(alpha=2.0, kappa=3.0)


def test_numerical_methods_agree_with_exact_on_a_linear_scene():
    exact = solve(alpha=2.5, beta=0.05)
    adaptive = solve(alpha=2.5, beta=0.05, method="adaptive", rtol=1e-10)
    assert adaptive.method == "adaptive" and adaptive.n_collisions == exact.n_collisions
    assert adaptive.cor == pytest.approx(exact.cor, abs=1e-8)


def test_solve_many_mixes_exact_and_numerical_rows():
    frame = pd.DataFrame(
        {
            "alpha": [2.0, 2.0, 2.5, 0.3],
            "beta": [0.01, 0.01, 0.05, 0.0],
            "contact": ["plastic", "linear", "linear", None],
            "eta": [0.5, np.nan, np.nan, np.nan],
            "dr": [0.5, np.nan, np.nan, np.nan],
            "method": ["auto", "auto", "adaptive", "auto"],
        }
    )
    out = solve_many(frame)
    assert list(out["method"]) == ["adaptive", "piecewise", "adaptive", "impulsive"]
    assert set(out["status"]) == {"ok"}
    assert out["cor"].iloc[0] == solve(2.0, 0.01, contact="plastic", eta=0.5, dr=0.5).cor
    assert out["cor"].iloc[2] == pytest.approx(solve(2.5, 0.05).cor, abs=1e-8)
    assert out["cor"].iloc[3] == pytest.approx(0.7 / 1.3, abs=1e-14)
    with pytest.raises(SceneError, match=r"'verlet' does not fit.*rigid wall \(row 0\)"):
        solve_many(pd.DataFrame({"alpha": [1.0], "n_masses": [3], "method": ["verlet"]}))
