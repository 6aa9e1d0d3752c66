"""Check that a workflow run went through SLURM job by job, and measure the overhead per job.

Usage: python .ci/slurm_jobs.py SQUEUE_DUMP RUN_DIR LOCAL_SECONDS SLURM_SECONDS

SQUEUE_DUMP holds `squeue -h -t all -o '%i|%k|%T|%V|%S|%e|%C|%m|%l'` of the test cluster, taken
right after the run (finished jobs stay listed for MinJobAge seconds); RUN_DIR is the scratch
copy the SLURM run worked in; the two times are the wall times of the local and SLURM runs.

Checks (exit status 1, one line each, when one fails): every job COMPLETED; one SLURM job per
workflow job (as many as benchmark files the jobs wrote under RUN_DIR/logs/benchmarks); the
chunked simulate rules ran one SLURM job per chunk table, at least two each. Then prints, per
rule, the resources SLURM granted and the mean times, and the overhead per job: elapsed time in
SLURM minus the job's own benchmark (snakemake starting inside the job), and submit to start.
"""

from __future__ import annotations

import sys
from collections import defaultdict
from datetime import datetime
from pathlib import Path
from statistics import mean, median

# Chunked simulate rules and the chunk tables their jobs write, relative to the run directory.
CHUNKED = {
    "simulate_fig2a": "results/fig2a/beta~*/chunk_*.parquet",
    "simulate_fig7": "results/fig7/xi~*/chunk_*.parquet",
}


def parse(dump: Path) -> list[dict]:
    """One dictionary per SLURM job of the squeue dump."""
    keys = ("id", "comment", "state", "submit", "start", "end", "cpus", "mem", "limit")
    jobs = []
    for line in dump.read_text().splitlines():
        if not line.strip():
            continue
        job = dict(zip(keys, line.split("|"), strict=True))
        # The executor names each job's comment rule_<rule>[_wildcards_<values>].
        job["rule"] = job["comment"].removeprefix("rule_").split("_wildcards_")[0]
        for key in ("submit", "start", "end"):
            job[key] = datetime.fromisoformat(job[key])
        jobs.append(job)
    return jobs


def benchmark_seconds(run: Path) -> list[float]:
    """The `s` column (wall seconds of the job's script) of every benchmark file of the run."""
    seconds = []
    for path in sorted((run / "logs" / "benchmarks").rglob("*.tsv")):
        header, *rows = path.read_text().splitlines()
        column = header.split("\t").index("s")
        seconds += [float(row.split("\t")[column]) for row in rows[-1:]]
    return seconds


def main(argv: list[str]) -> int:
    if len(argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    dump, run = Path(argv[0]), Path(argv[1])
    local_seconds, slurm_seconds = float(argv[2]), float(argv[3])
    jobs = parse(dump)
    benchmarks = benchmark_seconds(run)
    problems = []
    if not jobs:
        problems.append(f"squeue lists no job at all ({dump}): nothing ran through SLURM")
    for job in jobs:
        if job["state"] != "COMPLETED":
            problems.append(f"SLURM job {job['id']} ({job['comment']}) is {job['state']}")
    if len(jobs) != len(benchmarks):
        problems.append(
            f"{len(jobs)} SLURM jobs but {len(benchmarks)} workflow jobs (benchmark files): "
            "some jobs did not run as their own SLURM job"
        )
    by_rule = defaultdict(list)
    for job in jobs:
        by_rule[job["rule"]].append(job)
    for rule, pattern in CHUNKED.items():
        chunks = len(list(run.glob(pattern)))
        if chunks < 2 or len(by_rule[rule]) != chunks:
            problems.append(
                f"{rule}: {len(by_rule[rule])} SLURM jobs for {chunks} chunk tables "
                "(want one job per chunk, at least two)"
            )
    if problems:
        print("SLURM job check failed:", file=sys.stderr)
        for problem in problems:
            print(f"  {problem}", file=sys.stderr)
        return 1

    print(f"{len(jobs)} SLURM jobs, all COMPLETED, one per workflow job:")
    print(f"  {'rule':<18} {'jobs':>4} {'cpus':>4} {'mem':>6} {'limit':>8} {'elapsed s':>9}")
    for rule, group in sorted(by_rule.items()):
        elapsed = mean((j["end"] - j["start"]).total_seconds() for j in group)
        first = group[0]
        print(
            f"  {rule:<18} {len(group):>4} {first['cpus']:>4} {first['mem']:>6} "
            f"{first['limit']:>8} {elapsed:>9.1f}"
        )
    elapsed = [(j["end"] - j["start"]).total_seconds() for j in jobs]
    waits = [(j["start"] - j["submit"]).total_seconds() for j in jobs]
    in_job = (sum(elapsed) - sum(benchmarks)) / len(jobs)
    print(
        f"overhead per job: {in_job:.1f} s inside the job (SLURM elapsed {mean(elapsed):.1f} s "
        f"minus the script's own {mean(benchmarks):.1f} s, mean of {len(jobs)}; 1 s resolution)"
    )
    print(
        f"submit to start: median {median(waits):.0f} s, max {max(waits):.0f} s "
        "(includes waiting for CPUs held by other jobs of the run)"
    )
    print(
        f"whole run: {slurm_seconds:.0f} s through SLURM vs {local_seconds:.0f} s locally "
        f"(-c2): {(slurm_seconds - local_seconds) / len(jobs):.1f} s more per job"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
