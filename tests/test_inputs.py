"""Every bad input is refused before any work with a one-line SceneError naming the parameter
(issues 24 and 29): range edges and wrong types of every parameter of ``solve``, ``solve_many``,
``trajectory`` and the command line, null cells, decimal parquet columns, law cells of the wrong
shape; and the input classes that must be read correctly (two-mass CSV tables).

The edges come from the one range table (``restitution.model.chain.RANGES``): just inside, a scene
runs and ends finished or honestly flagged; just outside, it is refused naming the parameter.
"""

from __future__ import annotations

import decimal
import fractions
import math
import os
import re
import subprocess
import sys

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import restitution
from conftest import REPO
from restitution import cli
from restitution.model.chain import RANGES, SceneError
from restitution.solvers.result import MESSAGES
from restitution.tables.io import read_table, write_table

PROFILE = dict(
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)

# A small scene each parameter is set on (the others at cheap values): the paper form, the
# general form, the plastic and scissor laws, and the numerical settings.
PAPER = dict(alpha=0.5, beta=0.1)
GENERAL = dict(masses=[1.0, 0.5], springs=[1.0])
PLASTIC = dict(alpha=0.5, beta=1.0, contact="plastic", dr=0.3)
SCISSOR = dict(alpha=0.5, beta=1.0, structure="scissor")
BASE = {
    "alpha": PAPER,
    "beta": PAPER,
    "xi": PAPER,
    "n_masses": PAPER,
    "max_events": PAPER,
    "k_contact": GENERAL,
    "v0": PLASTIC,
    "rtol": PLASTIC,
    "step": dict(PAPER, method="verlet"),
    "eta": dict(PLASTIC, dr=0.6),  # dr >= (1 - eta)/2 at the low edge
    "dr": PLASTIC,
    "L": SCISSOR,
    "theta0": SCISSOR,  # with ks_ratio = tan(theta0)**2 / 2 (_scene): rest slope k2/2
    "corner": SCISSOR,
}
SCALARS = tuple(BASE)
LISTS = ("masses", "springs", "dashpots")
STATUSES = set(MESSAGES)


def _edges(name: str) -> tuple[list, list]:
    """(just inside, just outside) of RANGES[name] as (end, value) pairs, end "low" or "high"
    (an infinite end has none)."""
    r = RANGES[name]
    inside, outside = [], []
    ends = (("low", r.low, r.low_open, math.inf), ("high", r.high, r.high_open, -math.inf))
    for label, end, open_, toward in ends:
        if not math.isfinite(end):
            continue
        if r.integer:
            step = 1 if toward > 0 else -1
            inside.append((label, int(end)))
            outside.append((label, int(end) - step))
            continue
        inside.append((label, math.nextafter(end, toward) if open_ else end))
        outside.append((label, end if open_ else math.nextafter(end, -toward)))
    return inside, outside


# Inside edges that no scene reaches because of a combined constraint (checked, and worded,
# by its own message): dr -> 1 makes the plastic contact's loading secant vanish, so any beta
# leaves the handled contact ratios; k_contact -> 0 makes beta = springs[0]/k_contact exceed
# its range (RATIOS). The nearest reachable values instead:
FEASIBLE = {("dr", "high"): 0.999, ("k_contact", "low"): 1e-6}
# The largest chain is solved in tests/test_full_range.py; here a cheaper one.
SLOW_INSIDE = {("n_masses", "high"): 64}


def _scene(name, value):
    scene = {**BASE[name], name: value}
    if name == "theta0" and isinstance(value, float) and 0.0 < value < math.pi / 2:
        scene["ks_ratio"] = 0.5 * math.tan(value) ** 2  # the middle of its range at theta0
    return scene


def _assert_finished_or_flagged(r):
    assert r.status in STATUSES, r.status
    if r.status == "ok":
        assert math.isfinite(r.cor) and r.cor >= 0.0
        total = r.e_translational + r.e_vibrational + r.e_dissipated
        assert abs(total - 1.0) <= 1e-3, (r.status, total)


