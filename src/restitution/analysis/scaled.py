"""Solving chains given in scaled units (m_1 = 1, omega = 1; ``k_contact = inf``: rigid wall),
the units of the design study (restitution.analysis.design) and of the grazing map
(restitution.analysis.cormap):
the one place where they call the solver.

Paper scenes (every two-mass chain, the uniform chain of Fig. 6) go through the paper form
``restitution.solve(alpha=..., ...)`` (its fast path, bit for bit the paper's results), all others
through the general form ``restitution.solve(masses=..., springs=..., k_contact=...)``. Batches of
one chain length given as arrays (``solve_scaled_arrays``, the design searches' populations) skip
the table and its Chains where they can, with the same results bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from restitution.api import solve, solve_many
from restitution.kernels.constants import MAX_EVENTS_DEFAULT


def paper_form(masses, springs, k_contact):
    """(alpha, beta, n_masses) if the scaled chain is a paper scene (m = [1, a, .., a], equal
    springs k = a/(1 + a)), else None."""
    m, k = masses, springs
    uniform = m[0] == 1.0 and all(x == m[1] for x in m[1:]) and all(x == k[0] for x in k)
    if uniform and abs(k[0] - m[1] / (1.0 + m[1])) <= 1e-14 * k[0]:  # omega = 1
        beta = 0.0 if math.isinf(k_contact) else k[0] / k_contact
        return m[1], beta, len(m)
    return None


def solve_scaled(masses, springs, k_contact, *, history=False, max_events=MAX_EVENTS_DEFAULT):
    """The Result of one chain in scaled units."""
    m = [float(x) for x in masses]
    k = [float(x) for x in springs]
    paper = paper_form(m, k, k_contact)
    if paper is not None:
        alpha, beta, n = paper
        return solve(alpha=alpha, beta=beta, n_masses=n, history=history, max_events=max_events)
    return solve(masses=m, springs=k, k_contact=k_contact, history=history, max_events=max_events)


def contact_times(masses, springs, k_contact, *, max_events=MAX_EVENTS_DEFAULT, check=True):
    """(result, omega_t_start, omega_t_end): ``solve_scaled(..., history=True)``'s result and
    its history's contact times (kernel units), bit for bit, without the history's table
    (the design polish evaluates ~50,000 grazing conditions a design; the table was a fifth of
    each). A general chain's result has no ``history`` (one of the paper's form is
    ``solve_scaled``'s own, with it).

    ``check=False`` is an optimiser's evaluation, as in ``solve_scaled_arrays``: a general
    chain is run once, without the replica check (a third of the work); its contact times are
    the checked run's and, at a rigid wall, so is its COR, but ``success`` only says that the
    run finished. Not a result to report."""
    from restitution.kernels import layout as L
    from restitution.model.chain import Chain
    from restitution.solvers import methods as M
    from restitution.solvers.exact import exact_row
    from restitution.solvers.result import Result

    m = [float(x) for x in masses]
    k = [float(x) for x in springs]
    if paper_form(m, k, k_contact) is None:
        # solve's general form, step for step (the same checks and errors, the same kernel row)
        opts = M.options(True, max_events)
        ch = Chain(m, k, k_contact=k_contact)
        chosen = M.choose(ch)
        if chosen.exact and ch.paper_form is None:
            hist = np.zeros((opts.max_events, L.N_HIST))
            out = exact_row(ch, opts.max_events, hist, check)
            n = min(int(out[L.OUT_NEVENTS]), hist.shape[0])
            res = Result.from_row(ch, out, chosen.name, None, passive=True)
            return res, hist[:n, 0].copy(), hist[:n, 1].copy()
    res = solve_scaled(m, k, k_contact, history=True, max_events=max_events)
    h = res.history
    return res, h["omega_t_start"].to_numpy(), h["omega_t_end"].to_numpy()


def solve_scaled_many(chains, max_events=MAX_EVENTS_DEFAULT):
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


def solve_scaled_arrays(masses, springs, k_contact, max_events=MAX_EVENTS_DEFAULT, check=True):
    """``solve_scaled_many`` of chains of one length given as arrays: masses (S, N), springs
    (S, N - 1), k_contact (S,). The same (cor, ok), bit for bit, without DataFrames or Chains
    where that is possible (``_general_arrays``); else through ``solve_scaled_many``.

    ``check=False`` is an optimiser's objective (the design search's): where the general
    kernel takes the rows, each scene is run once, without the replica check, and ``ok`` says
    only that the run finished (a scene the check would call ill-conditioned keeps its COR).
    Not a result to report: a design found so is solved again, checked."""
    m = np.asarray(masses, dtype=np.float64)
    k = np.asarray(springs, dtype=np.float64)
    kc = np.asarray(k_contact, dtype=np.float64)
    done = _general_arrays(m, k, kc, max_events, check)
    if done is not None:
        return done
    return solve_scaled_many(list(zip(m, k, kc, strict=True)), max_events)


def _general_arrays(m, k, kc, max_events, check=True):
    """(cor, ok) as ``solve_many`` gives them for a general table of these undamped chains, or
    None where its reading would do more than the general exact kernel on every row: a row not
    plainly valid (the table's reading words its error), a row of the paper's form (its own
    kernel) or a chain whose method is not an exact one. The plan and the kernel units are
    those of ``tables.linear_rows.read`` and ``SceneTable.scaled``, operation for operation.
    (The design searches solve ~10^6 chains: the table's per-row reading cost a third of their
    kernel time.) ``check``: ``solve_scaled_arrays``'."""
    from restitution.kernels import layout as L
    from restitution.model.chain import RANGES, Chain
    from restitution.model.units import kernel_params
    from restitution.solvers import methods as M
    from restitution.solvers.exact import general_block
    from restitution.tables.linear_rows import omega_column, paper_rows, plainly_valid

    s, n = m.shape
    c = np.zeros((s, n - 1))
    if s == 0 or n < 2 or k.shape != (s, n - 1) or kc.shape != (s,):
        return None
    if not (RANGES["k_contact"].accepts(kc).all() and plainly_valid(m, k, c, kc)):
        return None
    if paper_rows(m, k, c).any():
        return None  # the paper kernel's rows
    rigid = kc == math.inf
    for kind in (rigid, ~rigid):
        if kind.any():
            i = int(np.argmax(kind))
            if not M.choose(Chain(masses=m[i], springs=k[i], k_contact=float(kc[i]))).exact:
                return None
    omega = omega_column(m, k)
    ms, ks, cs, kcs = kernel_params(m, k, c, kc[:, None], m[:, :1], omega[:, None])
    rows = np.full(s, n, dtype=np.int64)
    out, errors = general_block(ms, ks, cs, rows, kcs[:, 0], max_events, check)
    ok = out[:, L.OUT_STATUS] == L.STATUS_OK
    if errors:
        ok[list(errors)] = False
    if not ok.all():
        out = L.void_unfinished(out, passive=True)
    return out[:, L.OUT_COR], ok


__all__ = [
    "contact_times",
    "paper_form",
    "solve_scaled",
    "solve_scaled_arrays",
    "solve_scaled_many",
]
