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


#: Relative scalings d of every dashpot tried, in turn, around a scene flagged
#: FLAG_NEAR_DEFECTIVE (``bracketed``): the first that leaves the four rows at 1 -+ d and
#: 1 -+ 2 d sound and alike is used. The basis's condition falls like 1 / d (8e7 -> 1e2 on the
#: paper chain at alpha = 1e8, xi = 1, d = 1e-5), the mean's error grows like d^2.
DEFECT_STEPS = (1e-5, 1e-4, 1e-6, 1e-3)


def _flags(out) -> int:
    f = float(out[L.OUT_FLAGS])
    return int(f) if f == f else 0


def _alike(rows) -> bool:
    """Every row finished ok, none near-defective itself, all with the same contacts."""
    first = rows[0]
    return all(
        r[L.OUT_STATUS] == L.STATUS_OK
        and not _flags(r) & L.FLAG_NEAR_DEFECTIVE
        and r[L.OUT_NCOL] == first[L.OUT_NCOL]
        and r[L.OUT_NEVENTS] == first[L.OUT_NEVENTS]
        for r in rows
    )


def bracketed(row_at, out: np.ndarray, hist: np.ndarray) -> np.ndarray:
    """The row ``out`` of a scene, or where the kernel flagged it FLAG_NEAR_DEFECTIVE (a damped
    mode next to critical damping, whose eigenbasis degenerates: a loose estimate, or
    ill_conditioned) ``off_critical`` from rows with every dashpot scaled off that point."""
    if not _flags(out) & L.FLAG_NEAR_DEFECTIVE:
        return out
    return off_critical(row_at, out, hist)


def off_critical(row_at, out: np.ndarray, hist: np.ndarray, steps=DEFECT_STEPS) -> np.ndarray:
    """The row of a scene next to critical damping, extrapolated from rows with every dashpot
    scaled off that point (``out``: the scene's own row, kept where that fails).

    ``row_at(s, h)`` is the scene's kernel row with its dashpots times 1 + s (history into h).
    The COR is smooth in the damping there (only the basis is singular), so the mean m(d) of
    the rows at 1 - d and 1 + d is off by f'' d^2 / 2 + O(d^4) (the odd terms cancel), and
    (4 m(d) - m(2 d)) / 3 by O(d^4). The estimate is m(2 d) - m(d) (three times m(d)'s leading
    error) plus 5/3 of the rows' largest own estimate (the weights' sum of moduli). Every number
    of the row (COR, duration, energies, which still add up to 1, history entries) is combined
    alike; flagged FLAG_CRITICAL_BRACKET. Used only where the four rows finished ok, none
    near-defective, with the same contacts (else the next d of ``steps``), and where the
    result beats the row's own estimate (or the row did not finish); else ``out`` unchanged."""
    done = out[L.OUT_STATUS] == L.STATUS_OK
    for d in steps:
        hs = [np.zeros_like(hist) for _ in range(4)]
        rows = [row_at(-d, hs[0]), row_at(d, hs[1])]
        if not _alike(rows):
            continue
        rows += [row_at(-2.0 * d, hs[2]), row_at(2.0 * d, hs[3])]
        if not _alike(rows):
            continue
        near = 0.5 * (rows[0] + rows[1])
        far = 0.5 * (rows[2] + rows[3])
        new = rows[0].copy()
        for f in (L.OUT_COR, L.OUT_TCOL, L.OUT_ETRANS, L.OUT_EVIB, L.OUT_EDISS):
            new[f] = (4.0 * near[f] - far[f]) / 3.0
        own = max(r[L.OUT_ERR] for r in rows)
        new[L.OUT_ERR] = abs(far[L.OUT_COR] - near[L.OUT_COR]) + 5.0 / 3.0 * own
        if done and not new[L.OUT_ERR] < out[L.OUT_ERR]:
            return out
        new[L.OUT_FLAGS] = _flags(rows[0]) | _flags(rows[1]) | L.FLAG_CRITICAL_BRACKET
        n = min(int(new[L.OUT_NEVENTS]), hist.shape[0])
        hist[:n] = (2.0 * (hs[0][:n] + hs[1][:n]) - 0.5 * (hs[2][:n] + hs[3][:n])) / 3.0
        return new
    return out


def kv_row(ch: Chain, max_events: int, hist: np.ndarray):
    """Kernel row of a Kelvin-Voigt chain (``kelvin_voigt``): ``exact_chain.solve_chain_kv``
    with the contact's k and c in kernel units as the numerical methods pack them
    (``laws.pack_chain``), from the chain's initial state if it has one (``bracketed``: next to
    critical damping, its link and contact dashpots scaled together)."""
    from restitution.solvers.numerical import packed

    m, k, c, _ = ch.scaled()
    cp = packed(ch, numerical=False)[3]  # (exact: the numerical ranges do not apply)
    kc, cc = float(cp[2]), float(cp[3])
    y0 = ch.initial_state(ch.v0 / ch.omega, ch.v0)
    out = _kv_kernel(m, k, c, kc, cc, y0, max_events, hist)
    return bracketed(
        lambda s, h: _kv_kernel(m, k, c * (1.0 + s), kc, cc * (1.0 + s), y0, max_events, h),
        out,
        hist,
    )


