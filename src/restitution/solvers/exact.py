"""Runners of the exact methods (``impulsive``, ``piecewise``): one scene or a block of rows.

A Kelvin-Voigt contact (``kelvin_voigt``: a spring with a dashpot in parallel) on linear links
is piecewise linear too: ``kernels.exact_chain`` solves it (``solve_chain_kv``), row by row.

Which kernel solves a linear chain is decided here and nowhere else (``linear_kernel``): the
paper's two-mass rigid-wall scenes by the closed form ``kernels.rigid2``, the paper's other scenes
(equal masses m_2..m_N, equal springs, a dashpot on the first link) by ``kernels.paper_chain``, bit
for bit the paper's results, and every other linear chain by ``kernels.exact_chain``. A contact
stiffer than the kernels' rigid limit comes back flagged ``FLAG_RIGID_LIMIT`` with its error bound.

Kernel rows follow ``restitution.kernels.layout``; times are omega * t.
"""

from __future__ import annotations

import numpy as np

from restitution.kernels import layout as L
from restitution.kernels.compiling import announce
from restitution.model.chain import Chain
from restitution.solvers import blas

NO_HIST = np.zeros((0, L.N_HIST))  # kernels write no history rows into it

# Kernels of linear chains (see the module docstring), imported on first use so that ``import
# restitution`` stays cheap for the CLI's --help and snakemake.
RIGID2, PAPER, GENERAL = "rigid2", "paper_chain", "exact_chain"


def linear_kernel(paper_form: tuple | None) -> str:
    """The kernel of a linear chain: its paper form (alpha, beta, xi, n_masses) or None."""
    if paper_form is None:
        return GENERAL
    return RIGID2 if paper_form[1] == 0.0 and paper_form[3] == 2 else PAPER


def paper_kernels():
    """(rigid2, rigid2_batch, solve_linear, solve_linear_batch), imported on first use."""
    global _PAPER_KERNELS
    if _PAPER_KERNELS is None:
        from restitution.kernels.paper_chain import solve_linear, solve_linear_batch
        from restitution.kernels.rigid2 import rigid2, rigid2_batch

        _PAPER_KERNELS = rigid2, rigid2_batch, solve_linear, solve_linear_batch
    return _PAPER_KERNELS


_PAPER_KERNELS = None


def run_paper(alpha: float, beta: float, xi: float, n: int, max_events: int, hist) -> np.ndarray:
    """Kernel row of a paper scene whose values are already checked (the per-call overhead
    matters for sweeps written as loops: no Chain is built)."""
    rigid2, _, solve_linear, _ = paper_kernels()
    if linear_kernel((alpha, beta, xi, n)) == RIGID2:
        announce(rigid2)
        return rigid2(alpha, xi, max_events, hist)
    announce(solve_linear)
    if n < blas.SMALL_N:  # (no context manager: this path is timed per call)
        return solve_linear(alpha, beta, xi, n, max_events, hist)
    with blas.one_thread():
        return solve_linear(alpha, beta, xi, n, max_events, hist)


def kelvin_voigt(ch: Chain) -> bool:
    """A Kelvin-Voigt contact on linear links: the exact chain kernel's piecewise-linear
    contact (``kv_row``)."""
    return ch.kelvin_voigt


#: A link of two masses damped within this (relative) of critical, |xi - 1|, has a free mode too
#: close to defective for the modal closed form of the flight inside a Kelvin-Voigt penetration
#: (at xi = 1 exactly its eigenbasis is singular: ill_conditioned, and so was `precise`); its
#: error estimate grows like 2e-18 / |xi - 1| (2e-10 at 1e-8). Such a scene is solved at
#: xi = 1 -+ XI_BRACKET and interpolated linearly (``_critical_kv``).
XI_BRACKET = 1e-8


