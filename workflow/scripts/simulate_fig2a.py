"""Fig. 2(a) sweep, one job: one beta, one chunk of the log-spaced alpha grid, cusps refined.

The COR minima are cusps at the alpha where one more contact just grazes the wall: the contact
count ``n_collisions`` changes there and the COR is continuous with a kink. A grid misses their
depth, so between every pair of grid neighbours whose contact counts differ, the alpha bracket is
bisected ``refine_steps`` times on the contact count (geometric midpoints: halving on the log
axis), all brackets at once with one ``solve_many`` call per step. Every point evaluated is kept;
they cluster at the cusp, so the curve is drawn down to its depth. If the count changes more than
once inside one bracket (possible for finite beta), bisection resolves one of the changes.

Chunk k holds grid indices k*chunk_size .. (k+1)*chunk_size inclusive: neighbouring chunks share
their boundary alpha, so no change of the count between chunks is missed (aggregate drops the
duplicate row).
"""

import pandas as pd


def main(params, output_path, beta: float, chunk: int, logger, progress=False) -> pd.DataFrame:
    from functools import partial

    from _common import chunk_alphas

    from restitution.analysis import sweeps
    from restitution.tables.io import write_table

    grid, solver = params.grid, params.solver
    alphas = chunk_alphas(grid, chunk)
    logger.info(
        "beta %r, chunk %d: %d grid alphas in [%g, %g]",
        beta,
        chunk,
        len(alphas),
        alphas[0],
        alphas[-1],
    )
    evaluate = partial(
        sweeps.solve_along,
        "alpha",
        scene={"beta": beta},
        method=solver["method"],
        max_events=solver["max_events"],
    )
    result = sweeps.sweep_curve(
        evaluate, "alpha", alphas, grid["refine_steps"], logger, f"beta {beta:g}", progress
    )
    write_table(result, output_path, config={"grid": grid, "solver": solver, "beta": beta})
    return result


if __name__ == "__main__":
    from _common import Timer, setup, show_progress

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "simulate"):
        main(
            snakemake.params,  # noqa: F821
            snakemake.output.table,  # noqa: F821
            beta=float(snakemake.wildcards.beta),  # noqa: F821
            chunk=int(snakemake.wildcards.chunk),  # noqa: F821
            logger=log,
            progress=show_progress(),
        )
