"""Trajectories as a table: every mass's position and velocity and the wall force over time.

``trajectory(scene, times)`` samples the motion of any scene ``restitution.solve`` accepts at
the requested times, in the scene's own units, from the same event sequence the solver finds:

* linear chains from their exact kernels (closed form per phase; ``attrs["method"]`` is
  ``"impulsive"`` or ``"piecewise"``); next to critical damping, where the modal basis
  degenerates (the scene's checked row, as ``solve``'s, is flagged near-defective), by the
  adaptive method at CRITICAL_RTOL within the numerical ranges, else from runs with the
  dashpots scaled off that point (``_bracketed``, ``"+critical-bracket"``);
* every other scene (Hertz, plastic contact, scissor links; the Kelvin-Voigt contact too, which
  ``solve`` takes exactly) from the solver's own adaptive run
  (``restitution.kernels.stepping.sample_scene``: the same DOP853 steps and events as the run
  at rtol/100 that ``solve`` returns, its result bit for bit), each sample from the 7th-order
  dense output of the step that crosses it (in sigma = sqrt(x) at the ends of a power-law
  contact, in closed form in the free flight of two masses with a linear link);
  ``attrs["method"]`` is ``"adaptive"`` and ``attrs["rtol"]`` its tolerance (the setting).

At a rigid wall a contact is an instant: it appears as an extra row at its time with
``event = "impact"`` and the wall's ``impulse``; the force column is 0 there (an impulse has no
finite force); positions are continuous there, velocities jump (the row shows the velocities
after the reversal). A finite contact law adds a row at each contact start and end
(``event = "contact_start"`` / ``"contact_end"``) of the adaptive method.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping

import numpy as np
import pandas as pd

from restitution.kernels import layout as LY
from restitution.model.chain import Chain, SceneError, check
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
from restitution.solvers.methods import METHODS, Options, check_events, check_settings, choose


def _scene(scene, keywords: dict) -> tuple[Chain, dict]:
    """A Chain from a Chain, a mapping of keywords or the keywords themselves, and the numerical
    settings given with the paper's form (rtol)."""
    if isinstance(scene, Chain):
        if keywords:
            raise SceneError(f"unknown keyword(s) {', '.join(sorted(keywords))} with a Chain")
        return scene, {}
    if isinstance(scene, Mapping):
        keywords = {**scene, **keywords}
    elif scene is not None:
        raise SceneError(f"scene must be a restitution.Chain or a mapping; got {scene!r}")
    from restitution.model.chain import LAW_KEYS, make_chain, paper_with_laws

    if "alpha" in keywords:
        p = {k: keywords.pop(k) for k in ("alpha", "beta", "xi", "n_masses") if k in keywords}
        # (trajectory's own keywords: solve's method and history are not among them)
        allowed = (
            f"alpha, beta, xi, n_masses, {', '.join(LAW_KEYS)}, times, max_events, rtol (or "
            f"{', '.join(_CHAIN_KEYS)} for a general chain)"
        )
        ch, settings = paper_with_laws(
            p["alpha"], p.get("beta", 0.0), p.get("xi", 0.0), p.get("n_masses", 2), keywords,
            allowed,
        )  # fmt: skip
        if "step" in settings:
            raise SceneError("step: not used by trajectory (it samples the adaptive method)")
        return ch, settings
    unknown = sorted(set(keywords) - set(_CHAIN_KEYS), key=str)
    if unknown:
        raise SceneError(
            f"unknown scene parameter(s) {', '.join(map(str, unknown))} for a general chain; "
            f"allowed: {', '.join(_CHAIN_KEYS)} (or alpha, beta, xi, n_masses)"
        )
    return make_chain(**keywords), {}


_CHAIN_KEYS = (
    "masses",
    "springs",
    "dashpots",
    "k_contact",
    "v0",
    "contact",
    "links",
    "velocities",
    "stretches",
)


def _sample(ch: Chain, wt: np.ndarray, max_events: int, s: float = 0.0, impacts: bool = True):
    """(u, v, f, impacts) in kernel units (omega*t, V0/omega, V0, m1 V0 omega, m1 V0), with
    every dashpot scaled by 1 + s (``_bracketed``). ``impacts`` False: the rigid paper chain's
    impacts are not computed (a checked solve with its history), the fourth item is empty."""
    with blas.one_thread(ch.n_masses):
        return _sample_kernels(ch, wt, max_events, s, impacts)


