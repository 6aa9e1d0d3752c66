"""The one list of result tables (workflow/tables.yaml) against the documentation and the DAG.

Both ways: every table the DAG of target `all` writes under results/ is listed, every listed
table is written by that DAG (by the rule the list names), and every listed table without a
{wildcard} is an input of `all` itself, so that a deleted table is rebuilt by `snakemake all`
(the rebuild itself is tested in test_reliability.py).
"""

import importlib.util
import re

import pytest
import yaml

from conftest import REPO, copy_workflow, run_snakemake

ENTRIES = yaml.safe_load((REPO / "workflow" / "tables.yaml").read_text())["tables"]


def _pattern(path: str) -> re.Pattern:
    """A listed path as a regex: each {wildcard} stands for one path component part."""
    parts = re.split(r"\{[^}]+\}", path)
    return re.compile("[^/]+".join(re.escape(p) for p in parts) + "$")


@pytest.fixture(scope="module")
def summary() -> dict[str, str]:
    """output file -> rule, for every job of the DAG of `all` (paper configuration)."""
    result = run_snakemake("--summary", "all")
    assert result.returncode == 0, result.stderr[-3000:]
    rows = [line.split("\t") for line in result.stdout.splitlines()[1:] if line.strip()]
    return {row[0]: row[2] for row in rows}


def test_docs_page_is_generated_from_the_list():
    path = REPO / "workflow" / "scripts" / "tables_doc.py"
    spec = importlib.util.spec_from_file_location("tables_doc", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert (REPO / "docs" / "tables.md").read_text() == module.render(), (
        "docs/tables.md is stale: python workflow/scripts/tables_doc.py > docs/tables.md"
    )


def test_list_has_no_duplicates_and_names_a_rule_each():
    paths = [e["path"] for e in ENTRIES]
    assert len(paths) == len(set(paths))
    for entry in ENTRIES:
        assert set(entry) == {"path", "rule", "about"}, entry
        assert entry["path"].startswith("results/"), entry


TABLE_SUFFIXES = (".parquet", ".csv", ".json")  # tables; not e.g. rendered captions (.rst)


def test_every_table_of_the_dag_is_listed(summary):
    tables = sorted(p for p in summary if p.startswith("results/") and p.endswith(TABLE_SUFFIXES))
    assert tables, "no results/ outputs in snakemake --summary all"
    patterns = [_pattern(e["path"]) for e in ENTRIES]
    unlisted = [t for t in tables if not any(p.match(t) for p in patterns)]
    assert not unlisted, f"tables of `all` missing from workflow/tables.yaml: {unlisted}"


def test_every_listed_table_is_made_by_its_rule(summary):
    for entry in ENTRIES:
        pattern = _pattern(entry["path"])
        made = {path: rule for path, rule in summary.items() if pattern.match(path)}
        assert made, f"{entry['path']}: listed, but no job of `all` writes it"
        assert set(made.values()) == {entry["rule"]}, (entry, made)


def test_all_requests_every_listed_table():
    """The `all` job's own inputs (dry run): a table nothing downstream reads is requested too."""
    # --quiet host: the full job blocks (the profile's listing is one line per job).
    result = run_snakemake("-n", "--forceall", "all", "--quiet", "host")
    assert result.returncode == 0, result.stderr[-3000:]
    block = result.stdout.split("rule all:", 1)[1]
    inputs = set(block.split("input:", 1)[1].split("\n", 1)[0].strip().split(", "))
    fixed = [e["path"] for e in ENTRIES if "{" not in e["path"]]
    missing = [path for path in fixed if path not in inputs]
    assert not missing, f"listed tables that `all` does not request: {missing}"


def test_every_deleted_table_is_planned_again(tmp_path):
    """Small run with every output present (empty files, put in order by --touch: no
    simulation), then every listed table deleted: a dry run of `all` plans each one again,
    naming it as a missing output."""
    work = copy_workflow(tmp_path)
    small = ("--configfile", str(work / "config" / "small.yaml"))
    listed = run_snakemake("--summary", "all", *small, cwd=work)
    assert listed.returncode == 0, listed.stderr[-3000:]
    run = work / "runs" / "small"
    for line in listed.stdout.splitlines()[1:]:
        path = run / line.split("\t")[0]
        path.parent.mkdir(parents=True, exist_ok=True)
        path.touch()
    touched = run_snakemake("-c1", "all", *small, "--touch", cwd=work)
    assert touched.returncode == 0, touched.stdout[-3000:] + touched.stderr[-3000:]
    assert run_snakemake("-n", "all", *small, cwd=work).stdout.count("\nrule ") == 0
    fixed = [e["path"] for e in ENTRIES if "{" not in e["path"]]
    for path in fixed:
        (run / path).unlink()
    result = run_snakemake("-n", "all", *small, cwd=work)
    assert result.returncode == 0, result.stdout + result.stderr
    reasons = [line for line in result.stdout.splitlines() if "Missing output files:" in line]
    missing = {
        p.strip()
        for line in reasons
        for p in line.split("Missing output files:", 1)[1].split(";")[0].split(",")
    }
    assert set(fixed) <= missing, sorted(set(fixed) - missing)
