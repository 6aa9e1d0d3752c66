"""Write docs/tables.md from workflow/tables.yaml (the one list of the result tables).

Usage: ``python workflow/scripts/tables_doc.py > docs/tables.md`` (tests/test_tables_list.py
checks that the committed page is what this prints).
"""

import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]

HEAD = """\
# Result tables

<!-- Generated from workflow/tables.yaml by workflow/scripts/tables_doc.py: edit those, not this
page. tests/test_tables_list.py checks this page, the list and the workflow's outputs agree. -->

Every table target `all` writes (`snakemake -c2 all`, `make all`). Paths are relative to the
run's folder: the repository for the paper's run, `runs/<run>/` for any other run
([runs](runs.md)). `all` requests every table below, so a deleted or missing table is rebuilt by
the next `snakemake -c2 all`. A `{wildcard}` path stands for one file per value (per beta, chunk,
chain length, damping ratio); these are the inputs of the table after them and are rebuilt with it.

Parquet tables carry their provenance (package version, git commit, configuration and its hash,
library versions) in the file's metadata under the key `restitution`:
`restitution.tables.io.read_provenance(path)` returns it. Tables are written atomically (a
complete file or none).

| table | made by rule | contents |
|---|---|---|
"""

TAIL = """
Tables of the other targets (not part of `all`):

| table | target | contents |
|---|---|---|
| `results/studies/<name>/*` | `study` | a user's own study ([studies](study.md)) |
| `results/benchmarks/*` | `benchmarks` | the work-precision study (`make benchmarks`) |
"""


def render(tables_yaml: Path = ROOT / "workflow" / "tables.yaml") -> str:
    """The text of docs/tables.md."""
    entries = yaml.safe_load(tables_yaml.read_text())["tables"]
    rows = [f"| `{e['path']}` | `{e['rule']}` | {e['about']} |" for e in entries]
    return HEAD + "\n".join(rows) + "\n" + TAIL


if __name__ == "__main__":
    sys.stdout.write(render())
