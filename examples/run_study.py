"""Run the study examples/study/two_mass_rod.yaml (or yours) with the workflow, outside the
repository, and make its report.

    python examples/run_study.py [OUT] [--study FILE] [--no-report]

The workflow runs in OUT (default: a new temp dir) with `snakemake --directory OUT`; it writes
OUT/results/studies/<name>/{sweep.parquet, minima.csv}, OUT/figures/studies/<name>/*.png and
OUT/report.html. The command it runs is printed: copy it to run a study by hand.
"""

import argparse
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[1]
parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("out", nargs="?", help="folder for the outputs (default: a new temp dir)")
parser.add_argument("--study", default=REPO / "examples" / "study" / "two_mass_rod.yaml")
parser.add_argument("--cores", type=int, default=2)
parser.add_argument("--no-report", action="store_true", help="skip the HTML report")
args = parser.parse_args()
out = Path(args.out or tempfile.mkdtemp(prefix="restitution-study-")).absolute()
out.mkdir(parents=True, exist_ok=True)
# The workflow reads src/ (the plot style), workflow/ and config/ (config.yaml) relative to its
# working directory: links to the repository's, as for a named run (docs/runs.md).
for folder in ("src", "workflow", "config"):
    if not (out / folder).exists():
        (out / folder).symlink_to(REPO / folder, target_is_directory=True)

study = Path(args.study).absolute()
# The target first, then the options (--config takes every word after it).
options = ["--snakefile", str(REPO / "Snakefile"), "--directory", str(out)]
commands = [[sys.executable, "-m", "snakemake", "study", f"-c{args.cores}", *options]]
if not args.no_report:
    commands.append([*commands[0][:4], "--report", str(out / "report.html"), *options])
commands = [[*command, "--config", f"study={study}"] for command in commands]
env = {**os.environ, "MPLBACKEND": "Agg"}
for command in commands:
    print("$", shlex.join(command), flush=True)
    subprocess.run(command, check=True, env=env)

# What it found: the COR minima of each curve (one row per minimum).
from restitution_workflow.study import load_study  # noqa: E402 (after the run: its errors come first)

name = load_study(study).name
minima = pd.read_csv(out / "results" / "studies" / name / "minima.csv")
print(minima.to_string(index=False))
print(f"outputs under {out}")
