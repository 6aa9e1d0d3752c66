"""A general scene table whose rows are all linear chains, read and checked column-wise.

Reading a general table row by row (``Chain(...)`` per row: list parsing, range and ratio
checks, then the plan from the Chain's properties) cost ~44 us per row, 15 times the exact
kernel. Most tables are plain linear chains (lists of numbers, no law columns), and for those
every check is a handful of array operations over all rows of one chain length at once.

``read`` is a screen, not a second set of rules: it accepts a table only when every cell is
plainly valid - numbers of the plain numeric types, in their ranges, every ratio inside its
``chain.RATIOS`` interval by a margin (1e-9 in log10) - and returns None otherwise, so that the
row-by-row reading (the one place that words the errors, ``tables.SceneTable``) decides every
table with a bad or borderline cell. Accepted rows give the same Chains and the same plan,
bit for bit, as the row-by-row reading (tests/test_linear_rows.py).
"""

from __future__ import annotations

import math
from itertools import chain as _concat

import numpy as np

from restitution.model.chain import RANGES, RATIOS, Chain
from restitution.model.ranges import MAX_MASSES, SceneError, missing_cell, missing_list
from restitution.solvers import methods as M

# Cell element types read as numbers (bool, str, None, complex and nested lists are not:
# the row-by-row reading words their errors).
_NUMBER = frozenset(
    {float, int, np.float64, np.float32, np.float16, np.int64, np.int32, np.int16, np.int8}
    | {np.uint64, np.uint32, np.uint16, np.uint8}
)
_MARGIN = 1e-9  # log10 units: a ratio this close to its bound goes the row-by-row way
# The general-form columns (tables.GENERAL) this reader knows: those it reads, and the law
# columns, accepted only when every cell is missing. A new general-form column must be added
# here too (tests/test_linear_rows.py checks that the two lists agree).
READS = ("masses", "springs", "dashpots", "k_contact", "v0")
# (and the initial-state columns: a table that gives one goes row by row, as a law column)
LAW_COLUMNS = ("contact", "links", "velocities", "stretches")


def read(frame, columns, kc: np.ndarray, v0: np.ndarray, method: np.ndarray):
    """(chains, plan, method_of_row, (m, k, c)) for a general table of linear chains, or None
    when any cell is not plainly valid (then the row-by-row reading decides). ``kc``, ``v0``:
    the checked k_contact and v0 columns; ``method``: the requested method per row. m, k, c:
    every row's masses, springs, dashpots, padded to the longest chain (m and k with 1, c with
    0); each Chain's arrays are views of their rows."""
    n = len(frame)
    if n == 0 or not _no_laws(frame, columns):
        return None
    masses = _cells(frame["masses"].to_numpy(dtype=object))
    springs = _cells(frame["springs"].to_numpy(dtype=object))
    if masses is None or springs is None:
        return None
    if "dashpots" in columns:
        dashpots = _cells(frame["dashpots"].to_numpy(dtype=object), missing_ok=True)
        if dashpots is None:
            return None
    else:
        dashpots = [None] * n
    nm = np.fromiter(map(len, masses), dtype=np.int64, count=n)
    if nm.min() < 2 or nm.max() > MAX_MASSES:
        return None
    chains = [None] * n
    size_max = int(nm.max())
    m_all = np.ones((n, size_max))
    k_all = np.ones((n, size_max - 1))
    c_all = np.zeros((n, size_max - 1))
    plan = {
        name: np.empty(n)
        for name in ("alpha", "beta", "xi", "omega")
    }  # fmt: skip
    plan["n_masses"] = nm
    plan["paper"] = np.zeros(n, dtype=bool)
    for size in np.unique(nm):
        rows = np.flatnonzero(nm == size)
        group = _group(rows, int(size), masses, springs, dashpots, kc[rows])
        if group is None:
            return None
        m, k, c = group
        m_all[rows, :size], k_all[rows, : size - 1], c_all[rows, : size - 1] = m, k, c
        rigid = kc[rows] == math.inf
        # the properties of Chain (alpha, omega, beta, xi, paper_form), column-wise, same ops
        omega = omega_column(m, k)
        plan["alpha"][rows] = m[:, 1] / m[:, 0]
        plan["omega"][rows] = omega
        plan["beta"][rows] = np.where(rigid, 0.0, k[:, 0] / kc[rows])
        plan["xi"][rows] = c[:, 0] * omega / (2.0 * k[:, 0])
        plan["paper"][rows] = paper_rows(m, k, c)
        for i in rows:
            m_i, k_i, c_i = m_all[i, :size], k_all[i, : size - 1], c_all[i, : size - 1]
            chains[i] = Chain._checked(m_i, k_i, c_i, float(kc[i]), float(v0[i]))
    # One dispatcher call per (rigid wall, N, requested method): the solver table decides.
    chosen = np.empty(n, dtype=object)
    key = {}
    for i in range(n):
        key.setdefault((kc[i] == math.inf, int(nm[i]), method[i]), []).append(i)
    for rows in key.values():
        try:
            chosen[rows] = M.choose(chains[rows[0]], method[rows[0]]).name
        except SceneError:
            return None  # a forced method that does not fit: worded row by row
    return chains, plan, chosen, (m_all, k_all, c_all)


