"""Fig. 4(b)-(d) sweep, one job per panel: COR against alpha with a plastic contact (Sec. 3.1).

Each curve of a panel is one plastic contact law (power-law loading F1 = kappa*x**eta, linear
unloading with slope k1 = k2/beta; kappa follows from the nominal dissipation ratio DR, see
``restitution.model.laws``), solved by the adaptive DOP853 kernel (``restitution.solve_many``,
method ``adaptive``, rows in parallel batches) on a log-spaced alpha grid. The elastic linear
contact at the same beta (the Fig. 2(a) curve, exact closed-form solver) is added as a reference
curve.

Cusps: between grid neighbours whose contact counts differ, the alpha bracket is bisected
``refine_steps`` times on the count (all brackets of a curve at once, one batch call per step) and
every evaluated point is kept, so the cusp-shaped minima are drawn to their depth
(``restitution.analysis.sweeps``).

Eq. 23 check: no COR may exceed e_pmax = sqrt(1 - DR/(1 + alpha)). Rows above it are counted in
the log (warning); a row above it by more than its own error estimate fails the job. A per-curve
summary (first minima, largest COR, smallest margin to the bound, rows not ok) is written as CSV,
so numbers quoted in prose come from a generated file.

The minima summary (``minima_columns``) is shared with ``simulate_fig5.py``.
"""

import numpy as np
import pandas as pd

V0 = 1.0  # kappa scales as v0**(1 - eta) at fixed DR, so the COR does not depend on v0 (laws.py)


# ---------------------------------------------------------------------------------------------
# Minima summary (also used by simulate_fig5.py)
# ---------------------------------------------------------------------------------------------
def minima_columns(curve: pd.DataFrame, count: int = 3) -> dict:
    """Summary columns of one curve: its first ``count`` COR minima, how many it has, its lowest
    and its largest COR (rows with status ok; ``restitution.analysis.sweeps.local_minima``)."""
    from restitution.analysis.sweeps import local_minima

    ok = curve[curve["status"] == "ok"].sort_values("alpha")
    found = local_minima(ok, "alpha")
    row = {}
    for k in range(count):
        a, c = found.iloc[k][["alpha", "cor"]] if k < len(found) else (np.nan, np.nan)
        row[f"min{k + 1}_alpha"], row[f"min{k + 1}_cor"] = float(a), float(c)
    row["n_minima"] = len(found)
    i = ok["cor"].idxmin() if len(ok) else None
    row["cor_min"] = float(ok.loc[i, "cor"]) if i is not None else np.nan
    row["alpha_at_cor_min"] = float(ok.loc[i, "alpha"]) if i is not None else np.nan
    row["cor_max"] = float(ok["cor"].max()) if len(ok) else np.nan
    return row


# ---------------------------------------------------------------------------------------------
# Fig. 4
# ---------------------------------------------------------------------------------------------
def eq23_bound(alpha, dr):
    """Upper bound of the COR with nominal dissipation ratio DR (paper Eq. 23)."""
    return np.sqrt(1.0 - np.asarray(dr) / (1.0 + np.asarray(alpha)))


def curves(panel: dict) -> list[dict]:
    """Laws of a panel's curves: the plastic ones (a list of DRs or of etas), then linear."""
    if "drs" in panel:
        laws = [dict(contact="plastic", eta=float(panel["eta"]), dr=float(d)) for d in panel["drs"]]
    else:
        laws = [dict(contact="plastic", eta=float(e), dr=float(panel["dr"])) for e in panel["etas"]]
    laws.append(dict(contact="linear", eta=1.0, dr=0.0))
    return [dict(curve=i, beta=float(panel["beta"]), **law) for i, law in enumerate(laws)]


def evaluator(law: dict, sweep: dict, solver: dict):
    """alphas -> result table for one curve's law."""
    import restitution

    def evaluate(alphas):
        alphas = np.asarray(alphas, dtype=np.float64)
        base = pd.DataFrame({"alpha": alphas, "beta": law["beta"], "xi": 0.0, "n_masses": 2})
        if law["contact"] == "linear":
            out = restitution.solve_many(
                base.assign(method=solver["method"]), max_events=solver["max_events"]
            )
        else:
            scenes = base.assign(
                contact="plastic", eta=law["eta"], dr=law["dr"], v0=V0, method="adaptive",
                rtol=sweep["rtol"],
            )  # fmt: skip
            out = restitution.solve_many(scenes, max_events=sweep["max_events"])
        return out.assign(contact=law["contact"], eta=law["eta"], dr=law["dr"], curve=law["curve"])

    return evaluate


def check_bound(curve: pd.DataFrame, logger, label: str) -> dict:
    """Eq. 23 check of one plastic curve: warn on any excess, fail beyond the error estimate."""
    ok = curve[curve["status"] == "ok"]
    excess = ok["cor"].to_numpy() - eq23_bound(ok["alpha"].to_numpy(), ok["dr"].to_numpy())
    above = int((excess > 0).sum())
    if above:
        logger.warning(
            "%s: %d rows above the Eq. 23 bound (max excess %.3g)", label, above, excess.max()
        )
    tolerance = ok["error_estimate"].fillna(0.0).to_numpy()
    beyond = excess > tolerance
    if beyond.any():
        worst = ok.iloc[int(np.argmax(excess - tolerance))]
        raise RuntimeError(
            f"{label}: {int(beyond.sum())} rows exceed the Eq. 23 bound by more than their error "
            f"estimate, worst at alpha = {worst['alpha']:.6g}: COR {worst['cor']:.9f} > bound "
            f"{float(eq23_bound(worst['alpha'], worst['dr'])):.9f}"
        )
    i = int(np.argmax(excess)) if len(excess) else None
    return {
        "bound_max_excess": float(excess[i]) if i is not None else np.nan,
        "bound_alpha_at_max_excess": float(ok["alpha"].iloc[i]) if i is not None else np.nan,
        "n_above_bound": above,
    }


def main(params, output_path, summary_path, logger) -> pd.DataFrame:
    from restitution.analysis import sweeps
    from restitution.tables.io import write_table

    sweep, panel, solver = params.sweep, params.panel, params.solver
    alphas = sweeps.log_grid(sweep["alpha_min"], sweep["alpha_max"], sweep["n_alpha"])
    logger.info(
        "panel %s: %d grid alphas in [%g, %g], beta %g",
        params.name,
        len(alphas),
        alphas[0],
        alphas[-1],
        panel["beta"],
    )
    tables, summary = [], []
    for law in curves(panel):
        label = f"fig4{params.name} {law['contact']} eta={law['eta']:g} DR={law['dr']:g}"
        evaluate = evaluator(law, sweep, solver)
        curve = sweeps.sweep_curve(evaluate, "alpha", alphas, sweep["refine_steps"], logger, label)
        row = dict(law, n_rows=len(curve), n_not_ok=int((curve["status"] != "ok").sum()))
        row.update(minima_columns(curve))
        if law["contact"] == "plastic":
            row.update(check_bound(curve, logger, label))
        tables.append(curve)
        summary.append(row)
    result = pd.concat(tables, ignore_index=True)
    config = {"panel": params.name, "sweep": sweep, "fig4": panel, "solver": solver}
    write_table(result, output_path, config=config)
    write_table(pd.DataFrame(summary), summary_path)
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
        )
