"""Strict tables: a malformed scene table never reaches a kernel (same rules for solve_many and
``restitution batch``), and table I/O fails with one line and a non-zero exit code."""

import math
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest

from restitution import SceneError, solve, solve_many
from restitution.tables.io import TableError, clean_leftovers, read_table, write_table


def _run(*args, **kw):
    return subprocess.run(
        [sys.executable, "-m", "restitution.cli", *map(str, args)],
        capture_output=True,
        text=True,
        **kw,
    )


def _csv(path, text):
    path.write_text(text)
    return path


# ----------------------------------------------------------------------------------------------
# Columns
# ----------------------------------------------------------------------------------------------
def test_unknown_column_is_rejected_with_a_suggestion(tmp_path):
    frame = pd.DataFrame({"alpha": [1.0], "bta": [0.1]})
    with pytest.raises(SceneError, match=r"unknown column\(s\) 'bta' \(did you mean 'beta'\?\)"):
        solve_many(frame)
    src = _csv(tmp_path / "in.csv", "alpha,bta\n1.0,0.1\n")
    p = _run("batch", src, "-o", tmp_path / "out.csv")
    assert p.returncode == 2 and "did you mean 'beta'?" in p.stderr
    assert p.stderr.count("\n") == 1 and not (tmp_path / "out.csv").exists()
    # named with keep, any column is carried through
    assert list(solve_many(frame.rename(columns={"bta": "x"}), keep=["x"])["x"]) == [0.1]


def test_duplicate_columns_are_rejected(tmp_path):
    frame = pd.DataFrame([[1.0, 2.0]], columns=["alpha", "alpha"])
    with pytest.raises(SceneError, match="column 'alpha' appears more than once"):
        solve_many(frame)
    src = _csv(tmp_path / "in.csv", "alpha,beta,alpha\n1,0,2\n")
    with pytest.raises(TableError, match="column 'alpha' appears more than once"):
        read_table(src)
    p = _run("batch", src, "-o", tmp_path / "out.csv")
    assert p.returncode == 2 and "more than once" in p.stderr


def test_stray_whitespace_in_a_header_is_rejected(tmp_path):
    with pytest.raises(SceneError, match=r"column ' beta' has stray whitespace"):
        solve_many(pd.DataFrame({"alpha": [1.0], " beta": [0.1]}))
    src = _csv(tmp_path / "in.csv", "alpha, beta\n1,0.1\n")
    p = _run("batch", src, "-o", tmp_path / "out.csv")
    assert p.returncode == 2 and "stray whitespace" in p.stderr


def test_ragged_rows_are_rejected_naming_the_row(tmp_path):
    for text, fields in (("alpha,beta\n1,0\n2,0,7\n", 3), ("alpha,beta\n1,0\n2\n", 1)):
        src = _csv(tmp_path / "in.csv", text)
        with pytest.raises(TableError, match=rf"line 3 \(row 1\) has {fields} fields"):
            read_table(src)
        p = _run("batch", src, "-o", tmp_path / "out.csv")
        assert p.returncode == 2 and "line 3 (row 1)" in p.stderr


@pytest.mark.parametrize("column", ["alpha", "beta", "xi", "n_masses"])
def test_booleans_are_not_numbers(column):
    frame = pd.DataFrame({"alpha": [1.0, 2.0]})
    frame[column] = [True, False] if column != "alpha" else [1.0, True]
    with pytest.raises(SceneError, match=rf"{column} must be .*got True \(row [01]\)"):
        solve_many(frame)


def test_booleans_in_csv(tmp_path):
    src = _csv(tmp_path / "in.csv", "alpha,beta\n1.0,True\n")
    p = _run("batch", src, "-o", tmp_path / "out.csv")
    assert p.returncode == 2 and "beta must be" in p.stderr and "(row 0)" in p.stderr


def test_text_and_nan_cells_name_row_and_column():
    with pytest.raises(SceneError, match=r"xi must be in \[0, 1e3\]; got 'lots' \(row 'b'\)"):
        solve_many(pd.DataFrame({"alpha": [1.0, 2.0], "xi": [0.0, "lots"]}, index=["a", "b"]))
    with pytest.raises(SceneError, match=r"alpha must be in \[1e-8, 1e8\]; got nan \(row 1\)"):
        solve_many(pd.DataFrame({"alpha": [1.0, np.nan]}))
    with pytest.raises(SceneError, match=r"masses must be ';'-separated numbers.*\(row 0\)"):
        solve_many(pd.DataFrame({"masses": ["1; x"], "springs": ["1"]}))
    with pytest.raises(SceneError, match=r"masses\[1\] must be in \[1e-100, 1e100\].*\(row 0\)"):
        solve_many(pd.DataFrame({"masses": ["1; -1"], "springs": ["1"]}))


