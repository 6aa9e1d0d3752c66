"""Plain-Python entry points: validate, pick the method the scene needs, call a numba kernel.

Method names say which exact model a result comes from (DESIGN.md, "model only what a scene needs"):

========== ============================================================================
impulsive  rigid wall (beta = 0): impulsive reversal of m1's velocity at each contact,
           closed-form motion between contacts (kernel ``rigid2`` for two masses,
           ``linear`` for chains)
piecewise  linear contact spring (beta > 0): closed-form motion in each phase (free /
           in contact) with exact switching times (kernel ``linear``)
adaptive   embedded Dormand-Prince 5(4) with guaranteed event location, only for the
           phases whose force law is nonlinear (two masses; ``restitution.nonlinear``)
verlet     the paper's velocity Verlet, fixed step (a fraction of the shortest period)
reference  scipy ``solve_ivp`` DOP853 with events: slow, for checks
auto       the exact method a linear scene needs; ``adaptive`` for nonlinear laws
========== ============================================================================

Nonlinear laws (plastic contact, scissor spring; Sections 3.1-3.2) are chosen with the keyword
arguments of ``restitution.nonlinear.solve_nonlinear`` (``contact``, ``eta``, ``dr``,
``structure``, ``L``, ``ks_ratio``, ``theta0``, ``corner``, ``v0``, ``rtol``, ``step``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .kernels import layout as L
from .result import RESULT_COLUMNS, Result, status_name
from .scene import EXACT_METHODS, METHODS, NUMERICAL_METHODS, Scene, SceneError, check_method

INPUT_COLUMNS = ("alpha", "beta", "xi", "n_masses", "method")
LAW_KEYS = ("contact", "eta", "dr", "structure", "L", "ks_ratio", "theta0", "corner", "v0")
NUMERICAL_KEYS = (*LAW_KEYS, "rtol", "step")
DEFAULTS = {"beta": 0.0, "xi": 0.0, "n_masses": 2, "method": "auto"}
_BLOCK = 2048  # rows per parallel batch call; the progress bar advances per block


def resolve_method(scene: Scene, method: str = "auto") -> str:
    """Return the method a scene needs, or raise if a forced method does not fit it."""
    check_method(method)
    needed = "impulsive" if scene.beta == 0.0 else "piecewise"
    if method in NUMERICAL_METHODS:
        return method
    if method not in ("auto", needed):
        raise SceneError(
            f"method {method!r} does not fit beta={scene.beta!r}: 'impulsive' needs beta = 0 "
            f"(rigid wall), 'piecewise' needs beta > 0; use method='auto' or '{needed}'"
        )
    return needed


def _kernels():
    # Imported lazily so `import restitution` stays cheap for the CLI's --help and for snakemake.
    from .kernels.linear import solve_linear, solve_linear_batch
    from .kernels.rigid2 import rigid2, rigid2_batch

    return rigid2, rigid2_batch, solve_linear, solve_linear_batch


def solve(
    alpha: float,
    beta: float = 0.0,
    xi: float = 0.0,
    n_masses: int = 2,
    method: str = "auto",
    *,
    history: bool = False,
    max_events: int = 100_000,
    **law,
) -> Result:
    """COR of one scene.

    Parameters
    ----------
    alpha : float
        Mass ratio m2/m1, in (0, 1e8].
    beta : float
        Stiffness ratio k2/k1, in [0, 1e6]; 0 is the rigid wall.
    xi : float
        Damping ratio of the dashpot between m1 and m2, in [0, 1e3].
    n_masses : int
        Number of masses in the chain, in [2, 512].
    method : {"auto", "impulsive", "piecewise", "adaptive", "verlet", "reference"}
        See the module docstring; the method used is recorded in ``Result.method``.
    history : bool
        Also return one row per contact (``Result.history``).
    max_events : int
        Contact budget; a longer sequence ends with status ``event_budget_exhausted``.
    **law
        Nonlinear laws and numerical settings (two masses only), passed to
        ``restitution.nonlinear.solve_nonlinear``: contact, eta, dr, structure, L, ks_ratio,
        theta0, corner, v0, rtol, step.

    Examples
    --------
    >>> r = solve(alpha=1.0)
    >>> round(r.cor, 12), r.n_collisions
    (1.0, 2)
    """
    scene = Scene(alpha, beta, xi, n_masses)
    chosen = resolve_method(scene, method)
    max_events = _check_max_events(max_events)
    if chosen in NUMERICAL_METHODS or _is_nonlinear(law):
        return _solve_numerical(scene, method, history, max_events, law)
    rigid2, _, solve_linear, _ = _kernels()
    hist = np.zeros((max_events if history else 0, L.N_HIST))
    if chosen == "impulsive" and scene.n_masses == 2:
        out = rigid2(scene.alpha, scene.xi, max_events, hist)
    else:
        out = solve_linear(scene.alpha, scene.beta, scene.xi, scene.n_masses, max_events, hist)
    return Result.from_row(scene, out, chosen, hist if history else None)


def _is_nonlinear(law: dict) -> bool:
    unknown = sorted(set(law) - set(NUMERICAL_KEYS))
    if unknown:
        raise SceneError(
            f"unknown scene parameter(s) {', '.join(unknown)}; allowed: alpha, beta, xi, "
            f"n_masses, method, history, max_events, {', '.join(NUMERICAL_KEYS)}"
        )
    return law.get("contact", "linear") != "linear" or law.get("structure", "linear") != "linear"


def _check_numerical(scene: Scene, method: str) -> None:
    """Nonlinear laws and numerical methods exist for two masses and exclude exact methods."""
    if scene.n_masses != 2:
        raise SceneError(
            f"n_masses must be 2 for nonlinear laws and for the numerical methods "
            f"{', '.join(NUMERICAL_METHODS)}; got {scene.n_masses}"
        )
    if method in EXACT_METHODS:
        raise SceneError(
            f"method {method!r} is exact only for linear laws; use one of auto, "
            f"{', '.join(NUMERICAL_METHODS)}"
        )


def _solve_numerical(scene: Scene, method: str, history: bool, max_events: int, law: dict):
    """Nonlinear laws, or a numerical method forced on a linear scene (two masses)."""
    from .nonlinear import solve_nonlinear

    _check_numerical(scene, method)
    return solve_nonlinear(
        scene.alpha,
        scene.beta,
        scene.xi,
        method=method,
        history=history,
        max_events=max_events,
        **law,
    )


def _check_max_events(value) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise SceneError(f"max_events must be a positive integer; got {value!r}")
    return int(value)


def _column(frame: pd.DataFrame, name: str, check) -> np.ndarray:
    """Column ``name`` (or its default); on a bad cell, raise ``check``'s error naming the row."""
    if name not in frame:
        return np.full(len(frame), DEFAULTS[name])
    values = frame[name].to_numpy()
    ok = np.zeros(len(values), dtype=bool)
    if name != "method" and values.dtype.kind in "fiu":
        # Vectorised fast path: probe a value's acceptance once per distinct value.
        distinct, inverse = np.unique(values, return_inverse=True)
        good = np.array([_accepts(check, v) for v in distinct], dtype=bool)
        ok = good[inverse]
    elif name == "method":
        ok = pd.Series(values).isin(METHODS).to_numpy()
    for i in np.flatnonzero(~ok):
        try:
            check(values[i])
        except SceneError as e:
            raise SceneError(f"{e} (row {frame.index[i]!r})") from None
    return values