def _rigid_paper(ch: Chain) -> bool:
    """A rigid-wall chain in the paper's form, sampled by the paper kernels' sampler, whose
    impacts come from a history (``_sample_kernels``)."""
    return ch.rigid and exact.linear_kernel(ch.paper_form) != exact.GENERAL


def _sample_kernels(ch: Chain, wt: np.ndarray, max_events: int, s: float, impacts: bool):
    paper = ch.paper_form
    if exact.linear_kernel(paper) != exact.GENERAL:  # the kernels solve() runs, their sampler
        from restitution.api import solve
        from restitution.kernels.paper_chain import sample_linear

        alpha, beta, xi, n = paper
        xi = xi * (1.0 + s)
        u, v = sample_linear(alpha, beta, xi, n, wt, max_events=max_events)
        kc = ch.scaled()[3]
        f = np.zeros(len(wt)) if ch.rigid else kc * np.maximum(-u[:, 0], 0.0)
        hits = np.empty((0, 2))
        if ch.rigid and impacts:
            h = solve(alpha, beta, xi, n, history=True, max_events=max_events).history
            hits = h[["omega_t_start", "impulse"]].to_numpy()
        return u, v, f, hits
    from restitution.kernels.exact_chain import sample_chain, sample_chain_state

    m, k, c, kc = ch.scaled()
    c = c * (1.0 + s)
    y0 = ch.initial_state(ch.v0 / ch.omega, ch.v0)  # (the kernels' units, as exact.exact_row)
    if y0 is not None:
        return sample_chain_state(m, k, c, kc, y0, wt, max_events)
    return sample_chain(m, k, c, kc, wt, max_events)


def _exact_parts(ch: Chain, wt: np.ndarray, max_events: int, impacts=None) -> tuple:
    """The exact sampler's (u, v, f) at wt, the impacts (time, impulse) within [min wt, max wt]
    and the states (u, v) at them (after the reversal). ``impacts``: a rigid paper chain's
    (time, impulse) rows, when its checked row was computed with its history already."""
    u, v, f, found = _sample(ch, wt, max_events, impacts=impacts is None)
    impacts = np.asarray(found if impacts is None else impacts, dtype=float).reshape(-1, 2)
    inside = impacts[_within(impacts, wt)]
    return (u, v, f, inside, *_impact_states(ch, inside[:, 0], max_events))


def _within(impacts, wt) -> np.ndarray:
    """Which impacts (rows of time, impulse) fall within the times asked for."""
    return (impacts[:, 0] >= wt.min()) & (impacts[:, 0] <= wt.max())


def _impact_states(ch: Chain, times, max_events: int, s: float = 0.0) -> tuple:
    """(u, v) at the impact times (after the reversal), dashpots scaled by 1 + s."""
    if not len(times):
        return np.zeros((0, ch.n_masses)), np.zeros((0, ch.n_masses))
    u, v, _, _ = _sample(ch, np.ascontiguousarray(times), max_events, s, impacts=False)
    return u, v


# A sample of the bracketed runs (``_bracketed``) is extrapolated where the four runs are smooth
# in the dashpot scale s there: their difference g(2d) - 2 g(d) + 2 g(-d) - g(-2d), which is
# 2 g''' d**3 for a smooth g, within SMOOTH_TOL of the values' size (at least 1: V0 / omega,
# V0). Elsewhere an event of one run falls between the others': next to an impact (a jump in
# velocity) each run is sampled as far from its own impact instead; where that is not smooth
# either, the sample is the run at 1 + d's, one motion off by d in the damping.
SMOOTH_TOL = 1e-8


