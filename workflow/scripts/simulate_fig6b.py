"""Fig. 6(b) sweep, one job: one chain length N, COR against x = (N-1)*alpha, cusps refined.

The chain (paper Sec. 3.3, Appendix): m1 at the wall, m2..mN all alpha*m1, identical springs k2
between neighbours; the rigid wall (beta = 0) of the Appendix unless ``fig6.sweep.beta`` says
otherwise. The axis variable x = (N-1)*alpha is the rear mass over m1; the grid is log-spaced in
x and alpha = x/(N-1). As for Fig. 2(a), between grid neighbours whose contact counts differ the x
bracket is bisected ``refine_steps`` times on the count (geometric midpoints, all brackets at
once, one ``solve_many`` call per step) and every point evaluated is kept, so each cusp-shaped
minimum is drawn down to its depth.
"""

import numpy as np
import pandas as pd


def solve_x(x, n: int, beta: float, solver: dict) -> pd.DataFrame:
    """One row per x = (N-1)*alpha for chain length ``n`` (column ``x`` added first)."""
    from restitution.analysis import sweeps

    result = sweeps.solve_along(
        "alpha",
        np.asarray(x, dtype=np.float64) / (n - 1),
        {"beta": beta, "n_masses": n},
        method=solver["method"],
        max_events=solver["max_events"],
    )
    result.insert(0, "x", np.asarray(x, dtype=np.float64))
    return result


def main(params, output_path, n: int, logger, progress=False) -> pd.DataFrame:
    from functools import partial

    from restitution.analysis import sweeps
    from restitution.tables.io import write_table

    sweep, solver = dict(params.sweep), dict(params.solver)
    if n < 2:
        raise ValueError(f"fig6.n_masses: a chain needs N >= 2 masses, got {n}")
    grid = sweeps.log_grid(sweep["x_min"], sweep["x_max"], sweep["n_x"])
    logger.info(
        "N = %d, beta %g: %d grid x in [%g, %g]", n, sweep["beta"], len(grid), grid[0], grid[-1]
    )
    evaluate = partial(solve_x, n=n, beta=sweep["beta"], solver=solver)
    result = sweeps.sweep_curve(
        evaluate, "x", grid, sweep["refine_steps"], logger, f"N = {n}", progress
    )
    write_table(
        result, output_path, config={"fig6": {"sweep": sweep}, "solver": solver, "n_masses": n}
    )
    return result


if __name__ == "__main__":
    from _common import Timer, setup, show_progress

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "simulate"):
        main(
            snakemake.params,  # noqa: F821
            snakemake.output.table,  # noqa: F821
            n=int(snakemake.wildcards.n),  # noqa: F821
            logger=log,
            progress=show_progress(),
        )
