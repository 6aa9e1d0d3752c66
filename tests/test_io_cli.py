"""Tables on disk (schema, provenance, atomicity, clear errors) and the command line."""

import json
import subprocess
import sys

import pandas as pd
import pyarrow.parquet as pq
import pytest

from restitution.tables.io import TableError, config_hash, read_provenance, read_table, write_table


def _run(*args):
    return subprocess.run(
        [sys.executable, "-m", "restitution.cli", *args], capture_output=True, text=True
    )


def test_parquet_has_explicit_schema_and_provenance(tmp_path):
    frame = pd.DataFrame({"alpha": [1, 2], "n_masses": [2, 3], "method": ["a", "b"]})
    path = write_table(frame, tmp_path / "t.parquet", config={"b": 1, "a": [1, 2]})
    schema = pq.read_schema(path)
    assert str(schema.field("alpha").type) == "double"  # ints in, contract type out
    assert str(schema.field("n_masses").type) == "int64"
    meta = read_provenance(path)
    assert meta["config_hash"] == config_hash({"a": [1, 2], "b": 1})
    assert {"numpy", "numba", "pyarrow"} <= set(meta["libraries"])
    assert meta["git_commit"] and meta["package_version"]
    assert meta["methods"] == {"a": {"rows": 1}, "b": {"rows": 1}}
    assert list(path.parent.iterdir()) == [path]  # no temporary file left behind


def test_truncated_parquet_names_the_file(tmp_path):
    path = write_table(pd.DataFrame({"alpha": [1.0] * 100}), tmp_path / "t.parquet")
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(TableError, match="t.parquet"):
        read_table(path)
    with pytest.raises(TableError, match="no such results file"):
        read_table(tmp_path / "missing.parquet")


@pytest.mark.parametrize("suffix", [".parquet", ".csv"])
def test_required_columns_are_checked(tmp_path, suffix):
    path = write_table(pd.DataFrame({"alpha": [1.0], "cor": [0.5]}), tmp_path / f"t{suffix}")
    assert list(read_table(path, columns=("alpha", "cor")).columns) == ["alpha", "cor"]
    with pytest.raises(TableError, match=r"t\.\w+: missing column\(s\) \['n_collisions'\]"):
        read_table(path, columns=("alpha", "n_collisions"))


