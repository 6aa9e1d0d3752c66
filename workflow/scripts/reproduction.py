"""Every number the paper prints next to ours (rule ``reproduction``): results/reproduction.csv.

The paper's printed values come from config/paper_values.yaml (the file the captions quote too).
Reads existing results tables only (no solver runs): the exact beta = 0 special points, the
Fig. 2(a) minima, the finite-beta smooth minima, the Fig. 3 marginal beta and the law fits. Each
row holds the paper's value as printed (a string), ours, ``difference = ours - paper`` and a
verdict: "agrees" when |ours - paper| is at most half a unit of the paper's last printed digit,
otherwise "differs" with the reason in ``note``. A quantity outside a small configuration's
range (e.g. the second beta = 0 minimum when fig2a.alpha_max < 2) is listed as "missing".
"""

import json
import math
from decimal import Decimal
from pathlib import Path

import pandas as pd

NAN = float("nan")
#: The paper's printed numbers, one committed file shared with the figure captions.
PAPER_VALUES = Path(__file__).resolve().parents[2] / "config" / "paper_values.yaml"
COLUMNS = ["quantity", "paper", "ours", "difference", "verdict", "note", "source"]


def printed_number(paper: str) -> Decimal:
    """The numeric value of a printed string ("0.178", "97%", "4.49341")."""
    return Decimal(paper.strip().rstrip("%").strip())


def half_unit(paper: str) -> Decimal:
    """Half a unit of the last printed digit: "0.178" -> 0.0005, "97%" -> 0.5, "0.1" -> 0.05."""
    exponent = printed_number(paper).as_tuple().exponent
    return Decimal(5).scaleb(exponent - 1)


def compare(paper: str, ours: float) -> tuple[float, str]:
    """(ours - paper, verdict), in exact decimal arithmetic on ours' shortest repr."""
    if math.isnan(float(ours)):
        return NAN, "missing"
    diff = Decimal(repr(float(ours))) - printed_number(paper)
    verdict = "agrees" if abs(diff) <= half_unit(paper) else "differs"
    return float(diff), verdict


def omega_dt_first(alpha_star_1: float) -> float:
    """omega*dt*_1 from Eq. (10), 2 cos x = 1 - 1/alpha, on the branch x in (pi, 2 pi)."""
    return 2 * math.pi - math.acos((1 - 1 / alpha_star_1) / 2)


def quantities(special, minima2a, finite, marginal, fit, paper: dict | None = None) -> list[dict]:
    """Rows (quantity, paper, ours, note-if-differs, source) before the verdicts.

    ``paper`` holds the paper's printed values (default: the committed config/paper_values.yaml).
    """
    paper = load_paper(PAPER_VALUES) if paper is None else paper
    sp1 = special.sort_values("n").iloc[0]
    a1, e1 = float(sp1["alpha_star"]), float(sp1["e_star"])
    m0 = minima2a[minima2a["beta"] == 0].sort_values("alpha").reset_index(drop=True)
    b1 = finite[(finite["beta"] == 1) & (finite["kind"] == "smooth_minimum")]
    b1 = b1.loc[b1["cor"].idxmin()] if len(b1) else pd.Series({"alpha": NAN, "cor": NAN})
    fits = fit["fits"]
    x1 = omega_dt_first(a1)
    rows = []
    m2a = "results/fig2a/minima.csv (beta = 0)"
    for i in range(3):
        cor, alpha = paper[f"rigid_min{i + 1}_cor"], paper[f"rigid_min{i + 1}_alpha"]
        rows += [
            dict(quantity=f"beta=0 minimum {i + 1}: COR", paper=cor, ours=m0["cor"].get(i, NAN),
                 why="the paper truncates: 0.5576 rounds to 0.558", source=m2a),
            dict(quantity=f"beta=0 minimum {i + 1}: alpha", paper=alpha,
                 ours=m0["alpha"].get(i, NAN), why="", source=m2a),
        ]  # fmt: skip
    sp = "results/approx/special_points.parquet (n = 1)"
    rows += [
        dict(quantity="alpha*_1", paper=paper["alpha_star_1"], ours=a1, why="", source=sp),
        dict(quantity="e*_1 (minimum COR)", paper=paper["e_star_1"], ours=e1,
             why="0.178481 is e1 at the rounded alpha = 0.6971, on the steep single-contact "
                 "branch; the exact minimum at alpha*_1 = 0.697123 is 0.178465", source=sp),
        dict(quantity="omega*dt*_1 (first root of tan x = x)", paper=paper["first_root_tan"],
             ours=x1,
             why="", source="Eq. 10 (2 cos x = 1 - 1/alpha) at alpha*_1 of " + sp),
        dict(quantity="energy stored in vibration at alpha*_1, 1 - e*_1^2 (%)",
             paper=paper["energy_in_vibration"], ours=100 * (1 - e1**2), why="", source=sp),
    ]  # fmt: skip
    fb = "results/approx/finite_beta_points.parquet (beta = 1, smallest smooth minimum)"
    rows += [
        dict(quantity="beta=1 smallest COR", paper=paper["beta1_min_cor"],
             ours=b1["cor"], why="", source=fb),
        dict(quantity="beta=1 alpha of smallest COR", paper=paper["beta1_min_alpha"],
             ours=b1["alpha"],
             why="the beta = 1 minimum is smooth and flat: COR at alpha = 3.42 is only ~4e-5 above "
                 "the minimum (both print 0.91), so the paper's scan step sets its alpha; ours "
                 "is root-solved", source=fb),
        dict(quantity="Fig. 3 marginal beta (alpha = 2.2, third contact vanishes)",
             paper=paper["fig3_marginal_beta"], ours=float(marginal["beta_marginal"].iloc[0]),
             why="", source="results/fig3/marginal_beta.csv"),
    ]  # fmt: skip
    fj = "results/approx/fit.json"
    rows += [
        dict(quantity="Eq. 19 exponent p", paper=paper["eq19_p"],
             ours=fits["eq19_unity"]["params"]["p"],
             why="", source=fj + " eq19_unity"),
        dict(quantity="Eq. 22 exponent q", paper=paper["eq22_q"],
             ours=fits["eq22_gap_n1"]["params"]["q"],
             why="", source=fj + " eq22_gap_n1"),
        dict(quantity="minima-fit constant c in e = (alpha* - c)/(1 + alpha*)",
             paper=paper["minima_c"], ours=fits["minima_c_n1"]["params"]["c"], why="",
             source=fj + " minima_c_n1"),
        dict(quantity="COR reduction from 1 to e*_1, 1 - e*_1 (%)", paper=paper["cor_reduction"],
             ours=100 * (1 - e1), why="", source=sp),
        dict(quantity="alpha reduction from 1 to alpha*_1, 1 - alpha*_1 (%)",
             paper=paper["alpha_reduction"], ours=100 * (1 - a1), why="", source=sp),
    ]  # fmt: skip
    return rows


