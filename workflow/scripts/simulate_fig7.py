"""Fig. 7(a)-(c) sweep, one job: one damping ratio xi, one chunk of the log-spaced alpha grid.

Same scheme as Fig. 2(a) (``simulate_fig2a.py``) with a dashpot F_v = 2 xi k2 (u2' - u1')/omega
between m1 and m2 and one contact stiffness ratio beta (config ``fig7.beta``). The COR minima are
cusps where the contact count ``n_collisions`` changes, so between every pair of grid neighbours
whose counts differ the alpha bracket is bisected ``refine_steps`` times on the count (geometric
midpoints), all brackets at once with one ``solve_many`` call per step, and every point is kept.
Past the peak of the count the count falls, sometimes by many contacts at once (a lost chatter,
not a graze): bisection then locates that drop. Brackets still holding a jump of more than one
contact after refinement are counted in the log.

Chunk k holds grid indices k*chunk_size .. (k+1)*chunk_size inclusive (shared boundary point,
dropped again by aggregate_fig7).
"""

from functools import partial

import numpy as np
import pandas as pd


def chunk_alphas(grid: dict, chunk: int) -> np.ndarray:
    """Grid alphas of one chunk of config['fig7'], the boundary point shared with the next."""
    from restitution.analysis import sweeps

    alphas = sweeps.log_grid(grid["alpha_min"], grid["alpha_max"], grid["n_alpha"])
    return sweeps.chunk(alphas, grid["chunk_size"], chunk)


def solve(alphas, beta: float, xi: float, solver: dict, progress: bool = False) -> pd.DataFrame:
    import restitution

    scenes = pd.DataFrame(
        {
            "alpha": np.asarray(alphas, dtype=np.float64),
            "beta": float(beta),
            "xi": float(xi),
            "n_masses": 2,
            "method": solver["method"],
        }
    )
    return restitution.solve_many(scenes, max_events=solver["max_events"], progress=progress)


def main(params, output_path, xi: float, chunk: int, logger, progress=False) -> pd.DataFrame:
    from restitution.analysis import sweeps
    from restitution.tables.io import write_table

    grid, solver = params.grid, params.solver
    beta = float(grid["beta"])
    if solver["method"] == "impulsive":
        raise ValueError(
            f"method = 'impulsive' needs a rigid wall, but fig7.beta = {beta!r} > 0: "
            "use 'auto' or 'piecewise'"
        )
    alphas = chunk_alphas(grid, chunk)
    logger.info(
        "beta %r, xi %r, chunk %d: %d grid alphas in [%g, %g]",
        beta,
        xi,
        chunk,
        len(alphas),
        alphas[0],
        alphas[-1],
    )
    result = sweeps.refined_sweep(
        solve(alphas, beta, xi, solver, progress=progress),
        partial(solve, beta=beta, xi=xi, solver=solver),
        "alpha",
        grid["refine_steps"],
        logger,
        progress=progress,
    )
    sweeps.log_not_ok(result, logger, where="alpha")
    logger.info(
        "%d rows (%d refined), contacts %d..%d, COR min %.6f",
        len(result),
        result["refined"].sum(),
        result["n_collisions"].min(),
        result["n_collisions"].max(),
        result["cor"].min(),
    )
    write_table(result, output_path, config={"grid": grid, "solver": solver, "xi": xi})
    return result


if __name__ == "__main__":
    from _common import Timer, setup, show_progress

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "simulate"):
        main(
            snakemake.params,  # noqa: F821
            snakemake.output.table,  # noqa: F821
            xi=float(snakemake.wildcards.xi),  # noqa: F821
            chunk=int(snakemake.wildcards.chunk),  # noqa: F821
            logger=log,
            progress=show_progress(),
        )