def _bracketed(ch: Chain, wt: np.ndarray, max_events: int) -> tuple | None:
    """``_exact_parts`` of a scene next to critical damping, extrapolated from runs with every
    dashpot scaled by 1 -+ d and 1 -+ 2 d as ``solvers.exact.off_critical`` does for the row:
    (4 m(d) - m(2 d)) / 3 of the means m, sample by sample and impact by impact (each run's own
    impacts by their index, those whose extrapolated time is within the times asked for). The
    first d of ``exact.DEFECT_STEPS`` whose runs are not near-defective themselves, finite, and
    have as many impacts; None if none is."""
    for d in exact.DEFECT_STEPS:
        scales = (-d, d, -2.0 * d, 2.0 * d)
        if any(exact.near_defective(_off_critical(ch, s), max_events) for s in scales):
            continue
        runs = [_sample(ch, wt, max_events, s) for s in scales]  # (u, v, f, impacts)
        if any(not (np.isfinite(r[0]).all() and np.isfinite(r[1]).all()) for r in runs):
            continue
        if len({np.asarray(r[3]).reshape(-1, 2).shape[0] for r in runs}) != 1:
            continue

        def combined(g):
            return (2.0 * (g[0] + g[1]) - 0.5 * (g[2] + g[3])) / 3.0  # (4 m(d) - m(2 d)) / 3

        u, v, f = (combined([r[j] for r in runs]) for j in range(3))
        impacts = [np.asarray(r[3], dtype=float).reshape(-1, 2) for r in runs]
        inside = combined(impacts)
        pick = _within(inside, wt)
        by_run = list(zip(impacts, scales, strict=True))
        at = [_impact_states(ch, imp[pick, 0], max_events, s) for imp, s in by_run]
        ui, vi = (combined([a[j] for a in at]) for j in range(2))
        rough = _rough(runs)
        if rough.any() and len(inside):
            # next to an impact: each run sampled at the same time from its own impact (its
            # time shifts with the damping, by about 1e-4 after 200 impacts at d = 1e-5)
            idx = np.flatnonzero(rough)
            k = np.abs(wt[idx, None] - inside[None, :, 0]).argmin(axis=1)
            tau = wt[idx] - inside[k, 0]
            near = [_sample(ch, np.ascontiguousarray(np.maximum(imp[k, 0] + tau, 0.0)),
                            max_events, s, impacts=False) for imp, s in by_run]  # fmt: skip
            for x, j in ((u, 0), (v, 1), (f, 2)):
                x[idx] = combined([r[j] for r in near])
            rough[idx] = _rough(near)
        for x, j in ((u, 0), (v, 1), (f, 2)):
            x[rough] = runs[1][j][rough]
        return u, v, f, inside[pick], ui, vi
    return None


def _rough(runs) -> np.ndarray:
    """The samples at which the runs at s = -d, d, -2 d, 2 d are not smooth in s (SMOOTH_TOL)."""
    rough = np.zeros(len(runs[0][0]), dtype=bool)
    for j in (0, 1):  # positions and velocities
        g = [r[j] for r in runs]
        third = np.abs(g[3] - 2.0 * g[1] + 2.0 * g[0] - g[2])
        size = np.maximum(np.maximum.reduce([np.abs(x) for x in g]), 1.0)
        rough |= (third > SMOOTH_TOL * size).any(axis=1)
    return rough


def _off_critical(ch: Chain, s: float) -> Chain:
    """``ch`` with every dashpot scaled by 1 + s (a paper scene stays one)."""
    if ch.preset is not None:
        alpha, beta, xi, n = ch.paper_form
        return Chain.paper(alpha, beta, xi * (1.0 + s), n)
    return Chain(
        ch.masses, ch.springs, ch.dashpots * (1.0 + s), ch.k_contact,
        ch.v0 if ch.velocities is None else 1.0, None, None, ch.velocities, ch.stretches,
    )  # fmt: skip


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


EVENT_NAMES = ("contact_start", "contact_end", "impact")  # stepping.EV_START, EV_END, EV_IMPACT


def _sample_adaptive(ch: Chain, wt: np.ndarray, rtol: float, max_events: int):
    """(y, f, (evt, evk), hist, out) of the adaptive method's run of ``ch`` at the kernel times
    wt (any order): states (len(wt), 2n + 2) and forces in the stepping kernels' units (m_1 = 1,
    omega = 1, the scene's speed unit), the contact events (times, kinds), the history and the
    result row. The run is the one ``solve`` returns for this rtol: its finer run
    (``numerical._finer``: rtol/100), or where that one does not finish the setting's own."""
    from restitution.kernels import stepping
    from restitution.solvers.numerical import (
        _check_cap,
        _default_etol,
        _finer,
        _work_budget,
        packed,
    )

    ms, lk, cs, cp, _, _ = packed(ch)
    order = np.argsort(wt, kind="stable")
    etol = _default_etol("adaptive", rtol, 0.0)
    budget = _work_budget("adaptive")  # (as solve runs them)
    for tol, cap in ((_finer(rtol), stepping.HMAX_FREE), (rtol, _check_cap(rtol))):
        hist = np.zeros((max_events, LY.N_HIST))
        with blas.one_thread(ch.n_masses):
            out, ys, fs, evt, evk = stepping.sample_scene(
                ms, lk, cs, cp, float(ch.v0), tol, etol, max_events,
                budget, np.ascontiguousarray(wt[order]), hist,
                ch.initial_state(1.0 / ch.omega, 1.0),  # (None: the uniform approach)
                cap,
            )  # fmt: skip
        if out[LY.OUT_STATUS] in (LY.STATUS_OK, LY.STATUS_EVENT_BUDGET):
            break  # (a cut sequence: the setting's own run is cut too)
    y = np.empty_like(ys)
    y[order] = ys
    f = np.empty_like(fs)
    f[order] = fs
    return y, f, (evt, evk), hist, out


