"""The reproduction table's verdict logic (workflow/scripts/reproduction.py) on synthetic input."""

import importlib.util
import math
from decimal import Decimal
from pathlib import Path

import pandas as pd
import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "workflow" / "scripts" / "reproduction.py"
_spec = importlib.util.spec_from_file_location("reproduction", SCRIPT)
reproduction = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(reproduction)


@pytest.mark.parametrize(
    "paper, half",
    [("0.178", "0.0005"), ("0.710", "0.0005"), ("0.6971", "0.00005"), ("0.1", "0.05"),
     ("97%", "0.5"), ("4.49341", "0.000005"), ("3.42", "0.005")],
)  # fmt: skip
def test_half_unit_counts_digits_of_the_printed_string(paper, half):
    assert reproduction.half_unit(paper) == Decimal(half)


@pytest.mark.parametrize(
    "paper, ours, verdict",
    [
        ("0.178", 0.1785, "agrees"),  # exactly half a unit above: agrees
        ("0.178", 0.1775, "agrees"),  # exactly half a unit below: agrees
        ("0.178", 0.17851, "differs"),
        ("0.178", 0.17749, "differs"),
        ("0.710", 0.7105, "agrees"),  # trailing zero counts as a printed digit
        ("0.710", 0.7106, "differs"),
        ("0.71", 0.7149, "agrees"),
        ("97%", 96.5, "agrees"),
        ("97%", 96.49, "differs"),
        ("0.178481", 0.178465, "differs"),
    ],
)
def test_verdict_at_the_half_unit_boundary(paper, ours, verdict):
    diff, got = reproduction.compare(paper, ours)
    assert got == verdict
    assert diff == pytest.approx(ours - float(paper.rstrip("%")), abs=1e-12)


def test_omega_dt_is_the_tan_root():
    x = reproduction.omega_dt_first(0.6971229182979068)
    assert math.pi < x < 2 * math.pi
    assert math.tan(x) == pytest.approx(x, rel=1e-6)


def synthetic_inputs(e1=0.178465, second=0.5576):
    special = pd.DataFrame({"n": [2, 1], "alpha_star": [2.07, 0.697123], "e_star": [0.5576, e1]})
    minima = pd.DataFrame(
        {"beta": [0.0, 0.0, 0.0, 1.0], "alpha": [0.697, 2.07, 3.64, 3.4],
         "cor": [0.178, second, 0.710, 0.91]}
    )  # fmt: skip
    finite = pd.DataFrame(
        {"beta": [1.0, 1.0, 1.0, 0.1], "kind": ["smooth_minimum"] * 2 + ["count_change"] * 2,
         "alpha": [0.68, 3.42, 3.0, 1.0], "cor": [0.96, 0.91, 0.5, 0.5]}
    )  # fmt: skip
    marginal = pd.DataFrame({"beta_marginal": [0.1]})
    fit = {"fits": {"eq19_unity": {"params": {"p": 0.8}}, "eq22_gap_n1": {"params": {"q": 0.21}},
                    "minima_c_n1": {"params": {"c": 0.4}}}}  # fmt: skip
    return special, minima, finite, marginal, fit


def test_table_from_synthetic_frames():
    table = reproduction.build_table(reproduction.quantities(*synthetic_inputs()))
    assert list(table.columns) == reproduction.COLUMNS
    assert table["paper"].map(type).eq(str).all()
    rows = table.set_index("quantity")
    # Picked from the right rows: n = 1 although listed second, beta = 0 only, smallest smooth
    # minimum at beta = 1 (count changes ignored).
    assert rows.loc["alpha*_1", "ours"] == 0.697123
    assert rows.loc["beta=1 smallest COR", "ours"] == 0.91
    assert rows.loc["beta=1 alpha of smallest COR", "verdict"] == "agrees"
    assert rows.loc["beta=0 minimum 2: COR", "verdict"] == "differs"  # 0.5576 vs "0.557"
    e1 = rows.loc["e*_1 (minimum COR)"]
    assert e1["verdict"] == "differs" and "0.6971" in e1["note"]
    assert e1["difference"] == pytest.approx(0.178465 - 0.178481)
    for q in ("Eq. 19 exponent p", "Eq. 22 exponent q", "beta=0 minimum 1: COR"):
        assert rows.loc[q, "verdict"] == "agrees" and rows.loc[q, "difference"] == 0
    assert rows.loc["COR reduction from 1 to e*_1, 1 - e*_1 (%)", "ours"] == pytest.approx(82.1535)
    assert (table.loc[table.verdict == "differs", "note"].str.len() > 0).all()


def test_agreeing_e1_when_exactly_the_printed_value():
    table = reproduction.build_table(reproduction.quantities(*synthetic_inputs(e1=0.178481)))
    assert table.set_index("quantity").loc["e*_1 (minimum COR)", "verdict"] == "agrees"


def test_quantities_outside_a_small_range_are_missing():
    special, minima, finite, marginal, fit = synthetic_inputs()
    minima = minima[minima["alpha"] < 1]  # only the first beta = 0 minimum
    finite = finite[finite["beta"] != 1]
    table = reproduction.build_table(
        reproduction.quantities(special, minima, finite, marginal, fit)
    )
    rows = table.set_index("quantity")
    assert rows.loc["beta=0 minimum 1: COR", "verdict"] == "agrees"
    for q in ("beta=0 minimum 2: COR", "beta=0 minimum 3: alpha", "beta=1 smallest COR"):
        assert rows.loc[q, "verdict"] == "missing" and math.isnan(rows.loc[q, "difference"])
    assert reproduction.compare("0.178", float("nan"))[1] == "missing"
