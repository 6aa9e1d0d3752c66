"""``scipy.integrate.solve_ivp`` with events on any scene: the tool a researcher would reach for.

One runner, :func:`solve_ivp_scene`, takes the same scene parameters as ``restitution.solve`` plus
the scipy ``method`` (RK45, DOP853, Radau, LSODA, ...), ``rtol`` and ``atol``:

* two masses (any law: rigid wall, linear or plastic contact, linear or scissor structure) reuse
  the phase machine of ``restitution.solvers.reference`` (terminal sign-change events switch the
  law);
* chains (``n_masses > 2``, linear laws) integrate M u'' + C u' + K u = contact force in one
  phase per contact state, with the free-flight stop test of ``tests/test_linear.py``.

By default no ``max_step`` is applied (``steps_per_period=None``): scipy checks event signs only at
its step ends, so a contact shallower than one step is missed -- exactly what the grazing scenes
probe. ``steps_per_period=50`` restores the reference's safeguard. Every run has a contact budget
(``max_events``) and a wall-clock budget (``time_budget`` seconds, checked at every right-hand side
evaluation); running out gives status ``event_budget_exhausted`` / ``time_budget_exhausted``,
never a hang.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

from restitution.kernels import layout as LY
from restitution.model.chain import LAW_KEYS, Chain, SceneError, paper_with_laws
from restitution.solvers.numerical import packed
from restitution.solvers.reference import DeadlineExceeded, solve_reference
from restitution.solvers.result import Result

IVP_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
TIME_BUDGET_STATUS = "time_budget_exhausted"
_LAW_KEYS = LAW_KEYS


def _check(method, rtol, atol, steps_per_period, time_budget, max_events):
    if method not in IVP_METHODS:
        raise SceneError(f"method must be one of {', '.join(IVP_METHODS)}; got {method!r}")
    for name, value, low, high in (("rtol", rtol, 1e-14, 1.0), ("atol", atol, 1e-300, 1.0)):
        if value is None and name == "atol":
            continue
        if not (isinstance(value, (int, float)) and low <= value <= high):
            raise SceneError(f"{name} must be a number in [{low:g}, {high:g}]; got {value!r}")
    if steps_per_period is not None and not (
        isinstance(steps_per_period, (int, float)) and 1 <= steps_per_period <= 1e6
    ):
        raise SceneError(f"steps_per_period must be None or in [1, 1e6]; got {steps_per_period!r}")
    if not (isinstance(time_budget, (int, float)) and 0 < time_budget <= 1e5):
        raise SceneError(f"time_budget must be in (0, 1e5] seconds; got {time_budget!r}")
    if isinstance(max_events, bool) or not isinstance(max_events, int) or max_events < 1:
        raise SceneError(f"max_events must be a positive integer; got {max_events!r}")


def solve_ivp_scene(
    alpha: float,
    beta: float = 0.0,
    xi: float = 0.0,
    n_masses: int = 2,
    *,
    method: str = "DOP853",
    rtol: float = 1e-6,
    atol: float | None = None,
    steps_per_period: float | None = None,
    time_budget: float = 60.0,
    max_events: int = 100_000,
    **law,
) -> Result:
    """COR of one scene by ``solve_ivp`` with terminal events (module docstring).

    ``atol`` defaults to ``rtol`` (velocities are in units of the impact speed). Returns a
    ``Result`` whose ``method`` is ``"solve_ivp:<method>"`` and whose ``error_estimate`` is rtol;
    the energy account is reported, not enforced (benchmarks measure it separately).
    """
    unknown = sorted(set(law) - set(_LAW_KEYS))
    if unknown:
        raise SceneError(f"unknown law parameter(s) {unknown}; allowed: {', '.join(_LAW_KEYS)}")
    _check(method, rtol, atol, steps_per_period, time_budget, max_events)
    scene = Chain.paper(alpha, beta, xi, n_masses)
    atol = rtol if atol is None else atol
    nonlinear = law.get("contact", "linear") != "linear" or law.get("structure") == "scissor"
    if nonlinear and scene.n_masses != 2:
        raise SceneError(f"nonlinear laws need n_masses = 2; got {scene.n_masses}")
    deadline = time.perf_counter() + time_budget
    timed_out = False
    try:
        args = (scene, method, rtol, atol, steps_per_period, deadline, max_events)
        out = _two_masses(*args, law) if scene.n_masses == 2 else _chain(*args)
    except DeadlineExceeded:
        timed_out = True
        out = np.full(LY.N_OUT, np.nan)
        out[LY.OUT_NCOL] = -1
        out[LY.OUT_STATUS] = LY.STATUS_OK  # replaced below
    result = Result.from_row(scene, out, f"solve_ivp:{method}")
    if timed_out:
        result = dataclasses.replace(result, status=TIME_BUDGET_STATUS)
    return result


def _two_masses(scene, method, rtol, atol, steps_per_period, deadline, max_events, law):
    ch, _ = paper_with_laws(scene.alpha, scene.beta, scene.xi, 2, dict(law))
    _, lk, _, cp, _, _ = packed(ch)
    v0, sp = float(ch.v0), lk[0]
    out, _ = solve_reference(
        scene.alpha,
        v0,
        scene.xi,
        cp,
        sp,
        rtol,
        max_events,
        np.zeros(5),
        math.inf,  # energy is measured by the caller, not turned into a status
        method=method,
        atol=atol * v0,
        steps_per_period=steps_per_period,
        deadline=deadline,
        minima=False,  # plain sign-change events, as solve_ivp is usually used
        branches=False,  # and the law's branch picked by x at every evaluation
    )
    return out


def chain_matrices(alpha, beta, xi, n):
    """Masses, stiffness, damping matrices and k1 of the chain (units of docs/physics.md)."""
    m = np.full(n, float(alpha))
    m[0] = 1.0
    k2 = alpha / (1.0 + alpha)
    K = np.zeros((n, n))
    for i in range(n - 1):
        K[i : i + 2, i : i + 2] += k2 * np.array([[1.0, -1.0], [-1.0, 1.0]])
    C = np.zeros((n, n))
    C[:2, :2] = 2.0 * xi * k2 * np.array([[1.0, -1.0], [-1.0, 1.0]])
    k1 = 0.0 if beta == 0 else k2 / beta
    return m, K, C, k1


def _chain(scene, method, rtol, atol, steps_per_period, deadline, max_events):
    """Linear chain: state (u, v, dissipated energy); u1 < 0 is penetration of the wall."""
    n = scene.n_masses
    m, K, C, k1 = chain_matrices(scene.alpha, scene.beta, scene.xi, n)
    mt = m.sum()
    e0 = 0.5 * mt

    def max_step(kk):
        if steps_per_period is None:
            return math.inf
        wmax = math.sqrt(max(np.max(np.abs(np.linalg.eigvals(kk / m[:, None]))), 1e-300))
        return 2 * math.pi / wmax / steps_per_period

    Kc = K.copy()
    Kc[0, 0] += k1
    step_free, step_contact = max_step(K), max_step(Kc)
    # Stop test of free flight: |u1 - X| <= sqrt(2 E_rel g) with E_rel non-increasing, g = max
    # u1^2 / u'Ku over displacements with zero centre of mass; no contact once X exceeds it.
    Q = np.linalg.svd(m[None, :])[2][1:].T
    g = Q[0] @ np.linalg.solve(Q.T @ K @ Q, Q[0])

    def rhs(kc):
        def f(t, y):
            if time.perf_counter() > deadline:
                raise DeadlineExceeded("wall-clock budget exhausted")
            u, v = y[:n], y[n : 2 * n]
            cv = C @ v
            a = -(K @ u + cv) / m
            a[0] -= kc * u[0] / m[0]
            return np.concatenate([v, a, [v @ cv]])

        return f

    def hit(t, y):
        return y[0]

    hit.terminal = True
    y = np.concatenate([np.zeros(n), -np.ones(n), [0.0]])
    t, count, t_sep = 0.0, 1, 0.0
    contact = scene.beta > 0
    if not contact:
        y[n] = 1.0
    status = LY.STATUS_OK
    opts = dict(method=method, rtol=rtol, atol=atol, events=hit)
    while True:
        if t > 1e5:
            status = LY.STATUS_NONCONVERGED
            break
        if contact:
            hit.direction = 1.0
            y[0] = min(y[0], -1e-300)  # start inside; the event is the return of u1 to zero
            sol = solve_ivp(rhs(k1), (t, t + 1e4), y, max_step=step_contact, **opts)
            if not sol.t_events[0].size:
                status = LY.STATUS_NONCONVERGED
                break
            t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
            y[0] = 0.0
            t_sep, contact = t, False
            continue
        hit.direction = -1.0
        u, v = y[:n], y[n : 2 * n]
        V, X = m @ v / mt, m @ u / mt
        erel = 0.5 * (m @ (v - V) ** 2) + 0.5 * u @ K @ u
        if V > 0 and X - math.sqrt(2 * max(erel, 0.0) * g) > 0.0:
            break
        y[0] = max(y[0], 1e-300)
        sol = solve_ivp(rhs(0.0), (t, t + 20.0), y, max_step=step_free, **opts)
        if not sol.t_events[0].size:
            t, y = sol.t[-1], sol.y[:, -1].copy()
            continue
        t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
        y[0] = 0.0
        if count >= max_events:
            status = LY.STATUS_EVENT_BUDGET
            break
        count += 1
        if scene.beta == 0:
            y[n] = -y[n]
            t_sep = t
        else:
            contact = True
    u, v = y[:n], y[n : 2 * n]
    V = m @ v / mt
    out = np.zeros(LY.N_OUT)
    out[LY.OUT_COR] = V
    out[LY.OUT_NCOL] = count
    out[LY.OUT_TCOL] = t_sep
    out[LY.OUT_ETRANS] = V * V
    out[LY.OUT_EVIB] = (0.5 * (m @ (v - V) ** 2) + 0.5 * u @ K @ u) / e0
    out[LY.OUT_EDISS] = y[2 * n] / e0
    out[LY.OUT_STATUS] = status
    out[LY.OUT_NEVENTS] = count
    out[LY.OUT_ERR] = rtol
    return out