def _accepts(check, value) -> bool:
    try:
        check(value)
    except SceneError:
        return False
    return True


def validate_frame(frame: pd.DataFrame) -> pd.DataFrame:
    """Return the scenes with defaults filled in; raise SceneError naming the first bad cell.

    The returned ``method`` column holds the method each row will use; rows with a nonlinear law
    or a numerical method are checked again, with their laws, by ``solve_nonlinear_many``.
    """
    from .scene import check_alpha, check_beta, check_n_masses, check_xi

    if not isinstance(frame, pd.DataFrame):
        raise SceneError(f"expected a pandas DataFrame with a column 'alpha'; got {type(frame)}")
    if "alpha" not in frame:
        raise SceneError(
            f"the scene table needs a column 'alpha' (optional: beta, xi, n_masses, method); "
            f"got columns {list(frame.columns)}"
        )
    clash = [c for c in RESULT_COLUMNS if c in frame and c != "method"]
    if clash:
        raise SceneError(f"the scene table already has result columns {clash}; drop them first")
    scenes = pd.DataFrame(index=frame.index)
    scenes["alpha"] = _column(frame, "alpha", check_alpha).astype(float)
    scenes["beta"] = _column(frame, "beta", check_beta).astype(float)
    scenes["xi"] = _column(frame, "xi", check_xi).astype(float)
    scenes["n_masses"] = _column(frame, "n_masses", check_n_masses).astype(np.int64)
    method = _column(frame, "method", check_method).astype(object)
    nonlinear = np.zeros(len(frame), dtype=bool)
    for key in ("contact", "structure"):
        if key in frame:
            nonlinear |= frame[key].fillna("linear").to_numpy() != "linear"
    numerical = nonlinear | np.isin(method, NUMERICAL_METHODS)
    rigid = scenes["beta"].to_numpy() == 0.0
    exact = np.where(rigid, "impulsive", "piecewise")
    wrong = ~numerical & np.isin(method, EXACT_METHODS) & (method != exact)
    wrong |= numerical & np.isin(method, EXACT_METHODS)
    wrong |= numerical & (scenes["n_masses"].to_numpy() != 2)
    for i in np.flatnonzero(wrong)[:1]:
        row = scenes.iloc[i]
        try:
            sc = Scene(row.alpha, row.beta, row.xi, row.n_masses)
            if numerical[i]:
                _check_numerical(sc, method[i])
            resolve_method(sc, method[i])
        except SceneError as e:
            raise SceneError(f"{e} (row {frame.index[i]!r})") from None
    chosen = np.where(numerical, np.where(method == "auto", "adaptive", method), exact)
    scenes["method"] = chosen.astype(object)
    return scenes