@pytest.mark.parametrize("name", SCALARS)
def test_scalar_range_edges(name):
    inside, outside = _edges(name)
    assert outside, name  # every scalar has a finite end
    for end, value in inside:
        value = FEASIBLE.get((name, end), SLOW_INSIDE.get((name, end), value))
        _assert_finished_or_flagged(restitution.solve(**_scene(name, value)))
    for _, value in outside:
        with pytest.raises(SceneError, match=rf"\b{name}\b") as e:
            restitution.solve(**_scene(name, value))
        assert "\n" not in str(e.value)


@pytest.mark.parametrize("name", LISTS)
def test_list_range_edges(name):
    inside, outside = _edges(name)
    for _, value in inside:
        scene = {**GENERAL, name: [value]} if name != "masses" else {**GENERAL, name: [value] * 2}
        if name == "springs":
            scene["masses"] = [value, value]  # the ratios of masses and springs stay in range
        if name == "masses":
            scene["springs"] = [value]
        if name == "dashpots":  # a damping ratio c omega / (2 k) in range: k, m scale with c
            scale = max(value, 1.0)
            scene.update(masses=[scale, scale], springs=[scale])
        _assert_finished_or_flagged(restitution.solve(**scene))
    for _, value in outside:
        scene = {**GENERAL, name: [1.0, value] if name == "masses" else [value]}
        with pytest.raises(SceneError, match=rf"\b{name}\b"):
            restitution.solve(**scene)


# Values that are not a number in any range: wrong types, non-finite, beyond float64.
WRONG = st.sampled_from(
    [
        None,
        "0.5",
        "",
        True,
        False,
        np.bool_(True),
        0.5 + 0j,
        np.complex128(0.5),
        [0.5],
        [[0.5]],
        {"law": "linear"},
        math.nan,
        -math.inf,
        decimal.Decimal("NaN"),
        10**400,
        -(10**400),
        pd.NA,
        object(),
        np.array("0.5"),
        np.array("0.5", dtype=object),
        np.array(True),
    ]
)


# Text, booleans and complex numbers inside 0-d numpy arrays: float() parsed np.array("0.5")
# as 0.5 and read np.array(True) as 1.
ZERO_D = [np.array("0.5"), np.array(b"0.5"), np.array("0.5", dtype=object), np.array(True),
          np.array(0.5 + 0j)]  # fmt: skip


@pytest.mark.parametrize("value", ZERO_D, ids=repr)
def test_text_in_a_0d_array_is_not_a_number(value):
    with pytest.raises(SceneError, match=r"beta must be in \[0, 1e6\]"):
        restitution.solve(alpha=2.0, beta=value)
    with pytest.raises(SceneError, match=r"masses must be a list of numbers.*masses\[1\]"):
        restitution.solve(masses=[1.0, value], springs=[1.0])
    frame = pd.DataFrame({"alpha": [2.0, 2.0], "beta": [0.5, value]})
    with pytest.raises(SceneError, match=r"beta must be .*row 1"):
        restitution.solve_many(frame)


def test_numbers_in_0d_arrays_are_read():
    for value in (np.array(0.5), np.array(0.5, dtype=object), np.array(np.float32(0.5))):
        assert restitution.solve(alpha=2.0, beta=value).cor == restitution.solve(2.0, 0.5).cor
    assert restitution.solve(alpha=2.0, n_masses=np.array(3)).n_collisions >= 1


@settings(max_examples=120, **PROFILE)
@given(name=st.sampled_from(SCALARS), value=WRONG)
def test_scalar_wrong_types_are_refused_by_name(name, value):
    if name == "v0" and value is None:
        return  # solve's v0=None means "not given" (default 1)
    with pytest.raises(SceneError, match=rf"\b{name}\b") as e:
        restitution.solve(**_scene(name, value))
    assert "\n" not in str(e.value)


@settings(max_examples=60, **PROFILE)
@given(name=st.sampled_from(LISTS), value=WRONG, where=st.integers(0, 1))
def test_list_wrong_types_are_refused_by_name(name, value, where):
    scene = dict(GENERAL, dashpots=[0.0])
    cell = list(scene[name])
    if where < len(cell):
        cell[where] = value  # a bad element
    else:
        cell = value  # or the whole parameter
    with pytest.raises(SceneError, match=rf"\b{name}\b"):
        restitution.solve(**{**scene, name: cell})


