"""Fig. 8(a) map, one chunk: COR and contact count of the two-mass model on an (alpha, beta) grid.

alpha log-spaced in [alpha_min, alpha_max]; beta = 0 (the rigid wall, the map's bottom strip) plus
a log grid in [beta_min, beta_max]. The grid's beta rows are split into ``chunks`` jobs; each calls
``restitution.solve_many`` once.
"""

import numpy as np
import pandas as pd


def grid(m: dict):
    """(alphas, betas) of the map: betas start with 0 (the rigid-wall strip)."""
    alphas = np.geomspace(m["alpha_min"], m["alpha_max"], m["n_alpha"])
    betas = np.r_[0.0, np.geomspace(m["beta_min"], m["beta_max"], m["n_beta"])]
    return alphas, betas


def main(params, output_path, chunk: int, logger, progress=False) -> pd.DataFrame:
    import restitution
    from restitution.tables.io import write_table

    m, solver = dict(params.map), dict(params.solver)
    alphas, betas = grid(m)
    mine = np.array_split(betas, m["chunks"])[chunk]
    A, B = np.meshgrid(alphas, mine)
    scenes = pd.DataFrame({"alpha": A.ravel(), "beta": B.ravel(), "method": solver["method"]})
    logger.info("chunk %d: %d betas x %d alphas", chunk, mine.size, alphas.size)
    result = restitution.solve_many(scenes, max_events=solver["max_events"], progress=progress)
    bad = (result["status"] != "ok").sum()
    logger.info("chunk %d: %d scenes, %d not ok, COR %.4f..%.4f", chunk, len(result), bad,
                result["cor"].min(), result["cor"].max())  # fmt: skip
    write_table(result, output_path, config={"fig8": {"map": m}, "solver": solver, "chunk": chunk})
    return result


if __name__ == "__main__":
    from _common import Timer, setup, show_progress

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "simulate"):
        main(
            snakemake.params,  # noqa: F821
            snakemake.output.table,  # noqa: F821
            chunk=int(snakemake.wildcards.chunk),  # noqa: F821
            logger=log,
            progress=show_progress(),
        )
