"""The column-wise reading of general tables (restitution.tables.linear_rows) against the row-by-row
reading it stands in for: same Chains, plan, kernel input and results, bit for bit; every cell
that is not plainly valid left to the row-by-row reading (which words the error)."""

import math

import numpy as np
import pandas as pd
import pytest

from restitution import solve_many
from restitution.model.chain import SceneError
from restitution.tables import linear_rows
from restitution.tables.scene_table import GENERAL, scene_table


@pytest.fixture
def row_by_row(monkeypatch):
    """Run a block with the column-wise reading switched off."""

    def run(fn, *args, **kwargs):
        with monkeypatch.context() as m:
            m.setattr(linear_rows, "read", lambda *a: None)
            return fn(*args, **kwargs)

    return run


def _table(rng, n=300, text=False, dashpots=True, kc=True, v0=False, method=False):
    sizes = rng.integers(2, 9, n)
    cells = {
        "masses": [list(10 ** rng.uniform(-3, 3, s)) for s in sizes],
        "springs": [list(10 ** rng.uniform(-3, 3, s - 1)) for s in sizes],
    }
    if dashpots:
        some = [
            np.where(rng.random(s - 1) < 0.5, 0.0, 10 ** rng.uniform(-3, 0, s - 1)) for s in sizes
        ]
        cells["dashpots"] = [None if j % 7 == 0 else list(c) for j, c in enumerate(some)]
    if text:
        for name in list(cells):
            cells[name] = [
                "" if v is None else "; ".join(repr(float(x)) for x in v) for v in cells[name]
            ]
    frame = pd.DataFrame(cells)
    if kc:
        frame["k_contact"] = np.where(rng.random(n) < 0.4, math.inf, 10 ** rng.uniform(-2, 4, n))
    if v0:
        frame["v0"] = 10 ** rng.uniform(-2, 2, n)
    if method:
        finite = frame["k_contact"].to_numpy() < math.inf
        frame["method"] = np.where(finite, "piecewise", "auto")
    return frame


