"""Compile every kernel once, so that later first calls load it from numba's cache.

``restitution warmup`` (and ``make env``, which runs it) calls each entry point on one small
scene of every kind the solvers dispatch to, in a fixed order, and reports the seconds each took:
with a cold cache that is the kernel's compile time (what a user's first call of that kind would
wait), with a warm one the time to load it. The cache is the one every entry point shares
(``restitution.kernels.compiling``).
"""

from __future__ import annotations

import time
from collections.abc import Callable


def _steps() -> list[tuple[str, Callable[[], object]]]:
    import pandas as pd

    import restitution as r

    chain = {"masses": [1.0, 0.5, 2.0], "springs": [0.3, 1.2]}
    general = pd.DataFrame({"masses": [chain["masses"]] * 2, "springs": [chain["springs"]] * 2})
    return [
        ("two masses, rigid wall (impulsive)", lambda: r.solve(alpha=2.0)),
        ("paper chain, contact spring (piecewise)", lambda: r.solve(alpha=2.0, beta=0.1)),
        ("general linear chain", lambda: r.solve(**chain, k_contact=50.0)),
        ("table: two masses, rigid wall", lambda: r.solve_many(pd.DataFrame({"alpha": [1.0]}))),
        (
            "table: paper chains",
            lambda: r.solve_many(pd.DataFrame({"alpha": [1.0], "beta": [0.1], "n_masses": [3]})),
        ),
        ("table: general chains", lambda: r.solve_many(general)),
        ("trajectory, paper chain", lambda: r.trajectory(alpha=2.0, beta=0.1, times=[0.5])),
        ("trajectory, general chain", lambda: r.trajectory(**chain, times=[0.5])),
        (
            "Kelvin-Voigt contact (piecewise)",
            lambda: r.solve(**chain, contact={"law": "kelvin_voigt", "k": 50.0, "c": 0.5}),
        ),
        (
            "plastic contact (adaptive)",
            lambda: r.solve(alpha=2.0, beta=0.1, contact="plastic", eta=1.5, dr=0.3),
        ),
        (
            "Hertz contact, chain (adaptive)",
            lambda: r.solve(**chain, contact={"law": "hertz", "k": 50.0}),
        ),
        ("Verlet", lambda: r.solve(alpha=2.0, beta=0.1, method="verlet")),
        (
            "trajectory, Hertz contact (adaptive sampler)",
            lambda: r.trajectory(**chain, contact={"law": "hertz", "k": 50.0}, times=[0.5]),
        ),
    ]


def warmup(report: Callable[[str, float], None] | None = None) -> list[tuple[str, float]]:
    """Run every step (see the module docstring); ``report(label, seconds)`` after each.
    Returns the (label, seconds) of every step."""
    times = []
    for label, step in _steps():
        t0 = time.perf_counter()
        step()
        times.append((label, time.perf_counter() - t0))
        if report is not None:
            report(*times[-1])
    return times


__all__ = ["warmup"]
