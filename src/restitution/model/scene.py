"""The paper's scene (alpha, beta, xi, n_masses) and its derived non-dimensional system.

The ranges live in ``restitution.model.chain.RANGES`` (checked once, there); the general model is
``restitution.Chain``, of which these scenes are the preset ``Chain.paper``.

Units: m1 = 1, V0 = 1 and omega = 1 with omega**2 = k2/m1 + k2/m2, so for
alpha = m2/m1 the structural stiffness is k2 = alpha/(1 + alpha). The contact stiffness is
k1 = k2/beta (beta = 0: rigid wall). An N-mass chain has m1 = 1, m2..mN = alpha and the same k2
between every pair of neighbours. The dashpot (Section 3.4) acts between m1 and m2 only, with
coefficient c = 2*xi*k2/omega, in the chain as well as for two masses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from restitution.model.chain import SceneError, check


def check_alpha(value) -> float:
    return check("alpha", value)


def check_beta(value) -> float:
    return check("beta", value)


def check_xi(value) -> float:
    return check("xi", value)


def check_n_masses(value) -> int:
    return check("n_masses", value)


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


__all__ = [
    "Scene",
    "SceneError",
    "check_alpha",
    "check_beta",
    "check_n_masses",
    "check_xi",
]
