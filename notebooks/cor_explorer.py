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
# # Exploring the coefficient of restitution
#
# This notebook reads the workflow's results and calls the `restitution` package; it never copies
# solver code. It
#
# 1. loads the Fig. 2(a) sweep (`results/fig2a/sweep.parquet`) and re-plots it, with a zoom on
#    the first minimum that you can move;
# 2. maps the COR over the (alpha, beta) plane, a view the paper does not show;
# 3. answers the design question of the paper's conclusion: which mass ratio alpha minimises the
#    COR for a given contact stiffness beta and chain length N;
# 4. solves one scene with its event history (`restitution.solve(..., history=True)`).
#
# Units as everywhere in the project: m1 = 1, V0 = 1, omega = 1 with omega^2 = k2/m1 + k2/m2;
# alpha = m2/m1 (in a chain, every rear mass is alpha m1), beta = k2/k1 (0: rigid wall).
#
# Parameters come from environment variables, so the test suite can run the notebook on a small
# configuration (`tests/test_notebooks.py`); the defaults are the ones to explore with:
#
# | variable | default | meaning |
# |---|---|---|
# | `RESTITUTION_RESULTS` | `results` | folder of the workflow's results (`make all`) |
# | `NB_HEATMAP_N_ALPHA`, `NB_HEATMAP_N_BETA` | 240, 120 | grid of the (alpha, beta) map |
# | `NB_DESIGN_BETAS` | `0,0.001,0.01,0.1,1` | betas of the design table |
# | `NB_DESIGN_N_MASSES` | `2,3,5,10` | chain lengths N of the design table |
# | `NB_DESIGN_N_ALPHA` | 400 | log-spaced alphas per (beta, N) before refinement |
# | `NB_REFINE_STEPS` | 40 | bisection steps at every change of the contact count |

# %%
import os
import warnings
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import display
from scipy.optimize import minimize_scalar

import restitution
from restitution import plotting
from restitution.analysis import special_points, sweeps
from restitution.tables.io import read_provenance, read_table

plotting.use_style()
# solve_many may show a tqdm bar; without ipywidgets tqdm falls back to text and says so.
warnings.filterwarnings("ignore", message="IProgress not found")


def env_list(name: str, default: str) -> list[float]:
    return [float(v) for v in os.environ.get(name, default).split(",")]


# The notebook may run from the repository root or any folder below it (notebooks/, ...).
ROOT = next(
    (p for p in (Path.cwd(), *Path.cwd().parents) if (p / "Snakefile").is_file()), Path.cwd()
)
RESULTS = Path(os.environ.get("RESTITUTION_RESULTS", "results"))
RESULTS = RESULTS if RESULTS.is_absolute() else ROOT / RESULTS
HEATMAP_N_ALPHA = int(os.environ.get("NB_HEATMAP_N_ALPHA", 240))
HEATMAP_N_BETA = int(os.environ.get("NB_HEATMAP_N_BETA", 120))
DESIGN_BETAS = env_list("NB_DESIGN_BETAS", "0,0.001,0.01,0.1,1")
DESIGN_N_MASSES = [int(n) for n in env_list("NB_DESIGN_N_MASSES", "2,3,5,10")]
DESIGN_N_ALPHA = int(os.environ.get("NB_DESIGN_N_ALPHA", 400))
REFINE_STEPS = int(os.environ.get("NB_REFINE_STEPS", 40))
print(f"results from {RESULTS}")

# %% [markdown]
# ## 1. The Fig. 2(a) sweep, re-plotted
#
# The table carries its provenance (package version, git commit, configuration hash) in the
# parquet metadata. Only rows whose `status` is `ok` are drawn. Change `ZOOM` (an alpha range)
# and rerun the cell to look at another minimum; in Jupyter, `%matplotlib widget` (with ipympl
# installed) makes the figure pan and zoom with the mouse.

# %%
sweep_path = RESULTS / "fig2a" / "sweep.parquet"
sweep = read_table(sweep_path)
provenance = read_provenance(sweep_path)
print({k: provenance.get(k) for k in ("package_version", "git_commit", "config_hash")})
print(sweep.groupby("beta")["status"].value_counts().unstack(fill_value=0))

ZOOM = (0.6, 0.8)  # alpha range of the right panel: the first minimum, alpha*_1 = 0.697