def _solve_exact_rows(scenes: pd.DataFrame, idx: np.ndarray, max_events: int, bar) -> np.ndarray:
    """Kernel rows for the exact methods, in parallel blocks (the progress bar moves per block)."""
    _, rigid2_batch, _, solve_linear_batch = _kernels()
    alpha = scenes["alpha"].to_numpy(np.float64)[idx]
    beta = scenes["beta"].to_numpy(np.float64)[idx]
    xi = scenes["xi"].to_numpy(np.float64)[idx]
    nm = scenes["n_masses"].to_numpy(np.int64)[idx]
    out = np.empty((len(idx), L.N_OUT))
    fast = (beta == 0.0) & (nm == 2)  # the closed-form two-mass rigid-wall kernel
    for group, is_fast in ((np.flatnonzero(fast), True), (np.flatnonzero(~fast), False)):
        for start in range(0, len(group), _BLOCK):
            sel = group[start : start + _BLOCK]
            if is_fast:
                out[sel] = rigid2_batch(alpha[sel], xi[sel], max_events)
            else:
                out[sel] = solve_linear_batch(alpha[sel], beta[sel], xi[sel], nm[sel], max_events)
            bar.update(len(sel))
    return out


def _solve_numerical_rows(frame, scenes, idx, max_events, bar) -> list:
    """Rows with nonlinear laws or numerical methods, grouped by method: [(positions, frame)]."""
    from .nonlinear import solve_nonlinear_many

    parts = []
    methods = scenes["method"].to_numpy()[idx]
    for m in ("adaptive", "verlet", "reference"):
        sel = idx[methods == m]
        if len(sel) == 0:
            continue
        sub = frame.iloc[sel].drop(columns=["method"], errors="ignore")
        sub = sub.assign(**{k: scenes[k].to_numpy()[sel] for k in ("beta", "xi")})
        if m == "reference":
            rows = [
                _solve_numerical(
                    Scene(r.alpha, r.beta, r.xi, 2),
                    m,
                    False,
                    max_events,
                    {
                        k: getattr(r, k)
                        for k in NUMERICAL_KEYS
                        if k in sub and pd.notna(getattr(r, k))
                    },
                ).to_dict()
                for r in sub.itertuples()
            ]
            done = sub.assign(**{c: [d[c] for d in rows] for c in RESULT_COLUMNS})
        else:
            done = solve_nonlinear_many(sub, method=m, max_events=max_events)
        parts.append((sel, done))
        bar.update(len(sel))
    return parts