def test_real_numbers_of_other_types_are_read_as_floats():
    expected = restitution.solve(0.5, 0.1).cor
    for alpha in (decimal.Decimal("0.5"), fractions.Fraction(1, 2), np.float32(0.5)):
        assert restitution.solve(alpha, 0.1).cor == expected
    assert restitution.solve(masses=[decimal.Decimal(1), 2], springs=[1]).status == "ok"


def test_plain_float_below_range_is_refused_like_a_numpy_scalar():
    low = RANGES["alpha"].low
    for alpha in (low / 10, np.float64(low / 10)):
        with pytest.raises(SceneError, match="alpha"):
            restitution.solve(alpha)


@pytest.mark.parametrize("law", [None, 3, ["linear"], {"law": "linear"}, ""])
def test_law_names_must_be_known_text(law):
    with pytest.raises(SceneError, match="contact"):
        restitution.solve(**GENERAL, contact={"law": law, "k": 1.0})
    with pytest.raises(SceneError, match=r"links\[0\]"):
        restitution.solve(**GENERAL, links=[{"law": law}])
    with pytest.raises(SceneError, match="contact"):
        restitution.trajectory(**GENERAL, contact={"law": law}, times=[0.0, 1.0])


@pytest.mark.parametrize(
    "law, law_value, params",
    [("contact", "plastic", ("eta", "dr")), ("structure", "scissor", ("L", "ks_ratio", "theta0"))],
)
def test_law_parameters_without_their_law_are_refused(law, law_value, params):
    for p in params:
        with pytest.raises(SceneError, match=rf"{p}.*{law_value}"):
            restitution.solve(0.5, 1.0, **{p: 0.5})
        frame = pd.DataFrame({"alpha": [0.5, 0.7], "beta": [1.0, 1.0], p: [np.nan, 0.5]})
        with pytest.raises(SceneError, match=rf"{p}.*row 1"):
            restitution.solve_many(frame)


@pytest.mark.parametrize(
    "scene, name",
    [
        (dict(PLASTIC, eta=-1.0), "eta"),
        (dict(PLASTIC, dr=2.0), "dr"),
        (dict(PLASTIC, eta=0.1, dr=0.0), "dr"),
        (dict(SCISSOR, L=-1.0), "L"),
        (dict(SCISSOR, L=1e7), "L"),
        (dict(SCISSOR, theta0=2.0), "theta0"),
        (dict(SCISSOR, corner=-1.0), "corner"),
        (dict(SCISSOR, ks_ratio=5.0), "ks_ratio"),
    ],
)
def test_paper_form_law_errors_name_the_keyword(scene, name):
    """The paper form's law keywords are named as the user gave them, not by the law's place in
    the chain it builds ("links[0].L", "contact: eta")."""
    with pytest.raises(SceneError) as e:
        restitution.solve(**scene)
    assert str(e.value).startswith(f"{name} "), str(e.value)


# A chain whose first link is not the unit: m1 = 2, omega**2 = k (1/m1 + 1/m2) = 25/6, so a law
# parameter's kernel value differs from the one given.
UNITS = dict(masses=[2.0, 3.0], springs=[5.0])


@pytest.mark.parametrize(
    "law, where",
    [
        (dict(contact={"law": "kelvin_voigt", "k": 1.0, "c": -1.0}), "contact.c"),
        (dict(links=[{"law": "scissor", "L": -1.0, "ks": 1.0}]), "links[0].L"),
        (dict(links=[{"law": "scissor", "L": 1.0, "ks": -1.0}]), "links[0].ks"),
    ],
)
def test_negative_law_parameters_are_refused_as_given(law, where):
    """The packers check kernel values (m1 = 1, omega = 1): the error names the value given,
    not its kernel value (c = -1 was reported as -0.2449)."""
    with pytest.raises(SceneError, match=re.escape(f"{where} must not be negative; got -1.0")):
        restitution.solve(**UNITS, **law)