def plot_sweep(ax, table, alpha_range=None):
    # The rigid wall black and broad, each finite beta in its own colour (colour-blind safe).
    colours = iter(["#E69F00", "#56B4E9", "#009E73", "#D55E00", "#CC79A7", "#0072B2"] * 10)
    for beta, curve in table[table["status"] == "ok"].groupby("beta"):
        curve = curve.sort_values("alpha")
        if alpha_range is not None:
            curve = curve[curve["alpha"].between(*alpha_range)]
        ax.plot(
            curve["alpha"],
            curve["cor"],
            lw=1.2 if beta == 0 else 0.8,
            color="black" if beta == 0 else next(colours),
            label=plotting.beta_text(beta),
        )
    ax.set_xscale("log")
    ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")


fig, (ax_all, ax_zoom) = plt.subplots(1, 2, figsize=(10, 3.8))
plot_sweep(ax_all, sweep)
ax_all.set_ylabel("COR")
ax_all.legend(loc="lower right")
plot_sweep(ax_zoom, sweep, ZOOM)
ax_zoom.set_title(f"zoom: alpha in {ZOOM}")
plt.show()

# The depth of each curve's deepest point in the zoom window, read from the table.
window = sweep[sweep["alpha"].between(*ZOOM) & (sweep["status"] == "ok")]
display(
    window.loc[window.groupby("beta")["cor"].idxmin(), ["beta", "alpha", "cor", "n_collisions"]]
)

# %% [markdown]
# ## 2. The COR over the (alpha, beta) plane
#
# The paper shows the COR against alpha at a few betas (Fig. 2(a)) and against beta at a few
# alphas (Fig. 3(a)). Here is the whole plane for two masses, solved with
# `restitution.solve_many` (exact methods: the impulsive map at beta = 0, closed-form piecewise
# motion for beta > 0). The white lines separate regions of different contact counts; each COR
# minimum sits on one of them, where one more contact just grazes the wall. The ticks on the
# bottom axis are the exact rigid-wall minima alpha*_n (`restitution.analysis.special_points`).

# %%
alphas = sweeps.log_grid(0.1, 10.0, HEATMAP_N_ALPHA)
betas = sweeps.log_grid(1e-4, 10.0, HEATMAP_N_BETA)
A, B = np.meshgrid(alphas, betas)
plane = restitution.solve_many(pd.DataFrame({"alpha": A.ravel(), "beta": B.ravel()}))
assert (plane["status"] == "ok").all(), plane["status"].value_counts()
cor = plane["cor"].to_numpy().reshape(A.shape)
contacts = plane["n_collisions"].to_numpy().reshape(A.shape)
rigid_minima = special_points.special_points(8)

fig, ax = plt.subplots(figsize=(7, 4.5))
mesh = ax.pcolormesh(A, B, cor, shading="nearest", cmap="viridis", vmin=0, vmax=1)
ax.contour(A, B, contacts, levels=np.arange(1.5, contacts.max()), colors="white", linewidths=0.5)
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel(r"mass ratio $\alpha = m_2/m_1$")
ax.set_ylabel(r"stiffness ratio $\beta = k_2/k_1$")
ax.plot(
    rigid_minima["alpha_star"],
    np.full(len(rigid_minima), betas[0]),
    "r|",
    ms=12,
    label=r"$\alpha^*_n$ (rigid wall)",
)
ax.set_xlim(alphas[0], alphas[-1])
ax.legend(loc="upper left")
fig.colorbar(mesh, label="COR")
plt.show()
print(
    f"smallest COR on this grid: {cor.min():.4f} at alpha = {A.flat[cor.argmin()]:.4g}, "
    f"beta = {B.flat[cor.argmin()]:.3g}"
)

# %% [markdown]
# ## 3. Design question: which mass ratio minimises the COR?
#
# The paper's conclusion: the COR drops from 1 to 0.178 when alpha goes from 1 to 0.6971, so the
# conditions for a very small COR are "not difficult to meet but easily overlooked". For each
# contact stiffness beta and chain length N (m1 at the wall, N - 1 rear masses of alpha m1
# each), we scan alpha on a log grid, bisect every change of the contact count (the minima are
# cusps there, `restitution.analysis.sweeps.refined_sweep`) and polish the smallest point with a
# bounded
# scalar minimisation between its neighbours (for smooth minima, e.g. beta = 1). The table gives
# the minimising alpha, the total rear mass (N - 1) alpha (the axis of Fig. 6(b)) and the COR.