def kv_row(ch: Chain, max_events: int, hist: np.ndarray):
    """Kernel row of a Kelvin-Voigt chain (``kelvin_voigt``): ``exact_chain.solve_chain_kv``
    with the contact's k and c in kernel units as the numerical methods pack them
    (``laws.pack_chain``), from the chain's initial state if it has one; two masses whose link
    is damped within XI_BRACKET of critical by ``_critical_kv``."""
    from restitution.solvers.numerical import packed

    m, k, c, _ = ch.scaled()
    cp = packed(ch, numerical=False)[3]  # (exact: the numerical ranges do not apply)
    kc, cc = float(cp[2]), float(cp[3])
    y0 = ch.initial_state(ch.v0 / ch.omega, ch.v0)
    if m.size == 2 and abs(c[0] / (2.0 * k[0]) - 1.0) < XI_BRACKET:
        return _critical_kv(m, k, c, kc, cc, y0, max_events, hist)
    return _kv_kernel(m, k, c, kc, cc, y0, max_events, hist)


def _kv_kernel(m, k, c, kc, cc, y0, max_events, hist):
    from restitution.kernels.exact_chain import solve_chain_kv, solve_chain_kv_state

    if y0 is not None:
        announce(solve_chain_kv_state)
        with blas.one_thread(m.size):
            return solve_chain_kv_state(m, k, c, kc, cc, y0, max_events, hist)
    announce(solve_chain_kv)
    with blas.one_thread(m.size):
        return solve_chain_kv(m, k, c, kc, cc, max_events, hist)


def _critical_kv(m, k, c, kc, cc, y0, max_events, hist):
    """A two-mass Kelvin-Voigt row whose link is (nearly) critically damped: the rows at
    xi = 1 -+ XI_BRACKET, interpolated linearly to the scene's xi (the COR, the contact
    duration, the energies and every history entry; the energy fractions still add up to 1).
    Its estimate is the two rows' COR difference (first order in XI_BRACKET, the
    interpolation's error is second order) plus the larger of their estimates; flagged
    FLAG_CRITICAL_BRACKET. Where the two rows differ in status or contacts, the kernel's own
    row at the scene's xi."""
    xi = c[0] / (2.0 * k[0])
    rows = []
    for side in (-1.0, 1.0):
        cs = c.copy()
        cs[0] = 2.0 * k[0] * (1.0 + side * XI_BRACKET)
        h = np.zeros_like(hist)
        rows.append((_kv_kernel(m, k, cs, kc, cc, y0, max_events, h), h))
    (lo, hlo), (hi, hhi) = rows
    same = (
        all(lo[f] == hi[f] for f in (L.OUT_STATUS, L.OUT_NCOL, L.OUT_NEVENTS))
        and lo[L.OUT_STATUS] == L.STATUS_OK
    )
    if not same:
        return _kv_kernel(m, k, c, kc, cc, y0, max_events, hist)
    w = (xi - (1.0 - XI_BRACKET)) / (2.0 * XI_BRACKET)  # weight of the upper row
    out = lo.copy()
    for f in (L.OUT_COR, L.OUT_TCOL, L.OUT_ETRANS, L.OUT_EVIB, L.OUT_EDISS):
        out[f] = (1.0 - w) * lo[f] + w * hi[f]
    out[L.OUT_ERR] = abs(hi[L.OUT_COR] - lo[L.OUT_COR]) + max(lo[L.OUT_ERR], hi[L.OUT_ERR])
    out[L.OUT_FLAGS] = int(lo[L.OUT_FLAGS]) | int(hi[L.OUT_FLAGS]) | L.FLAG_CRITICAL_BRACKET
    n = min(int(out[L.OUT_NEVENTS]), hist.shape[0])
    hist[:n] = (1.0 - w) * hlo[:n] + w * hhi[:n]
    return out


