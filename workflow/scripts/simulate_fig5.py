"""Fig. 5(b) sweep: COR against alpha with the scissor structural spring (Sec. 3.2, Eq. 24).

One curve per bar length L at the impact speed v0, and one per impact speed at a fixed L (the
velocity dependence the paper stresses; ``fig5.b.velocity``), beta = k2/k1 and ks = ks_over_k1 * k1
from the config (the paper:
beta = 1, ks = k1/100, so ks_ratio = ks/k2 = ks_over_k1/beta = 0.01), impact speed v0 (the
scissor law makes the response velocity dependent), rest half angle theta0 and the corner
stiffening parameter (both left open by the paper; see ``restitution.model.laws``). Solved by the
adaptive DOP853 kernel (``restitution.solve_many``, rows in parallel batches); the linear
structural spring at the same beta (the exact closed-form solver) is added as the reference
curve. Cusps refined on the contact count as in Fig. 4
(``restitution.analysis.sweeps.refined_sweep``); per-curve minima written as a CSV summary.
"""

import math

import numpy as np
import pandas as pd


def spring_law(spring: dict) -> dict:
    """Scissor law columns of a ``restitution.solve_many`` table from the config's spring
    subtree."""
    return {
        "ks_ratio": float(spring["ks_over_k1"]) / float(spring["beta"]),
        "theta0": math.radians(float(spring["theta0_deg"])),
        "corner": float(spring["corner"]),
    }


def curves(spring: dict, panel: dict) -> list[dict]:
    """The curves of Fig. 5(b): ``series`` "L" (each L of panel.Ls at panel.v0), "v0" (each
    impact speed of panel.velocity.v0s at the fixed panel.velocity.L) and the linear spring."""
    base = dict(beta=float(spring["beta"]), **spring_law(spring))
    laws = [
        dict(series="L", structure="scissor", L=float(L), v0=float(panel["v0"]))
        for L in panel["Ls"]
    ]
    velocity = panel.get("velocity")
    if velocity:
        laws += [
            dict(series="v0", structure="scissor", L=float(velocity["L"]), v0=float(v0))
            for v0 in velocity["v0s"]
        ]
    laws.append(dict(series="linear", structure="linear", L=np.nan, v0=float(panel["v0"])))
    return [dict(curve=i, **base, **law) for i, law in enumerate(laws)]


def evaluator(law: dict, panel: dict, solver: dict):
    import restitution

    def evaluate(alphas):
        alphas = np.asarray(alphas, dtype=np.float64)
        base = pd.DataFrame({"alpha": alphas, "beta": law["beta"], "xi": 0.0, "n_masses": 2})
        if law["structure"] == "linear":
            out = restitution.solve_many(
                base.assign(method=solver["method"]), max_events=solver["max_events"]
            )
        else:
            scenes = base.assign(
                structure="scissor",
                L=law["L"],
                ks_ratio=law["ks_ratio"],
                theta0=law["theta0"],
                corner=law["corner"],
                v0=law["v0"],
                method="adaptive",
                rtol=panel["rtol"],
            )
            out = restitution.solve_many(scenes, max_events=panel["max_events"])
        keys = ("series", "structure", "L", "ks_ratio", "theta0", "corner", "v0", "curve")
        return out.assign(**{k: law[k] for k in keys})

    return evaluate


def free_choice_scan(spring: dict, panel: dict, logger) -> pd.DataFrame:
    """Does the paper's "smaller L, smaller COR" hold for another reading of its free choices?

    For every rest half angle theta0 and corner law of ``panel.scan`` and every L of panel.Ls
    (at panel.v0): the mean and the smallest COR over a log-spaced alpha grid (no refinement; a
    trend check, not a figure), and for each (theta0, corner) whether the mean COR falls as L
    grows. Runs whose status is not ok are left out of the means and counted.
    """
    import restitution

    scan = panel["scan"]
    alphas = np.geomspace(panel["alpha_min"], panel["alpha_max"], int(scan["n_alpha"]))
    rows = []
    for theta0 in scan["theta0_degs"]:
        for corner in scan["corners"]:
            law = dict(spring, theta0_deg=theta0, corner=corner)
            for L in sorted(panel["Ls"]):  # noqa: N806
                scenes = pd.DataFrame({"alpha": alphas, "beta": float(spring["beta"]),
                                       "xi": 0.0, "n_masses": 2, "structure": "scissor",
                                       "L": float(L), "v0": float(panel["v0"]),
                                       "method": "adaptive", "rtol": panel["rtol"],
                                       **spring_law(law)})  # fmt: skip
                out = restitution.solve_many(scenes, max_events=panel["max_events"])
                ok = out[out["status"] == "ok"]
                rows.append(dict(theta0_deg=float(theta0), corner=float(corner), L=float(L),
                                 mean_cor=float(ok["cor"].mean()), min_cor=float(ok["cor"].min()),
                                 n_alpha=len(out), n_not_ok=len(out) - len(ok)))  # fmt: skip
    table = pd.DataFrame(rows)
    falls = table.groupby(["theta0_deg", "corner"])["mean_cor"].apply(
        lambda m: bool(np.all(np.diff(m.to_numpy()) < 0))
    )
    table = table.merge(falls.rename("mean_cor_falls_with_L").reset_index())
    logger.info("free-choice scan (theta0, corner, L):\n%s", table.to_string())
    return table


def main(params, output_path, summary_path, logger, scan_path=None) -> pd.DataFrame:
    from simulate_fig4 import minima_columns

    from restitution.analysis import sweeps
    from restitution.tables.io import write_table

    spring, panel, solver = params.spring, params.panel, params.solver
    alphas = sweeps.log_grid(panel["alpha_min"], panel["alpha_max"], panel["n_alpha"])
    logger.info(
        "fig5b: %d grid alphas in [%g, %g], law %s, v0 %g",
        len(alphas),
        alphas[0],
        alphas[-1],
        spring_law(spring),
        panel["v0"],
    )
    tables, summary = [], []
    for law in curves(spring, panel):
        label = f"fig5b {law['structure']} L={law['L']:g} v0={law['v0']:g}"
        evaluate = evaluator(law, panel, solver)
        curve = sweeps.sweep_curve(evaluate, "alpha", alphas, panel["refine_steps"], logger, label)
        row = dict(law, n_rows=len(curve), n_not_ok=int((curve["status"] != "ok").sum()))
        row.update(minima_columns(curve))
        tables.append(curve)
        summary.append(row)
    result = pd.concat(tables, ignore_index=True)
    write_table(result, output_path, config={"spring": spring, "fig5b": panel, "solver": solver})
    write_table(pd.DataFrame(summary), summary_path)
    if scan_path is not None:
        free_choice_scan(spring, panel, logger).to_csv(scan_path, index=False, float_format="%.8g")
    return result


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "simulate"):
        main(
            snakemake.params,  # noqa: F821
            snakemake.output.table,  # noqa: F821
            snakemake.output.summary,  # noqa: F821
            log,
            snakemake.output.scan,  # noqa: F821
        )
