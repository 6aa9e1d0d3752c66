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

import pandas as pd


def main(params, output_path, xi: float, chunk: int, logger, progress=False) -> pd.DataFrame:
    from functools import partial

    from _common import chunk_alphas

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
    evaluate = partial(
        sweeps.solve_along,
        "alpha",
        scene={"beta": beta, "xi": xi},
        method=solver["method"],
        max_events=solver["max_events"],
    )
    result = sweeps.sweep_curve(
        evaluate, "alpha", alphas, grid["refine_steps"], logger, f"xi {xi:g}", progress
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
