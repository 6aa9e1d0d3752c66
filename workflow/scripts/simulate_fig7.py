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

import numpy as np
import pandas as pd


def alpha_grid(grid: dict) -> np.ndarray:
    """The full log-spaced grid of config['fig7']."""
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


def refine(table, beta, xi, solver, steps, logger, progress=False) -> pd.DataFrame:
    """Bisect every grid interval whose contact count changes; return the new rows."""
    from tqdm.auto import tqdm

    table = table.sort_values("alpha")
    alpha = table["alpha"].to_numpy()
    count = table["n_collisions"].to_numpy()
    jumps = np.flatnonzero(count[1:] != count[:-1])
    logger.info("%d changes of the contact count to refine, %d steps each", len(jumps), steps)
    if steps == 0 or len(jumps) == 0:
        return table.iloc[:0]
    lo, hi = alpha[jumps], alpha[jumps + 1]
    n_lo, n_hi = count[jumps].copy(), count[jumps + 1].copy()
    rows = []
    for _ in tqdm(range(steps), desc="refine", disable=not progress):
        mid = np.sqrt(lo * hi)
        new = solve(mid, beta, xi, solver)
        rows.append(new)
        n_mid = new["n_collisions"].to_numpy()
        same = n_mid == n_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        n_hi = np.where(same, n_hi, n_mid)
    width = np.log10(hi / lo)
    step = np.abs(n_hi - n_lo)
    logger.info(
        "final brackets: widest %.3g decades of alpha; %d of %d end on a jump of more than one "
        "contact (largest %d)",
        width.max(),
        int((step > 1).sum()),
        len(step),
        int(step.max()),
    )
    return pd.concat(rows, ignore_index=True)


def main(params, output_path, xi: float, chunk: int, logger, progress=False) -> pd.DataFrame:
    from restitution.io import write_table

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
    table = solve(alphas, beta, xi, solver, progress=progress)
    table["refined"] = False
    extra = refine(table, beta, xi, solver, grid["refine_steps"], logger, progress)
    extra = extra.assign(refined=True)
    result = (
        pd.concat([table, extra], ignore_index=True)
        .drop_duplicates(subset="alpha", keep="first")
        .sort_values("alpha", ignore_index=True)
    )
    bad = result["status"] != "ok"
    if bad.any():
        logger.warning(
            "%d of %d scenes not ok: %s; first at alpha %s",
            bad.sum(),
            len(result),
            result.loc[bad, "status"].value_counts().to_dict(),
            result.loc[bad, "alpha"].head(5).tolist(),
        )
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
