"""Fig. 3 simulations (paper Sec. 3.1): the contact stiffness beta = k2/k1 at a fixed mass ratio.

Two rules run this script (chosen by the rule name):

``simulate_fig3a``
    COR against beta on a log-spaced grid for every alpha of ``fig3.sweep``. The COR minima are
    cusps at the beta where one more contact just grazes the wall (the contact count changes, the
    COR is continuous with a kink), so between grid neighbours whose counts differ the beta
    bracket is bisected ``refine_steps`` times on the count (geometric midpoints, all brackets of
    one alpha at once) and every point evaluated is kept, as for Fig. 2(a). Writes the sweep and
    its local COR minima (CSV).

``simulate_fig3b``
    The contact compression x1 = -u1 (units V0/omega; 0 out of contact) against omega*t for the
    betas of ``fig3.compression``, sampled in closed form (``restitution.trajectory``) on a
    uniform grid plus the exact start and end times of every contact; the per-contact history
    (start, end, largest compression); and the marginal beta: the bracket ``marginal_bracket`` is
    bisected on the contact count until the round-off, giving the beta at which the last contact
    appears.
"""

from functools import partial

import numpy as np
import pandas as pd

# Golden-section steps at a smooth COR minimum: 0.618**20 ~ 7e-5 of a ~2% bracket puts beta within
# ~1e-6 (relative) of the minimum, where the COR differs from the minimum by ~1e-12; more steps
# only chase round-off. Fewer if refine_steps is smaller (0 switches it off).
POLISH_STEPS = 20
# Local minima closer than this (relative beta) are one minimum (the one with the lowest COR).
SAME_MINIMUM = 1e-5


# ---------------------------------------------------------------------------------------------
# Fig. 3(a)
# ---------------------------------------------------------------------------------------------
def solve_betas(alpha: float, betas, solver: dict) -> pd.DataFrame:
    """One row per beta at mass ratio ``alpha`` (two masses, no dashpot)."""
    from restitution.analysis import sweeps

    return sweeps.solve_along(
        "beta", betas, {"alpha": alpha}, method=solver["method"], max_events=solver["max_events"]
    )


def polish_minima(table: pd.DataFrame, alpha: float, solver: dict, steps: int, logger):
    """Golden-section search (on log beta) around every local COR minimum; the new rows.

    For finite beta a minimum need not sit exactly where the count changes: at alpha = 2.2 the
    COR of the three-contact branch bottoms out just below the beta where the third contact
    vanishes. Each minimum of the (already cusp-refined) curve is bracketed by its neighbours and
    narrowed ``steps`` times (factor 0.618 each), so smooth minima are drawn at their depth too; a
    minimum at a cusp stays at the cusp (the COR is continuous there).
    """
    from restitution.analysis.sweeps import interior_minima

    table = table[table["status"] == "ok"].sort_values("beta")
    beta = np.log(table["beta"].to_numpy())
    inner = interior_minima(table["cor"].to_numpy())
    if steps == 0 or len(inner) == 0:
        return table.iloc[:0]
    golden = (np.sqrt(5.0) - 1.0) / 2.0
    a, b = beta[inner - 1], beta[inner + 1]
    c, d = b - golden * (b - a), a + golden * (b - a)
    rows = [solve_betas(alpha, np.exp(np.concatenate([c, d])), solver)]
    fc, fd = np.split(rows[0]["cor"].to_numpy(), 2)
    for _ in range(steps):
        left = fc < fd  # the minimum lies in [a, d]
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        d_new = np.where(left, c, a + golden * (b - a))
        c_new = np.where(left, b - golden * (b - a), d)
        fd_keep = np.where(left, fc, fd)
        fc_keep = np.where(left, fc, fd)
        probe = np.where(left, c_new, d_new)
        new = solve_betas(alpha, np.exp(probe), solver)
        rows.append(new)
        f_new = new["cor"].to_numpy()
        fc = np.where(left, f_new, fc_keep)
        fd = np.where(left, fd_keep, f_new)
        c, d = c_new, d_new
    logger.info(
        "alpha %g: %d COR minima polished, %d golden-section steps, final brackets <= %.2g",
        alpha,
        len(inner),
        steps,
        np.max(b - a),
    )
    return pd.concat(rows, ignore_index=True)