def test_paper_and_general_columns_do_not_mix():
    with pytest.raises(SceneError, match="either the paper's form"):
        solve_many(pd.DataFrame({"alpha": [1.0], "masses": [[1.0, 2.0]], "springs": [[1.0]]}))
    with pytest.raises(SceneError, match="belong to the paper's form"):
        solve_many(pd.DataFrame({"masses": [[1.0, 2.0]], "springs": [[1.0]], "xi": [0.1]}))


@pytest.mark.parametrize("column, cell", [("velocities", "5;-3"), ("stretches", [0.5])])
def test_an_initial_state_column_does_not_go_with_alpha(column, cell):
    """(A paper-form table solved the uniform approach, ok, the column unread.)"""
    with pytest.raises(SceneError, match=rf"columns \['{column}'\] belong to the general form"):
        solve_many(pd.DataFrame({"alpha": [2.0], column: [cell]}))


@pytest.mark.parametrize(
    "cell, unknown",
    [('{"law": "linear", "k": 5, "c": 3.0}', "c"), ({"law": "rigid", "k": 5.0}, "k")],
)
def test_unknown_keys_of_a_linear_contact_cell_are_refused(cell, unknown):
    """(They were dropped: the linear contact's c=3 gave the undamped contact's COR, ok.)"""
    frame = pd.DataFrame({"masses": ["1;2", "1;2"], "springs": ["1", "1"], "contact": [None, cell]})
    with pytest.raises(SceneError, match=rf"unknown parameter\(s\) {unknown} .*\(row 1\)"):
        solve_many(frame)


# ----------------------------------------------------------------------------------------------
# Per-row settings
# ----------------------------------------------------------------------------------------------
def test_per_row_rtol_is_honoured_on_numerical_rows():
    frame = pd.DataFrame(
        {
            "alpha": [2.0, 2.0],
            "beta": [0.01, 0.01],
            "contact": ["plastic", "plastic"],
            "eta": [0.5, 0.5],
            "dr": [0.5, 0.5],
            "rtol": [1e-5, 1e-10],
        }
    )
    out = solve_many(frame)
    for i, rtol in enumerate((1e-5, 1e-10)):
        r = solve(2.0, 0.01, contact="plastic", eta=0.5, dr=0.5, rtol=rtol)
        assert out["cor"].iat[i] == r.cor and out["error_estimate"].iat[i] == r.error_estimate
    assert out["cor"].iat[0] != out["cor"].iat[1]


def test_per_row_settings_on_exact_rows_are_refused():
    frame = pd.DataFrame({"alpha": [2.0, 3.0], "rtol": [np.nan, 1e-6]})
    with pytest.raises(SceneError, match=r"rtol would do nothing: the method 'impulsive'.*row 1"):
        solve_many(frame)
    with pytest.raises(SceneError, match=r"rtol must be in \[1e-14, 1e-2\]"):
        solve_many(frame.assign(rtol=[np.nan, 5.0], method="adaptive"))


def test_a_setting_the_rows_method_does_not_read_is_refused():
    """step on an adaptive row, rtol on a verlet row: accepted and unread before."""
    frame = pd.DataFrame({"alpha": [2.0, 2.0], "beta": 0.5, "method": ["verlet", "adaptive"]})
    with pytest.raises(SceneError, match=r"step would do nothing: the method 'adaptive' .*row 1"):
        solve_many(frame.assign(step=[0.01, 0.1]))
    with pytest.raises(SceneError, match=r"rtol would do nothing: the method 'verlet' .*row 0"):
        solve_many(frame.assign(rtol=[1e-6, 1e-6]))
    out = solve_many(frame.assign(step=[0.01, np.nan], rtol=[np.nan, 1e-8]))
    assert list(out["status"]) == ["ok", "ok"]


