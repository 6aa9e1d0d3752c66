"""Solving chains given in scaled units (m_1 = 1, omega = 1; ``k_contact = inf``: rigid wall),
the units of the design study (restitution.analysis.design) and of the grazing map
(restitution.analysis.cormap):
the one place where they call the solver.

Paper scenes (every two-mass chain, the uniform chain of Fig. 6) go through the paper form
``restitution.solve(alpha=..., ...)`` (its fast path, bit for bit the paper's results), all others
through the general form ``restitution.solve(masses=..., springs=..., k_contact=...)``.
"""

from __future__ import annotations

import math

import pandas as pd

from restitution.api import solve, solve_many


def paper_form(masses, springs, k_contact):
    """(alpha, beta, n_masses) if the scaled chain is a paper scene (m = [1, a, .., a], equal
    springs k = a/(1 + a)), else None."""
    m, k = masses, springs
    uniform = m[0] == 1.0 and all(x == m[1] for x in m[1:]) and all(x == k[0] for x in k)
    if uniform and abs(k[0] - m[1] / (1.0 + m[1])) <= 1e-14 * k[0]:  # omega = 1
        beta = 0.0 if math.isinf(k_contact) else k[0] / k_contact
        return m[1], beta, len(m)
    return None


def solve_scaled(masses, springs, k_contact, *, history=False, max_events=100_000):
    """The Result of one chain in scaled units."""
    m = [float(x) for x in masses]
    k = [float(x) for x in springs]
    paper = paper_form(m, k, k_contact)
    if paper is not None:
        alpha, beta, n = paper
        return solve(alpha=alpha, beta=beta, n_masses=n, history=history, max_events=max_events)
    return solve(masses=m, springs=k, k_contact=k_contact, history=history, max_events=max_events)


def solve_scaled_many(chains, max_events=100_000):
    """COR and success (status ok) of many scaled chains ``[(masses, springs, k_contact), ...]``
    in one call to ``solve_many`` (the paper form when every chain is a paper scene)."""
    forms = [paper_form([float(x) for x in m], [float(x) for x in k], kc) for m, k, kc in chains]
    if all(f is not None for f in forms):
        frame = pd.DataFrame(forms, columns=["alpha", "beta", "n_masses"])
    else:
        frame = pd.DataFrame(
            {
                "masses": [list(map(float, c[0])) for c in chains],
                "springs": [list(map(float, c[1])) for c in chains],
                "k_contact": [float(c[2]) for c in chains],
            }
        )
    res = solve_many(frame, max_events=max_events)
    return res["cor"].to_numpy(), (res["status"] == "ok").to_numpy()


__all__ = ["paper_form", "solve_scaled", "solve_scaled_many"]
