"""Public entry points: ``solve`` (one scene) and ``solve_many`` (a table of scenes).

Both take either the paper's form (alpha, beta, xi, n_masses) or a general chain (masses,
springs, dashpots, k_contact, contact, links, v0; see ``restitution.Chain``), check everything
before any work, pick the method with the solver table ``restitution.solvers.methods.METHODS`` and
record
it in every result. Nonlinear laws in the paper's form (two masses) are the keywords contact,
eta, dr, structure, L, ks_ratio, theta0, corner, v0 (``restitution.model.chain.paper_with_laws``
turns them into a Chain).

pandas and the table modules are imported inside the table functions: a single ``solve`` (the
command line's ``cor``) does without them (0.3 s of imports).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from restitution.kernels.constants import MAX_EVENTS_DEFAULT

if TYPE_CHECKING:  # imported where used (a single solve needs no pandas)
    import pandas as pd

from restitution.kernels import layout as L
from restitution.model.chain import (
    LAW_KEYS,
    RANGES,
    Chain,
    SceneError,
    check,
    make_chain,
    paper_with_laws,
)
from restitution.model.ranges import HISTORY_MAX_EVENTS
from restitution.model.units import user_time
from restitution.solvers import exact
from restitution.solvers import methods as M
from restitution.solvers.result import (
    BRACKETED,
    EXTRAPOLATED,
    RESULT_COLUMNS,
    STATUS,
    T_COL,
    Result,
    status_name,
)

_BLOCK = 2048  # rows per parallel batch call; the progress bar advances per block


def _block(rows: int, progress: bool) -> int:
    """Rows per batch call: without a progress bar one call (the threads share the whole load);
    with one about 100 updates (so its ETA follows the real rate), each large enough to keep
    every thread busy. Results do not depend on it."""
    return max(64, min(_BLOCK, rows // 100)) if progress else max(rows, 1)


class _Unset:
    """The default of solve's keywords whose "not given" must be told from any value (None
    included, which their checks refuse): beta, xi, n_masses (paper form: 0, 0, 2) and
    k_contact (general form: inf)."""

    def __repr__(self) -> str:
        return "<not given>"


_UNSET = _Unset()
_UNSET_DEFAULTS = ("beta", "xi", "n_masses", "k_contact")


def solve(
    alpha: float | Chain | None = None,
    beta: float = _UNSET,
    xi: float = _UNSET,
    n_masses: int = _UNSET,
    method: str = "auto",
    *,
    masses=None,
    springs=None,
    dashpots=None,
    k_contact: float = _UNSET,
    v0: float | None = None,
    contact=None,
    links=None,
    velocities=None,
    stretches=None,
    history: bool = False,
    max_events: int = MAX_EVENTS_DEFAULT,
    **law,
) -> Result:
    """COR of one scene.

    A parameter of the other form, or any scene parameter given with a Chain (which carries its
    whole scene), is refused (SceneError), never ignored; so is a setting (rtol, step) that the
    method solving the scene does not read.

    Parameters
    ----------
    alpha : float or Chain
        Paper form: mass ratio m2/m1, in [1e-8, 1e8]. Or a ``restitution.Chain``.
    beta, xi, n_masses : float, float, int
        Paper form: stiffness ratio k2/k1 in [0, 1e6] (0: rigid wall), damping ratio of the
        dashpot between m1 and m2 in [0, 1e3], number of masses in [2, 512]; not given: 0, 0
        and 2.
    masses, springs, dashpots : sequence of float
        General form (instead of alpha...): m_1..m_N (> 0), N - 1 link stiffnesses (> 0) and
        optional N - 1 dashpot coefficients (>= 0), in any consistent units.
    k_contact : float
        General form: contact stiffness (> 0); ``math.inf`` (the default) is the rigid wall.
    v0 : float, optional
        Approach speed in [1e-6, 1e6] (default 1; only nonlinear laws depend on it).
    contact, links : mapping, sequence of mapping, optional
        Contact and per-link laws (docs/general-chains.md).
    velocities, stretches : sequence of float, optional
        General form: the initial state, N velocities (positive towards the wall; instead of
        v0) and N - 1 link extensions (positive: stretched); see ``restitution.Chain``.
    method : str
        "auto" or a name of ``restitution.solvers.methods.METHODS``; recorded in ``Result.method``.
    history : bool
        Also return one row per contact (``Result.history``).
    max_events : int
        Contact budget; a longer sequence ends with status ``event_budget_exhausted``.
    **law
        Paper form only: the nonlinear laws and numerical settings (contact, eta, dr, structure,
        L, ks_ratio,
        theta0, corner, rtol, step).

    Examples
    --------
    >>> r = solve(alpha=1.0)
    >>> round(r.cor, 12), r.n_collisions
    (1.0, 2)
    >>> r = solve(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], dashpots=[0.0, 0.05])
    """
    general = masses is not None or springs is not None
    if isinstance(alpha, Chain):
        ch, settings = alpha, {k: law.pop(k) for k in ("rtol", "step") if k in law}
        scene = _given(
            beta=beta, xi=xi, n_masses=n_masses, masses=masses, springs=springs,
            dashpots=dashpots, k_contact=k_contact, v0=v0, contact=contact, links=links,
            velocities=velocities, stretches=stretches,
        )  # fmt: skip
        if law or scene:
            raise SceneError(
                f"unknown keyword(s) {', '.join(sorted(law) + scene)} with a Chain (it carries "
                "its whole scene; with it solve takes method, history, max_events, rtol, step)"
            )
    elif general:
        mixed = _given(alpha=alpha, beta=beta, xi=xi, n_masses=n_masses)
        if mixed:
            raise SceneError(
                "give either the paper's form (alpha, beta, xi, n_masses) or a general chain "
                f"(masses, springs, ...), not both; got {', '.join(mixed)} with masses/springs"
            )
        if velocities is not None and v0 is not None:
            raise SceneError(
                "give either v0 (every mass approaching at v0) or velocities (one per mass), "
                "not both"
            )
        settings = {k: law.pop(k) for k in ("rtol", "step") if k in law}
        if law:
            raise SceneError(
                f"unknown scene parameter(s) {', '.join(sorted(law))} for a general chain; "
                "use contact={...} and links=[...] for nonlinear laws"
            )
        kc = math.inf if k_contact is _UNSET else k_contact
        ch = make_chain(masses, springs, dashpots, kc, 1.0 if v0 is None else v0,
                        contact, links, velocities, stretches)  # fmt: skip
    else:
        if alpha is None:
            raise SceneError(
                "solve needs alpha (the paper's form) or masses and springs (a general chain)"
            )
        if velocities is not None or stretches is not None:
            raise SceneError(
                "velocities=[...] and stretches=[...] need the general form (masses=..., "
                "springs=...; Chain(...) for a Chain)"
            )
        if dashpots is not None or k_contact is not _UNSET:
            mixed = _given(dashpots=dashpots, k_contact=k_contact)
            raise SceneError(
                "give either the paper's form (alpha, beta, xi, n_masses) or a general chain "
                f"(masses, springs, ...), not both; got {', '.join(mixed)} with alpha"
            )
        # the paper form's defaults (set here, so that the other forms can tell what was given)
        beta = 0.0 if beta is _UNSET else beta
        xi = 0.0 if xi is _UNSET else xi
        n_masses = 2 if n_masses is _UNSET else n_masses
        if not law and v0 is None and contact is None and links is None:
            fast = _solve_paper(alpha, beta, xi, n_masses, method, history, max_events)
            if fast is not None:
                return fast
        if isinstance(contact, str):  # the paper form's contact="plastic"
            law["contact"], contact = contact, None
        if contact is not None or links is not None:
            raise SceneError("contact={...} and links=[...] need the general form (masses=...)")
        if v0 is not None:
            law["v0"] = v0
        ch, settings = paper_with_laws(alpha, beta, xi, n_masses, law)
    opts = M.options(history, max_events, **settings)
    chosen = M.choose(ch, method)
    M.check_settings(chosen, settings)
    return _run(ch, chosen, opts)


def _given(**values) -> list:
    """The names of the keywords given, in order: not None, or for those with the default
    _UNSET (where None is a value, refused by its check) not _UNSET."""
    return [
        name
        for name, value in values.items()
        if value is not (_UNSET if name in _UNSET_DEFAULTS else None)
    ]


_R = RANGES  # the one range table, read once here for the fast path below
_A_LO, _A_HI, _B_HI, _X_HI = _R["alpha"].low, _R["alpha"].high, _R["beta"].high, _R["xi"].high
_N_HI, _E_HI = _R["n_masses"].high, _R["max_events"].high


def _solve_paper(alpha, beta, xi, n_masses, method, history, max_events):
    """The paper's linear scenes straight to their kernel (the per-call overhead matters for
    sweeps written as loops); None when a numerical method is forced."""
    if (
        type(alpha) is float
        and type(beta) is float
        and type(xi) is float
        and type(n_masses) is int
        and type(max_events) is int
        and type(history) is bool
        and _A_LO <= alpha <= _A_HI
        and 0.0 <= beta <= _B_HI
        and 0.0 <= xi <= _X_HI
        and 2 <= n_masses <= _N_HI
        and 1 <= max_events <= _E_HI
        and (not history or max_events <= HISTORY_MAX_EVENTS)
    ):  # plain Python numbers inside RANGES (NaN fails every comparison)
        a, b, x, n = alpha, beta, xi, n_masses
    else:  # anything else through the full checks (and their messages)
        a, b, x = check("alpha", alpha), check("beta", beta), check("xi", xi)
        n, max_events = check("n_masses", n_masses), M.options(history, max_events).max_events
    chosen = M.choose_paper(b, n, method)  # raises for a misfit
    if not chosen.exact:
        return None  # a numerical method forced: the general path
    hist = np.zeros((max_events, L.N_HIST)) if history else exact.NO_HIST
    out = exact.paper_row(a, b, x, n, max_events, hist)
    hist = hist if history else None
    return Result.from_row((a, b, x, n), out, chosen.name, hist, passive=True)


def _run(ch: Chain, chosen: M.Method, opts: M.Options) -> Result:
    out, hist = chosen.run(ch, opts)
    if isinstance(out, Result):  # numerical runners return a Result of ch, t_col in its units
        return out
    return Result.from_row(ch, out, chosen.name, hist, passive=True)  # exact: linear laws


# ----------------------------------------------------------------------------------------------
# Tables
# ----------------------------------------------------------------------------------------------
def validate_frame(frame: pd.DataFrame, keep=()) -> pd.DataFrame:
    """The scene table checked strictly (``restitution.tables.scene_table``), with the method of
    every row
    in column ``method``; raises SceneError naming the first bad row and column."""
    import pandas as pd

    from restitution.tables.scene_table import scene_table

    return pd.DataFrame(scene_table(frame, keep).plan, index=frame.index)


class _Labels:
    """A string result column kept as integer codes into a short list of names until the end: a
    table has few distinct statuses and methods, and 20,000 Python strings per column cost
    milliseconds to build, mask and factorise."""

    def __init__(self, codes: np.ndarray, names: list):
        self.codes, self.names = codes, list(names)
        self._index = {name: i for i, name in enumerate(self.names)}

    def code(self, name: str) -> int:
        if name not in self._index:
            self._index[name] = len(self.names)
            self.names.append(name)
        return self._index[name]

    def set(self, rows, name: str) -> None:
        self.codes[rows] = self.code(name)

    def column(self):
        """The pandas string column (from an object array on small tables, where building
        the Arrow array costs more than the strings; one repeated Arrow scalar where every row
        has the same label, 2.5 x faster than a take on 20,000 rows)."""
        import pandas as pd

        names = np.asarray(self.names, dtype=object)
        if len(self.codes) == 0:  # (pandas infers str from strings: none here)
            return pd.array([], dtype="str")
        if len(self.codes) <= 2000:
            return names[self.codes]
        if (self.codes == self.codes[0]).all():
            import pyarrow as pa

            return pd.array(
                pa.repeat(pa.scalar(names[self.codes[0]]), len(self.codes)), dtype="str"
            )
        return pd.array(names, dtype="str").take(self.codes)


def _status_codes(status: np.ndarray, labels: _Labels) -> np.ndarray:
    """Label codes of kernel status codes (NaN or unknown: not_run)."""
    table = np.array([labels.code(status_name(c)) for c in range(max(STATUS) + 1)])
    finite = np.isfinite(status)
    known = finite & (status >= 0) & (status < len(table))
    out = np.full(len(status), labels.code("not_run"), dtype=np.int64)
    out[known] = table[status[known].astype(np.int64)]
    return out


def _with_settings(frame, **settings) -> pd.DataFrame:
    """``frame`` with a column for each setting given as a keyword of ``solve_many`` (checked
    here, so the error names the keyword, not a row)."""
    import pandas as pd

    given = {name: value for name, value in settings.items() if value is not None}
    if not given:
        return frame
    if not isinstance(frame, pd.DataFrame):
        return frame  # scene_table refuses it with its own message
    for name, value in given.items():
        if name in frame.columns:
            raise SceneError(
                f"{name} is given twice: as solve_many's keyword and as a column of the table; "
                f"keep one"
            )
        if name == "method":
            if not isinstance(value, str) or value not in M.NAMES:
                raise SceneError(f"method must be one of {', '.join(M.NAMES)}; got {value!r}")
        else:
            given[name] = check(name, value)
    return frame.assign(**given)


def solve_many(
    frame: pd.DataFrame,
    *,
    method: str | None = None,
    rtol: float | None = None,
    step: float | None = None,
    max_events: int = MAX_EVENTS_DEFAULT,
    progress: bool = False,
    keep=(),
) -> pd.DataFrame:
    """Solve every row of a scene table (in parallel batches with numba ``prange``).

    The table takes the paper's form (column ``alpha``; optional ``beta, xi, n_masses``,
    defaults 0, 0, 2) or the general form (list columns ``masses, springs`` and optional
    ``dashpots``, scalar ``k_contact, v0``, struct columns ``contact, links``, list columns
    ``velocities, stretches`` of an initial state; see
    docs/general-chains.md), plus optional ``method`` and, for numerical methods, ``rtol`` and
    ``step`` per row. Columns are read strictly (``restitution.tables.scene_table``): any other
    column is an error unless named in ``keep`` (carried through unchanged). Every row is checked
    before any work. ``method``, ``rtol`` and ``step`` given as keywords apply to every row, as a
    column of that name would (a table with the column too is refused: one place for a setting).
    Returns a copy of ``frame`` with the result columns ``cor, n_collisions,
    omega_t_col, e_translational, e_vibrational, e_dissipated, method, status, error_estimate``
    (and ``t_col`` in the user's time unit for general tables). A row whose kernel failed is NaN
    with a status naming the failure. Rows are independent: results are bit-identical for any
    thread count.
    """
    import pandas as pd

    from restitution.tables.scene_table import scene_table

    max_events = check("max_events", max_events)
    frame = _with_settings(frame, method=method, rtol=rtol, step=step)
    table = scene_table(frame, keep)
    plan = table.plan
    n = len(frame)
    method = _Labels(table.method_codes.copy(), table.method_names)
    cols = {
        "cor": np.full(n, np.nan),
        "n_collisions": np.zeros(n, dtype=np.int64),
        "omega_t_col": np.full(n, np.nan),
        "e_translational": np.full(n, np.nan),
        "e_vibrational": np.full(n, np.nan),
        "e_dissipated": np.full(n, np.nan),
        "method": method,
        "status": _Labels(np.zeros(n, dtype=np.int64), ["not_run"]),
        "error_estimate": np.full(n, np.nan),
    }
    block = _block(n, progress)
    with _bar(n, progress) as bar:
        # Each method's batch runner on its rows (methods.METHODS: the exact ones in parallel
        # blocks), in the table's order of methods.
        codes = method.codes.copy()  # (_fill adds labels such as "+sticking" as it goes)
        names = list(method.names)
        for code in np.unique(codes):
            rows = np.arange(n) if len(names) == 1 else np.flatnonzero(codes == code)
            chosen = M.METHODS[names[code]]
            out, errors, results = chosen.run_many(table, rows, max_events, bar, block)
            _fill(cols, rows, out, errors, passive=chosen.exact)
            for j, r in results.items():
                i = int(rows[j])
                for c in RESULT_COLUMNS:
                    if isinstance(cols[c], _Labels):
                        cols[c].set(i, getattr(r, c))
                    else:
                        cols[c][i] = getattr(r, c)
    # One DataFrame construction (column-by-column insertion is slow on large tables), without
    # copies: the result columns are fresh arrays of ours; the user's columns enter as Series
    # (copy-on-write: the result never writes into the user's frame).
    data = {}
    for name in frame.columns:
        data[name] = frame[name]
    if table.chains is None:
        for name in ("alpha", "beta", "xi", "n_masses"):
            if name not in data or data[name].dtype != plan[name].dtype:
                # a default or the checked numbers of a converted column (e.g. decimals): never
                # the user's memory
                data[name] = pd.Series(plan[name], index=frame.index)
    else:
        for name, checked in (("k_contact", table.k_contact), ("v0", table.v0)):
            if name in data and data[name].dtype != checked.dtype:
                data[name] = pd.Series(checked, index=frame.index)  # e.g. decimals: as read
        # list cells as the checked floats (CSV text and parquet lists alike; object columns
        # also when the table is empty)
        for name in ("masses", "springs", "dashpots"):
            if name in data:
                cells = [getattr(ch, name).tolist() for ch in table.chains]
                data[name] = pd.Series(cells, index=frame.index, dtype=object)
    data.update(cols)
    for c in ("method", "status"):
        data[c] = cols[c].column()
    if table.chains is not None:
        data[T_COL] = user_time(cols["omega_t_col"], plan["omega"])
    return pd.DataFrame(data, index=frame.index, copy=False)


class _NoBar:
    def update(self, n: int) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        pass


def _bar(n: int, progress: bool):
    """A tqdm progress bar over n scenes, or a silent stand-in (tqdm costs ~10 us even when
    disabled, a tenth of a 100-row table's kernel time)."""
    if not progress:
        return _NoBar()
    from tqdm.auto import tqdm

    return tqdm(total=n, unit="scene", desc="solve_many")


def _fill(cols: dict, idx: np.ndarray, out: np.ndarray, errors: dict, passive=True) -> None:
    """Result columns of rows ``idx`` from their kernel rows (``passive``: linear scenes solved
    exactly, whose open energy account also voids the row; numerical rows keep their COR with
    status ``energy_account_open``, as ``Result.from_row`` does)."""
    if len(idx) == 0 or not len(out):
        return
    at = slice(None) if len(idx) == len(cols["cor"]) else idx  # (a slice writes 5x faster)
    status_col = out[:, L.OUT_STATUS]
    all_ok = bool((status_col == L.STATUS_OK).all())  # the common case: no masks needed
    if not all_ok:
        out = L.void_unfinished(out, passive=passive)
    cols["cor"][at] = out[:, L.OUT_COR]
    ncol = out[:, L.OUT_NCOL]
    cols["n_collisions"][at] = ncol if all_ok else np.where(np.isfinite(ncol), ncol, 0)
    cols["omega_t_col"][at] = out[:, L.OUT_TCOL]
    cols["e_translational"][at] = out[:, L.OUT_ETRANS]
    cols["e_vibrational"][at] = out[:, L.OUT_EVIB]
    cols["e_dissipated"][at] = out[:, L.OUT_EDISS]
    cols["error_estimate"][at] = out[:, L.OUT_ERR]
    status = cols["status"]
    if all_ok:
        status.set(at, status_name(L.STATUS_OK))
    else:
        status.codes[at] = _status_codes(status_col, status)
    for j, msg in errors.items():
        status.set(idx[j], msg)
    # the method as methods.label names it, from the kernel's flags
    flag_col = out[:, L.OUT_FLAGS]
    if not flag_col.any():  # (NaN counts as set: the general path below)
        return
    method = cols["method"]
    flags = np.nan_to_num(flag_col, nan=0.0).astype(np.int64)
    method.set(idx[(flags & M.FLAG_RIGID_LIMIT) != 0], "impulsive+rigid-limit")
    method.set(idx[(flags & M.FLAG_EXTRAPOLATED) != 0], EXTRAPOLATED)
    for bit, suffix in ((L.FLAG_CRITICAL_BRACKET, BRACKETED), (M.FLAG_STICKING, "+sticking")):
        marked = idx[(flags & bit) != 0]
        for code in np.unique(method.codes[marked]):
            rows = marked[method.codes[marked] == code]
            method.set(rows, method.names[code] + suffix)


__all__ = ["LAW_KEYS", "solve", "solve_many", "validate_frame"]
