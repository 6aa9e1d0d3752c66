"""The COR against the impact speed V0 with Hertz contact, and its two limits (Fig. 9).

A Hertz contact F = k_h x**1.5 stiffens with the impact: its slope at the deepest penetration
grows like k_h**0.8 V0**0.4 and one body of mass M stays in contact t_c = 2 I T with

    T = x_max / V0 = (5 M V0**2 / (4 k_h))**0.4 / V0,   I = (2/5) B(2/5, 1/2) = 1.4716,

so the COR of a chain depends on V0 through k_h**2 V0 / (m_1**2 omega**5) alone (omega: the
chain's first-link frequency, ``restitution.Chain``). Two limits bound it:

- **rigid wall** (large V0, omega t_c -> 0): the COR tends to that of the same chain at a rigid
  wall, solved exactly by the impulsive method. The difference behaves as a power series in
  omega t_c: first order where several contacts follow each other (a finite contact shifts the
  phases of the later ones), second order with a single contact (tests/test_speed.py
  extrapolates it to the rigid-wall value).
- **soft contact** (small V0, omega_1 t_c -> infinity): the chain moves as one body under the
  Hertz pulse of its total mass M and each free mode j (frequency omega_j, mass-normalised shape
  phi_j) keeps the energy |phi_j(1) F^(omega_j)|**2 / 2 once the pulse is over. The pulse
  starts and ends like t**1.5, so its spectrum falls like q**-2.5 (q = omega T) and, to leading
  order,

      1 - COR = (M / 2) sum_j phi_j(1)**2 h(omega_j T)**2,
      h(q) = (5/2) Gamma(5/2) q**-2.5 cos(q I - 5 pi / 4) (1 + O(q**-2.5)),

  whose envelope (cos**2 = 1) is :func:`soft_limit_envelope`: 1 - COR falls like V0 (like
  (omega t_c)**-5). The structure's compliance shifts the phase of the cosine by O(1/q), so the
  envelope, not the oscillation, is the checked bound.

:func:`cor_against_speed` sweeps a log grid of V0 with ``restitution.solve_many`` (method
``auto``: the adaptive integrator for the Hertz law), bisects every change of the contact count
in log V0 with :func:`restitution.analysis.sweeps.refine_count_changes` and solves the rigid-wall
chain; every row keeps its ``status``, ``method`` and ``error_estimate``.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from restitution.kernels.constants import MAX_EVENTS_DEFAULT

__all__ = [
    "HERTZ_I",
    "SpeedSweep",
    "cor_against_speed",
    "count_changes",
    "free_modes",
    "hertz_contact_time",
    "hertz_time_scale",
    "soft_limit_envelope",
]

#: I = (2/5) B(2/5, 1/2) = int_0^1 dxi / sqrt(1 - xi**2.5): half the Hertz contact time over T.
HERTZ_I = 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)
#: Leading coefficient of the Hertz pulse spectrum at large q: h(q) ~ (5/2) Gamma(5/2) q**-2.5.
_SPECTRUM = 2.5 * math.gamma(2.5)

#: Result columns of ``restitution.solve_many`` kept in a sweep's table.
COLUMNS = ("v0", "cor", "n_collisions", "omega_t_col", "e_vibrational", "method", "status",
           "error_estimate")  # fmt: skip


def hertz_time_scale(mass, k_hertz, v0):
    """T = x_max / V0 of one body of mass ``mass`` hitting a Hertz contact ``k_hertz`` at ``v0``.

    x_max = (5 m V0**2 / (4 k_h))**0.4 is its deepest penetration; any consistent units.

    >>> round(float(hertz_time_scale(1.0, 1.0, 1.0)), 6)
    1.093362
    """
    v0 = np.asarray(v0, dtype=float)
    return (1.25 * mass * v0**2 / k_hertz) ** 0.4 / v0


def hertz_contact_time(mass, k_hertz, v0):
    """Contact duration t_c = 2 I T of one body of mass ``mass`` on a Hertz contact at ``v0``.

    >>> round(float(hertz_contact_time(1.0, 1.0, 1.0)), 6)  # C = 2 I (5/4)**0.4
    3.218065
    """
    return 2.0 * HERTZ_I * hertz_time_scale(mass, k_hertz, v0)


def free_modes(masses, springs) -> tuple[np.ndarray, np.ndarray]:
    """The vibration modes of the free chain (no wall): frequencies omega_j > 0, ascending, and
    the weights phi_j(1)**2 of m_1 in the mass-normalised shapes (the rigid mode left out).

    >>> omega, weight = free_modes([1.0, 2.0], [3.0])
    >>> round(float(omega[0]) ** 2, 12), round(float(weight[0]), 12)  # k (1/m1 + 1/m2), m2/(m1 M)
    (4.5, 0.666666666667)
    """
    m = np.asarray(masses, dtype=float)
    k = np.asarray(springs, dtype=float)
    n = len(m)
    stiffness = np.zeros((n, n))
    for i, ki in enumerate(k):
        stiffness[i, i] += ki
        stiffness[i + 1, i + 1] += ki
        stiffness[i, i + 1] -= ki
        stiffness[i + 1, i] -= ki
    scale = 1.0 / np.sqrt(m)
    lam, psi = np.linalg.eigh(scale[:, None] * stiffness * scale[None, :])
    # The rigid mode (eigenvalue 0 up to round-off) is the first of the ascending eigenvalues.
    return np.sqrt(np.maximum(lam[1:], 0.0)), psi[0, 1:] ** 2 / m[0]


def soft_limit_envelope(masses, springs, k_hertz, v0):
    """Leading-order envelope of 1 - COR for a soft Hertz contact (module docstring):
    (M/2) sum_j phi_j(1)**2 ((5/2) Gamma(5/2))**2 (omega_j T)**-5, proportional to ``v0``.

    Valid where omega_1 T >> 1 (the slowest mode's period well below the contact time).

    >>> e = soft_limit_envelope([1.0, 1.0], [0.5], 1.0, np.array([1e-6, 1e-5]))
    >>> round(float(e[1] / e[0]), 9)
    10.0
    """
    omega, weight = free_modes(masses, springs)
    total = float(np.sum(masses))
    t = hertz_time_scale(total, k_hertz, v0)
    q = np.multiply.outer(t, omega)
    return 0.5 * total * np.sum(weight * (_SPECTRUM * q**-2.5) ** 2, axis=-1)


@dataclass(frozen=True)
class SpeedSweep:
    """What :func:`cor_against_speed` returns.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per V0 evaluated, sorted by ``v0``: ``v0``, the result columns (``cor``,
        ``n_collisions``, ``omega_t_col``, ``e_vibrational``, ``method``, ``status``,
        ``error_estimate``) and ``refined`` (False on the grid, True for bisection points).
    rigid : dict
        The same chain at a rigid wall: ``cor``, ``n_collisions``, ``method``, ``status``,
        ``error_estimate``.
    changes : pandas.DataFrame
        One row per change of the contact count (:func:`count_changes`).
    tolerance : float
        Width in decades of log10 V0 a refined bracket ends within (grid step * 2**-steps).
    """

    table: pd.DataFrame
    rigid: dict
    changes: pd.DataFrame
    tolerance: float


def count_changes(table: pd.DataFrame, tolerance: float = math.inf) -> pd.DataFrame:
    """Where the contact count changes along ``v0``, read from the rows whose status is ok.

    One row per pair of ok neighbours (sorted by ``v0``) whose ``n_collisions`` differ:
    ``v0_lo, v0_hi`` (the bracket), ``n_lo, n_hi`` (the counts there), ``v0`` (its geometric
    midpoint), ``width`` (log10(v0_hi / v0_lo), decades) and ``resolved`` (width <= tolerance;
    False where a row that is not ok kept the bisection from closing in).

    >>> t = pd.DataFrame({"v0": [1.0, 2.0, 3.0], "n_collisions": [1, 1, 2], "status": "ok"})
    >>> count_changes(t)[["v0_lo", "v0_hi", "n_lo", "n_hi"]].values.tolist()
    [[2.0, 3.0, 1.0, 2.0]]
    """
    ok = table[table["status"] == "ok"].sort_values("v0")
    v, n = ok["v0"].to_numpy(), ok["n_collisions"].to_numpy()
    at = np.flatnonzero(n[1:] != n[:-1])
    lo, hi = v[at], v[at + 1]
    width = np.log10(hi / lo)
    return pd.DataFrame({
        "v0_lo": lo, "v0_hi": hi, "n_lo": n[at], "n_hi": n[at + 1], "v0": np.sqrt(lo * hi),
        "width": width, "resolved": width <= tolerance,
    })  # fmt: skip


def cor_against_speed(
    masses,
    springs,
    k_hertz: float,
    v0,
    *,
    refine_steps: int = 30,
    rtol: float | None = None,
    max_events: int = MAX_EVENTS_DEFAULT,
    logger: logging.Logger | None = None,
    label: str = "",
    progress: bool = False,
) -> SpeedSweep:
    """COR against V0 of the chain ``masses``, ``springs`` on a Hertz contact ``k_hertz``.

    Parameters
    ----------
    masses, springs : sequence of float
        The chain (``restitution.Chain``: m_1 touches the wall), undamped.
    k_hertz : float
        Hertz constant k_h of F = k_h x**1.5 (same units).
    v0 : array_like
        The grid of impact speeds (increasing; e.g. ``sweeps.log_grid``), each within
        ``restitution.model.ranges.RANGES['v0']`` and making a scene the solvers accept.
    refine_steps : int
        Bisection steps in log V0 at every change of the contact count between grid
        neighbours; a bracket ends within (its grid step) * 2**-refine_steps decades.
    rtol : float, optional
        The adaptive integrator's tolerance (``solve_many``'s ``rtol`` column; default its own).
    max_events : int
        Contact budget of every scene.
    logger, label, progress
        As for :func:`restitution.analysis.sweeps.refine_count_changes`.

    Returns
    -------
    SpeedSweep
        The rows, the rigid-wall result and the count changes.

    Raises
    ------
    restitution.SceneError
        If a scene is outside the solvers' ranges (the contact-to-spring ratio or the frequency
        spread at an end of the grid).

    Examples
    --------
    >>> s = cor_against_speed([1.0, 0.5], [1 / 3], 1.0, [1e-3, 1e6], refine_steps=0)
    >>> s.rigid["method"], round(s.rigid["cor"], 12)  # (1 - alpha)/(1 + alpha)
    ('impulsive', 0.333333333333)
    >>> bool(s.table["cor"].iloc[0] > 0.99), bool(abs(s.table["cor"].iloc[1] - 1 / 3) < 1e-3)
    (True, True)
    """
    from restitution.analysis.sweeps import refine_count_changes
    from restitution.api import solve, solve_many
    from restitution.model.chain import Chain

    masses = [float(m) for m in masses]
    springs = [float(k) for k in springs]
    contact = {"law": "hertz", "k": float(k_hertz)}
    grid = np.asarray(v0, dtype=float)
    if grid.ndim != 1 or len(grid) < 2 or not np.all(np.diff(grid) > 0):
        raise ValueError("cor_against_speed: v0 must be an increasing grid of two or more speeds")
    for end in (grid[0], grid[-1]):  # the scene checks (ratio, spread) before any work
        Chain(masses, springs, contact=contact, v0=float(end))

    def evaluate(values) -> pd.DataFrame:
        values = np.asarray(values, dtype=float)
        frame = {"masses": [masses] * len(values), "springs": [springs] * len(values),
                 "v0": values, "contact": [contact] * len(values)}  # fmt: skip
        if rtol is not None:
            frame["rtol"] = float(rtol)
        out = solve_many(pd.DataFrame(frame), max_events=max_events)
        return out[list(COLUMNS)]

    table = evaluate(grid).assign(refined=False)
    ok = table[table["status"] == "ok"]
    extra = refine_count_changes(ok, evaluate, "v0", refine_steps, logger, label, progress)
    if len(extra):
        table = pd.concat([table, extra.assign(refined=True)], ignore_index=True)
    table = table.drop_duplicates(subset="v0", keep="first").sort_values("v0", ignore_index=True)
    step = float(np.max(np.diff(np.log10(grid))))
    tolerance = step * 2.0**-refine_steps if refine_steps else step
    r = solve(Chain(masses, springs), max_events=max_events)
    rigid = {"cor": r.cor, "n_collisions": r.n_collisions, "method": r.method,
             "status": r.status, "error_estimate": r.error_estimate}  # fmt: skip
    # A bracket is halved refine_steps times from at most one grid step; log10 of a ratio
    # 1 + 5e-11 carries a relative round-off of ~1e-6, hence the slack.
    changes = count_changes(table, tolerance * (1.0 + 1e-3))
    if logger is not None:
        from restitution.analysis.sweeps import log_not_ok

        log_not_ok(table, logger, label, where="v0")
        prefix = f"{label}: " if label else ""
        logger.info(
            "%s%d rows (%d refined), contacts %d..%d, rigid wall COR %.9f (%d contacts, %s), "
            "%d count changes (%d within %.2g decades)",
            prefix, len(table), int(table["refined"].sum()), table["n_collisions"].min(),
            table["n_collisions"].max(), rigid["cor"], rigid["n_collisions"], rigid["method"],
            len(changes), int(changes["resolved"].sum()), tolerance,
        )  # fmt: skip
    return SpeedSweep(table, rigid, changes, tolerance)
