"""Fig. 7(d) traces: contact compression s1(t) = max(-u1, 0) for each (xi, alpha), closed form.

For every xi in ``traces.xis`` and alpha in ``traces.alphas`` (beta = fig7.beta) the scene is
solved once with its contact history (one row per contact: omega*t at start and end), then the
closed-form motion is sampled by ``restitution.trajectory`` on a time grid
made of ``n_uniform`` points over [0, omega*t_col] plus, inside every contact interval (its end
points included), ``samples_per_contact`` cosine-spaced points or more, so that no step exceeds
``max_step`` (omega*t units): each short contact (omega*t ~ 0.1 for beta = 1e-3) is drawn with its
true shape and peak, and so is the fast contact-spring ringing inside the long last contact.
Check: the uniform samples outside every recorded contact must have s1 = 0 (u1 >= 0), else the
job fails. The history's ``x_max`` is compared with the sampled peak of each contact (logged).

Outputs: ``traces`` (xi, alpha, omega_t, s1, in_contact), ``contacts`` (the history with xi,
alpha, contact number and duration) and ``summary`` CSV (per trace: contacts, omega*t_col,
duration of the last contact and its share of t_col, longest earlier contact).
"""

import numpy as np
import pandas as pd


def time_grid(history: pd.DataFrame, t_end: float, n_uniform: int, per_contact: int,
              max_step: float):  # fmt: skip
    """Sorted unique sample times and a flag: True where the time lies inside a contact."""
    uniform = np.linspace(0.0, t_end, n_uniform)
    inside = []
    for start, end in zip(history["omega_t_start"], history["omega_t_end"], strict=True):
        # Cosine spacing (dense at the ends, where s1 leaves and returns to 0); its largest step
        # is about (pi/2) * duration / (n - 1).
        n = max(per_contact, int(np.ceil(0.5 * np.pi * (end - start) / max_step)) + 1)
        nodes = 0.5 * (1.0 - np.cos(np.linspace(0.0, np.pi, n)))  # 0..1
        inside.append(start + (end - start) * nodes)
    times = np.unique(np.concatenate([uniform, *inside]))
    starts = history["omega_t_start"].to_numpy()
    ends = history["omega_t_end"].to_numpy()
    k = np.searchsorted(starts, times, side="right") - 1
    in_contact = (k >= 0) & (times <= ends[np.clip(k, 0, None)])
    return times, in_contact


def trace(alpha, beta, xi, settings, solver, logger):
    import restitution

    result = restitution.solve(
        alpha, beta, xi, n_masses=2, method=solver["method"], history=True,
        max_events=solver["max_events"],
    )  # fmt: skip
    if result.status != "ok":
        raise RuntimeError(f"xi {xi}, alpha {alpha}: status {result.status!r}, not plotted")
    history = result.history.reset_index(drop=True)
    if len(history) != result.n_collisions:
        raise RuntimeError(
            f"xi {xi}, alpha {alpha}: {len(history)} history rows for "
            f"{result.n_collisions} contacts"
        )
    t_end = float(history["omega_t_end"].iloc[-1])
    times, in_contact = time_grid(
        history, t_end, settings["n_uniform"], settings["samples_per_contact"],
        settings["max_step"],
    )  # fmt: skip
    motion = restitution.trajectory(
        alpha=alpha, beta=beta, xi=xi, times=times, max_events=solver["max_events"]
    )  # the paper's units: t = omega*t, u in V0/omega
    s1 = np.clip(-motion["u_1"].to_numpy(), 0.0, None)
    # Outside the recorded contacts m1 is free (u1 >= 0); allow round-off of the contact ends.
    scale = float(history["x_max"].max())
    leak = float(s1[~in_contact].max(initial=0.0))
    if leak > 1e-9 * max(scale, 1.0):
        raise RuntimeError(
            f"xi {xi}, alpha {alpha}: s1 = {leak:.3g} > 0 outside every recorded contact"
        )
    # Sampled peak of each contact against the history's x_max (logged, a cross-check).
    peaks = np.array(
        [
            s1[(times >= a) & (times <= b)].max()
            for a, b in zip(history["omega_t_start"], history["omega_t_end"], strict=True)
        ]
    )
    rel = (peaks - history["x_max"].to_numpy()) / history["x_max"].to_numpy()
    worst = int(np.argmax(np.abs(rel)))
    peak_err = f"{rel[worst]:+.2g} (contact {worst + 1})"
    duration = history["omega_t_end"] - history["omega_t_start"]
    contacts = history.assign(
        xi=xi, alpha=alpha, beta=beta, contact=np.arange(1, len(history) + 1), duration=duration
    )
    last = float(duration.iloc[-1])
    summary = {
        "xi": xi,
        "alpha": alpha,
        "beta": beta,
        "cor": result.cor,
        "n_collisions": int(result.n_collisions),
        "omega_t_col": float(result.omega_t_col),
        "last_contact_duration": last,
        "last_contact_share": last / float(result.omega_t_col),
        "longest_earlier_contact": float(duration.iloc[:-1].max()) if len(history) > 1 else 0.0,
    }
    logger.info(
        "xi %g, alpha %g: %d contacts, omega*t_col %.4f, last contact %.4f (%.1f%% of t_col), "
        "longest earlier %.4f; %d samples, sampled peak vs history x_max, worst %s",
        xi, alpha, summary["n_collisions"], summary["omega_t_col"], last,
        100 * summary["last_contact_share"], summary["longest_earlier_contact"], len(times),
        peak_err,
    )  # fmt: skip
    frame = pd.DataFrame(
        {"xi": xi, "alpha": alpha, "beta": beta, "omega_t": times, "s1": s1,
         "in_contact": in_contact}
    )  # fmt: skip
    return frame, contacts, summary


def main(params, outputs, logger):
    from restitution.tables.io import write_table

    beta, settings, solver = float(params.beta), params.traces, params.solver
    if solver["method"] == "impulsive":
        raise ValueError(f"method = 'impulsive' needs a rigid wall, but fig7.beta = {beta!r} > 0")
    frames, contacts, summaries = [], [], []
    for xi in settings["xis"]:
        for alpha in settings["alphas"]:
            frame, history, summary = trace(float(alpha), beta, float(xi), settings, solver, logger)
            frames.append(frame)
            contacts.append(history)
            summaries.append(summary)
    config = {"beta": beta, "traces": settings, "solver": solver}
    write_table(pd.concat(frames, ignore_index=True), outputs.traces, config=config)
    write_table(pd.concat(contacts, ignore_index=True), outputs.contacts, config=config)
    write_table(pd.DataFrame(summaries), outputs.summary, config=config)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "simulate"):
        main(snakemake.params, snakemake.output, log)  # noqa: F821
