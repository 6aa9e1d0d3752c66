# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Designing a chain for the smallest rebound
#
# The paper's two-mass optimum is alpha = m2/m1 = 0.6971 with a COR of 0.178. This notebook lets
# you ask the same for your own chain: how many masses, which bounds on the mass (and spring)
# ratios, a rigid wall or a contact spring, and how robust the answer is to mass errors. It calls
# `restitution.analysis.design` (the library behind Fig. 8(b)) and reads the workflow's design
# table when
# it exists. It never copies solver code.
#
# 1. optimise one chain: `minimize_cor(n_masses=N, bounds=..., beta=...)`;
# 2. look at the COR around the optimum: a cusp, where one more contact just grazes the wall;
# 3. the robust design: the smallest worst-case COR over independent mass errors;
# 4. the workflow's table of designs (`results/design/designs.parquet`, after `make all`).
#
# Units: ratios m_i/m_1 and k_i/k_12; beta = k_12/k_contact (0: rigid wall). Parameters are
# environment variables (the tests run this notebook small); edit the cell below to explore:
#
# | variable | default | meaning |
# |---|---|---|
# | `RESTITUTION_RESULTS` | `results` | folder of the workflow's results |
# | `NB_OPT_N` | 3 | number of masses N of the chain to optimise |
# | `NB_OPT_LOW`, `NB_OPT_HIGH` | 0.01, 100 | bounds of every ratio m_i/m_1 |
# | `NB_OPT_BETA` | 0 | k_12/k_contact (0: rigid wall) |
# | `NB_OPT_POPSIZE`, `NB_OPT_MAXITER` | 10, 60 | differential evolution settings |
# | `NB_ROBUST_TOL` | 0.01 | mass errors of the robust design (0 skips it) |

# %%
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import display

import restitution
from restitution.analysis import design

RESULTS = Path(os.environ.get("RESTITUTION_RESULTS", "results"))
N = int(os.environ.get("NB_OPT_N", "3"))
BOUNDS = (float(os.environ.get("NB_OPT_LOW", "0.01")), float(os.environ.get("NB_OPT_HIGH", "100")))
BETA = float(os.environ.get("NB_OPT_BETA", "0"))
POPSIZE = int(os.environ.get("NB_OPT_POPSIZE", "10"))
MAXITER = int(os.environ.get("NB_OPT_MAXITER", "60"))
TOL = float(os.environ.get("NB_ROBUST_TOL", "0.01"))
print(f"N = {N}, bounds {BOUNDS}, beta = {BETA}")

# %% [markdown]
# ## 1. Optimise your chain
#
# Differential evolution over the log ratios (seeded: the same answer every run), then a polish
# that solves the grazing condition of the cusp instead of poking at it. `progress` prints a line
# per generation; `vary="masses+springs"` frees the springs too.

# %%
lines = []
best = design.minimize_cor(N, bounds=BOUNDS, beta=BETA, popsize=POPSIZE, maxiter=MAXITER,
                           progress=lines.append)  # fmt: skip
print("\n".join(lines[-3:]))
print(f"N = {N}: smallest COR {best.cor:.6f}, masses m_i/m_1 = {np.round(best.masses, 6)}")
print(f"contacts {best.n_collisions}, re-solved COR {best.cor_check:.12f}, {best.method}")
print("on a bound:", best.bounds_hit or "none", "| grazing condition:", best.grazing)

# %% [markdown]
# ## 2. The cusp
#
# Move the heaviest-influence ratio around the optimum: the COR rises linearly on one side and
# like a square root on the other, where the grazing contact becomes a real one.

# %%
j = 1 if N == 2 else int(np.argmax(best.masses[1:])) + 1
factors = 1.0 + np.linspace(-0.05, 0.05, 401)
rows = []
for f in factors:
    m = best.masses.copy()
    m[j] *= f
    masses, springs, kc = design.scaled_chain(m, best.springs, BETA)
    r = design.solve_scaled(masses, springs, kc)
    rows.append((f, r.cor, r.n_collisions))
cut = pd.DataFrame(rows, columns=["factor", "cor", "n_collisions"])
fig, ax = plt.subplots(figsize=(5, 3.2))
ax.plot(cut["factor"], cut["cor"], lw=1)
ax.axvline(1.0, color="0.6", lw=0.6)
ax.set_xlabel(f"m_{j + 1} / its optimal value")
ax.set_ylabel("COR")
ax.set_title(f"N = {N}: COR near the optimum")
plt.show()

# %% [markdown]
# ## 3. Robust design
#
# Minimise the worst COR over independent errors of +-TOL in every mass (the worst case is
# searched, not assumed at a corner of the error box).

# %%
if TOL > 0:
    rob = design.minimize_cor(
        N, bounds=BOUNDS, beta=BETA, tolerance=TOL, popsize=POPSIZE,
        maxiter=max(5, MAXITER // 6), progress=None,
    )  # fmt: skip
    print(
        f"robust: nominal COR {rob.cor:.6f}, worst {rob.worst_cor:.6f} "
        f"(the plain optimum: {best.cor:.6f}); masses {np.round(rob.masses, 5)}"
    )

# %% [markdown]
# ## 4. The workflow's designs (Fig. 8(b))

# %%
path = RESULTS / "design" / "designs.parquet"
if path.exists():
    table = restitution.tables.io.read_table(path)
    display(table[["family", "n_masses", "cor", "worst_cor", "cor_resolved", "bounds_hit"]])
    fig, ax = plt.subplots(figsize=(5, 3.2))
    for family, rows in table.groupby("family"):
        ax.plot(rows["n_masses"], rows["cor"], marker="o", label=family)
    ax.set_yscale("log")
    ax.set_xlabel("N")
    ax.set_ylabel("smallest COR")
    ax.legend(fontsize="small")
    plt.show()
else:
    print(f"no {path}: run `make all` (or `snakemake -c2 fig8b`) first")