def test_scissor_length_range_is_stated_in_the_chains_units():
    """L's range [1e-6, 1e6] is in units V_ref/omega of the first link: the error gives it in
    the chain's units, and a length inside that range but below 1e-6 is solved."""
    omega = math.sqrt(5.0 * (1 / 2.0 + 1 / 3.0))
    low, high = 1e-6 / omega, 1e6 / omega
    for bad in (0.5 * low, 2.0 * high):
        link = {"law": "scissor", "L": bad, "ks": 1.0}
        with pytest.raises(SceneError, match=re.escape(f"[{low:.6g}, {high:.6g}]")):
            restitution.solve(**UNITS, links=[link])
    inside = restitution.solve(**UNITS, links=[{"law": "scissor", "L": 0.9e-6, "ks": 1.0}])
    assert inside.status == "ok" and 0.0 < inside.cor < 1.0


def test_unknown_keyword_lists_each_allowed_name_once():
    with pytest.raises(SceneError, match="unknown scene parameter") as err:
        restitution.solve(alpha=0.5, bogus=1.0)
    names = str(err.value).split("allowed: ")[1].split(", ")
    assert len(names) == len(set(names)) and "contact" in names


def test_history_budget_that_cannot_be_allocated_is_refused():
    for call in (
        lambda n: restitution.solve(0.5, history=True, max_events=n),
        lambda n: restitution.solve(**GENERAL, history=True, max_events=n),
        lambda n: restitution.trajectory(alpha=0.5, times=[0.0, 1.0], max_events=n),
    ):
        for n in (10**12, RANGES["max_events"].high):
            with pytest.raises(SceneError, match="max_events"):
                call(n)
    assert restitution.solve(0.5, max_events=RANGES["max_events"].high).status == "ok"
    with pytest.raises(SceneError, match="history"):
        restitution.solve(0.5, history="no")


@pytest.mark.parametrize(
    "times", ["abc", [1j], [[0.0, 1.0], [2.0]], [], [0.0, math.nan], [-1.0], None, {"t": 1}]
)
def test_trajectory_times_of_the_wrong_kind(times):
    with pytest.raises(SceneError, match="times"):
        restitution.trajectory(alpha=0.5, times=times)


def test_trajectory_unknown_keyword():
    with pytest.raises(SceneError, match="unknown scene parameter"):
        restitution.trajectory(**GENERAL, times=[1.0], beta=0.1)


# ----------------------------------------------------------------------------------------------
# Tables
# ----------------------------------------------------------------------------------------------
@settings(max_examples=80, **PROFILE)
@given(column=st.sampled_from(["alpha", "beta", "xi", "n_masses"]), value=WRONG)
def test_table_wrong_cells_name_row_and_column(column, value):
    frame = pd.DataFrame({"alpha": [0.5, 0.7], "beta": 0.1, "xi": 0.0, "n_masses": 2})
    frame[column] = frame[column].astype(object)
    frame.at[1, column] = value
    with pytest.raises(SceneError, match=rf"{column}.*row 1") as e:
        restitution.solve_many(frame)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("column", ["alpha", "beta", "xi", "n_masses", "k_contact", "v0"])
def test_complex_columns_are_refused(column):
    if column in ("k_contact", "v0"):
        frame = pd.DataFrame({"masses": [[1.0, 0.5]], "springs": [[1.0]], column: [1.0 + 1j]})
    else:
        frame = pd.DataFrame({"alpha": [0.5], column: [0.5 + 1j if column != "n_masses" else 2j]})
    with pytest.raises(SceneError, match=column):
        restitution.solve_many(frame)


@pytest.mark.parametrize(
    "column, cell",
    [
        ("contact", "[1, 2]"),
        ("contact", "3"),
        ("contact", '"soft"'),
        ("contact", '{"law": null}'),
        ("contact", '{"law": 3}'),
        ("contact", "{}"),
        ("links", "5"),
        ("links", '"abc"'),
        ("links", '{"law": "linear"}'),
        ("links", "[1]"),
        ("links", "[[1]]"),
        ("links", '[{"law": null}]'),
        ("links", "[{"),
    ],
)
def test_law_cells_of_the_wrong_shape(column, cell):
    frame = pd.DataFrame({"masses": ["1; 0.5"], "springs": ["1"], column: [cell]})
    with pytest.raises(SceneError, match=rf"{column}.*row 0") as e:
        restitution.solve_many(frame)
    assert "\n" not in str(e.value)


