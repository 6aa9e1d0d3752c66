"""Trajectories as a table: every mass's position and velocity and the wall force over time.

``trajectory(scene, times)`` samples the exact (closed-form per phase) motion of a linear chain
at the requested times, in the scene's own units, from the same event sequence the solver finds.
At a rigid wall a contact is an instant: it appears as an extra row at its time with
``event = "impact"`` and the wall's ``impulse``; the force column is 0 there (an impulse has no
finite force); positions are continuous there, velocities jump (the row shows the sampler's
value at that instant).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from restitution.model.chain import Chain, SceneError
from restitution.model.ranges import _real, _show
from restitution.model.units import (
    kernel_time,
    user_force,
    user_impulse,
    user_length,
    user_speed,
    user_time,
)
from restitution.solvers import blas, exact
from restitution.solvers.methods import check_events, choose


def _scene(scene, keywords: dict) -> Chain:
    """A Chain from a Chain, a mapping of keywords or the keywords themselves."""
    if isinstance(scene, Chain):
        if keywords:
            raise SceneError(f"unknown keyword(s) {', '.join(sorted(keywords))} with a Chain")
        return scene
    if isinstance(scene, Mapping):
        keywords = {**scene, **keywords}
    elif scene is not None:
        raise SceneError(f"scene must be a restitution.Chain or a mapping; got {scene!r}")
    from restitution.model.chain import make_chain, paper_with_laws

    if "alpha" in keywords:
        p = {k: keywords.pop(k) for k in ("alpha", "beta", "xi", "n_masses") if k in keywords}
        ch, settings = paper_with_laws(
            p["alpha"], p.get("beta", 0.0), p.get("xi", 0.0), p.get("n_masses", 2), keywords
        )
        if settings:
            raise SceneError(f"{', '.join(settings)}: not used by trajectory (exact methods)")
        return ch
    unknown = sorted(set(keywords) - set(_CHAIN_KEYS), key=str)
    if unknown:
        raise SceneError(
            f"unknown scene parameter(s) {', '.join(map(str, unknown))} for a general chain; "
            f"allowed: {', '.join(_CHAIN_KEYS)} (or alpha, beta, xi, n_masses)"
        )
    return make_chain(**keywords)


_CHAIN_KEYS = ("masses", "springs", "dashpots", "k_contact", "v0", "contact", "links")


def _sample(ch: Chain, wt: np.ndarray, max_events: int):
    """(u, v, f, impacts) in kernel units (omega*t, V0/omega, V0, m1 V0 omega, m1 V0)."""
    with blas.one_thread(ch.n_masses):
        return _sample_kernels(ch, wt, max_events)


def _sample_kernels(ch: Chain, wt: np.ndarray, max_events: int):
    paper = ch.paper_form
    if exact.linear_kernel(paper) != exact.GENERAL:  # the kernels solve() runs, their sampler
        from restitution.api import solve
        from restitution.kernels.paper_chain import sample_linear

        alpha, beta, xi, n = paper
        u, v = sample_linear(alpha, beta, xi, n, wt, max_events=max_events)
        kc = ch.scaled()[3]
        f = np.zeros(len(wt)) if ch.rigid else kc * np.maximum(-u[:, 0], 0.0)
        impacts = np.empty((0, 2))
        if ch.rigid:
            h = solve(alpha, beta, xi, n, history=True, max_events=max_events).history
            impacts = h[["omega_t_start", "impulse"]].to_numpy()
        return u, v, f, impacts
    from restitution.kernels.exact_chain import sample_chain

    m, k, c, kc = ch.scaled()
    return sample_chain(m, k, c, kc, wt, max_events)


def _times(times) -> np.ndarray:
    """The requested times as a flat float64 array; SceneError for anything but a non-empty
    list (or array) of finite real numbers >= 0."""
    what = "times must be a non-empty list of finite times >= 0"
    if times is None:
        raise SceneError(f"{what} (none given)")
    if isinstance(times, (str, bytes, Mapping)):
        raise SceneError(f"{what}; got {_show(times)}")
    try:
        arr = np.asarray(times)
    except (TypeError, ValueError):  # ragged nesting
        arr = np.asarray(times, dtype=object)
    if arr.dtype.kind in "fiu":  # real numbers: checked at once
        t = arr.astype(np.float64).ravel()
        bad = ~(np.isfinite(t) & (t >= 0.0))
        if t.size and bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise SceneError(f"{what}; times[{i}] is {_show(arr.ravel()[i])}")
        seq = ()
    else:  # any other element type: one real number each
        seq = arr.ravel()
        t = np.empty(len(seq))
    for i, v in enumerate(seq):
        x = _real(v)
        if x is None or not math.isfinite(x) or x < 0.0:
            raise SceneError(f"{what}; times[{i}] is {_show(v)}")
        t[i] = x
    if t.size == 0:
        raise SceneError(f"{what}; got an empty list")
    return t


def trajectory(scene=None, times=None, *, max_events: int = 10_000, **keywords) -> pd.DataFrame:
    """Positions, velocities and the wall force of every mass at the requested times.

    Parameters
    ----------
    scene : Chain or mapping, optional
        The scene; or give its keywords directly (``alpha=...`` for the paper's form,
        ``masses=..., springs=...`` for a general chain, as for ``restitution.solve``).
    times : array_like
        Times (the scene's time unit; omega*t for the paper's scenes), finite and >= 0, from
        the first contact at t = 0.
    max_events : int
        Contact budget of the underlying solve.

    Returns
    -------
    DataFrame
        Columns ``t, omega_t, u_1..u_N, v_1..v_N, f_contact, impulse, event``: positions in the
        scene's length unit (V0/omega for the paper's scenes; 0 = where the mass was at the first
        contact, the wall at u_1 = 0), velocities, the wall's contact force on m_1 and, on rows
        with ``event == "impact"`` (rigid wall only, one per contact within the time range), the
        wall's impulse. Rows are sorted by time; requested times have ``event == "sample"``.
    """
    ch = _scene(scene, dict(keywords))
    chosen = choose(ch)
    if not chosen.exact:
        raise SceneError(
            "trajectory samples the exact closed-form motion of linear chains; this scene needs "
            f"the numerical method {chosen.name!r}"
        )
    max_events = check_events(max_events, history=True)  # impacts are read from a history
    t = _times(times)
    w, m1, v0 = ch.omega, float(ch.masses[0]), ch.v0
    wt = kernel_time(t, w)
    u, v, f, impacts = _sample(ch, np.ascontiguousarray(wt), max_events)
    n = ch.n_masses
    frame = {"t": t, "omega_t": wt}
    for i in range(n):
        frame[f"u_{i + 1}"] = user_length(u[:, i], w, v0)
    for i in range(n):
        frame[f"v_{i + 1}"] = user_speed(v[:, i], v0)
    frame["f_contact"] = user_force(f, m1, w, v0)
    frame["impulse"] = np.zeros(len(t))
    frame["event"] = np.full(len(t), "sample", dtype=object)
    out = pd.DataFrame(frame)
    impacts = np.asarray(impacts).reshape(-1, 2)
    lo, hi = wt.min(), wt.max()
    inside = impacts[(impacts[:, 0] >= lo) & (impacts[:, 0] <= hi)]
    if len(inside):
        ui, vi, _, _ = _sample(ch, np.ascontiguousarray(inside[:, 0]), max_events)
        rows = {"t": user_time(inside[:, 0], w), "omega_t": inside[:, 0]}
        for i in range(n):
            rows[f"u_{i + 1}"] = user_length(ui[:, i], w, v0)
        for i in range(n):
            rows[f"v_{i + 1}"] = user_speed(vi[:, i], v0)
        rows["f_contact"] = np.zeros(len(inside))
        rows["impulse"] = user_impulse(inside[:, 1], m1, v0)
        rows["event"] = np.full(len(inside), "impact", dtype=object)
        out = pd.concat([out, pd.DataFrame(rows)], ignore_index=True)
        out = out.sort_values("t", kind="stable", ignore_index=True)
    if math.isnan(out["u_1"].iloc[0]):
        raise SceneError("the sampler returned NaN: the scene could not be solved")
    return out


__all__ = ["trajectory"]