def omega_column(m: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Chain.omega of every row (one chain length): sqrt(k_12/m_1 + k_12/m_2)."""
    return np.sqrt(k[:, 0] / m[:, 0] + k[:, 0] / m[:, 1])


def paper_rows(m: np.ndarray, k: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Rows of the paper's form (Chain.paper_form): equal masses m_2..m_N, equal springs, a
    dashpot on the first link only."""
    return (m[:, 1:] == m[:, 1:2]).all(axis=1) & (k == k[:, :1]).all(axis=1) & ~c[:, 1:].any(axis=1)


def _no_laws(frame, columns) -> bool:
    """No law column, or only missing law cells (linear laws everywhere)."""
    return all(
        missing_cell(v)
        for c in LAW_COLUMNS
        if c in columns
        for v in frame[c].to_numpy(dtype=object)
    )


def _cells(values: np.ndarray, missing_ok: bool = False):
    """The cells as lists of numbers (';'-text split and parsed), None for a missing cell
    (when ``missing_ok``); None for the whole column if any cell is anything else."""
    out = []
    for cell in values:
        if missing_ok and missing_list(cell):
            out.append(None)
        elif isinstance(cell, str):
            try:
                out.append([float(p) for p in cell.split(";")])
            except ValueError:
                return None
        elif isinstance(cell, (list, tuple)) or (isinstance(cell, np.ndarray) and cell.ndim == 1):
            out.append(cell)
        elif type(cell) in _NUMBER:  # one number: a one-entry list (tables.parse_list)
            out.append([cell])
        else:
            return None
    if not set(map(type, _concat.from_iterable(c for c in out if c is not None))) <= _NUMBER:
        return None
    return out


def _group(rows, size, masses, springs, dashpots, kc):
    """(m, k, c) arrays of the rows of one chain length, or None unless every value and ratio is
    plainly in range (the checks of Chain.__post_init__ and chain._check_ratios)."""
    if any(len(springs[i]) != size - 1 for i in rows):
        return None
    if any(dashpots[i] is not None and len(dashpots[i]) != size - 1 for i in rows):
        return None
    m = np.array([masses[i] for i in rows], dtype=np.float64).reshape(len(rows), size)
    k = np.array([springs[i] for i in rows], dtype=np.float64).reshape(len(rows), size - 1)
    c = np.zeros((len(rows), size - 1))
    for j, i in enumerate(rows):
        if dashpots[i] is not None:
            c[j] = dashpots[i]
    return (m, k, c) if plainly_valid(m, k, c, kc) else None


def plainly_valid(m: np.ndarray, k: np.ndarray, c: np.ndarray, kc: np.ndarray) -> bool:
    """Whether every row of the arrays (one chain length) is plainly in range: the checks of
    Chain.__post_init__ and chain._check_ratios, column-wise, with the _MARGIN."""
    for name, x in (("masses", m), ("springs", k), ("dashpots", c)):
        if not (RANGES[name].accepts(x) & np.isfinite(x)).all():
            return False
    with np.errstate(divide="ignore"):
        lm, lk, lc = np.log10(m), np.log10(k), np.log10(c)
    lw = 0.5 * (
        lk[:, 0] - lm[:, 0] + np.log10(1.0 + 10.0 ** np.minimum(lm[:, 0] - lm[:, 1], 300.0))
    )
    finite = np.isfinite(kc)
    beta = lk[finite, 0] - np.log10(kc[finite])
    damping = (lc + (lw - math.log10(2.0) - lk[:, 0])[:, None])[c > 0.0]
    for name, logs in (
        ("masses[i]/masses[0]", lm - lm[:, :1]),
        ("springs[i]/springs[0]", lk - lk[:, :1]),
        ("beta = springs[0]/k_contact", beta),
        ("damping ratio dashpots[i]*omega/(2*springs[0])", damping),
    ):
        low, high = RATIOS[name]
        if (logs > math.log10(high) - _MARGIN).any():
            return False
        if low > 0.0 and (logs < math.log10(low) + _MARGIN).any():
            return False
    return True
