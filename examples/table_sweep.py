"""A table sweep: the paper's two-mass scene over a grid of mass ratios alpha and contact
stiffness ratios beta, solved with ``restitution.solve_many``, written to parquet (with its
provenance) and plotted in the house style.

    python examples/table_sweep.py [OUT] [--n-alpha 201]

Writes OUT/sweep.parquet (one row per scene: the inputs, cor, n_collisions, energy fractions,
method, status) and OUT/cor_vs_alpha.{png,pdf}. OUT defaults to a new temp dir.
"""

import argparse
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

import restitution
from restitution import plotting
from restitution.tables.io import read_provenance, write_table

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("out", nargs="?", help="folder for the outputs (default: a new temp dir)")
parser.add_argument("--n-alpha", type=int, default=201,
                    help="alpha values, log-spaced 0.1..10 (at least 2: a curve)")  # fmt: skip
args = parser.parse_args()
if args.n_alpha < 2:  # (0 wrote an empty table; 1 point draws no curve)
    parser.error(f"--n-alpha must be at least 2 (the points of each curve); got {args.n_alpha}")
if args.out is not None and Path(args.out).exists() and not Path(args.out).is_dir():
    parser.error(f"OUT {args.out} exists and is not a folder; give a folder for the outputs")
out = Path(args.out or tempfile.mkdtemp(prefix="restitution-sweep-"))

# The grid: one row per scene. The paper's units (m1 = 1, V0 = 1, omega = 1); beta = 0 is a
# rigid wall, beta > 0 a contact spring k1 = k2/beta. Columns not given take their defaults
# (xi = 0, n_masses = 2).
alphas = np.geomspace(0.1, 10.0, args.n_alpha)
betas = [0.0, 1e-3, 1e-2, 1e-1]
grid = pd.DataFrame([(a, b) for b in betas for a in alphas], columns=["alpha", "beta"])

table = restitution.solve_many(grid)  # the grid with the result columns added
# Provenance (package version, git commit, library versions, the grid) in the parquet's metadata.
grid_spec = {"alpha": f"geomspace(0.1, 10, {args.n_alpha})", "beta": betas}
path = write_table(table, out / "sweep.parquet", config=grid_spec)
print(f"wrote {path}: {len(table)} scenes, statuses {table['status'].value_counts().to_dict()}")
print("provenance:", {k: read_provenance(path)[k] for k in ("package_version", "config")})

# The plot: COR against alpha, one curve per beta, the house colours of beta.
fig = plotting.new_figure("single", aspect=0.72)
ax = fig.add_subplot()
for beta, part in table[table["status"] == "ok"].groupby("beta"):
    ax.plot(part["alpha"], part["cor"], lw=0.9, label=plotting.beta_text(beta),
            color=plotting.beta_colour(beta, betas))  # fmt: skip
plotting.log_axis(ax, "x")
ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
ax.set_ylabel("coefficient of restitution $e$")
ax.set_ylim(0.0, 1.02)
ax.legend(loc="lower right")
plotting.check_figure(fig)  # the house rules: text size, one colour one meaning
for written in plotting.save_figure(fig, out / "cor_vs_alpha"):
    print(f"wrote {written}")

# A first look at the numbers: the smallest COR of each curve (on the grid, not refined).
lowest = table.loc[table.groupby("beta")["cor"].idxmin(), ["beta", "alpha", "cor", "n_collisions"]]
print(lowest.to_string(index=False))