def test_cli_cor_json():
    p = _run("cor", "--alpha", "1", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["cor"] == pytest.approx(1.0, abs=1e-12)
    assert d["n_collisions"] == 2 and d["method"] == "impulsive" and d["status"] == "ok"


def test_cli_cor_bad_input_names_parameter():
    p = _run("cor", "--alpha", "-2")
    assert p.returncode == 2
    assert "alpha must be in [1e-8, 1e8]; got -2.0" in p.stderr


@pytest.mark.parametrize("suffix_in, suffix_out", [(".csv", ".parquet"), (".parquet", ".csv")])
def test_cli_batch_roundtrip(tmp_path, suffix_in, suffix_out):
    frame = pd.DataFrame({"alpha": [0.3, 2.0], "beta": [0.0, 0.05], "tag": ["x", "y"]})
    src, dst = tmp_path / f"in{suffix_in}", tmp_path / f"out{suffix_out}"
    write_table(frame, src)
    p = _run("batch", str(src), "-o", str(dst))
    assert p.returncode == 2 and "unknown column(s) 'tag'" in p.stderr and "--keep" in p.stderr
    p = _run("batch", str(src), "-o", str(dst), "--keep", "tag")
    assert p.returncode == 0, p.stderr
    out = read_table(dst)
    assert list(out["tag"]) == ["x", "y"]
    assert out["cor"].iloc[0] == pytest.approx(0.7 / 1.3, abs=1e-14)
    assert set(out["status"]) == {"ok"}


def test_cli_batch_bad_row_fails_before_writing(tmp_path):
    src, dst = tmp_path / "in.csv", tmp_path / "out.parquet"
    pd.DataFrame({"alpha": [1.0, 0.0]}).to_csv(src, index=False)
    p = _run("batch", str(src), "-o", str(dst))
    assert p.returncode == 2 and "alpha" in p.stderr and "(row 1)" in p.stderr
    assert not dst.exists()


def test_cli_cor_plastic_contact():
    p = _run(
        "cor",
        "--alpha",
        "2",
        "--beta",
        "0.01",
        "--contact",
        "plastic",
        "--eta",
        "0.5",
        "--dr",
        "0.5",
        "--json",
    )
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["method"] == "adaptive" and d["status"] == "ok"
    assert 0 < d["cor"] <= (1 - 0.5 / 3) ** 0.5  # paper Eq. 23 bound
    p = _run("cor", "--alpha", "2", "--beta", "0.01", "--contact", "plastic", "--eta", "-1")
    assert p.returncode == 2 and "eta" in p.stderr


def test_cli_version_and_exit_codes_in_help():
    import restitution

    p = _run("--version")
    assert p.returncode == 0 and p.stdout.strip() == f"restitution {restitution.__version__}"
    p = _run("--help")
    assert p.returncode == 0
    for code in ("0 ", "1 ", "2 ", "3 ", "130", "143"):
        assert f"  {code}" in p.stdout
    assert "exit codes" in _run("batch", "--help").stdout


def test_cli_batch_progress_only_on_a_terminal(tmp_path):
    src = write_table(pd.DataFrame({"alpha": [0.3, 2.0]}), tmp_path / "in.csv")
    p = _run("batch", str(src), "-o", str(tmp_path / "out.csv"))  # stderr is a pipe here
    assert p.returncode == 0 and "scene" not in p.stderr
    p = _run("batch", str(src), "-o", str(tmp_path / "out.csv"), "--progress")
    assert p.returncode == 0 and "2/2" in p.stderr and "scene" in p.stderr


def test_cli_batch_exit_code_3_when_a_row_does_not_finish(tmp_path):
    src = write_table(pd.DataFrame({"alpha": [0.3, 100.0]}), tmp_path / "in.csv")
    p = _run("batch", str(src), "-o", str(tmp_path / "out.csv"), "--max-events", "3")
    assert p.returncode == 3 and "1 event_budget_exhausted" in p.stderr
    assert read_table(tmp_path / "out.csv")["status"].tolist() == ["ok", "event_budget_exhausted"]


def test_cli_cor_json_carries_law_parameters():
    p = _run("cor", "--alpha", "2", "--beta", "0.01", "--contact", "plastic", "--eta", "0.5",
             "--dr", "0.5", "--json")  # fmt: skip
    d = json.loads(p.stdout)
    assert d["scene"]["contact"] == {"law": "plastic", "k": 2 / 3 / 0.01, "eta": 0.5, "dr": 0.5}
    p = _run("cor", "--alpha", "0.5", "--json")
    d = json.loads(p.stdout)
    assert d["scene"]["contact"] == {"law": "rigid"} and d["scene"]["k_contact"] == "inf"


def test_cli_batch_prints_a_one_line_summary(tmp_path):
    src = write_table(pd.DataFrame({"alpha": [0.3, 2.0, 100.0]}), tmp_path / "in.csv")
    dst = tmp_path / "out.parquet"
    p = _run("batch", str(src), "-o", str(dst), "--max-events", "3")
    assert p.returncode == 3
    [summary] = [line for line in p.stderr.splitlines() if line.startswith("restitution: 3 rows")]
    assert summary.endswith(f"(2 ok, 1 event_budget_exhausted) -> {dst}")
    assert float(summary.split(" in ")[1].split(" s ")[0]) > 0  # the time, in seconds
    p = _run("batch", str(src), "-o", str(dst), "--max-events", "3", "--quiet", "--progress")
    assert p.returncode == 3 and "restitution: 3 rows" not in p.stderr and "3/3" not in p.stderr
    assert "1 event_budget_exhausted" in p.stderr  # the warning stays


def test_batch_summary_line():
    from pathlib import Path

    from restitution.cli import batch_summary

    status = pd.Series(["ok", "precise_failed", "ok", "ill_conditioned", "ill_conditioned"])
    assert batch_summary(status, 12.34, Path("o.csv")) == (
        "restitution: 5 rows in 12.3 s (2 ok, 2 ill_conditioned, 1 precise_failed) -> o.csv"
    )
    assert batch_summary(pd.Series(["ok"]), 0.04, Path("o.csv")) == (
        "restitution: 1 row in 0.0 s (1 ok) -> o.csv"
    )
    assert "(0 ok, 1 x)" in batch_summary(pd.Series(["x"]), 1.0, Path("o.csv"))
