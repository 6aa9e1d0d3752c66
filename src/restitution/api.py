"""Plain-Python entry points: validate, pick the method the scene needs, call a numba kernel.

Method names say which exact model a result comes from (DESIGN.md, "model only what a scene needs"):

========== ============================================================================
impulsive  rigid wall (beta = 0): impulsive reversal of m1's velocity at each contact,
           closed-form motion between contacts (kernel ``rigid2`` for two masses,
           ``linear`` for chains)
piecewise  linear contact spring (beta > 0): closed-form motion in each phase (free /
           in contact) with exact switching times (kernel ``linear``)
auto       the one of the two that the scene needs
========== ============================================================================
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .kernels import layout as L
from .result import RESULT_COLUMNS, Result, status_name
from .scene import METHODS, Scene, SceneError, check_method

INPUT_COLUMNS = ("alpha", "beta", "xi", "n_masses", "method")
DEFAULTS = {"beta": 0.0, "xi": 0.0, "n_masses": 2, "method": "auto"}
_BLOCK = 2048  # rows per parallel batch call; the progress bar advances per block


def resolve_method(scene: Scene, method: str = "auto") -> str:
    """Return the method a scene needs, or raise if a forced method does not fit it."""
    check_method(method)
    needed = "impulsive" if scene.beta == 0.0 else "piecewise"
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
    method : {"auto", "impulsive", "piecewise"}
    history : bool
        Also return one row per contact (``Result.history``).
    max_events : int
        Contact budget; a longer sequence ends with status ``event_budget_exhausted``.

    Examples
    --------
    >>> r = solve(alpha=1.0)
    >>> round(r.cor, 12), r.n_collisions
    (1.0, 2)
    """
    scene = Scene(alpha, beta, xi, n_masses)
    chosen = resolve_method(scene, method)
    max_events = _check_max_events(max_events)
    rigid2, _, solve_linear, _ = _kernels()
    hist = np.zeros((max_events if history else 0, L.N_HIST))
    if chosen == "impulsive" and scene.n_masses == 2:
        out = rigid2(scene.alpha, scene.xi, max_events, hist)
    else:
        out = solve_linear(scene.alpha, scene.beta, scene.xi, scene.n_masses, max_events, hist)
    return Result.from_row(scene, out, chosen, hist if history else None)


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
    """Return the scenes with defaults filled in; raise SceneError naming the first bad cell."""
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
    scenes["method"] = _column(frame, "method", check_method).astype(object)
    rigid = scenes["beta"].to_numpy() == 0.0
    wrong = (scenes["method"] == "impulsive").to_numpy() & ~rigid
    wrong |= (scenes["method"] == "piecewise").to_numpy() & rigid
    if wrong.any():
        i = int(np.flatnonzero(wrong)[0])
        row = scenes.iloc[i]
        resolve_method(Scene(row.alpha, row.beta, row.xi, row.n_masses), row.method)
    scenes["method"] = np.where(rigid, "impulsive", "piecewise")
    return scenes


def solve_many(
    frame: pd.DataFrame, *, max_events: int = 100_000, progress: bool = False
) -> pd.DataFrame:
    """Solve every row of a scene table in parallel (numba ``prange``).

    ``frame`` needs a column ``alpha``; ``beta, xi, n_masses, method`` are optional (defaults
    0, 0, 2, "auto"). Returns a copy of ``frame`` with the result columns ``cor, n_collisions,
    omega_t_col, e_translational, e_vibrational, e_dissipated, method, status`` added (``method``
    is replaced by the method actually used). Every row is checked before any work starts. Rows
    are independent, so results are bit-identical for any number of threads.
    """
    from tqdm.auto import tqdm

    max_events = _check_max_events(max_events)
    scenes = validate_frame(frame)
    _, rigid2_batch, _, solve_linear_batch = _kernels()
    alpha = scenes["alpha"].to_numpy(np.float64)
    beta = scenes["beta"].to_numpy(np.float64)
    xi = scenes["xi"].to_numpy(np.float64)
    nm = scenes["n_masses"].to_numpy(np.int64)
    out = np.empty((len(scenes), L.N_OUT))
    fast = (beta == 0.0) & (nm == 2)  # the closed-form two-mass rigid-wall kernel
    groups = [(np.flatnonzero(fast), True), (np.flatnonzero(~fast), False)]
    total = len(scenes)
    with tqdm(total=total, disable=not progress, unit="scene", desc="solve_many") as bar:
        for idx, is_fast in groups:
            for start in range(0, len(idx), _BLOCK):
                sel = idx[start : start + _BLOCK]
                if is_fast:
                    out[sel] = rigid2_batch(alpha[sel], xi[sel], max_events)
                else:
                    out[sel] = solve_linear_batch(
                        alpha[sel], beta[sel], xi[sel], nm[sel], max_events
                    )
                bar.update(len(sel))
    result = frame.copy()
    for name in ("beta", "xi", "n_masses"):
        result[name] = scenes[name]
    result["cor"] = out[:, L.OUT_COR]
    result["n_collisions"] = out[:, L.OUT_NCOL].astype(np.int64)
    result["omega_t_col"] = out[:, L.OUT_TCOL]
    result["e_translational"] = out[:, L.OUT_ETRANS]
    result["e_vibrational"] = out[:, L.OUT_EVIB]
    result["e_dissipated"] = out[:, L.OUT_EDISS]
    result["method"] = scenes["method"]
    result["status"] = [status_name(s) for s in out[:, L.OUT_STATUS]]
    return result


__all__ = ["METHODS", "solve", "solve_many", "resolve_method", "validate_frame"]
