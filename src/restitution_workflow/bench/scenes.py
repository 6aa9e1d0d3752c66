"""The hard-case scene suite (issue #7 item 3): one definition for benchmarks and tests.

Each :class:`Scene` is a declarative scene plus a reference COR and contact count obtained by an
independent method (never the code under test): ``benchmarks/reference_values.py`` recomputes
them and prints the constants pasted here, with their source and absolute error bound.

* Two-mass linear scenes: the exact piecewise-linear motion in 40 and 50 digits (mpmath matrix
  exponentials, contacts found from u1's sign and from its local minima, roots polished to
  1e-32); bound = 10 x the 40/50-digit difference + half an ulp for the rounding to float64.
  ``reference_condition`` = |d cor / d ln alpha| (mpmath), which sets a float64 solver's
  round-off bound.
* N = 32 chain: scipy DOP853 per phase (max_step 1/125 of the fastest period), rtol 1e-11..1e-13;
  bound = 10 x the spread of the sweep, at least 1e-12.
* Nonlinear laws: the plastic contact by ``benchmarks/mp_nonlinear.py`` (mpmath Taylor series, the
  power law's first loading in sigma = sqrt(x)) at 30 and 40 digits, bound 10 x their difference
  plus half an ulp (the scipy reference at rtol 1e-13 was 5e-13 off, within its 3.6e-10); the
  scissor spring by ``restitution.solvers.precise_scissor`` (mpmath Taylor series, its branch
  points located on the series) at 30 and 40 digits, bound 10 x their difference plus half an
  ulp (the scipy reference at rtol 1e-13 that it replaces was 3.6e-13 off, within its 4.1e-11).

Contact count at a grazing point. At alpha*_n the (n+1)-th contact is a tangency with zero
depth and zero impulse: not a contact interval. The scene's alpha is the largest float64 below
alpha*_n, whose exact solution misses the tangency by 4.5e-16 (n = 2) and 1.3e-15 (n = 5), so the
reference count is n. That is also the exact kernels' rule (a touch within round-off of the gap's
scale does not count). A float solver may register the round-off touch instead; the COR is
continuous there but has a square-root cusp, so that costs ~C sqrt(depth), C = 0.95
(tests/test_hard.py accepts n + 1 for the numerical methods with that allowance).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Scene:
    """One hard scene: parameters of ``restitution.solve`` and its reference result."""

    name: str  # short id for tables and file names
    title: str  # one line for plot titles
    alpha: float
    beta: float = 0.0
    xi: float = 0.0
    n_masses: int = 2
    law: Mapping[str, object] = field(default_factory=dict)  # nonlinear law kwargs; {} if linear
    reference_cor: float | None = None  # from an independent reference (reference_source)
    reference_contacts: int | None = None
    reference_bound: float | None = None  # absolute error bound of reference_cor
    reference_source: str = ""
    # relative condition number |d cor / d ln alpha| of the exact problem (None: not measured,
    # taken as 1); sets the round-off bound of the exact solvers in tests/test_hard.py
    reference_condition: float | None = None

    @property
    def linear(self) -> bool:
        """True when contact and structure are linear (the exact solvers apply)."""
        return self.law.get("contact", "linear") == "linear" and (
            self.law.get("structure", "linear") == "linear"
        )

    def solve_kwargs(self) -> dict:
        """Keyword arguments for ``restitution.solve(**kwargs)`` (add ``method=`` as needed)."""
        return dict(
            alpha=self.alpha, beta=self.beta, xi=self.xi, n_masses=self.n_masses, **self.law
        )


# Grazing points of the rigid wall (beta = 0): the largest float64 <= alpha*_n, with alpha*_n
# from a 40-digit root of the gap minimum (benchmarks/reference_values.py::grazing_alpha):
# alpha*_2 = 2.07007423855219326473919307545, alpha*_5 = 7.15161749471496563844707364465.
# Below alpha*_n the exact solution has n contacts and its (n+1)-th gap minimum is a miss of
# 4.5e-16 (n = 2) and 1.3e-15 (n = 5): a touch no float64 solver can resolve. (The float
# restitution.analysis.special_points.alpha_star returns, 2 ulp above alpha*_2, has a real touch of
# depth
# 1.7e-15 that moves the COR by 3.9e-8: on the other side of the cusp.)
ALPHA_STAR_2 = 2.070074238552193
ALPHA_STAR_5 = 7.151617494714965

SCENES: tuple[Scene, ...] = (
    # Exactly at a grazing point: the exact solution misses the next contact by round-off.
    Scene(
        "graze2",
        "grazing contact at alpha*_2 (beta = 0)",
        ALPHA_STAR_2,
        reference_cor=0.5576289282044364,
        reference_contacts=2,
        reference_bound=5.6e-17,
        reference_source="mpmath 50 digits",
        reference_condition=0.86,
    ),
    # Just past it: the extra contact is 5e-6 deep and lasts 0.006 (period 6.3); sign-change
    # event detection at step ends misses it.
    Scene(
        "graze2_past",
        "just past alpha*_2: alpha*_2 (1 + 1e-6)",
        ALPHA_STAR_2 * (1 + 1e-6),
        reference_cor=0.5597448870466861,
        reference_contacts=3,
        reference_bound=5.6e-17,
        reference_source="mpmath 50 digits",
        reference_condition=1100.0,
    ),
    # The fifth grazing point: a longer sequence before the tangent touch.
    Scene(
        "graze5",
        "grazing contact at alpha*_5 (beta = 0)",
        ALPHA_STAR_5,
        reference_cor=0.8357923556518749,
        reference_contacts=5,
        reference_bound=5.6e-17,
        reference_source="mpmath 50 digits",
        reference_condition=1.1,
    ),
    # Just past alpha*_5: the sixth contact is 1.2e-5 deep, its dip 0.009 long.
    Scene(
        "graze5_past",
        "just past alpha*_5: alpha*_5 (1 + 1e-6)",
        ALPHA_STAR_5 * (1 + 1e-6),
        reference_cor=0.8371141640159867,
        reference_contacts=6,
        reference_bound=5.6e-17,
        reference_source="mpmath 50 digits",
        reference_condition=660.0,
    ),
    # Very stiff contact: contact frequency sqrt(k1/m1) = 870 omega, so an explicit step must
    # shrink 870-fold in contact. alpha = 3 (between alpha*_2 and alpha*_3): 3 contacts.
    Scene(
        "stiff",
        "very stiff contact, beta = 1e-6",
        3.0,
        beta=1e-6,
        reference_cor=0.8916695785430213,
        reference_contacts=3,
        reference_bound=5.6e-17,
        reference_source="mpmath 50 digits",
        reference_condition=0.82,
    ),
    # Fig. 7(d)'s alpha = 200, beta = 1e-3, undamped: the most contacts at this alpha (68 over
    # omega t = 43, each ~0.1 long; fewer than the "about a hundred"). The long last
    # contact of Fig. 7(d) needs its dashpot (xi = 0.3: 22 contacts, the last one 36 long).
    Scene(
        "many",
        "many contacts: alpha = 200, beta = 1e-3",
        200.0,
        beta=1e-3,
        reference_cor=0.9954729953128181,
        reference_contacts=68,
        reference_bound=5.6e-17,
        reference_source="mpmath 50 digits",
        reference_condition=0.63,
    ),
    # xi = 1 exactly: the free phase is critically damped (a double eigenvalue, no eigenbasis).
    # alpha = 3 is in the multiple-contact range of Fig. 7(b): 7 contacts.
    Scene(
        "xi1",
        "critical dashpot xi = 1, beta = 1e-3",
        3.0,
        beta=1e-3,
        xi=1.0,
        reference_cor=0.20984782963703066,
        reference_contacts=7,
        reference_bound=1.4e-17,
        reference_source="mpmath 50 digits",
        reference_condition=1.8,
    ),
    # Overdamped, yet 12 contacts at alpha = 3 (Fig. 7(a): minima persist for xi > 1).
    Scene(
        "xi3",
        "overdamped dashpot xi = 3, beta = 1e-3",
        3.0,
        beta=1e-3,
        xi=3.0,
        reference_cor=0.05666619272174521,
        reference_contacts=12,
        reference_bound=3.5e-18,
        reference_source="mpmath 50 digits",
        reference_condition=0.045,
    ),
    # 64 state variables. alpha = 0.1 puts the rear mass (N - 1) alpha = 3.1 in the
    # multiple-contact range of Fig. 6(b) (8 contacts) while a scipy reference stays affordable.
    Scene(
        "chain32",
        "N = 32 chain, alpha = 0.1, beta = 1e-3",
        0.1,
        beta=1e-3,
        n_masses=32,
        reference_cor=0.743662336970728,
        reference_contacts=8,
        reference_bound=1.0e-12,
        reference_source="scipy DOP853 per phase, rtol 1e-13, max_step 1/125 period",
    ),
    # Plastic contact, eta = 0.5, DR = 0.3, beta = 0.01 (Fig. 4(c)), alpha = 5: 5 contacts, of
    # which the 2nd and 3rd load 1.64 and 1.73 times deeper than the 1st (reloads past the
    # earlier maximum, continuing on the power law; tests/test_hard.py checks it).
    Scene(
        "plastic",
        "plastic contact eta = 0.5 reloading past its maximum",
        5.0,
        beta=1e-2,
        law={"contact": "plastic", "eta": 0.5, "dr": 0.3},
        reference_cor=0.8544527913387966,
        reference_contacts=5,
        reference_bound=1.2e-16,
        reference_source="benchmarks/mp_nonlinear.py (mpmath Taylor series), 30 and 40 digits",
    ),
    # Scissor spring of Fig. 5(b) (beta = 1, ks = k1/100), alpha = 1, L = 54: the peak
    # compression is 1.01 times the lock extension x_lock (where the slope vanishes and the
    # corner pads take over; reference_values.py prints the ratio). 2 contacts.
    Scene(
        "scissor",
        "scissor spring near its lock angle",
        1.0,
        beta=1.0,
        law={"structure": "scissor", "ks_ratio": 0.01, "L": 54.0},
        reference_cor=0.9997647062625835,
        reference_contacts=2,
        reference_bound=5.6e-17,
        reference_source="restitution.solvers.precise_scissor (mpmath Taylor series), 30/40 digits",
    ),
    # Tiny mass ratio: m2 vibrates 30 times faster than m1 bounces on the contact spring
    # (beta = 1e-3, so every method applies); one contact, 1 - COR = 1.4e-12.
    Scene(
        "tiny",
        "tiny mass ratio alpha = 1e-6",
        1e-6,
        beta=1e-3,
        reference_cor=0.9999999999986209,
        reference_contacts=1,
        reference_bound=5.6e-17,
        reference_source="mpmath 50 digits",
        reference_condition=4.2e-11,
    ),
)

_BY_NAME = {s.name: s for s in SCENES}


def scene(name: str) -> Scene:
    """The scene called ``name``; KeyError listing the names otherwise."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise KeyError(f"no scene {name!r}; known: {', '.join(_BY_NAME)}") from None


__all__ = ["SCENES", "Scene", "scene"]