# ----------------------------------------------------------------------------------------------
# Files
# ----------------------------------------------------------------------------------------------
def test_list_columns_round_trip_through_the_cli(tmp_path):
    src = _csv(
        tmp_path / "in.csv",
        "masses,springs,dashpots,k_contact\n1; 0.5; 2,0.3;1.2,0; 0.05,inf\n1;2,1,,50\n",
    )
    for out in (tmp_path / "out.parquet", tmp_path / "out.csv"):
        p = _run("batch", src, "-o", out)
        assert p.returncode == 0, p.stderr
        table = read_table(out)
        r = solve(masses=[1, 0.5, 2], springs=[0.3, 1.2], dashpots=[0, 0.05])
        assert table["cor"].iat[0] == pytest.approx(r.cor, abs=1e-15)
        assert table["status"].tolist() == ["ok", "ok"]
        if out.suffix == ".csv":  # lists written back as ';'-separated cells
            assert table["masses"].iat[0] == "1.0;0.5;2.0"
    # the parquet output (list columns) is itself a valid input
    again = tmp_path / "again.parquet"
    parquet_in = read_table(tmp_path / "out.parquet")
    write_table(parquet_in.drop(columns=[c for c in parquet_in if c not in
                                          ("masses", "springs", "dashpots", "k_contact")]),
                tmp_path / "in2.parquet")  # fmt: skip
    p = _run("batch", tmp_path / "in2.parquet", "-o", again)
    assert p.returncode == 0, p.stderr
    assert read_table(again)["cor"].tolist() == parquet_in["cor"].tolist()


def test_a_bad_csv_cell_is_named_not_the_columns_first(tmp_path, capsys):
    """One text cell made pandas read the whole column as text, and the error named its first
    cell, a good number ('2.0' (row 0))."""
    from restitution import cli

    path = _csv(tmp_path / "in.csv", "alpha,beta\n2.0,0.1\n0.5,0.2\nfoo,0.3\n")
    assert cli.main(["batch", str(path), "-o", str(tmp_path / "o.csv")]) == cli.EXIT_INPUT
    err = capsys.readouterr().err
    assert "alpha must be in [1e-8, 1e8]; got 'foo' (row 2)" in err
    path = _csv(tmp_path / "in.csv", "alpha,beta\n2.0,0.1\n0.5,x\n")
    with pytest.raises(SceneError, match=r"beta must be .*; got 'x' \(row 1\)"):
        solve_many(read_table(path))
    # the numbers of such a column are read as the numbers they are
    assert read_table(path)["beta"].tolist() == [0.1, "x"]


def test_output_may_not_be_the_input(tmp_path):
    src = write_table(pd.DataFrame({"alpha": [1.0]}), tmp_path / "in.csv")
    before = src.read_bytes()
    p = _run("batch", src, "-o", src)
    assert p.returncode == 2 and "is the input table" in p.stderr
    link = tmp_path / "link.csv"
    link.symlink_to(src)
    p = _run("batch", src, "-o", link)
    assert p.returncode == 2 and "is the input table" in p.stderr
    sub = tmp_path / "sub"
    sub.mkdir()
    p = _run("batch", src, "-o", sub / ".." / "in.csv")
    assert p.returncode == 2 and "is the input table" in p.stderr
    assert src.read_bytes() == before


def test_missing_input_and_bad_output_directory_are_one_line(tmp_path):
    p = _run("batch", tmp_path / "nope.csv", "-o", tmp_path / "out.csv")
    assert p.returncode == 2 and "nope.csv: no such scene table" in p.stderr  # (not "results")
    assert p.stderr.count("\n") == 1
    (tmp_path / "dir.csv").mkdir()
    p = _run("batch", tmp_path / "dir.csv", "-o", tmp_path / "out.csv")
    assert p.returncode == 2 and "dir.csv: is a directory, not a scene table" in p.stderr
    with pytest.raises(TableError, match="nope.parquet: no such results file"):
        read_table(tmp_path / "nope.parquet")
    src = write_table(pd.DataFrame({"alpha": [1.0]}), tmp_path / "in.csv")
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    p = _run("batch", src, "-o", blocker / "out.csv")
    assert p.returncode == 2 and "cannot write the table" in p.stderr
    assert p.stderr.count("\n") == 1 and "Traceback" not in p.stderr


def _mount_tmpfs(path, options):
    path.mkdir()
    p = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)],
                       capture_output=True)  # fmt: skip
    return p.returncode == 0


@pytest.fixture
def small_tmpfs(tmp_path):
    mnt = tmp_path / "small"
    if not _mount_tmpfs(mnt, "size=64k"):
        pytest.skip("mounting a small tmpfs needs root (mount -t tmpfs); the full-disk case "
                    "cannot be produced without it")  # fmt: skip
    yield mnt
    subprocess.run(["umount", str(mnt)], check=False)


def test_full_disk_is_one_line_and_leaves_nothing(tmp_path, small_tmpfs):
    src = write_table(pd.DataFrame({"alpha": np.linspace(0.1, 50, 20_000)}), tmp_path / "in.csv")
    p = _run("batch", src, "-o", small_tmpfs / "out.csv")
    assert p.returncode == 2, p.stderr
    assert "no space left on the device" in p.stderr and p.stderr.count("\n") == 1
    assert list(small_tmpfs.iterdir()) == []  # no temporary file left behind


