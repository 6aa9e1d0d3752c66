"""Special points of the COR curve: exact beta = 0 points, and their finite-beta counterparts.

Rule ``approx_points`` (beta = 0): alpha*_n, e*_n, alpha#_n for n = 1..n_max by root solving
their defining conditions (restitution.analysis.special_points), written with provenance, plus a
log of
the residuals of the conditions and of the closed-form checks (alpha*_1 from tan x = x,
alpha#_2 = 1).

Rule ``approx_finite_beta``: for each beta > 0, every alpha where the contact count changes
(bisection on the count of restitution.solve_many; the COR there is the cusp minimum) and the
smooth COR minima that are not at a count change (beta = 1 has only those).
"""

import numpy as np
import pandas as pd


def exact_points(n_max: int, logger) -> pd.DataFrame:
    from restitution.analysis import special_points as sp

    pts = sp.special_points(n_max)
    closed = sp.alpha_star_1_closed_form()
    logger.info("alpha*_1 = %.16g, closed form %.16g (diff %.2e)", pts.alpha_star[0], closed,
                pts.alpha_star[0] - closed)  # fmt: skip
    logger.info("alpha#_2 = %.16g (exact 1)", pts.alpha_unity[1])
    for col in ("grazing_residual", "unity_residual", "vibration_residual"):
        logger.info("max |%s| = %.2e", col, np.abs(pts[col]).max())
    return pts


def finite_beta_points(betas, alpha_min, alpha_max, n_grid, steps, max_events, logger):
    from restitution.analysis import special_points as sp

    frames = []
    for beta in betas:
        solver = sp.kernel_solver(float(beta), max_events)
        ch = sp.count_changes(solver, alpha_min, alpha_max, n_grid, steps)
        frames.append(
            pd.DataFrame({"beta": float(beta), "kind": "count_change", "alpha": ch.alpha_change,
                          "cor": np.minimum(ch.cor_below, ch.cor_above), "bracket": ch.bracket,
                          "n_below": ch.n_below, "n_above": ch.n_above})
        )  # fmt: skip
        sm = sp.smooth_minima(solver, alpha_min, alpha_max, n_grid)
        frames.append(
            pd.DataFrame({"beta": float(beta), "kind": "smooth_minimum", "alpha": sm.alpha_min,
                          "cor": sm.cor_min, "bracket": np.nan, "n_below": sm.n_collisions,
                          "n_above": sm.n_collisions})
        )  # fmt: skip
        logger.info(
            "beta %g: %d count changes, %d smooth minima; first %s",
            beta,
            len(ch),
            len(sm),
            ch.head(3)[["alpha_change", "cor_below"]].to_numpy().round(6).tolist(),
        )
    out = pd.concat([f for f in frames if len(f)], ignore_index=True)
    out["n_below"] = out["n_below"].astype(np.int64)
    out["n_above"] = out["n_above"].astype(np.int64)
    return out.sort_values(["beta", "alpha"], ignore_index=True)


if __name__ == "__main__":
    from _common import Timer, setup

    from restitution.tables.io import write_table

    smk = snakemake  # noqa: F821 (injected by Snakemake)
    log = setup(smk)
    cfg = dict(smk.params.approx)
    with Timer(log, smk.rule):
        if smk.rule == "approx_points":
            table = exact_points(int(cfg["n_max"]), log)
        else:
            table = finite_beta_points(
                cfg["finite_betas"],
                cfg["finite_alpha_min"],
                cfg["finite_alpha_max"],
                int(cfg["finite_n_grid"]),
                int(cfg["finite_steps"]),
                int(smk.params.max_events),
                log,
            )
        write_table(table, smk.output.table, config=cfg)