def test_null_cells(tmp_path):
    """A missing required cell is refused by name; a missing law or setting cell takes its
    default (None, NaN and pandas' NA alike)."""
    for null in (None, np.nan, pd.NA):
        frame = pd.DataFrame({"alpha": [0.5, null]}, dtype=object)
        with pytest.raises(SceneError, match=r"alpha.*row 1"):
            restitution.solve_many(frame)
        frame = pd.DataFrame({"masses": [[1.0, 0.5], null], "springs": [[1.0], [1.0]]})
        with pytest.raises(SceneError, match=r"masses.*row 1"):
            restitution.solve_many(frame)
    plain = restitution.solve_many(pd.DataFrame({"alpha": [0.5, 0.7], "beta": 1.0}))
    for null in (None, np.nan, pd.NA):
        frame = pd.DataFrame({"alpha": [0.5, 0.7], "beta": 1.0, "eta": [null, null]})
        got = restitution.solve_many(frame)
        assert got["cor"].tolist() == plain["cor"].tolist()


def test_decimal_parquet_columns(tmp_path):
    """decimal128 columns (paper and general form) are read as their floats; the results
    table is written (its parquet writer raised ArrowInvalid on the decimals)."""
    dec = [decimal.Decimal("0.5"), decimal.Decimal("2.25")]
    path = tmp_path / "dec.parquet"
    pq.write_table(pa.table({"alpha": pa.array(dec, pa.decimal128(10, 4))}), path)
    got = restitution.solve_many(read_table(path))
    want = restitution.solve_many(pd.DataFrame({"alpha": [0.5, 2.25]}))
    pd.testing.assert_frame_equal(got, want)
    write_table(got, tmp_path / "out.parquet")
    assert read_table(tmp_path / "out.parquet")["alpha"].dtype == np.float64
    general = pa.table(
        {
            "masses": pa.array([dec], pa.list_(pa.decimal128(10, 4))),
            "springs": pa.array([dec[:1]], pa.list_(pa.decimal128(10, 4))),
            "k_contact": pa.array([decimal.Decimal("5")], pa.decimal128(10, 2)),
        }
    )
    pq.write_table(general, tmp_path / "g.parquet")
    out = tmp_path / "g.out.parquet"
    assert cli.main(["batch", str(tmp_path / "g.parquet"), "-o", str(out)]) == 0
    row = read_table(out).iloc[0]
    direct = restitution.solve(masses=[0.5, 2.25], springs=[0.5], k_contact=5.0)
    assert row["cor"] == direct.cor


def test_two_mass_csv_round_trips(tmp_path):
    """A CSV of two-mass chains (springs: one number per cell) is read, also the tool's own
    output read back, with the results of the direct solves."""
    src = tmp_path / "two.csv"
    pd.DataFrame({"masses": ["1;2", "1;3"], "springs": [1.0, 2.0]}).to_csv(src, index=False)
    assert cli.main(["batch", str(src), "-o", str(tmp_path / "out.csv")]) == 0
    out = read_table(tmp_path / "out.csv")
    direct = [
        restitution.solve(masses=[1.0, 2.0], springs=[1.0]).cor,
        restitution.solve(masses=[1.0, 3.0], springs=[2.0]).cor,
    ]
    assert out["cor"].tolist() == direct
    again = restitution.solve_many(out[["masses", "springs"]])
    assert again["cor"].tolist() == direct