@pytest.mark.parametrize(
    "kwargs",
    [{}, {"text": True}, {"dashpots": False}, {"kc": False}, {"v0": True}, {"method": True}],
)
def test_same_chains_plan_and_kernel_input_as_row_by_row(row_by_row, kwargs):
    frame = _table(np.random.default_rng(len(kwargs) + 7 * len(str(kwargs))), **kwargs)
    fast = scene_table(frame)
    slow = row_by_row(scene_table, frame)
    assert fast._raw is not None and slow._raw is None  # the two readings did run
    for name, value in slow.plan.items():
        assert np.array_equal(fast.plan[name], value), name
    assert [fast.method_names[c] for c in fast.method_codes] == [
        slow.method_names[c] for c in slow.method_codes
    ]
    for a, b in zip(fast.chains, slow.chains, strict=True):
        for name in ("masses", "springs", "dashpots"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name
            assert not getattr(a, name).flags.writeable
        assert (a.k_contact, a.v0, a.contact, a.links) == (b.k_contact, b.v0, b.contact, b.links)
        assert (type(a.k_contact), type(a.v0)) == (type(b.k_contact), type(b.v0)) == (float, float)
        assert (a.alpha, a.beta, a.xi, a.omega) == (b.alpha, b.beta, b.xi, b.omega)
    rows = np.flatnonzero(~slow.plan["paper"])
    for x, y in zip(fast.scaled(rows), slow.scaled(rows), strict=True):
        assert np.array_equal(x, y)


def test_same_results_as_row_by_row(row_by_row):
    frame = _table(np.random.default_rng(3), n=200)
    pd.testing.assert_frame_equal(
        solve_many(frame), row_by_row(solve_many, frame), check_exact=True
    )


@pytest.mark.parametrize(
    ("column", "cell"),
    [
        ("masses", [1.0, True]),  # bool is not a number here
        ("masses", ["1", 2.0]),
        ("masses", [1.0, None]),
        ("masses", [1.0, math.nan]),
        ("springs", [math.inf]),
        ("masses", [[1.0], [2.0]]),
        ("masses", [1.0]),  # N = 1
        ("springs", [1.0, 2.0]),  # one link too many
        ("masses", "1, 2"),
        ("masses", ""),
        ("masses", 2.0),
        ("masses", [1.0, 1e8]),  # a ratio on its bound: accepted, but decided row by row
        ("masses", [1.0, 1.00000001e8]),  # just over it
        ("dashpots", [-0.1]),
        ("dashpots", [1e9]),  # damping ratio far over 1e3
        ("masses", [1.0, 1 + 0j]),
        ("masses", np.array([[1.0, 2.0]])),
    ],
)
def test_anything_not_plainly_valid_is_read_row_by_row(row_by_row, column, cell):
    cells = {"masses": [[1.0, 2.0]] * 3, "springs": [[1.0]] * 3, "dashpots": [[0.1]] * 3}
    cells[column] = [cells[column][0], cell, cells[column][0]]
    frame = pd.DataFrame(cells)
    auto = np.full(3, "auto", dtype=object)
    assert linear_rows.read(frame, frozenset(frame), np.full(3, math.inf), np.ones(3), auto) is None
    try:
        expected = row_by_row(solve_many, frame)
    except SceneError as e:
        with pytest.raises(SceneError) as got:
            solve_many(frame)
        assert str(got.value) == str(e)
    else:
        pd.testing.assert_frame_equal(solve_many(frame), expected, check_exact=True)


def test_law_columns_go_row_by_row_unless_all_missing():
    base = {"masses": [[1.0, 2.0]] * 2, "springs": [[1.0]] * 2, "k_contact": [10.0, 10.0]}
    assert scene_table(pd.DataFrame({**base, "contact": [None, None]}))._raw is not None
    hertz = pd.DataFrame({**base, "contact": [None, {"law": "hertz", "k": 10.0}]}).drop(
        columns="k_contact"
    )
    assert scene_table(hertz)._raw is None


def test_forced_method_that_does_not_fit_is_worded_for_its_row():
    frame = pd.DataFrame({"masses": [[1.0, 2.0]] * 3, "springs": [[1.0]] * 3})
    frame["method"] = ["auto", "auto", "impulsive"]
    frame["k_contact"] = [math.inf, math.inf, 5.0]
    with pytest.raises(SceneError, match=r"'impulsive' does not fit.*\(row 2\)"):
        solve_many(frame)


@pytest.mark.parametrize(
    "cell",
    [
        lambda v: tuple(v),
        lambda v: np.asarray(v),
        lambda v: [int(x) if float(x).is_integer() else x for x in v],
        lambda v: [np.float32(x) for x in v],
    ],
)
def test_plain_number_cells_of_any_sequence_type_are_read_column_wise(row_by_row, cell):
    frame = pd.DataFrame(
        {
            "masses": [cell(v) for v in ([1.0, 2.0, 3.0], [2.0, 0.5], [1.0, 1.0, 1.0])],
            "springs": [cell(v) for v in ([1.0, 4.0], [3.0], [1.0, 1.0])],
            "k_contact": [math.inf, 50.0, 8.0],
        }
    )
    assert scene_table(frame)._raw is not None
    pd.testing.assert_frame_equal(
        solve_many(frame), row_by_row(solve_many, frame), check_exact=True
    )


def test_every_general_form_column_is_known_to_the_column_wise_reader():
    """A general-form column the reader does not know would be silently ignored by it."""
    assert set(GENERAL) == set(linear_rows.READS) | set(linear_rows.LAW_COLUMNS)


def test_numerical_rows_of_a_column_wise_table_equal_row_by_row(row_by_row):
    """Rows forced to a numerical method run from the column-wise Chains as from the others."""
    frame = pd.DataFrame(
        {
            "masses": [[1.0, 2.0], [1.0, 0.5, 3.0], [2.0, 1.0]],
            "springs": [[1.0], [2.0, 0.7], [3.0]],
            "dashpots": [[0.1], None, [0.0]],
            "k_contact": [40.0, 25.0, math.inf],
            "method": ["adaptive", "verlet", "adaptive"],
        }
    )
    assert scene_table(frame)._raw is not None
    pd.testing.assert_frame_equal(
        solve_many(frame), row_by_row(solve_many, frame), check_exact=True
    )