def exact_row(ch: Chain, max_events: int, hist: np.ndarray, check: bool = True):
    """Kernel row of a linear chain, on the kernel ``linear_kernel`` names (a Kelvin-Voigt
    chain: ``kv_row``). ``check=False``: a general chain from the uniform approach is run
    once, without the replica check (``solve_chain``'s search row); every other row is
    checked."""
    if ch.contact is not None:
        return kv_row(ch, max_events, hist)
    paper = ch.paper_form
    if paper is not None:
        return run_paper(*paper, max_events, hist)
    from restitution.kernels.exact_chain import solve_chain, solve_chain_state

    m, k, c, kc = ch.scaled()
    y0 = ch.initial_state(ch.v0 / ch.omega, ch.v0)  # (the kernels' units: V0 / omega, V0)
    if y0 is not None:  # a given initial state: the general kernel from it (paper_form is None)
        announce(solve_chain_state)
        with blas.one_thread(ch.n_masses):
            return solve_chain_state(m, k, c, kc, y0, max_events, hist)
    announce(solve_chain)
    with blas.one_thread(ch.n_masses):
        return solve_chain(m, k, c, kc, max_events, hist, check)


def run(ch: Chain, opts) -> tuple:
    """The single runner of the exact methods: (kernel row, history or None)."""
    hist = np.zeros((opts.max_events if opts.history else 0, L.N_HIST))
    out = exact_row(ch, opts.max_events, hist)
    return out, (hist if opts.history else None)


# ----------------------------------------------------------------------------------------------
# Blocks of table rows
# ----------------------------------------------------------------------------------------------
def guarded(batch, args, sel, single, uses_blas=True):
    """``batch(*args)`` (announcing a compilation if it is cold); if the kernel raises, run the
    block row by row so that only the failing rows are lost (NaN with status ``kernel_error``),
    never an uninitialised row."""
    announce(batch)
    try:
        if not uses_blas:  # (the limit costs 10-20 us: a tenth of a 100-row table's kernel)
            return batch(*args), None
        with blas.one_thread():  # numba's parallel rows must not each start BLAS threads
            return batch(*args), None
    except Exception:  # noqa: BLE001 - a kernel failure must not lose the whole table
        out = np.full((len(sel), L.N_OUT), np.nan)
        errors = {}
        for j in range(len(sel)):
            try:
                out[j] = single(j)
            except Exception as e:  # noqa: BLE001
                errors[j] = f"kernel_error ({type(e).__name__}: {e})"
        return out, errors


def _paper_rows(table, idx: np.ndarray, max_events: int, bar, block: int):
    """Kernel rows of paper-form rows, in parallel blocks (the progress bar moves per block)."""
    plan = table.plan
    rigid2, rigid2_batch, solve_linear, solve_linear_batch = paper_kernels()
    every = len(idx) == len(plan["alpha"])  # all rows, in order (idx is sorted): no copies
    pick = (lambda a: a) if every else (lambda a: a[idx])
    alpha = pick(plan["alpha"].astype(np.float64, copy=False))
    beta = pick(plan["beta"].astype(np.float64, copy=False))
    xi = pick(plan["xi"].astype(np.float64, copy=False))
    nm = pick(plan["n_masses"].astype(np.int64, copy=False))
    out = None  # allocated unless one block covers every row
    errors = {}
    fast = (beta == 0.0) & (nm == 2)  # linear_kernel's RIGID2 rows, column-wise
    for group, is_fast in ((np.flatnonzero(fast), True), (np.flatnonzero(~fast), False)):
        for start in range(0, len(group), block):
            sel = group[start : start + block]
            whole = len(sel) == len(idx)
            if is_fast:
                done, err = guarded(
                    rigid2_batch,
                    (alpha, xi, max_events) if whole else (alpha[sel], xi[sel], max_events),
                    sel,
                    lambda j, s=sel: rigid2(alpha[s[j]], xi[s[j]], max_events, NO_HIST),
                    uses_blas=False,  # closed form, no linear algebra
                )
            else:
                done, err = guarded(
                    solve_linear_batch,
                    (alpha[sel], beta[sel], xi[sel], nm[sel], max_events),
                    sel,
                    lambda j, s=sel: solve_linear(
                        alpha[s[j]], beta[s[j]], xi[s[j]], nm[s[j]], max_events, NO_HIST
                    ),
                )
            if whole and done.shape[1] == L.N_OUT:
                out = done  # one block of every row, in order: no copy
            else:
                if out is None:
                    out = np.full((len(idx), L.N_OUT), np.nan)
                out[sel, : done.shape[1]] = done
            if err:
                errors.update({int(sel[j]): msg for j, msg in err.items()})
            bar.update(len(sel))
    return (np.full((0, L.N_OUT), np.nan) if out is None else out), errors