# ----------------------------------------------------------------------------------------------
# Command line
# ----------------------------------------------------------------------------------------------
CLI_BAD = [
    (["--alpha", "1e-9"], "alpha"),
    (["--alpha", "0.5", "--history", "--max-events", "1000000000000"], "max_events"),
    (["--alpha", "0.5", "--beta", "1", "--eta", "2"], "eta"),
    (
        ["--alpha", "0.5", "--beta", "1", "--structure", "scissor", "--theta0", "1.5707963"],
        "theta0",
    ),
    (["--masses", "1,2", "--springs", "1", "--contact-law", '{"law": null}'], "contact"),
    (["--masses", "1,2", "--springs", "1", "--links", "5"], "links"),
    (["--masses", "1,2", "--springs", "1", "--links", '[{"law": 3}]'], r"links\[0\]"),
    (["--masses", "1,2", "--springs", "1", "--v0", "1e-7"], "v0"),
    (["--alpha", "0.5", "--n-masses", "513"], "n_masses"),
    # an option of the other form is refused, not ignored (each exited 0 without reading it)
    (["--alpha", "2", "--k-contact", "5"], "--k-contact"),
    (["--alpha", "2", "--dashpots", "5"], "--dashpots"),
    (["--alpha", "2", "--contact-law", '{"law": "hertz", "k": 50}'], "--contact-law"),
    (["--alpha", "2", "--links", '[{"law": "linear"}]'], "--links"),
    (["--masses", "1,2", "--springs", "1", "--beta", "0.5"], "--beta"),
    (["--masses", "1,2", "--springs", "1", "--xi", "0.1"], "--xi"),
    (["--masses", "1,2", "--springs", "1", "--n-masses", "2"], "--n-masses"),
    (["--alpha", "2", "--rtol", "1e-5"], "rtol would do nothing"),
    (["--alpha", "2", "--beta", "0.5", "--method", "verlet", "--rtol", "1e-5"], "rtol"),
    (["--masses", "1,2", "--springs", "1", "--contact-law", '{"law": "rigid", "k": 5}'], "'rigid'"),
]


@pytest.mark.parametrize("args, name", CLI_BAD)
def test_cli_bad_input_is_one_line(args, name, capsys):
    assert cli.main(["cor", *args]) == cli.EXIT_INPUT
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("restitution: error:"), err
    assert name.split("\\")[0] in err[0]


def test_cli_bad_table_cells_are_one_line(tmp_path, capsys):
    for frame, name in (
        (pd.DataFrame({"masses": ["1;2"], "springs": ["1"], "links": ["5"]}), "links"),
        (pd.DataFrame({"alpha": [0.5], "eta": [2.0]}), "eta"),
        (pd.DataFrame({"alpha": ["1e-9"]}), "alpha"),
    ):
        path = tmp_path / "in.csv"
        frame.to_csv(path, index=False)
        assert cli.main(["batch", str(path), "-o", str(tmp_path / "o.csv")]) == cli.EXIT_INPUT
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and name in err[0], err
        assert not (tmp_path / "o.csv").exists()