def _frame(t, wt, u, v, f, impulse, event, n, w, m1, v0) -> pd.DataFrame:
    """The table in user units from kernel-unit columns (lengths in units of v0 / omega, speeds
    of v0, forces of m1 v0 omega, impulses of m1 v0)."""
    frame = {"t": t, "omega_t": wt}
    for i in range(n):
        frame[f"u_{i + 1}"] = user_length(u[:, i], w, v0)
    for i in range(n):
        frame[f"v_{i + 1}"] = user_speed(v[:, i], v0)
    frame["f_contact"] = user_force(f, m1, w, v0)
    frame["impulse"] = user_impulse(impulse, m1, v0)
    frame["event"] = np.asarray(event, dtype=object)
    return pd.DataFrame(frame)


def _adaptive_frame(ch: Chain, t, wt, rtol: float, max_events: int) -> pd.DataFrame:
    from restitution.solvers.result import MESSAGES, status_name

    n, w, m1 = ch.n_masses, ch.omega, float(ch.masses[0])
    y, f, (evt, evk), hist, out = _sample_adaptive(ch, wt, rtol, max_events)
    status = status_name(out[LY.OUT_STATUS])
    if status == "event_budget_exhausted":
        _within_cut(out, wt, w, max_events)
    elif status != "ok":
        raise SceneError(
            f"the adaptive run of this scene ended with status {status!r}: "
            f"{MESSAGES.get(status, status)}"
        )
    if not np.isfinite(y[:, : 2 * n]).all():  # the free flight after the last contact
        late = float(t[~np.isfinite(y[:, : 2 * n]).all(axis=1)].min())
        raise SceneError(
            f"times: the free flight after the last contact (t_col = {out[LY.OUT_TCOL] / w:.6g}) "
            f"was not integrated to t = {late:.6g} within the work budget; ask for earlier times"
        )
    # the stepping kernels' speed unit is the scene's own (v0 as given): lengths in 1 / omega
    parts = [_frame(t, wt, y[:, :n], y[:, n : 2 * n], f, np.zeros(len(t)), ["sample"] * len(t),
                    n, w, m1, 1.0)]  # fmt: skip
    inside = (evt >= wt.min()) & (evt <= wt.max())
    if inside.any():
        # the states at the events: the same run sampled at their times (stepping.sample_scene:
        # a sample at an event's time is the state after its switch)
        ev, _, _, _, _ = _sample_adaptive(ch, evt[inside], rtol, max_events)
        kinds = evk[inside]
        impulse = np.zeros(len(kinds))
        impact = kinds == 2
        if impact.any():  # the j-th impact is contact j of the history (m1 v0 units)
            at = np.flatnonzero(evk == 2)
            j = np.searchsorted(at, np.flatnonzero(inside)[impact])
            impulse[impact] = hist[j, LY.H_IMPULSE] * ch.v0
        te = evt[inside]
        parts.append(
            _frame(
                user_time(te, w),
                te,
                ev[:, :n],
                ev[:, n : 2 * n],
                np.zeros(len(te)),
                impulse,
                [EVENT_NAMES[k] for k in kinds],
                n,
                w,
                m1,
                1.0,
            )  # fmt: skip
        )
    frame = pd.concat(parts, ignore_index=True) if len(parts) > 1 else parts[0]
    frame = frame.sort_values("t", kind="stable", ignore_index=True)  # (times in any order)
    frame.attrs["status"] = status
    return frame


