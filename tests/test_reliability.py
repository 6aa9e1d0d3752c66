"""Reliability of the pipeline: interrupted runs resume to identical outputs, the core count does
not change the data, and a damaged parquet input stops its consumer with the file named.

All runs use config/small.yaml on two chunked sweeps (Fig. 2(a): 2 betas x 2 chunks, Fig. 7:
2 xis x 2 chunks) in scratch copies of the workflow; the small run (run: small) writes under
runs/small/ of the copy and never into its figures/. The tests share one uninterrupted -c2 run
(module fixture); the xdist group keeps them on one worker so it is made once.
"""

import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from conftest import SMALL_CONFIG, SNAKEMAKE, copy_workflow, run_snakemake, snakemake_env

pytestmark = [pytest.mark.pipeline, pytest.mark.slow, pytest.mark.xdist_group("reliability")]

TARGETS = ("fig2a", "fig7a")
RUN = Path("runs") / "small"  # the small configuration's run folder
CONFIG = (f"--configfile={SMALL_CONFIG}",)  # "=": the option takes several values
SIMULATE_OUTPUTS = (
    [f"results/fig2a/beta~{b}/chunk_{c}.parquet" for b in ("0", "0.1") for c in (0, 1)],
    [f"results/fig7/xi~{x}/chunk_{c}.parquet" for x in ("0.3", "1") for c in (0, 1)],
)


def build(work: Path, *extra, cores=2, timeout=900):
    result = run_snakemake(f"-c{cores}", *CONFIG, *extra, *TARGETS, cwd=work, timeout=timeout)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-5000:]
    return result


def outputs(work: Path) -> dict[str, Path]:
    """Every table and figure the targets produce (logs and timings excluded), by relative path."""
    run = work / RUN
    files = [*(run / "results").rglob("*"), *(run / "figures").glob("fig*")]
    return {str(p.relative_to(run)): p for p in files if p.is_file()}


def assert_same_outputs(work: Path, reference: Path):
    mine, theirs = outputs(work), outputs(reference)
    assert sorted(mine) == sorted(theirs)
    for name, path in theirs.items():
        if name.endswith(".parquet"):
            # Data, schema and provenance metadata (no timestamps in it) all equal.
            a, b = pq.read_table(mine[name]), pq.read_table(path)
            assert a.equals(b, check_metadata=True), name
        else:
            assert mine[name].read_bytes() == path.read_bytes(), name


@pytest.fixture(scope="module")
def reference_run(tmp_path_factory) -> Path:
    work = copy_workflow(tmp_path_factory.mktemp("reference"))
    build(work)
    for path in [*SIMULATE_OUTPUTS[0], *SIMULATE_OUTPUTS[1]]:
        assert (work / RUN / path).is_file(), f"the small config no longer produces {path}"
    # The small run keeps to its folder: nothing in the copy's own results/, figures/, logs/.
    for folder in ("results", "figures", "logs"):
        assert not (work / folder).exists(), f"the small run wrote into {folder}/"
    return work


def test_one_core_gives_identical_data(reference_run, tmp_path):
    work = copy_workflow(tmp_path / "c1")
    build(work, cores=1)
    assert_same_outputs(work, reference_run)


def _start(work: Path, log: Path) -> subprocess.Popen:
    return subprocess.Popen(
        [*SNAKEMAKE, "-c2", *CONFIG, *TARGETS],
        cwd=work,
        env=snakemake_env(),
        stdout=log.open("w"),
        stderr=subprocess.STDOUT,
        start_new_session=True,  # its own process group: the kill reaches the jobs too
    )


