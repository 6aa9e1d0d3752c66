"""Fig. 9 data, one job: the COR against the impact speed V0 with Hertz contact, every curve.

Curves: the two-mass chains m = [1, alpha], spring alpha/(1 + alpha) of ``fig9.alphas`` (panel
a) and the paper's uniform chains of ``fig9.chain_n`` masses (Fig. 6: m2..mN = chain_alpha m1,
equal springs; panel b), all built by ``restitution.Chain.paper`` (omega = 1), on the Hertz
contact ``fig9.k_hertz``. Each is swept by ``restitution.analysis.speed.cor_against_speed``: the
log V0 grid, every change of the contact count bisected in log V0, the rigid-wall chain solved
exactly. Three tables:

- ``table``: every row solved (status, method, error_estimate kept), with the curve's
  identifiers and, per V0, omega t_c (Hertz contact time of the total mass), q = omega_1 T
  (slowest mode over the pulse's time scale) and the soft-limit envelope of 1 - COR;
- ``limits``: one row per curve, its rigid-wall result and slowest mode;
- ``changes``: one row per count change, its bracket and whether it closed to the tolerance.
"""

import numpy as np
import pandas as pd


def curves(fig9: dict) -> list[dict]:
    """Identifiers and chain of every curve, panel (a) first."""
    from restitution_workflow.config_check import fig9_chains

    out = []
    for (label, chain), panel in zip(fig9_chains(fig9), ["a"] * len(fig9["alphas"])
                                     + ["b"] * len(fig9["chain_n"]), strict=True):  # fmt: skip
        out.append(dict(curve=label, panel=panel, alpha=float(chain.masses[-1]),
                        n_masses=len(chain.masses), masses=chain.masses.tolist(),
                        springs=chain.springs.tolist()))  # fmt: skip
    return out


def main(params, paths: dict, logger, progress=False) -> dict:
    from restitution.analysis import speed, sweeps
    from restitution.tables.io import write_table

    fig9 = dict(params.fig9)
    grid = sweeps.log_grid(fig9["v0_min"], fig9["v0_max"], fig9["n_v0"])
    kh = fig9["k_hertz"]
    logger.info("Hertz k_h = %g, %d V0 in [%g, %g], %d bisection steps, rtol %g", kh, len(grid),
                grid[0], grid[-1], fig9["refine_steps"], fig9["rtol"])  # fmt: skip
    tables, limits, changes = [], [], []
    todo = curves(fig9)
    if progress:
        from tqdm.auto import tqdm

        todo = tqdm(todo, desc="fig9 curves")
    for c in todo:
        ident = {k: c[k] for k in ("curve", "panel", "alpha", "n_masses")}
        s = speed.cor_against_speed(c["masses"], c["springs"], kh, grid,
                                    refine_steps=fig9["refine_steps"], rtol=fig9["rtol"],
                                    max_events=params.max_events, logger=logger,
                                    label=c["curve"])  # fmt: skip
        omega, _ = speed.free_modes(c["masses"], c["springs"])
        total = float(np.sum(c["masses"]))
        t = s.table
        v0 = t["v0"].to_numpy()
        derived = pd.DataFrame({
            "omega_tc": speed.hertz_contact_time(total, kh, v0),  # omega = 1 (Chain.paper)
            "q": omega[0] * speed.hertz_time_scale(total, kh, v0),
            "soft_envelope": speed.soft_limit_envelope(c["masses"], c["springs"], kh, v0),
        })  # fmt: skip
        tables.append(pd.concat([pd.DataFrame([ident] * len(t)), t, derived], axis=1))
        limits.append({**ident, **{f"rigid_{k}": v for k, v in s.rigid.items()},
                       "omega_1": float(omega[0]), "tolerance": s.tolerance})  # fmt: skip
        ch = s.changes.reset_index(drop=True)
        cor = t.set_index("v0")["cor"]
        ch = ch.assign(cor_lo=cor.loc[ch["v0_lo"]].to_numpy(),
                       cor_hi=cor.loc[ch["v0_hi"]].to_numpy())  # fmt: skip
        changes.append(pd.concat([pd.DataFrame([ident] * len(ch)), ch], axis=1))
    provenance = {"fig9": fig9, "max_events": params.max_events}
    out = {
        "table": pd.concat(tables, ignore_index=True),
        "limits": pd.DataFrame(limits),
        "changes": pd.concat(changes, ignore_index=True),
    }
    for name, frame in out.items():
        write_table(frame, paths[name], config=provenance)
    logger.info("%d rows, %d not ok; %d count changes", len(out["table"]),
                int((out["table"]["status"] != "ok").sum()), len(out["changes"]))  # fmt: skip
    return out


if __name__ == "__main__":
    from _common import Timer, setup, show_progress

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "simulate"):
        main(
            snakemake.params,  # noqa: F821
            {k: snakemake.output[k] for k in ("table", "limits", "changes")},  # noqa: F821
            logger=log,
            progress=show_progress(),
        )
