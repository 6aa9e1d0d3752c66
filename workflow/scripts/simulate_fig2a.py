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

import numpy as np
import pandas as pd


def alpha_grid(grid: dict) -> np.ndarray:
    """The full log-spaced grid of config['fig2a']."""
    return np.geomspace(grid["alpha_min"], grid["alpha_max"], grid["n_alpha"])


def chunk_alphas(grid: dict, chunk: int) -> np.ndarray:
    """Grid alphas of one chunk, the boundary point shared with the next chunk included."""
    alphas = alpha_grid(grid)
    size = grid["chunk_size"]
    start = chunk * size
    if not 0 <= start < len(alphas) - 1:
        raise ValueError(
            f"chunk {chunk} is outside the grid of {len(alphas)} alphas ({size} a chunk)"
        )
    return alphas[start : min(start + size, len(alphas) - 1) + 1]


def solve(alphas: np.ndarray, beta: float, solver: dict, progress: bool = False) -> pd.DataFrame:
    import restitution

    scenes = pd.DataFrame(
        {
            "alpha": np.asarray(alphas, dtype=np.float64),
            "beta": float(beta),
            "xi": 0.0,
            "n_masses": 2,
            "method": solver["method"],
        }
    )
    return restitution.solve_many(scenes, max_events=solver["max_events"], progress=progress)


def refine(table: pd.DataFrame, beta: float, solver: dict, steps: int, logger, progress=False):
    """Bisect every grid interval whose contact count changes; return the new rows."""
    from tqdm.auto import tqdm

    table = table.sort_values("alpha")
    alpha = table["alpha"].to_numpy()
    count = table["n_collisions"].to_numpy()
    jumps = np.flatnonzero(count[1:] != count[:-1])
    logger.info("%d changes of the contact count to refine, %d steps each", len(jumps), steps)
    if steps == 0 or len(jumps) == 0:
        return table.iloc[:0]
    lo, hi, n_lo = alpha[jumps], alpha[jumps + 1], count[jumps]
    rows = []
    for _ in tqdm(range(steps), desc="refine", disable=not progress):
        mid = np.sqrt(lo * hi)
        new = solve(mid, beta, solver)
        rows.append(new)
        same = new["n_collisions"].to_numpy() == n_lo
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    width = np.log10(hi / lo)
    logger.info("final brackets: widest %.3g decades of alpha", width.max())
    return pd.concat(rows, ignore_index=True)


def main(params, output_path, beta: float, chunk: int, logger, progress=False) -> pd.DataFrame:
    from restitution.io import write_table

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
    table = solve(alphas, beta, solver, progress=progress)
    table["refined"] = False
    extra = refine(table, beta, solver, grid["refine_steps"], logger, progress)
    extra = extra.assign(refined=True)
    result = (
        pd.concat([table, extra], ignore_index=True)
        .drop_duplicates(subset="alpha", keep="first")
        .sort_values("alpha", ignore_index=True)
    )
    bad = result["status"] != "ok"
    if bad.any():
        logger.warning(
            "%d of %d scenes not ok: %s",
            bad.sum(),
            len(result),
            result.loc[bad, "status"].value_counts().to_dict(),
        )
    logger.info(
        "%d rows (%d refined), contacts %d..%d, COR min %.6f",
        len(result),
        result["refined"].sum(),
        result["n_collisions"].min(),
        result["n_collisions"].max(),
        result["cor"].min(),
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