def _kv_kernel(m, k, c, kc, cc, y0, max_events, hist):
    from restitution.kernels.exact_chain import solve_chain_kv, solve_chain_kv_state

    if y0 is not None:
        announce(solve_chain_kv_state)
        with blas.one_thread(m.size):
            return solve_chain_kv_state(m, k, c, kc, cc, y0, max_events, hist)
    announce(solve_chain_kv)
    with blas.one_thread(m.size):
        return solve_chain_kv(m, k, c, kc, cc, max_events, hist)


def exact_row(ch: Chain, max_events: int, hist: np.ndarray, check: bool = True):
    """Kernel row of a linear chain, on the kernel ``linear_kernel`` names (a Kelvin-Voigt
    chain: ``kv_row``). ``check=False``: a general chain from the uniform approach is run
    once, without the replica check (``solve_chain``'s search row); every other row is
    checked."""
    if ch.contact is not None:
        return kv_row(ch, max_events, hist)
    paper = ch.paper_form
    if paper is not None:
        return paper_row(*paper, max_events, hist)
    m, k, c, kc = ch.scaled()
    y0 = ch.initial_state(ch.v0 / ch.omega, ch.v0)  # (the kernels' units: V0 / omega, V0)
    if not check:
        return _chain_kernel(m, k, c, kc, y0, max_events, hist, False)
    out = _chain_kernel(m, k, c, kc, y0, max_events, hist)
    return bracketed(
        lambda s, h: _chain_kernel(m, k, c * (1.0 + s), kc, y0, max_events, h), out, hist
    )


def _chain_kernel(m, k, c, kc, y0, max_events, hist, check=True):
    """Row of the general kernel (from the state y0, if given, which is always checked)."""
    from restitution.kernels.exact_chain import solve_chain, solve_chain_state

    if y0 is not None:  # a given initial state: the general kernel from it (paper_form is None)
        announce(solve_chain_state)
        with blas.one_thread(m.size):
            return solve_chain_state(m, k, c, kc, y0, max_events, hist)
    announce(solve_chain)
    with blas.one_thread(m.size):
        return solve_chain(m, k, c, kc, max_events, hist, check)


def paper_row(alpha: float, beta: float, xi: float, n: int, max_events: int, hist):
    """``run_paper``, ``bracketed`` in xi next to critical damping."""
    out = run_paper(alpha, beta, xi, n, max_events, hist)
    if not _flags(out) & L.FLAG_NEAR_DEFECTIVE:  # (the common case: no closure, timed per call)
        return out
    return off_critical(
        lambda s, h: run_paper(alpha, beta, xi * (1.0 + s), n, max_events, h), out, hist
    )


def near_defective(ch: Chain, max_events: int) -> bool:
    """True where the exact kernel flags a phase of the linear chain ``ch`` FLAG_NEAR_DEFECTIVE
    (a damped mode next to critical damping): a row is then extrapolated (``bracketed``), but a
    sample of the motion from that basis is only as good as its condition."""
    if ch.contact is not None:
        return False  # (a Kelvin-Voigt chain: the trajectory integrates it anyway)
    if not ch.dashpots.any():
        return False  # no damping, no critically damped mode (and no run of the kernel)
    # the general kernel without its replica check (a third of the paper kernel's checked row
    # on 64 masses); the models, and so the flag, are the same
    m, k, c, kc = ch.scaled()
    y0 = ch.initial_state(ch.v0 / ch.omega, ch.v0)
    out = _chain_kernel(m, k, c, kc, y0, max_events, np.zeros((0, L.N_HIST)), False)
    return bool(_flags(out) & L.FLAG_NEAR_DEFECTIVE)


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
    if out is None:
        return np.full((0, L.N_OUT), np.nan), errors
    _rebracket(
        out,
        lambda j, s, h: run_paper(alpha[j], beta[j], xi[j] * (1.0 + s), nm[j], max_events, h),
    )
    return out, errors


def _rebracket(out: np.ndarray, row_at) -> None:
    """``bracketed`` for the rows of a block that the kernel flagged near-defective, in place
    (``row_at(j, s, h)``: row j's kernel row with its dashpots times 1 + s)."""
    flags = np.nan_to_num(out[:, L.OUT_FLAGS], nan=0.0).astype(np.int64)
    for j in np.flatnonzero(flags & L.FLAG_NEAR_DEFECTIVE):
        out[j] = off_critical(lambda s, h, j=j: row_at(j, s, h), out[j], NO_HIST)


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
    out, errors = guarded(solve_chain_batch, args, np.arange(len(n)), single)
    if check:

        def row_at(j, s, h):
            a, b = np.ascontiguousarray, n[j]
            cs = a(c[j, : b - 1]) * (1.0 + s)
            return solve_chain(a(m[j, :b]), a(k[j, : b - 1]), cs, kc[j], max_events, h)

        _rebracket(out, row_at)
    return out, errors


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
