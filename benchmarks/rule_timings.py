"""Per-rule cost of the last workflow run, from Snakemake's `benchmark:` files, as a Markdown table.

Usage: python benchmarks/rule_timings.py [logs/benchmarks]

Jobs of one rule (wildcards such as beta~0.1 or chunk_3 in the path) are grouped; per group the
table gives the job count, the summed and the longest wall time, the summed CPU time and the
largest resident memory. Wall times include each job's start-up (Python, package, numba cache).
CPU times are Snakemake's samples: every 0.5 s for a job's first 15 s, then every 30 s, so a job
longer than 15 s reports its CPU time as of its last sample (a free-masses-and-springs design
job of 43 s at full load reported 14.7 s); a group holding such a job shows its CPU sum as a
lower bound (">=").
"""

import re
import sys
from pathlib import Path

import pandas as pd

WILDCARD = re.compile(r"[^/]*~[^/]*|chunk_\d+")
# snakemake.benchmark: 30 samples 0.5 s apart, then one every 30 s (BENCHMARK_INTERVAL)
FULLY_SAMPLED_S = 15.0


def _cpu(total: float, longest: float) -> str:
    """A CPU sum, marked as a lower bound when a job in it ran past the dense sampling."""
    return f"{'>= ' if longest > FULLY_SAMPLED_S else ''}{total:.1f}"


def load(root: Path) -> pd.DataFrame:
    rows = []
    for path in sorted(root.rglob("*.tsv")):
        # Snakemake appends one line per run of the job: the last one is the latest run.
        last = pd.read_csv(path, sep="\t").iloc[-1]
        group = WILDCARD.sub("*", str(path.relative_to(root).with_suffix("")))
        rows.append(
            {"jobs": group, "s": last["s"], "cpu_s": last["cpu_time"], "rss": last["max_rss"]}
        )
    if not rows:
        raise SystemExit(f"{root}: no benchmark files (run the workflow first)")
    return pd.DataFrame(rows)


def table(frame: pd.DataFrame) -> str:
    grouped = frame.groupby("jobs").agg(
        n=("s", "size"),
        wall=("s", "sum"),
        longest=("s", "max"),
        cpu=("cpu_s", "sum"),
        rss=("rss", "max"),
    )
    lines = [
        "| jobs | n | wall s (sum) | wall s (longest) | CPU s (sum) | max RSS MB |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for name, r in grouped.sort_values("wall", ascending=False).iterrows():
        cells = (
            f"{int(r.n)} | {r.wall:.1f} | {r.longest:.1f} | {_cpu(r.cpu, r.longest)} | {r.rss:.0f}"
        )
        lines.append(f"| `{name}` | {cells} |")
    lines.append(
        f"| **all jobs** | {grouped.n.sum()} | {grouped.wall.sum():.1f} | "
        f"{grouped.longest.max():.1f} | {_cpu(grouped.cpu.sum(), grouped.longest.max())} | "
        f"{grouped.rss.max():.0f} |"
    )
    return "\n".join(lines)


if __name__ == "__main__":
    print(table(load(Path(sys.argv[1] if len(sys.argv) > 1 else "logs/benchmarks"))))
