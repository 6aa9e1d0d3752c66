"""Dimensional inputs to the non-dimensional scene, and results back to dimensional units.

The solvers work in the units of docs/physics.md (m1 = 1, V0 = 1, omega = 1 with
omega**2 = k2/m1 + k2/m2). A physical two-mass system (or chain: m2..mN all equal to m2) is

    m1, m2 [kg], structural spring k2 [N/m], contact spring k1 [N/m] (None: rigid wall),
    dashpot c [N s/m] between m1 and m2, impact speed V0 [m/s],

and maps to alpha = m2/m1, beta = k2/k1 (0 for a rigid wall), xi = c omega / (2 k2). The COR and
the energy fractions are dimensionless; the collision duration is omega_t_col / omega. Only the
linear laws are covered here (the nonlinear ones carry their own velocity scale ``v0``).

>>> p = nondimensional(m1=2.0, m2=4.0, k2=300.0, V0=3.0, k1=3e4, c=5.0)
>>> round(p["alpha"], 12), round(p["beta"], 12)
(2.0, 0.01)
"""

from __future__ import annotations

import math

from restitution.model.ranges import SceneError
from restitution.model.units import user_speed, user_time


def _positive(name: str, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SceneError(f"{name} must be a positive finite number; got {value!r}") from None
    if isinstance(value, bool) or not math.isfinite(x) or x <= 0.0:
        raise SceneError(f"{name} must be a positive finite number; got {value!r}")
    return x


def omega(m1: float, m2: float, k2: float) -> float:
    """The unit of frequency, omega = sqrt(k2/m1 + k2/m2) [1/s]."""
    m1, m2, k2 = _positive("m1", m1), _positive("m2", m2), _positive("k2", k2)
    return math.sqrt(k2 / m1 + k2 / m2)


def nondimensional(
    m1: float, m2: float, k2: float, V0: float, k1: float | None = None, c: float = 0.0
) -> dict:
    """``alpha, beta, xi`` of ``restitution.solve`` for a dimensional system (module docstring).

    ``V0`` is checked (> 0) but does not enter: the linear problem is scale-free in the speed.
    """
    _positive("V0", V0)
    w = omega(m1, m2, k2)
    beta = 0.0 if k1 is None else _positive("k2", k2) / _positive("k1", k1)
    cc = float(c)
    if not math.isfinite(cc) or cc < 0.0:
        raise SceneError(f"c (dashpot coefficient) must be finite and >= 0; got {c!r}")
    return dict(alpha=float(m2) / float(m1), beta=beta, xi=cc * w / (2.0 * float(k2)))


def to_dimensional(result, m1: float, m2: float, k2: float, V0: float, n_masses: int = 2) -> dict:
    """Dimensional view of a ``Result``: rebound speed, duration and energies in SI units.

    ``rebound_velocity`` is the final centre-of-mass velocity cor*V0 [m/s], ``t_col`` the time
    from first contact to final separation [s], energies are fractions times the initial kinetic
    energy (m1 + (N-1) m2) V0**2 / 2 [J].
    """
    V0 = _positive("V0", V0)
    w = omega(m1, m2, k2)
    e0 = 0.5 * (m1 + (n_masses - 1) * m2) * V0 * V0
    return dict(
        rebound_velocity=user_speed(result.cor, V0),
        t_col=user_time(result.omega_t_col, w),
        kinetic_energy=result.e_translational * e0,
        vibration_energy=result.e_vibrational * e0,
        dissipated_energy=result.e_dissipated * e0,
    )


__all__ = ["nondimensional", "omega", "to_dimensional"]
