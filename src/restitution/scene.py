"""Scene parameters, their allowed ranges, and the derived non-dimensional system.

Units (DESIGN.md): m1 = 1, V0 = 1 and omega = 1 with omega**2 = k2/m1 + k2/m2, so for
alpha = m2/m1 the structural stiffness is k2 = alpha/(1 + alpha). The contact stiffness is
k1 = k2/beta (beta = 0: rigid wall). An N-mass chain has m1 = 1, m2..mN = alpha and the same k2
between every pair of neighbours. The dashpot (Section 3.4) acts between m1 and m2 only, with
coefficient c = 2*xi*k2/omega, in the chain as well as for two masses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# Exact methods for piecewise-linear scenes, numerical ones for nonlinear laws (and for checks).
EXACT_METHODS = ("impulsive", "piecewise")
NUMERICAL_METHODS = ("adaptive", "verlet", "reference")
METHODS = ("auto", *EXACT_METHODS, *NUMERICAL_METHODS)


class SceneError(ValueError):
    """A scene parameter is outside its allowed range."""


def _show(value) -> str:
    """repr of a value as a user typed it (numpy scalars shown as plain Python numbers)."""
    return repr(value.item() if isinstance(value, np.generic) else value)


def _check_real(name: str, value, low: float, high: float, low_open: bool, allowed: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SceneError(f"{name} must be a number {allowed}; got {_show(value)}") from None
    if isinstance(value, bool) or math.isnan(x):
        raise SceneError(f"{name} must be a number {allowed}; got {_show(value)}")
    if (x <= low if low_open else x < low) or x > high:
        raise SceneError(f"{name} must be {allowed}; got {_show(value)}")
    return x


def check_alpha(value) -> float:
    return _check_real("alpha", value, 0.0, 1e8, True, "in (0, 1e8]")


def check_beta(value) -> float:
    return _check_real("beta", value, 0.0, 1e6, False, "in [0, 1e6] (0 = rigid wall)")


def check_xi(value) -> float:
    return _check_real("xi", value, 0.0, 1e3, False, "in [0, 1e3]")


def check_n_masses(value) -> int:
    ok = isinstance(value, (int, np.integer)) or (
        isinstance(value, (float, np.floating)) and float(value).is_integer()
    )
    if isinstance(value, bool) or not ok or not 2 <= int(value) <= 512:
        raise SceneError(f"n_masses must be an integer in [2, 512]; got {_show(value)}")
    return int(value)


def check_method(value) -> str:
    if value not in METHODS:
        raise SceneError(f"method must be one of {', '.join(METHODS)}; got {_show(value)}")
    return value


@dataclass(frozen=True)
class Scene:
    """A validated piecewise-linear scene (see the module docstring for units)."""

    alpha: float
    beta: float = 0.0
    xi: float = 0.0
    n_masses: int = 2

    def __post_init__(self):
        object.__setattr__(self, "alpha", check_alpha(self.alpha))
        object.__setattr__(self, "beta", check_beta(self.beta))
        object.__setattr__(self, "xi", check_xi(self.xi))
        object.__setattr__(self, "n_masses", check_n_masses(self.n_masses))

    @property
    def masses(self) -> np.ndarray:
        m = np.full(self.n_masses, self.alpha)
        m[0] = 1.0
        return m

    @property
    def k2(self) -> float:
        return self.alpha / (1.0 + self.alpha)

    @property
    def k1(self) -> float:
        return math.inf if self.beta == 0 else self.k2 / self.beta

    @property
    def c(self) -> float:
        return 2.0 * self.xi * self.k2

    @property
    def total_mass(self) -> float:
        return 1.0 + (self.n_masses - 1) * self.alpha