def main_sweep(params, sweep_path, minima_path, logger, progress=False) -> pd.DataFrame:
    from _common import log_minima

    from restitution.analysis import sweeps
    from restitution.tables.io import write_table

    sweep, solver = dict(params.sweep), dict(params.solver)
    grid = sweeps.log_grid(sweep["beta_min"], sweep["beta_max"], sweep["n_beta"])
    curves = []
    for alpha in sweep["alphas"]:
        curve = sweeps.sweep_curve(
            partial(solve_betas, alpha, solver=solver),
            "beta",
            grid,
            sweep["refine_steps"],
            logger,
            f"alpha {alpha:g}",
            progress,
        )
        steps = min(sweep["refine_steps"], POLISH_STEPS)
        polished = polish_minima(curve, alpha, solver, steps, logger)
        curves.append(pd.concat([curve, polished.assign(refined=True)], ignore_index=True))
    result = (
        pd.concat(curves, ignore_index=True)
        .drop_duplicates(subset=["alpha", "beta"], keep="first")
        .sort_values(["alpha", "beta"], ignore_index=True)
    )
    config = {"fig3": {"sweep": sweep}, "solver": solver}
    write_table(result, sweep_path, config=config)
    # Round-off ripples at the bottom of a polished minimum: the lowest of each cluster counts.
    minima = sweeps.local_minima(result, "beta", by="alpha", merge=SAME_MINIMUM)
    write_table(minima, minima_path, config=config)
    log_minima(logger, minima, "alpha", "beta")
    return result


# ---------------------------------------------------------------------------------------------
# Fig. 3(b)
# ---------------------------------------------------------------------------------------------
def compression_curve(alpha: float, beta: float, t_max: float, n_times: int, history):
    """(omega*t, compression) with the exact contact start and end times among the samples."""
    import restitution

    events = np.concatenate([history["omega_t_start"], history["omega_t_end"]])
    times = np.union1d(np.linspace(0.0, t_max, n_times), events[events <= t_max])
    motion = restitution.trajectory(alpha=alpha, beta=beta, times=times)  # omega = 1: t = omega*t
    compression = np.maximum(-motion["u_1"].to_numpy(), 0.0)
    # At the exact switching times the closed form leaves |u1| at round-off: make it zero.
    compression[np.isin(times, events)] = 0.0
    return times, compression


def marginal_beta(alpha: float, bracket, steps: int, solver: dict, logger) -> dict:
    """Bisect ``bracket`` (geometric midpoints) on the contact count; one row of the CSV.

    The bisection is ``restitution.analysis.sweeps.refine_count_changes`` on the two ends; the
    final bracket is the largest beta evaluated with the count of the low end and the smallest
    beta evaluated with another count (the brackets nest). Steps past the round-off repeat an end
    and change nothing.
    """
    import restitution
    from restitution.analysis import sweeps

    lo, hi = (float(b) for b in bracket)
    if not 0 < lo < hi:
        raise ValueError(
            f"fig3.compression.marginal_bracket = {list(bracket)!r}: need 0 < low < high"
        )
    evaluate = partial(solve_betas, alpha, solver=solver)
    ends = evaluate([lo, hi])
    n_lo, n_hi = (int(n) for n in ends["n_collisions"])
    if n_lo == n_hi:
        raise ValueError(
            f"fig3.compression.marginal_bracket = {list(bracket)!r}: the number of contacts is "
            f"{n_lo} at both ends (alpha = {alpha}); widen the bracket around the change"
        )
    rows = pd.concat(
        [ends, sweeps.refine_count_changes(ends, evaluate, "beta", steps)], ignore_index=True
    )
    below = rows[rows["n_collisions"] == n_lo]
    above = rows[rows["n_collisions"] != n_lo]
    low, high = below.loc[below["beta"].idxmax()], above.loc[above["beta"].idxmin()]
    lo, hi, n_hi = float(low["beta"]), float(high["beta"]), int(high["n_collisions"])
    cor_lo, cor_hi = float(low["cor"]), float(high["cor"])
    beta_star = float(np.sqrt(lo * hi))
    last = restitution.solve(alpha, lo if n_lo > n_hi else hi, history=True).history
    row = {
        "alpha": alpha,
        "beta_marginal": beta_star,
        "beta_low": lo,
        "beta_high": hi,
        "n_collisions_low": n_lo,
        "n_collisions_high": n_hi,
        "cor_low": cor_lo,
        "cor_high": cor_hi,
        "last_contact_x_max": float(last["x_max"].iloc[-1]),
        "paper_beta": 0.1,
        "relative_difference": beta_star / 0.1 - 1.0,
    }
    logger.info(
        "alpha %g: contacts %d -> %d at beta = %.15g (bracket width %.2g), COR %.9f / %.9f, "
        "the vanishing contact's largest compression %.3g",
        alpha,
        n_lo,
        n_hi,
        beta_star,
        hi - lo,
        cor_lo,
        cor_hi,
        row["last_contact_x_max"],
    )
    return row