def _wait_for_simulate_job(proc: subprocess.Popen, log: Path, timeout=300.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if "rule simulate_fig" in log.read_text():
            return
        if proc.poll() is not None:
            pytest.fail(f"snakemake ended before any simulate job started:\n{log.read_text()}")
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    pytest.fail(f"no simulate job started within {timeout} s:\n{log.read_text()}")


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_killed_run_resumes_to_identical_outputs(reference_run, tmp_path, sig):
    work = copy_workflow(tmp_path / "killed")
    log = tmp_path / "killed.log"
    proc = _start(work, log)
    _wait_for_simulate_job(proc, log)
    # A simulate job needs > 2 s to start (Python, package, numba cache): 0.5 s in, it is running.
    time.sleep(0.5)
    os.killpg(proc.pid, sig)
    try:
        proc.wait(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail(f"snakemake did not stop within 120 s of {sig.name}")
    assert proc.returncode != 0, (
        f"the run finished before the kill; nothing was interrupted\n{log.read_text()}"
    )

    simulated = [
        p for p in (*SIMULATE_OUTPUTS[0], *SIMULATE_OUTPUTS[1]) if (work / RUN / p).exists()
    ]
    assert len(simulated) < 8, "every simulate job had finished: the kill interrupted none"
    assert not (work / RUN / "figures" / "fig2a.png").exists()
    # Whatever the kill left under its final name is a complete table (writes are atomic).
    for path in (work / RUN / "results").rglob("*.parquet"):
        pq.read_table(path)

    if sig == signal.SIGKILL:
        # No chance to clean up: the killed jobs stay marked incomplete and the lock stays;
        # snakemake refuses to start and says how to remove it.
        assert any((work / RUN / ".snakemake" / "incomplete").iterdir())
        locked = run_snakemake("-c2", *CONFIG, *TARGETS, cwd=work)
        assert locked.returncode != 0 and "--unlock" in locked.stdout + locked.stderr
        assert run_snakemake("--unlock", *CONFIG, cwd=work).returncode == 0
    build(work, "--rerun-incomplete")
    assert_same_outputs(work, reference_run)


def _damaged_copy(reference: Path, work: Path) -> Path:
    shutil.copytree(reference, work, symlinks=True)
    return work


DAMAGE = {
    "truncated": lambda data: data[: len(data) // 2],
    "garbage": lambda data: b"not a parquet file" * 10,
    "empty": lambda data: b"",
}


@pytest.mark.parametrize("damage", DAMAGE)
def test_damaged_chunk_stops_the_aggregate_naming_the_file(reference_run, tmp_path, damage):
    work = _damaged_copy(reference_run, tmp_path / "damaged")
    chunk = work / RUN / SIMULATE_OUTPUTS[0][1]
    chunk.write_bytes(DAMAGE[damage](chunk.read_bytes()))
    figure = (work / RUN / "figures" / "fig2a.png").read_bytes()

    # The chunk is newer than the sweep: snakemake reruns the aggregate on it (not the simulation).
    result = run_snakemake("-c2", *CONFIG, "fig2a", cwd=work)
    text = result.stdout + result.stderr
    assert result.returncode != 0, "a damaged chunk was aggregated without error"
    log = (work / RUN / "logs" / "fig2a" / "aggregate.log").read_text()
    assert str(SIMULATE_OUTPUTS[0][1]) in log and "TableError" in log, log
    assert "aggregate_fig2a" in text
    # The failed job's outputs are removed and the figure is not redrawn from garbage.
    assert not (work / RUN / "results" / "fig2a" / "sweep.parquet").exists()
    assert (work / RUN / "figures" / "fig2a.png").read_bytes() == figure


def test_chunk_without_result_columns_is_refused(reference_run, tmp_path):
    """A readable parquet file that is not a sweep chunk (columns missing) is named too."""
    work = _damaged_copy(reference_run, tmp_path / "foreign")
    chunk = work / RUN / SIMULATE_OUTPUTS[1][0]
    table = pq.read_table(chunk)
    pq.write_table(table.drop_columns(["cor", "n_collisions"]), chunk)

    result = run_snakemake("-c2", *CONFIG, "fig7a", cwd=work)
    assert result.returncode != 0, "a chunk without cor/n_collisions was aggregated"
    log = (work / RUN / "logs" / "fig7" / "aggregate.log").read_text()
    assert SIMULATE_OUTPUTS[1][0] in log and "cor" in log and "n_collisions" in log, log


def _planned_rules(work: Path, *extra) -> set[str]:
    """The rules snakemake would run (dry run, default rerun triggers)."""
    result = run_snakemake("-n", *CONFIG, *extra, *TARGETS, cwd=work)
    assert result.returncode == 0, result.stdout + result.stderr
    return {line[5:-1] for line in result.stdout.splitlines() if line.startswith("rule ")}


def test_changes_rerun_only_what_depends_on_them(reference_run, tmp_path):
    work = _damaged_copy(reference_run, tmp_path / "edited")
    assert _planned_rules(work) == set(), "a no-op rerun would run jobs"

    # One figure's config: only that figure's jobs (fig7.* is passed to the fig7 rules only).
    changed = tmp_path / "changed.yaml"
    changed.write_text(SMALL_CONFIG.read_text().replace("xis: [0.3, 1.0]", "xis: [0.3, 1.0, 2.0]"))
    planned = _planned_rules(work, f"--configfile={changed}")
    assert planned == {"simulate_fig7", "aggregate_fig7", "fig7a"}, planned

    # Restyling: a render script edited reruns its render job only, never a simulation.
    script = work / "workflow" / "scripts" / "render_fig2a.py"
    script.write_text(script.read_text() + "\n# restyled\n")
    assert _planned_rules(work) == {"fig2a"}


def test_deleted_tables_are_rebuilt_by_all(reference_run, tmp_path):
    """A documented table (the minima, which Fig. 2(a) and 7(a) read) is planned again by `all`
    once deleted."""
    work = _damaged_copy(reference_run, tmp_path / "deleted")
    for table in ("results/fig2a/minima.csv", "results/fig7/minima.csv"):
        (work / RUN / table).unlink()
    result = run_snakemake("-n", *CONFIG, "all", cwd=work)
    assert result.returncode == 0, result.stdout + result.stderr
    jobs = result.stdout.split("\nrule ")
    for rule, table in (("aggregate_fig2a", "fig2a"), ("aggregate_fig7", "fig7")):
        planned = [job for job in jobs if job.startswith(f"{rule}:")]
        assert planned, f"{rule} not planned after deleting results/{table}/minima.csv"
        assert f"Missing output files: results/{table}/minima.csv" in planned[0], planned[0]