def build_table(rows: list[dict]) -> pd.DataFrame:
    """Verdicts for rows of (quantity, paper, ours, why, source); note = why when they differ."""
    out = []
    for row in rows:
        diff, verdict = compare(row["paper"], row["ours"])
        if math.isnan(float(row["ours"])):
            diff, verdict = NAN, "missing"
            note = "not in the results tables (outside the configured range)"
        elif verdict == "agrees":
            note = f"within half a unit of the last printed digit ({half_unit(row['paper'])})"
        else:
            note = row.get("why") or "no explanation found"
        out.append(
            dict(
                quantity=row["quantity"],
                paper=row["paper"],
                ours=float(row["ours"]),
                difference=diff,
                verdict=verdict,
                note=note,
                source=row["source"],
            )
        )
    return pd.DataFrame(out, columns=COLUMNS)


def load_paper(path) -> dict:
    """config/paper_values.yaml: the paper's printed numbers as strings (digits as printed)."""
    import yaml

    with open(path) as fh:
        return {key: str(value) for key, value in yaml.safe_load(fh).items()}


#: Page layout of results/reproduction.html: fixed, readable column widths, notes wrapped as prose.
PAGE_STYLE = """
body { font-family: sans-serif; font-size: 13px; margin: 1em; }
table { border-collapse: collapse; table-layout: fixed; width: 100%; min-width: 1100px; }
th, td { border-bottom: 1px solid #ccc; padding: 4px 6px; vertical-align: top; text-align: left; }
th { background: #f0f0f0; }
col.quantity { width: 22%; } col.num { width: 7%; } col.verdict { width: 6%; }
col.note { width: 32%; } col.source { width: 19%; }
td.differs { color: #a00; } td.agrees { color: #060; }
"""


def write_page(table: pd.DataFrame, path) -> None:
    """The table as a standalone HTML page (its own report page) with readable columns."""
    import html

    cols = ["quantity", "num", "num", "num", "verdict", "note", "source"]
    head = "".join(f'<col class="{c}">' for c in cols)
    names = "".join(f"<th>{html.escape(c)}</th>" for c in COLUMNS)
    body = []
    for row in table.itertuples(index=False):
        cells = []
        for name, value in zip(COLUMNS, row, strict=True):
            text = f"{value:.6g}" if isinstance(value, float) else str(value)
            cls = f' class="{value}"' if name == "verdict" else ""
            cells.append(f"<td{cls}>{html.escape(text)}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    Path(path).write_text(
        "<!DOCTYPE html><html><head><meta charset='utf-8'><title>Reproduction table</title>"
        f"<style>{PAGE_STYLE}</style></head><body><h2>Reproduction table: the paper's numbers "
        "and ours</h2><table><colgroup>"
        + head
        + "</colgroup><thead><tr>"
        + names
        + "</tr></thead><tbody>"
        + "".join(body)
        + "</tbody></table></body></html>\n"
    )


def main(inputs, output_path, logger, page_path=None) -> pd.DataFrame:
    from restitution.tables.io import read_table

    special = read_table(inputs.special)
    finite = read_table(inputs.finite)
    minima2a = pd.read_csv(inputs.minima)
    marginal = pd.read_csv(inputs.marginal)
    with open(inputs.fit) as fh:
        fit = json.load(fh)
    paper = load_paper(inputs.paper)
    table = build_table(quantities(special, minima2a, finite, marginal, fit, paper))
    table.to_csv(output_path, index=False, float_format="%.10g")
    if page_path is not None:
        write_page(table, page_path)
    logger.info("reproduction table:\n%s", table.drop(columns=["note", "source"]).to_string())
    return table


if __name__ == "__main__":
    from _common import setup

    smk = snakemake  # noqa: F821 (injected by Snakemake)
    log = setup(smk, numba=False)
    main(smk.input, smk.output.table, log, smk.output.page)