def solve_many(
    frame: pd.DataFrame, *, max_events: int = 100_000, progress: bool = False
) -> pd.DataFrame:
    """Solve every row of a scene table in parallel (numba ``prange``).

    ``frame`` needs a column ``alpha``; ``beta, xi, n_masses, method`` are optional (defaults
    0, 0, 2, "auto"), and so are the nonlinear law columns of ``LAW_KEYS`` (two masses; see
    ``restitution.nonlinear``). Returns a copy of ``frame`` with the result columns ``cor,
    n_collisions, omega_t_col, e_translational, e_vibrational, e_dissipated, method, status,
    error_estimate`` added (``method`` is replaced by the method actually used). Every row is
    checked before any work starts. Rows are independent, so results are bit-identical for any
    number of threads.
    """
    from tqdm.auto import tqdm

    max_events = _check_max_events(max_events)
    scenes = validate_frame(frame)
    numerical = np.isin(scenes["method"].to_numpy(), NUMERICAL_METHODS)
    result = frame.copy()
    for name in ("beta", "xi", "n_masses"):
        result[name] = scenes[name]
    for c in RESULT_COLUMNS:
        result[c] = pd.Series(
            index=frame.index, dtype=object if c in ("method", "status") else float
        )
    with tqdm(total=len(scenes), disable=not progress, unit="scene", desc="solve_many") as bar:
        exact = np.flatnonzero(~numerical)
        out = _solve_exact_rows(scenes, exact, max_events, bar)
        pos = result.columns.get_loc
        result.iloc[exact, pos("cor")] = out[:, L.OUT_COR]
        result.iloc[exact, pos("n_collisions")] = out[:, L.OUT_NCOL]
        result.iloc[exact, pos("omega_t_col")] = out[:, L.OUT_TCOL]
        result.iloc[exact, pos("e_translational")] = out[:, L.OUT_ETRANS]
        result.iloc[exact, pos("e_vibrational")] = out[:, L.OUT_EVIB]
        result.iloc[exact, pos("e_dissipated")] = out[:, L.OUT_EDISS]
        result.iloc[exact, pos("error_estimate")] = out[:, L.OUT_ERR]
        result.iloc[exact, pos("method")] = scenes["method"].to_numpy()[exact]
        result.iloc[exact, pos("status")] = [status_name(s) for s in out[:, L.OUT_STATUS]]
        cols = [pos(c) for c in RESULT_COLUMNS]
        for sel, done in _solve_numerical_rows(
            frame, scenes, np.flatnonzero(numerical), max_events, bar
        ):
            result.iloc[sel, cols] = done[list(RESULT_COLUMNS)].to_numpy()
    result["n_collisions"] = result["n_collisions"].astype(np.int64)
    for c in ("method", "status"):
        result[c] = result[c].astype(object)
    return result


__all__ = ["LAW_KEYS", "METHODS", "solve", "solve_many", "resolve_method", "validate_frame"]
