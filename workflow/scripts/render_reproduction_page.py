"""The reproduction table as a page of the report (rule ``reproduction_page``).

Reads results/reproduction.csv (rule ``reproduction``) and writes one self-contained HTML page:
the same rows and columns, numbers as written in the CSV, verdicts coloured, and column widths
set so that the notes and sources stay readable (the table used to sit on the report's front
page, where its note column wrapped one word per line).
"""

import html

import pandas as pd

STYLE = """
body { font-family: system-ui, sans-serif; font-size: 14px; margin: 1.5em; color: #1e293b; }
h1 { font-size: 1.3em; margin: 0 0 0.3em 0; }
p { max-width: 70em; line-height: 1.4; }
table { border-collapse: collapse; width: 100%; }
th, td { text-align: left; vertical-align: top; padding: 0.35em 0.6em;
         border-bottom: 1px solid #cbd5e1; }
th { background: #f1f5f9; position: sticky; top: 0; }
td.num { font-variant-numeric: tabular-nums; white-space: nowrap; }
td.quantity { min-width: 12em; }
td.note { min-width: 16em; }
td.source { color: #475569; overflow-wrap: anywhere; min-width: 10em; }
td.agrees { color: #047857; font-weight: 600; }
td.differs { color: #b91c1c; font-weight: 600; }
td.missing { color: #92400e; font-weight: 600; }
"""
NUMERIC = ("paper", "ours", "difference")


def page(table: pd.DataFrame) -> str:
    head = "".join(f"<th>{html.escape(c)}</th>" for c in table.columns)
    rows = []
    for _, row in table.iterrows():
        cells = []
        for column in table.columns:
            value = "" if pd.isna(row[column]) else str(row[column])
            css = "num" if column in NUMERIC else column
            if column == "verdict":
                css = value
            cells.append(f'<td class="{html.escape(css)}">{html.escape(value)}</td>')
        rows.append("<tr>" + "".join(cells) + "</tr>")
    counts = table["verdict"].value_counts().to_dict() if "verdict" in table else {}
    summary = ", ".join(f"{n} {v}" for v, n in sorted(counts.items()))
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'>"
        f"<title>Reproduction: paper vs ours</title><style>{STYLE}</style></head><body>"
        "<h1>Reproduction: paper vs ours</h1>"
        f"<p>{len(table)} numbers ({html.escape(summary)}). <code>difference</code> is ours - "
        "paper; the verdict is <em>agrees</em> when it is at most half a unit of the paper's "
        "last printed digit, otherwise <em>differs</em>, with the reason in <code>note</code>. "
        "The same table as CSV: results/reproduction.csv.</p>"
        f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>"
        "</body></html>\n"
    )


def main(table_path, out_path) -> None:
    # Read as text: the page shows the numbers exactly as the CSV holds them.
    table = pd.read_csv(table_path, dtype=str, keep_default_na=False)
    with open(out_path, "w", encoding="utf-8") as f:
        f.write(page(table))


if __name__ == "__main__":
    from _common import setup

    log = setup(snakemake, numba=False)  # noqa: F821 (``snakemake`` is injected by Snakemake)
    main(snakemake.input.table, snakemake.output.page)  # noqa: F821
    log.info("wrote %s", snakemake.output.page)  # noqa: F821