def test_read_only_directory(tmp_path):
    mnt = tmp_path / "ro"
    if not _mount_tmpfs(mnt, "ro,size=64k"):
        pytest.skip("mounting a read-only tmpfs needs root (mount -t tmpfs)")
    try:
        src = write_table(pd.DataFrame({"alpha": [1.0]}), tmp_path / "in.csv")
        p = _run("batch", src, "-o", mnt / "out.csv")
        assert p.returncode == 2 and "read-only file system" in p.stderr
    finally:
        subprocess.run(["umount", str(mnt)], check=False)


def test_interrupted_write_removes_its_temporary_file(tmp_path, monkeypatch):
    import restitution.tables.io as io

    def killed(*args, **kwargs):
        open(args[1], "wb").write(b"partial")
        raise SystemExit(143)  # what the CLI's SIGTERM handler raises

    monkeypatch.setattr(io.pq, "write_table", killed)
    with pytest.raises(SystemExit):
        write_table(pd.DataFrame({"alpha": [1.0]}), tmp_path / "out.parquet")
    assert list(tmp_path.iterdir()) == []


def test_sigterm_during_batch_leaves_no_temporary_file(tmp_path):
    # a million one-contact rows: reading, checking and writing take seconds of Python code,
    # where the signal is handled (a numba batch call is not interruptible)
    src = write_table(pd.DataFrame({"alpha": np.linspace(0.1, 0.6, 1_000_000)}),
                      tmp_path / "in.parquet")  # fmt: skip
    out = tmp_path / "out.csv"
    proc = subprocess.Popen([sys.executable, "-m", "restitution.cli", "batch", str(src), "-o",
                             str(out)], stderr=subprocess.PIPE, text=True)  # fmt: skip
    # Signal once the output's temporary file exists (the write is under way), not after a fixed
    # sleep: how long reading and solving take depends on the machine and the numba cache.
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        if any(p.name.startswith(".out.csv") for p in tmp_path.iterdir()):
            break
        time.sleep(0.01)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    if proc.returncode == 3 or proc.returncode == 0:
        pytest.fail("the batch finished before SIGTERM: make it longer")
    assert proc.returncode in (143, -signal.SIGTERM), err
    assert [p.name for p in tmp_path.iterdir()] == ["in.parquet"]


def test_leftovers_of_a_killed_writer_are_cleaned(tmp_path):
    dead = 2**22 + 12345  # above the default pid_max: no such process
    stale = tmp_path / f".out.parquet.{dead}.abc123.tmp"
    stale.write_bytes(b"x" * 1000)
    alive = tmp_path / f".out.parquet.{os.getppid()}.def456.tmp"  # a running writer: kept
    alive.write_bytes(b"y")
    other = tmp_path / f".other.parquet.{dead}.x.tmp"  # another table's file: not ours to touch
    other.write_bytes(b"z")
    write_table(pd.DataFrame({"alpha": [1.0]}), tmp_path / "out.parquet")
    assert not stale.exists() and alive.exists() and other.exists()
    assert clean_leftovers(tmp_path / "other.parquet") == [other]


@pytest.mark.parametrize(
    "frame",
    [
        pd.DataFrame(
            {
                "alpha": [1.0, 2.0, 3.0, 4.0],
                "beta": [0.01, 0.01, 0.0, 0.1],
                "contact": [None, "plastic", "linear", None],
                "eta": [None, 0.5, None, None],
                "dr": [None, 0.3, None, None],
                "method": [None, "auto", "impulsive", "adaptive"],
                "rtol": [None, None, None, 1e-8],
            }
        ),
        pd.DataFrame(
            {
                "masses": [[1.0, 2.0, 0.5], [1.0, 3.0], [1.0, 2.0]],
                "springs": [[1.0, 2.0], [0.5], [1.0]],
                "dashpots": [[0.0, 0.1], None, None],
                "k_contact": [math.inf, 20.0, 10.0],
                "links": [None, None, [{"law": "scissor", "L": 54.0, "ks": 0.01}]],
            }
        ),
    ],
    ids=["paper", "general"],
)
def test_parquet_nulls_read_with_the_pyarrow_backend(tmp_path, frame):
    """Parquet nulls read with dtype_backend="pyarrow" arrive as pandas' NA (not None or NaN):
    they are missing cells like any other, and the results equal the default backend's."""
    path = tmp_path / "scenes.parquet"
    frame.to_parquet(path)
    default = solve_many(pd.read_parquet(path))
    arrow = solve_many(pd.read_parquet(path, dtype_backend="pyarrow"))
    for c in ("cor", "n_collisions", "method", "status"):
        assert arrow[c].tolist() == default[c].tolist(), c