def _general_rows(table, idx: np.ndarray, max_events: int, bar, block: int):
    """Kernel rows of general linear chains (padded batch of restitution.kernels.exact_chain)."""
    out = np.full((len(idx), L.N_OUT), np.nan)
    errors = {}
    for start in range(0, len(idx), block):
        sel = np.arange(start, min(start + block, len(idx)))
        done, err = general_block(*table.scaled(idx[sel]), max_events)
        out[sel, : done.shape[1]] = done
        if err:
            errors.update({int(sel[j]): msg for j, msg in err.items()})
        bar.update(len(sel))
    return out, errors


def general_block(m, k, c, n, kc, max_events: int, check: bool = True):
    """Kernel rows (and {row: error message}) of one block of general linear chains in the
    kernels' units, padded (``SceneTable.scaled``): one parallel batch call (``guarded``).
    ``check=False``: an optimiser's unchecked search rows (``solve_chain_batch``)."""
    from restitution.kernels.exact_chain import solve_chain, solve_chain_batch

    def single(j):
        a, b = np.ascontiguousarray, n[j]
        return solve_chain(
            a(m[j, :b]), a(k[j, : b - 1]), a(c[j, : b - 1]), kc[j], max_events, NO_HIST
        )

    args = (m, k, c, n, kc, max_events, check)
    return guarded(solve_chain_batch, args, np.arange(len(n)), single)


def _initial_rows(table, idx: np.ndarray, max_events: int, bar, block: int):
    """Kernel rows of chains with a given initial state or a Kelvin-Voigt contact, one by one
    (``exact_row``; the batch kernel starts from the uniform approach at a linear contact)."""
    out = np.full((len(idx), L.N_OUT), np.nan)
    errors = {}
    for j, i in enumerate(idx):
        try:
            out[j] = exact_row(table.chains[int(i)], max_events, NO_HIST)
        except Exception as e:  # noqa: BLE001 - a kernel failure must not lose the table
            errors[j] = f"kernel_error ({type(e).__name__}: {e})"
        bar.update(1)
    return out, errors


def run_many(table, idx: np.ndarray, max_events: int, bar, block: int):
    """The batch runner of the exact methods: kernel rows of the table rows ``idx`` (sorted)
    and {position in idx: error message} of rows whose kernel raised."""
    if table.chains is None:
        return _paper_rows(table, idx, max_events, bar, block)
    # chains with a given initial state, or a Kelvin-Voigt contact: one by one (exact_row)
    initial = np.array(
        [table.chains[int(i)].initial or table.chains[int(i)].contact is not None for i in idx],
        dtype=bool,
    )
    paper = table.plan["paper"][idx] & ~initial  # (a KV chain may have the paper's form)
    out = np.full((len(idx), L.N_OUT), np.nan)
    errors = {}
    for part, rows in (
        (idx[paper], _paper_rows),
        (idx[~paper & ~initial], _general_rows),
        (idx[initial], _initial_rows),
    ):
        if len(part) == 0:
            continue
        o, e = rows(table, part, max_events, bar, block)
        where = np.searchsorted(idx, part)  # positions in idx (both sorted)
        out[where] = o
        errors.update({int(where[j]): msg for j, msg in e.items()})
    return out, errors
