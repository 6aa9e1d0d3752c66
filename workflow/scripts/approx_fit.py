"""Fits of the paper's laws and errors of the approximate COR models (rule ``approx_fit``).

Reads the exact special points (rule approx_points) and writes into results/approx/:

- ``fit.json``: every fit (values, standard errors from the Jacobian, R^2, RMS and max residual,
  the paper's values), the improved model's universal shape, max/RMS errors of each model over
  the configured alpha range, and the evaluation cost of each model (microseconds per alpha);
- ``law_residuals.parquet``: per n, the exact points next to the paper's and our fitted laws;
- ``errors.parquet``: the error table; ``shape_table.parquet``: the per-window shape coefficients;
- ``cor_curves.parquet``: exact and approximate COR on a plotting grid (Fig. 2(d)).
"""

import json
import time

import numpy as np
import pandas as pd


def models(fits: dict, universal: tuple, table: pd.DataFrame) -> dict:
    """name -> f(alpha) for every approximate model compared."""
    from restitution.analysis import approx

    p, q = fits["eq19_unity"].params["p"], fits["eq22_gap_n1"].params["q"]
    c = fits["minima_c_n1"].params["c"]
    eta = fits["eq21_eta"].params
    return {
        "paper": lambda a: approx.paper_cor(a),
        "paper_exact_first_branch": lambda a: approx.paper_cor(a, exact_first=True),
        "paper_refit": lambda a: approx.paper_cor(a, p, q, c, eta["eta1"], eta["eta2"]),
        "paper_shape_exact_points": lambda a: approx.paper_cor_exact_points(
            a, points=table, exact_gamma=True
        ),
        "improved": lambda a: approx.improved_cor(a, table),
        "improved_universal": lambda a: approx.improved_cor(a, table, shape=universal),
    }


def cost_us(f, alpha, repeats: int = 5) -> float:
    """Best wall time per alpha of a vectorised call, in microseconds."""
    f(alpha[:10])
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        f(alpha)
        best = min(best, time.perf_counter() - t)
    return 1e6 * best / alpha.size


def main(points_path, out, cfg, logger):
    from restitution.analysis import approx, fitting
    from restitution.analysis import special_points as sp
    from restitution.tables.io import read_table, write_table

    pts = read_table(points_path)
    lo, hi = float(cfg["alpha_min"]), float(cfg["alpha_max"])
    if pts["alpha_star"].iloc[-1] <= hi:
        raise ValueError(f"{points_path}: alpha*_n_max = {pts['alpha_star'].iloc[-1]:g} does not "
                         f"cover approx.alpha_max = {hi:g}; raise approx.n_max")  # fmt: skip
    fit_pts = pts[pts["alpha_star"] <= hi].reset_index(drop=True)
    fits = fitting.fit_all(pts, lo, hi, int(cfg["n_eta"]))
    # Per-window shapes on every tabulated window, universal shape pooled over the fit range.
    rows = [np.full(6, np.nan)] + [approx.fit_window_shape(pts, n) for n in range(2, len(pts) + 1)]
    coef = pd.DataFrame(np.array(rows), columns=["a1", "a2", "a3", "b0", "b1", "b2"])
    table = pd.concat([pts.reset_index(drop=True), coef], axis=1)
    fits["improved_shape"] = fitting.fit_universal_shape(table, 2, len(fit_pts))
    universal = tuple(fits["improved_shape"].params.values())
    for f in fits.values():
        logger.info("%s: %s +- %s (paper %s), R2 %.6f, rms %.3g", f.name, f.params, f.stderr,
                    f.paper, f.r2, f.rms)  # fmt: skip

    ms = models(fits, universal, table)
    grid = approx.error_grid(lo, hi, int(cfg["n_alpha"]))
    exact = sp.rigid_reference(grid)["cor"].to_numpy()
    err = approx.errors(ms, grid, exact)
    err["cost_us_per_alpha"] = [cost_us(ms[m], grid) for m in err["model"]]
    paper_max = float(err.loc[err.model == "paper", "max_abs_error"].iloc[0])
    err["max_error_ratio_vs_paper"] = paper_max / err["max_abs_error"]
    logger.info("errors over alpha in [%g, %g] (%d points):\n%s", lo, hi, grid.size,
                err.to_string())  # fmt: skip

    curve_a = approx.error_grid(lo, hi, int(cfg["n_plot"]))
    curves = pd.DataFrame({"alpha": curve_a, "exact": sp.rigid_reference(curve_a)["cor"]})
    for name, f in ms.items():
        curves[name] = f(curve_a)

    residuals = fitting.law_residuals(fit_pts, fits)
    write_table(residuals, out.residuals, config=cfg)
    write_table(err, out.errors, config=cfg)
    write_table(table, out.shapes, config=cfg)
    write_table(curves, out.curves, config=cfg)
    summary = {
        "paper": approx.PAPER,
        "fits": {k: f.to_dict() for k, f in fits.items()},
        "universal_shape": dict(zip(["a1", "a2", "a3", "b0", "b1", "b2"], universal, strict=True)),
        "errors": err.to_dict(orient="records"),
        "alpha_range": [lo, hi],
        "n_special_points_fitted": len(fit_pts),
        "first_special_points": pts.head(5)[["n", "alpha_star", "e_star", "alpha_unity"]].to_dict(
            orient="records"
        ),
    }
    with open(out.fit, "w") as fh:
        json.dump(summary, fh, indent=2, sort_keys=True)


if __name__ == "__main__":
    from _common import Timer, setup

    smk = snakemake  # noqa: F821 (injected by Snakemake)
    log = setup(smk)
    with Timer(log, "approx_fit"):
        main(smk.input.points, smk.output, dict(smk.params.approx), log)