def test_cli_process_prints_no_traceback():
    run = subprocess.run(
        [sys.executable, "-m", "restitution.cli", "cor", "--alpha", "0.5", "--history",
         "--max-events", "4611686018427387904"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert run.returncode == cli.EXIT_INPUT
    assert "Traceback" not in run.stderr and "max_events" in run.stderr


def test_unwritable_numba_cache_falls_back_to_a_private_one(tmp_path):
    """NUMBA_CACHE_DIR that cannot be written (here: below a file; in practice another user's
    folder): a private cache instead, with one line saying so, and no traceback."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(blocker / "cache"))
    run = subprocess.run(
        [sys.executable, "-c", "import os, restitution; print(os.environ['NUMBA_CACHE_DIR'])"],
        capture_output=True, text=True, env=env, timeout=120,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr
    assert "not writable" in run.stderr and "private cache" in run.stderr
    chosen = run.stdout.strip()
    assert chosen != str(blocker / "cache") and os.access(chosen, os.W_OK)


def test_every_entry_point_shares_one_numba_cache(tmp_path):
    """Without NUMBA_CACHE_DIR, Python, the command line and the processes they start use the
    checkout's .cache/numba (the folder make uses), not numba's __pycache__ per module."""
    from restitution.kernels.compiling import source_key

    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    expected = str(REPO / ".cache" / "numba" / source_key())  # the sources' own folder
    probe = (
        "import os, restitution\nfrom numba.core import config\n"
        "print(os.environ['NUMBA_CACHE_DIR'], config.CACHE_DIR)"
    )
    run = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, env=env, cwd=tmp_path,
        timeout=120,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == [expected, expected]
    # numba imported first (as a notebook may): the package still moves it to the one cache
    probe = "import numba, os, restitution\nprint(numba.config.CACHE_DIR)"
    run = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, env=env, cwd=tmp_path,
        timeout=120,
    )  # fmt: skip
    assert run.returncode == 0 and run.stdout.strip() == expected, run.stderr
    from restitution.kernels.compiling import default_cache_dir

    assert default_cache_dir() == str(REPO / ".cache" / "numba")
    # a process started with the keyed folder keeps it (no folder in a folder)
    run = subprocess.run(
        [sys.executable, "-c", "import os, restitution; print(os.environ['NUMBA_CACHE_DIR'])"],
        capture_output=True, text=True, env=dict(env, NUMBA_CACHE_DIR=expected), cwd=tmp_path,
        timeout=120,
    )  # fmt: skip
    assert run.returncode == 0 and run.stdout.strip() == expected, run.stderr


def test_cache_folder_follows_every_compiled_source(tmp_path):
    """numba checks a cached kernel against its own file only, while a kernel compiles in what
    it calls from other files (paper_chain.solve_linear ran exact_chain's old code after an edit
    of exact_chain.py): the cache folder is a hash of every compiled source, so an edit in any
    of them (a kernel, a law, a shared constant) is a new folder, and nothing else is."""
    import shutil

    package = tmp_path / "restitution"
    shutil.copytree(REPO / "src" / "restitution", package, ignore=shutil.ignore_patterns("*.pyc"))
    probe = "from restitution.kernels.compiling import source_key; print(source_key())"

    def key():
        env = dict(os.environ, PYTHONPATH=str(tmp_path))
        run = subprocess.run(
            [sys.executable, "-c", probe], capture_output=True, text=True, env=env, timeout=120
        )
        assert run.returncode == 0, run.stderr
        return run.stdout.strip()

    first = key()
    assert len(first) == 12 and key() == first
    for edited in ("kernels/exact_chain.py", "kernels/constants.py", "model/laws.py"):
        path = package / edited
        path.write_text(path.read_text() + "\n# edited\n")
        second = key()
        assert second != first, edited
        first = second
    docs = package / "cli.py"  # not compiled by numba: the same folder
    docs.write_text(docs.read_text() + "\n# edited\n")
    assert key() == first


def test_compile_notice_also_after_a_kernel_edit(tmp_path):
    """``cold`` (the compile notice's test): True before the first compile, False once the
    cache holds the kernel, True again once its source file is edited (numba's index is then
    stale and it compiles anew: the minutes of silence after a kernel edit). The notice goes to
    stderr and to a configured log (a workflow job's)."""
    module = tmp_path / "kern.py"
    source = "import numba\n\n@numba.njit(cache=True)\ndef f(x):\n    return x + 1\n"
    module.write_text(source)
    probe = (
        "import logging, sys\n"
        "logging.basicConfig(stream=sys.stdout, level=logging.INFO, format='log %(name)s')\n"
        "import restitution, kern\nfrom restitution.kernels.compiling import announce, cold\n"
        "print(cold(kern.f)); announce(kern.f); kern.f(1); print(cold(kern.f))"
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=os.pathsep.join(
        [str(tmp_path), str(REPO / "src"), os.environ.get("PYTHONPATH", "")]))  # fmt: skip

    def run():
        p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                           env=env, cwd=tmp_path, timeout=120)  # fmt: skip
        assert p.returncode == 0, p.stderr
        noticed = "restitution: compiling the numba kernels" in p.stderr
        logged = "log restitution.kernels.compiling" in p.stdout.splitlines()
        assert noticed == logged, (p.stdout, p.stderr)
        return [line for line in p.stdout.splitlines() if line in ("True", "False")], noticed

    assert run() == (["True", "False"], True)  # nothing cached; compiled in this process
    assert run() == (["False", "False"], False)  # loaded from the cache
    module.write_text(source.replace("x + 1", "x + 10"))  # an edit (the file's size changes)
    assert run() == (["True", "False"], True)  # the index is stale: numba compiles again
