"""Slow checking method: scipy ``solve_ivp`` (DOP853) with terminal events that switch the law.

Independent of the numba integrators: every phase, free flight included, is integrated by scipy
with the force laws of ``laws.py`` evaluated in Python. scipy checks event signs only at step
ends, so a contact shallower than one step would be stepped over (max_step = 1/50 of the shortest
local period did not prevent it just past alpha*_2): the gap's minima in free flight are events
too, and a minimum below the wall is a contact, located by a bracketed root (likewise a
compression minimum past the wall while unloading is a separation). Same phase machine and
projections as ``kernels/stepping.py``; same output layout.

The benchmark harness (``restitution_workflow.bench.ivp``) reuses ``solve_reference`` with another
scipy
``method``, its own ``atol``, no ``max_step`` (``steps_per_period=None``), plain sign-change event
detection (``minima=False``, as a researcher would first write it) and a wall-clock ``deadline``.
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from restitution.kernels import layout as LY
from restitution.model import laws

# solve_ivp's smallest rtol: it raises a smaller one to this itself, with a warning at every call
# (every phase). solve_reference takes it so at the start (the row's rtol says so).
SCIPY_RTOL_FLOOR = 100.0 * np.finfo(float).eps
# max_step: the shortest local period / STEPS_PER_PERIOD (solve_reference's default).
STEPS_PER_PERIOD = 50


# The error floor of a run, below which rtol means nothing: at rtol 1e-14..1e-13 the runs' COR
# errors stop shrinking at 5e-14..1.1e-13 (round-off; the two-mass scissor scenes of
# tests/test_scissor_events.py against precise_scissor at 30/40 digits), where the check run
# shares them (soft scissor: 5.25e-14 off under an estimate of 2.2e-14 at rtol 1e-14). A run's
# estimate is at least this, about 4.5 times the largest plateau measured.
ROUNDOFF_FLOOR = 5e-13


class DeadlineExceeded(RuntimeError):
    """Raised from inside the right-hand side when a run passes its wall-clock deadline."""


def _rhs_factory(cp, sp, mem, deadline=None):
    alpha, c = mem["alpha"], mem["c"]
    # A scissor link by the formula of its branch mem["link"] (held for a whole solve_ivp call,
    # which ends at the branch's ends: _link_events): analytic, not C1-only across the points.
    # mem["link"] < 0: the law's own pick by x (linear links; ``branches=False``).

    def force(sp, x, br):
        return laws.scissor_force_on(sp, x, br) if br >= 0 else laws.structure_force(sp, x)

    def rhs(t, y):
        # Checked at every evaluation: one solve_ivp call can otherwise run for minutes.
        if deadline is not None and time.perf_counter() > deadline:
            raise DeadlineExceeded("wall-clock budget exhausted")
        x = -y[0]
        fc = 0.0
        if mem["phase"] == 1:
            fc = laws.contact_force(cp, mem["branch"], mem["xmax"], mem["fmax"], x, -y[2])
        f2 = force(sp, y[1] - y[0], mem["link"])
        dv = y[3] - y[2]
        fd = c * dv
        return [y[2], y[3], fc + f2 + fd, -(f2 + fd) / alpha, -fc * y[2], c * dv * dv]

    return rhs


def _event(fun):
    fun.terminal = True
    fun.direction = -1
    return fun


def _off_start(fun, t0, order, limit):
    """``fun`` without its root at the phase start t0: fun / (t - t0)**order, ``limit`` at t0.

    A phase that starts on an event's own surface (a free flight from the separation, gap 0; a
    branch from a turn, v1 = 0) has that event at 0 there. solve_ivp brackets a sign change
    between step ends, so a first step that already crosses the surface again (m1 back on the
    wall within the step) had its root at t0: the phase ended where it began (a contact at the
    separation instant, with v1 > 0). Divided by (t - t0)**order (``order`` = the zeros at t0:
    2 at a turn of the plastic reload, x at its maximum with x' = 0) the event has the sign of
    ``fun`` after t0 and its own derivative's sign at t0, as the kernels' ``strip`` does."""

    def event(t, y):
        return fun(t, y) / (t - t0) ** order if t > t0 else limit

    return event


def _link_events(sp, mem, t0, y):
    """Terminal events where a scissor link's extension leaves its branch ``mem["link"]``
    (falling through the point below it, rising through the one above; none for a linear link).

    The scissor law is C1 but not C2 at its branch points: a DOP853 step across one took an error
    its error estimate does not see (the two orders share it), up to 40 rtol and erratic in rtol
    (docs/solvers.md). Each solve_ivp call holds one branch's formula (``_rhs_factory``) and
    stops where the extension leaves it, as the adaptive kernel does. A point the phase starts on
    (the branch just entered) is taken off its root there (``_off_start``)."""
    if mem["link"] < 0:
        return []
    x0, rate = y[1] - y[0], y[3] - y[2]
    out = []
    for j, direction in ((mem["link"] - 1, -1), (mem["link"], 1)):
        point = laws.scissor_point(sp, j)
        if math.isinf(point):
            continue
        fun = lambda t, y, p=point: y[1] - y[0] - p  # noqa: E731
        if x0 == point or (x0 - point) * direction > 0.0:  # on it (or past it by round-off)
            fun = _off_start(fun, t0, 1, rate)
        fun.terminal, fun.direction = True, direction
        out.append(fun)
    return out


def _crossed(sol, first: int) -> int | None:
    """Index (from ``first``) of the link event that ended ``sol``, if one did."""
    for i in range(first, len(sol.t_events)):
        if len(sol.t_events[i]) and sol.status == 1 and sol.t_events[i][0] == sol.t[-1]:
            return i
    return None


def _ivp(*args, **kwargs):
    """``solve_ivp`` without numpy's warnings on inf or NaN stages: a trial step far past the end
    of the scissor branch held (``_rhs_factory``) can overflow there; solve_ivp rejects it (its
    error norm is not < 1) and retries a fifth as long."""
    with np.errstate(invalid="ignore", over="ignore"):
        return solve_ivp(*args, **kwargs)


def _stepped_over_reload(sol, k, xm):
    """Time of a reload past the plastic law's largest penetration ``xm`` that solve_ivp stepped
    over on the unloading line (x above xm and back below between two step ends, so its
    terminal event saw no sign change), or None: the first maximum of the compression (event
    ``k``) above xm before the run's end, the crossing at the first root before it."""
    peaks, states = sol.t_events[k], sol.y_events[k]
    for n in range(len(peaks)):
        if peaks[n] < sol.t[-1] and -states[n][0] > xm:
            start = peaks[n - 1] if n > 0 else sol.t[0]
            return _first_root(lambda s: xm + sol.sol(s)[0], start, peaks[n])
    return None


def _minimum(fun):
    """Non-terminal event at the minima of a coordinate whose velocity is ``fun``."""
    fun.terminal = False
    fun.direction = 1
    return fun


def _first_root(gap, t0, t1, samples=64):
    """First zero of ``gap`` in [t0, t1] where gap(t0) >= 0 > gap(t1): bracketed on samples."""
    ts = np.linspace(t0, t1, samples + 1)
    values = [gap(s) for s in ts]
    for k in range(samples):
        if values[k] >= 0.0 > values[k + 1]:
            return brentq(gap, ts[k], ts[k + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps)
    return t1


def _no_contact_possible(y, sp, mem):
    a = mem["alpha"]
    m = 1.0 + a
    mu = a / m
    vcom = (y[2] + a * y[3]) / m
    if vcom <= 0.0:
        return False
    e = 0.5 * mu * (y[3] - y[2]) ** 2 + laws.structure_energy(sp, y[1] - y[0])
    rhi = laws.structure_extent(sp, e, 1.0)
    return (y[0] + a * y[1]) / m + mem["xp"] - mu * rhi > 0.0


def solve_reference(
    alpha,
    v0,
    xi,
    cp,
    sp,
    rtol,
    max_events,
    acct,
    etol,
    t_max=1e5,
    *,
    method="DOP853",
    atol=None,
    steps_per_period=STEPS_PER_PERIOD,
    deadline=None,
    minima=True,
    y0=None,
    branches=True,
):
    """Reference solution of one two-mass scene; returns (out, hist) in the kernel layout.

    ``y0`` (None: both masses at -v0, the spring unstretched) is a given initial state
    [u1, u2, v1, v2] in kernel units with u1 = 0 (``restitution.Chain.initial_state``): m1 hits
    the wall at t = 0 if v1 < 0, else a free flight comes first; the COR is then the centre of
    mass's velocity after over before, the energies fractions of the initial energy.

    ``method`` is any ``solve_ivp`` method; ``atol`` defaults to ``rtol * v0``; ``max_step`` is
    the shortest local period / ``steps_per_period`` (``None``: no max_step); ``deadline`` (a
    ``time.perf_counter()`` value) makes the run raise ``DeadlineExceeded`` once passed.
    ``minima`` (default) also stops at every minimum of the gap in free flight and of the
    compression while unloading, so that a contact or separation shallower than one step is not
    stepped over; ``False`` keeps scipy's plain sign-change detection (the benchmark's view of
    how solve_ivp is usually used). ``branches`` (default) holds a scissor link on one branch's
    formula per solve_ivp call and stops at its branch points (``_link_events``); ``False`` lets
    the law pick its branch by the extension at every evaluation (steps cross the points).
    """
    rtol = max(rtol, SCIPY_RTOL_FLOOR)
    kind = int(cp[0])
    k1, k2 = cp[1], sp[laws.SP_K2]
    mem = dict(phase=1, branch=1, xmax=0.0, fmax=0.0, xp=0.0, c=2.0 * xi * k2, alpha=alpha)
    mem["link"] = -1  # the scissor link's branch (_link_events), set from y below
    rhs = _rhs_factory(cp, sp, mem, deadline)
    atol = rtol * v0 if atol is None else atol
    tr = k1 + k2 + k2 / alpha
    lam = 0.5 * tr + math.sqrt(max(0.25 * tr * tr - k1 * k2 / alpha, 0.0))
    dt_contact, dt_free = math.inf, math.inf  # solve_ivp's default max_step
    if steps_per_period is not None:
        if kind != laws.C_RIGID:
            dt_contact = 2 * math.pi / math.sqrt(lam) / steps_per_period
        dt_free = 2 * math.pi / math.sqrt(k2 + k2 / alpha) / steps_per_period
    y = np.array([0.0, 0.0, -v0, -v0, 0.0, 0.0])
    t, tcol, ncol = 0.0, 0.0, 1
    hist = [[0.0, 0.0, -1.0, 0.0, 0.0, 0.0]]
    free0 = False
    if y0 is not None:
        y[:4] = y0
        hist[0][LY.H_VIN] = y[2] / v0
        free0 = y[2] > 0.0  # m1 leaves the wall: no contact at t = 0
        if free0:
            ncol, hist, mem["phase"] = 0, [], 0
    p_in = y[2] + alpha * y[3]
    ysep = y.copy()
    status = LY.STATUS_OK
    if branches and sp[laws.SP_KIND] == laws.S_SCISSOR:
        mem["link"] = int(laws.scissor_branch(sp, y[1] - y[0]))
    if kind == laws.C_RIGID and not free0:
        y[2] = -y[2]
        hist[0][LY.H_VOUT] = y[2] / v0
        hist[0][LY.H_IMPULSE] = (y[2] + alpha * y[3] - p_in) / v0
        ysep = y.copy()
        mem["phase"] = 0
    xmax_c = 0.0
    while True:
        if t > t_max:
            status = LY.STATUS_NONCONVERGED
            break
        if mem["phase"] == 1:
            a1 = rhs(t, y)[2]  # m1's acceleration at the phase start
            if mem["branch"] == 1:
                turn = lambda t, y: -y[2]  # noqa: E731
                if y[2] == 0.0:  # from a rise (v1 = 0): off its root there
                    turn = _off_start(turn, t, 1, -a1)
                events = [_event(turn)]
            else:
                xp, xm = mem["xp"], mem["xmax"]
                if kind == laws.C_PLASTIC:
                    second = lambda t, y, xm=xm: xm + y[0]  # noqa: E731
                    if xm + y[0] == 0.0 and y[2] == 0.0:  # from a turn at xmax: a double zero
                        second = _off_start(second, t, 2, 0.5 * a1)
                else:
                    second = lambda t, y: y[2]  # noqa: E731
                    if y[2] == 0.0:  # from a turn
                        second = _off_start(second, t, 1, a1)
                apart = lambda t, y, xp=xp: -y[0] - xp  # noqa: E731
                if -y[0] - xp == 0.0 and y[2] < 0.0:  # from a touch on the dent: off its root
                    apart = _off_start(apart, t, 1, -y[2])
                events = [_event(apart), _event(second)]
            n_phase = len(events)
            peaks = minima and mem["branch"] == 0 and kind == laws.C_PLASTIC
            if peaks:
                # The compression's maxima on the plastic unloading line (v1 rising through 0):
                # one past xmax is a reload shallower than one step, stepped over (below).
                peak = lambda t, y: y[2]  # noqa: E731
                if y[2] == 0.0:  # from a turn
                    peak = _off_start(peak, t, 1, a1)
                events.append(_minimum(peak))
            events += _link_events(sp, mem, t, y)
            sol = _ivp(
                rhs,
                (t, t + 1e4),
                y,
                method=method,
                rtol=rtol,
                atol=atol,
                events=events,
                max_step=dt_contact,
                dense_output=True,
            )
            reload = _stepped_over_reload(sol, n_phase, mem["xmax"]) if peaks else None
            j = _crossed(sol, n_phase + int(peaks))
            if reload is not None:  # a reload between step ends: there, on the power law
                i, t, y = 1, reload, sol.sol(reload).copy()
            elif j is not None:  # the scissor link leaves its branch: on with the next one
                t, y = sol.t_events[j][0], sol.y_events[j][0].copy()
                mem["link"] += events[j].direction
                continue
            else:
                hit = [i for i in range(n_phase) if len(sol.t_events[i])]
                if not hit:
                    status = LY.STATUS_NONCONVERGED
                    break
                i = min(hit, key=lambda j: sol.t_events[j][0])
                t, y = sol.t_events[i][0], sol.y_events[i][0].copy()
            xp = mem["xp"]
            if minima and mem["branch"] == 0 and i == 1 and kind != laws.C_PLASTIC and -y[0] < xp:
                # The compression's minimum is past the wall: a separation shorter than one step
                # (x back above xp at both step ends) was stepped over. It starts at the root
                # between the turn (x > xp) and this minimum, where x decreases throughout.
                t = brentq(lambda s, f=sol.sol, xp=xp: -f(s)[0] - xp, sol.t[0], t, xtol=1e-15)
                y, i = sol.sol(t).copy(), 0
            if mem["branch"] == 1:  # turn
                y[2] = 0.0
                x = -y[0]
                xmax_c = max(xmax_c, x)
                mem["branch"] = 0
                if kind == laws.C_PLASTIC and x >= mem["xmax"]:
                    mem["xmax"], mem["fmax"] = x, cp[2] * x ** cp[3]
                    mem["xp"] = x - mem["fmax"] / k1
            elif i == 1:
                if kind == laws.C_PLASTIC:
                    y[0] = -mem["xmax"]
                else:
                    y[2] = 0.0
                mem["branch"] = 1
            else:
                y[0] = -mem["xp"]
                mem["phase"] = 0
                tcol = t
                ysep = y.copy()
                hist[-1][LY.H_TEND] = t
                hist[-1][LY.H_VOUT] = y[2] / v0
                hist[-1][LY.H_XMAX] = xmax_c
                hist[-1][LY.H_IMPULSE] = (y[2] + alpha * y[3] - p_in) / v0
        else:
            xp = mem["xp"]
            # Besides the sign change of the gap u1 + xp, record its minima (v1 rising through
            # 0): a contact shallower than one step has the gap positive at both step ends, so
            # sign-change detection alone steps over it (measured: the 5e-6 deep contact just
            # past alpha*_2 was missed at max_step = period/50). A minimum below the wall is such
            # a contact; it starts at the first root after the previous minimum.
            gap = lambda t, y, xp=xp: y[0] + xp  # noqa: E731
            if y[0] + xp == 0.0 and y[2] > 0.0:  # from the separation: off its root there
                gap = _off_start(gap, t, 1, y[2])
            events = [_event(gap), _minimum(lambda t, y: y[2])] if minima else [_event(gap)]
            n_phase = len(events)
            events += _link_events(sp, mem, t, y)
            sol = _ivp(
                rhs,
                (t, t + 2 * math.pi),
                y,
                method=method,
                rtol=rtol,
                atol=atol,
                events=events,
                max_step=dt_free,
                dense_output=True,
            )
            hit, lows = sol.t_events[:2] if minima else (sol.t_events[0], [])
            j = _crossed(sol, n_phase)
            end = hit[0] if len(hit) else sol.t[-1]
            below = [
                k for k in range(len(lows)) if lows[k] < end and sol.y_events[1][k][0] + xp < 0
            ]
            if below:
                k = below[0]
                start = lows[k - 1] if k > 0 else sol.t[0]
                t_hit = _first_root(lambda s, f=sol.sol, xp=xp: f(s)[0] + xp, start, lows[k])
                sol.t_events[0] = np.array([t_hit])
                sol.y_events[0] = np.array([sol.sol(t_hit)])
            elif not len(hit) and j is not None:  # the scissor link leaves its branch
                t, y = sol.t_events[j][0], sol.y_events[j][0].copy()
                mem["link"] += events[j].direction
                if _no_contact_possible(y, sp, mem):  # (a link may switch every half period)
                    break
                continue
            elif not len(hit):
                t, y = sol.t[-1], sol.y[:, -1].copy()
                if _no_contact_possible(y, sp, mem):
                    break
                continue
            t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
            y[0] = -xp
            if ncol >= max_events:
                status = LY.STATUS_EVENT_BUDGET
                break
            ncol += 1
            xmax_c = -y[0]
            p_in = y[2] + alpha * y[3]
            hist.append([t, t, y[2] / v0, 0.0, 0.0, 0.0])
            if kind == laws.C_RIGID:
                y[2] = -y[2]
                tcol = t
                ysep = y.copy()
                hist[-1][LY.H_VOUT] = y[2] / v0
                hist[-1][LY.H_IMPULSE] = (y[2] + alpha * y[3] - p_in) / v0
            else:
                mem["phase"] = 1
                mem["branch"] = 1 if (kind == laws.C_LINEAR or mem["fmax"] == 0.0) else 0
    out = np.zeros(LY.N_OUT)
    m = 1.0 + alpha
    e0 = 0.5 * m * v0 * v0
    if y0 is not None:  # the given state's energy; the COR over its approach speed (below)
        e0 = 0.5 * (y0[2] ** 2 + alpha * y0[3] ** 2) + laws.structure_energy(sp, y0[1] - y0[0])
        v0 = -(y0[2] + alpha * y0[3]) / m
    vc = (ysep[2] + alpha * ysep[3]) / m
    w = ysep[3] - ysep[2]
    eel = laws.structure_energy(sp, ysep[1] - ysep[0])
    out[LY.OUT_COR] = vc / v0
    out[LY.OUT_NCOL] = ncol
    out[LY.OUT_TCOL] = tcol
    out[LY.OUT_ETRANS] = vc * vc / (v0 * v0)
    if y0 is not None:
        out[LY.OUT_ETRANS] = 0.5 * m * vc * vc / e0
    out[LY.OUT_EVIB] = (0.5 * alpha / m * w * w + eel) / e0
    out[LY.OUT_EDISS] = (ysep[4] + ysep[5]) / e0
    out[LY.OUT_NEVENTS] = ncol
    out[LY.OUT_ERR] = max(rtol, ROUNDOFF_FLOOR)
    acct[0] = 0.5 * (ysep[2] ** 2 + alpha * ysep[3] ** 2) / e0
    acct[1] = eel / e0
    acct[2] = ysep[4] / e0
    acct[3] = ysep[5] / e0
    acct[4] = out[LY.OUT_ETRANS] + out[LY.OUT_EVIB] + out[LY.OUT_EDISS] - 1.0
    if status == LY.STATUS_OK and not abs(acct[4]) <= etol:
        status = LY.STATUS_ENERGY
    # As in kernels/stepping.py: negative net contact work means the law created energy.
    if status == LY.STATUS_OK and acct[2] < -etol:
        status = LY.STATUS_ENERGY
    out[LY.OUT_STATUS] = status
    return out, np.array(hist[: max(ncol, 0)], dtype=float).reshape(-1, LY.N_HIST)