def trajectory(
    scene=None, times=None, *, max_events: int = 10_000, rtol: float | None = None, **keywords
) -> pd.DataFrame:
    """Positions, velocities and the wall force of every mass at the requested times.

    Parameters
    ----------
    scene : Chain or mapping, optional
        The scene; or give its keywords directly (``alpha=...`` for the paper's form, with its
        nonlinear laws if any, ``masses=..., springs=..., contact=..., links=...`` for a general
        chain, as for ``restitution.solve``). Any scene ``solve`` accepts.
    times : array_like
        Times (the scene's time unit; omega*t for the paper's scenes), finite and >= 0, from
        the first contact at t = 0.
    max_events : int
        Contact budget of the underlying solve.
    rtol : float, optional
        Relative tolerance of the adaptive method (scenes with a nonlinear law only; default
        the solver's, 1e-9).

    Returns
    -------
    DataFrame
        Columns ``t, omega_t, u_1..u_N, v_1..v_N, f_contact, impulse, event``: positions in the
        scene's length unit (V0/omega for the paper's scenes; 0 = where the mass was at the first
        contact, the wall at u_1 = 0; from a given initial state, 0 = the mass's rest position
        with m_1 at the wall, so u_i at t = 0 sums stretches[:i - 1]), velocities (the kernels'
        sign: negative towards the wall), the contact law's force on m_1 and, on rows
        with ``event == "impact"`` (rigid wall only, one per contact within the time range), the
        wall's impulse. Rows are sorted by time; requested times have ``event == "sample"``; the
        adaptive method adds ``"contact_start"`` / ``"contact_end"`` rows at the contacts of a
        finite contact law. ``attrs["method"]`` names the method that produced the samples
        (``"impulsive"`` or ``"piecewise"``: exact closed form, with ``"+critical-bracket"``
        next to critical damping; ``"adaptive"``: DOP853 at ``attrs["rtol"]``, NaN for the
        exact ones; the module docstring); ``attrs["scaled"]`` is True when the scene's
        units are the kernels' (m_1 = 1, omega = 1, V0 = 1: the paper's scenes);
        ``attrs["status"]`` is the scene's status as ``solve`` gives it: "ok";
        "event_budget_exhausted" (then every time must lie before the end of contact
        ``max_events``: SceneError otherwise); for a linear scene also "ill_conditioned" and
        the like (with a RuntimeWarning: the samples follow an event sequence double
        precision cannot vouch for), where an adaptive run that does not finish is a
        SceneError.
    """
    ch, settings = _scene(scene, dict(keywords))
    if rtol is not None and "rtol" in settings:
        raise SceneError("rtol given twice")
    rtol = settings.get("rtol", rtol)
    chosen = choose(ch)
    if exact.kelvin_voigt(ch):  # (the exact sampler has no Kelvin-Voigt contact: adaptive)
        chosen = METHODS["adaptive"]
    max_events = check_events(max_events, history=True)  # impacts are read from a history
    t = _times(times)
    w, m1, v0 = ch.omega, float(ch.masses[0]), ch.v0
    wt = kernel_time(t, w)
    if not chosen.exact:  # 'adaptive': any law, the solver's own run
        rtol = Options.rtol if rtol is None else check("rtol", rtol)
        out = _adaptive_frame(ch, t, np.ascontiguousarray(wt, dtype=np.float64), rtol,
                              max_events)  # fmt: skip
        out.attrs.update(method=chosen.name, rtol=rtol, scaled=_scaled(ch))
        return out
    if rtol is not None:
        check_settings(chosen, ("rtol",))  # raises: the exact samplers read no rtol
    wt = np.ascontiguousarray(wt, dtype=np.float64)
    method, parts = chosen.name, None
    # the scene's checked row (as solve's): its status, and the flag of a near-defective basis;
    # a rigid paper chain's with its history, whose impacts the exact sampler then reuses
    hist = np.zeros((max_events if _rigid_paper(ch) else 0, LY.N_HIST))
    row = exact.exact_row(ch, max_events, hist)
    if exact._flags(row) & (LY.FLAG_NEAR_DEFECTIVE | LY.FLAG_CRITICAL_BRACKET):  # _near_critical
        out = _near_critical(ch, t, wt, max_events)
        if out is not None:
            return out
        parts = _bracketed(ch, wt, max_events)
        if parts is None:
            warnings.warn(
                "trajectory: this linear scene is next to critical damping, where the exact "
                "sampler's modal basis is ill-conditioned, and neither the adaptive method nor "
                "runs with the dashpots scaled off that point could take it: its samples may "
                "be off in their 8th digit and beyond",
                RuntimeWarning,
                stacklevel=2,
            )
        else:
            method += "+critical-bracket"
    status = _exact_status(row, wt, w, max_events)
    if parts is None:
        hits = None
        if len(hist):
            hits = hist[: min(int(row[LY.OUT_NEVENTS]), len(hist))][:, [LY.H_TSTART, LY.H_IMPULSE]]
        parts = _exact_parts(ch, wt, max_events, hits)
    u, v, f, inside, ui, vi = parts
    n = ch.n_masses
    out = _frame(t, wt, u, v, f, np.zeros(len(t)), ["sample"] * len(t), n, w, m1, v0)
    if len(inside):
        rows = _frame(user_time(inside[:, 0], w), inside[:, 0], ui, vi, np.zeros(len(inside)),
                      inside[:, 1], ["impact"] * len(inside), n, w, m1, v0)  # fmt: skip
        out = pd.concat([out, rows], ignore_index=True)
    out = out.sort_values("t", kind="stable", ignore_index=True)  # (times in any order)
    if out.filter(regex="^[uv]_").isna().to_numpy().any():  # (any sample, not only the first)
        raise SceneError("the sampler returned NaN: the scene could not be solved")
    out.attrs.update(method=method, rtol=math.nan, scaled=_scaled(ch), status=status)
    return out