def main_compression(params, paths, logger) -> pd.DataFrame:
    import restitution
    from restitution.tables.io import write_table

    comp, solver = dict(params.compression), dict(params.solver)
    alpha = float(comp["alpha"])
    curves, contacts = [], []
    for beta in comp["betas"]:
        result = restitution.solve(
            alpha, beta, method=solver["method"], max_events=solver["max_events"], history=True
        )
        hist = result.history
        if hist["omega_t_end"].iloc[-1] > comp["t_max"]:
            logger.warning(
                "beta %g: the last contact ends at omega*t = %.3f, after t_max = %g",
                beta,
                hist["omega_t_end"].iloc[-1],
                comp["t_max"],
            )
        times, x = compression_curve(alpha, beta, comp["t_max"], comp["n_times"], hist)
        curves.append(
            pd.DataFrame({"alpha": alpha, "beta": float(beta), "omega_t": times, "compression": x})
        )
        contacts.append(
            hist.assign(
                alpha=alpha, beta=float(beta), contact=np.arange(1, len(hist) + 1), cor=result.cor
            )
        )
        logger.info(
            "beta %g: %d contacts, COR %.6f, contacts end at omega*t %s, largest compressions %s",
            beta,
            result.n_collisions,
            result.cor,
            ", ".join(f"{t:.4f}" for t in hist["omega_t_end"]),
            ", ".join(f"{v:.4g}" for v in hist["x_max"]),
        )
    config = {"fig3": {"compression": comp}, "solver": solver}
    write_table(pd.concat(curves, ignore_index=True), paths.compression, config=config)
    columns = [
        "alpha",
        "beta",
        "contact",
        "omega_t_start",
        "omega_t_end",
        "x_max",
        "impulse",
        "cor",
    ]
    write_table(pd.concat(contacts, ignore_index=True)[columns], paths.contacts, config=config)
    row = marginal_beta(alpha, comp["marginal_bracket"], comp["marginal_steps"], solver, logger)
    write_table(pd.DataFrame([row]), paths.marginal, config=config)
    return pd.DataFrame([row])


if __name__ == "__main__":
    from _common import Timer, setup, show_progress

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, snakemake.rule):  # noqa: F821
        if snakemake.rule == "simulate_fig3a":  # noqa: F821
            main_sweep(
                snakemake.params,  # noqa: F821
                snakemake.output.sweep,  # noqa: F821
                snakemake.output.minima,  # noqa: F821
                log,
                progress=show_progress(),
            )
        elif snakemake.rule == "simulate_fig3b":  # noqa: F821
            main_compression(snakemake.params, snakemake.output, log)  # noqa: F821
        else:
            raise ValueError(f"simulate_fig3.py does not serve rule {snakemake.rule!r}")  # noqa: F821
