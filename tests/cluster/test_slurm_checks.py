"""The checks of the SLURM test (.ci/slurm_compare.py, .ci/slurm_jobs.py) catch what they claim to.

The SLURM run itself needs root and a SLURM installation (`make slurm-test`, run by CI); these
tests only feed the two checks hand-made runs, so a check that cannot fail would show here.
"""

import importlib.util
import math
from pathlib import Path

import pandas as pd
import yaml

from restitution.tables.io import write_table

CI = Path(__file__).resolve().parents[2] / ".ci"
PROFILE = CI.parent / "workflow" / "profiles" / "slurm" / "config.yaml"


def load(name):
    spec = importlib.util.spec_from_file_location(name, CI / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


compare = load("slurm_compare")
jobs = load("slurm_jobs")

FRAME = pd.DataFrame(
    {"alpha": [0.5, 1.0, 2.0], "cor": [0.3, 0.1, math.nan], "status": ["ok", "ok", "ok"]}
)
CONFIG = {"fig2a": {"betas": [0.0]}}


def run_dir(root: Path, frame=FRAME, config=CONFIG) -> Path:
    write_table(frame, root / "results" / "fig2a" / "sweep.parquet", config=config)
    write_table(frame[["alpha"]], root / "results" / "fig2a" / "minima.csv")
    return root


def test_compare_equal_runs_pass_with_nan_in_the_same_place(tmp_path, capsys):
    a, b = run_dir(tmp_path / "a"), run_dir(tmp_path / "b")
    assert compare.main([str(a), str(b)]) == 0
    assert "2 tables equal" in capsys.readouterr().out


def test_compare_fails_on_one_ulp(tmp_path, capsys):
    changed = FRAME.copy()
    changed.loc[0, "cor"] = math.nextafter(0.3, 1.0)
    a, b = run_dir(tmp_path / "a"), run_dir(tmp_path / "b", frame=changed)
    assert compare.main([str(a), str(b)]) == 1
    assert "sweep.parquet: data differ" in capsys.readouterr().err


def test_compare_fails_on_provenance_naming_the_key(tmp_path, capsys):
    a = run_dir(tmp_path / "a")
    b = run_dir(tmp_path / "b", config={"fig2a": {"betas": [0.1]}})
    assert compare.main([str(a), str(b)]) == 1
    err = capsys.readouterr().err
    assert "restitution.config_hash" in err and "restitution.config.fig2a.betas" in err


def test_compare_fails_on_a_missing_table_and_on_empty_runs(tmp_path, capsys):
    a, b = run_dir(tmp_path / "a"), run_dir(tmp_path / "b")
    (b / "results" / "fig2a" / "minima.csv").unlink()
    assert compare.main([str(a), str(b)]) == 1
    assert "minima.csv: only in the local run" in capsys.readouterr().err
    (tmp_path / "c" / "results").mkdir(parents=True)
    (tmp_path / "d" / "results").mkdir(parents=True)
    assert compare.main([str(tmp_path / "c"), str(tmp_path / "d")]) == 1
    assert "no result tables in common" in capsys.readouterr().err


SQUEUE = """\
1|rule_simulate_fig2a_wildcards_0_0|COMPLETED|2026-11-22T10:00:00|2026-11-22T10:00:01|2026-11-22T10:00:11|2|1000M|20:00
2|rule_simulate_fig2a_wildcards_0_1|COMPLETED|2026-11-22T10:00:00|2026-11-22T10:00:11|2026-11-22T10:00:21|2|1000M|20:00
3|rule_simulate_fig7_wildcards_0.3_0|COMPLETED|2026-11-22T10:00:00|2026-11-22T10:00:21|2026-11-22T10:00:31|2|1000M|20:00
4|rule_simulate_fig7_wildcards_0.3_1|{state}|2026-11-22T10:00:00|2026-11-22T10:00:31|2026-11-22T10:00:41|2|1000M|20:00
"""


def jobs_run(root: Path, benchmarks=4) -> Path:
    """A run directory with two chunk tables per chunked rule and `benchmarks` benchmark files."""
    for chunk in ("results/fig2a/beta~0/chunk_0", "results/fig2a/beta~0/chunk_1"):
        write_table(FRAME, root / f"{chunk}.parquet")
    for chunk in ("results/fig7/xi~0.3/chunk_0", "results/fig7/xi~0.3/chunk_1"):
        write_table(FRAME, root / f"{chunk}.parquet")
    for i in range(benchmarks):
        path = root / "logs" / "benchmarks" / f"job{i}.tsv"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"s\th:m:s\tmax_rss\n{4.0 + 2 * (i % 2)}\t0:00:05\t250.0\n")
    return root


def test_jobs_overhead_is_slurm_elapsed_minus_benchmarks(tmp_path, capsys):
    run = jobs_run(tmp_path / "run")
    dump = tmp_path / "squeue.txt"
    dump.write_text(SQUEUE.format(state="COMPLETED"))
    assert jobs.main([str(dump), str(run), "20", "60"]) == 0
    out = capsys.readouterr().out
    # Four jobs of 10 s each in SLURM, scripts of 4, 6, 4, 6 s: 5.0 s per job around the script.
    assert "overhead per job: 5.0 s inside the job" in out
    assert "submit to start: median 16 s, max 31 s" in out
    assert "60 s through SLURM vs 20 s locally (-c2): 10.0 s more per job" in out


def test_jobs_fail_on_a_failed_job_and_on_missing_jobs(tmp_path, capsys):
    run = jobs_run(tmp_path / "run", benchmarks=5)
    dump = tmp_path / "squeue.txt"
    dump.write_text(SQUEUE.format(state="FAILED"))
    assert jobs.main([str(dump), str(run), "20", "60"]) == 1
    err = capsys.readouterr().err
    assert "SLURM job 4 (rule_simulate_fig7_wildcards_0.3_1) is FAILED" in err
    assert "4 SLURM jobs but 5 workflow jobs" in err


def test_jobs_fail_when_chunks_did_not_run_as_their_own_jobs(tmp_path, capsys):
    run = jobs_run(tmp_path / "run", benchmarks=3)
    dump = tmp_path / "squeue.txt"
    dump.write_text("\n".join(SQUEUE.format(state="COMPLETED").splitlines()[:3]) + "\n")
    assert jobs.main([str(dump), str(run), "20", "60"]) == 1
    assert "simulate_fig7: 1 SLURM jobs for 2 chunk tables" in capsys.readouterr().err


def test_slurm_profile_keeps_the_settings_without_which_it_hangs():
    """Without accounting, sacct (the default) never reports and snakemake waits forever."""
    profile = yaml.safe_load(PROFILE.read_text())
    assert profile["executor"] == "slurm"
    assert profile["slurm-status-command"] == "squeue"
    assert profile["slurm-no-account"] is True
    assert profile["default-resources"]["slurm_partition"]