def _within_cut(row, wt, w: float, max_events: int) -> None:
    """SceneError unless every kernel time wt is before the end of the last contact of a
    sequence cut by max_events (row: its kernel row; OUT_TCOL is that end)."""
    reached = float(row[LY.OUT_TCOL])
    if not wt.max() <= reached:
        raise SceneError(
            f"max_events: this scene needs more than max_events = {max_events} contacts, "
            f"so its motion is known only up to t = {user_time(reached, w):.6g} (the end of "
            f"contact {max_events}); raise max_events or ask for times up to that"
        )


def _exact_status(row, wt, w: float, max_events: int) -> str:
    """The status of the exact sampler's scene from its checked row: a sequence cut by
    max_events is followed only to the end of its last contact (the sampler would fly on through
    the wall after it), so a later time is a SceneError; any other unfinished status a
    RuntimeWarning (the samples come from the same event sequence)."""
    from restitution.solvers.result import MESSAGES, status_name

    status = status_name(row[LY.OUT_STATUS])
    if status == "event_budget_exhausted":
        _within_cut(row, wt, w, max_events)
    elif status not in ("ok", "permanent_contact"):
        warnings.warn(
            f"trajectory: the exact solution of this scene ended with status {status!r} "
            f"({MESSAGES.get(status, status)}); the samples come from that event sequence, the "
            "later ones the least trustworthy",
            RuntimeWarning,
            stacklevel=3,
        )
    return status


# The tolerance of a linear scene's trajectory next to critical damping (``_near_critical``).
CRITICAL_RTOL = 1e-12


def _near_critical(ch: Chain, t, wt, max_events: int) -> pd.DataFrame | None:
    """The trajectory of a linear chain whose exact kernel flags a phase near-defective (a damped
    mode next to critical damping, docs/accuracy.md#critical-damping), whose modal basis is
    ill-conditioned there (samples 2e-8 off on a six-mass chain, a rigid-wall chain at alpha =
    1e8 through the wall): the adaptive method's at CRITICAL_RTOL, where the chain is within the
    numerical methods' ranges and the run reaches every time asked; else None (``_bracketed``)."""
    from restitution.solvers.numerical import packed

    try:
        packed(ch)  # (the numerical methods' ranges)
        out = _adaptive_frame(ch, t, wt, CRITICAL_RTOL, max_events)
    except SceneError:
        return None
    out.attrs.update(method="adaptive", rtol=CRITICAL_RTOL, scaled=_scaled(ch))
    return out


def _scaled(ch: Chain) -> bool:
    """True when the scene's units are the kernels' (m_1 = 1, omega = 1, V0 = 1): the paper's
    non-dimensional scenes (times are omega*t, lengths omega*u/V0, speeds v/V0)."""
    return ch.omega == 1.0 and ch.v0 == 1.0 and float(ch.masses[0]) == 1.0


__all__ = ["trajectory"]