# %%
def min_cor(beta: float, n_masses: int, lo: float = 0.05, hi: float = 20.0) -> dict:
    """Smallest COR over alpha in [lo, hi] for one (beta, N): scan, refine cusps, polish."""

    def evaluate(alpha):
        frame = pd.DataFrame({"alpha": np.asarray(alpha), "beta": beta, "n_masses": n_masses})
        return restitution.solve_many(frame)

    table = sweeps.refined_sweep(
        evaluate(sweeps.log_grid(lo, hi, DESIGN_N_ALPHA)), evaluate, "alpha", REFINE_STEPS
    )
    table = table[table["status"] == "ok"].reset_index(drop=True)
    i = int(table["cor"].idxmin())
    left, right = (
        table["alpha"].iloc[max(i - 1, 0)],
        table["alpha"].iloc[min(i + 1, len(table) - 1)],
    )
    best = table.iloc[i]
    if right > left:
        polish = minimize_scalar(
            lambda log_a: restitution.solve(np.exp(log_a), beta, n_masses=n_masses).cor,
            bounds=(np.log(left), np.log(right)),
            method="bounded",
            options={"xatol": 1e-12},
        )
        if polish.fun < best["cor"]:
            best = evaluate([np.exp(polish.x)]).iloc[0]
    return {
        "beta": beta,
        "N": n_masses,
        "alpha_min": best["alpha"],
        "(N-1) alpha": (n_masses - 1) * best["alpha"],
        "cor_min": best["cor"],
        "n_collisions": int(best["n_collisions"]),
        "method": best["method"],
    }


design = pd.DataFrame([min_cor(b, n) for n in DESIGN_N_MASSES for b in DESIGN_BETAS])
display(design)

# %%
# Two masses at a rigid wall reproduce the paper's headline: COR 0.178 at alpha = 0.697.
rigid_two = design[(design["beta"] == 0) & (design["N"] == 2)]
if len(rigid_two):
    row = rigid_two.iloc[0]
    print(
        f"N = 2, beta = 0: smallest COR {row['cor_min']:.6f} at alpha = {row['alpha_min']:.6f} "
        f"(exact alpha*_1 = {rigid_minima['alpha_star'].iloc[0]:.6f}, "
        f"e*_1 = {rigid_minima['e_star'].iloc[0]:.6f})"
    )

fig, ax = plt.subplots(figsize=(6, 3.8))
for n, rows in design.groupby("N"):
    rows = rows.sort_values("beta")
    x = rows["beta"].where(rows["beta"] > 0, 1e-4)  # beta = 0 drawn at the left edge
    ax.plot(x, rows["cor_min"], "o-", label=f"N = {n}")
ax.set_xscale("log")
ax.set_xlabel(r"$\beta$ (beta = 0 drawn at 1e-4)")
ax.set_ylabel("smallest COR over alpha")
ax.legend()
plt.show()

# %% [markdown]
# ## 4. One scene and its event history
#
# The Fig. 3(b) scene, alpha = 2.2 at beta = 0.1, near the marginal beta where the third contact
# vanishes. `history=True` returns one row per contact: exact start and end times (omega t),
# m1's velocity before and after, the largest compression and the contact impulse. The energy
# account (translational = COR^2, vibrational, dissipated) adds up to 1.

# %%
scene = restitution.solve(alpha=2.2, beta=0.1, history=True)
print(scene)
print(
    f"energy account: {scene.e_translational:.6f} + {scene.e_vibrational:.6f} + "
    f"{scene.e_dissipated:.6f} = "
    f"{scene.e_translational + scene.e_vibrational + scene.e_dissipated:.12f}"
)
history = scene.history
display(history)

# %%
fig, ax = plt.subplots(figsize=(7, 2.4))
for k, row in history.iterrows():
    ax.broken_barh(
        [(row["omega_t_start"], row["omega_t_end"] - row["omega_t_start"])],
        (0, row["x_max"]),
        alpha=0.6,
    )
    ax.annotate(
        f"contact {k + 1}\nimpulse {row['impulse']:.3f}",
        (row["omega_t_start"], row["x_max"]),
        fontsize=8,
        va="bottom",
    )
ax.set_xlabel(r"$\omega t$")
ax.set_ylabel("largest compression")
ax.set_xlim(0, 1.05 * scene.omega_t_col)
ax.set_ylim(0, 1.4 * history["x_max"].max())
ax.set_title(f"alpha = 2.2, beta = 0.1: {scene.n_collisions} contacts, COR = {scene.cor:.4f}")
plt.show()
