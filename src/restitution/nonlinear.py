"""Plain-Python entry point for nonlinear scenes (Sections 3.1, 3.2) and forced methods.

``solve_nonlinear`` validates every parameter (SceneError naming it and its range), packs the laws
(``laws.py``) and calls the numba kernel (``kernels/nonlinear.py``) or the scipy reference.

Methods: ``auto`` = adaptive DP5(4) for nonlinear laws, the exact kernels
(``restitution.api.solve``: ``impulsive`` / ``piecewise``) when contact and structure are both
linear, ``adaptive``
(rtol), ``verlet`` (fixed step = ``step`` x shortest local period; the h/2 result is returned),
``reference`` (scipy DOP853 with events, slow).

``Result.error_estimate`` of a numerical method is the change of the COR between two settings:
|cor(h/2) - cor(h)| for ``verlet``; for ``adaptive`` and ``reference`` |cor(rtol) -
cor(10 rtol)|, and for ``adaptive`` at least the sum of its local error estimates of the total
momentum (/ M v0). Not divided by the Richardson factor (3 for a second-order method, 1023 for
DP5 at proportional tolerance): the hard-case suite (tests/test_hard.py) measured errors 1.5 to
6000 times above such asymptotic estimates, because contact events fall between steps and shallow
contacts appear or vanish with the setting, so convergence is not asymptotic there.
"""

from __future__ import annotations

import math

import numpy as np

from . import laws
from .kernels import layout as LY
from .result import Result
from .scene import Scene, SceneError

NL_METHODS = ("auto", "adaptive", "verlet", "reference")
CONTACTS = ("linear", "plastic")
STRUCTURES = ("linear", "scissor")


def _choice(name, value, allowed):
    if value not in allowed:
        raise SceneError(f"{name} must be one of {', '.join(map(repr, allowed))}; got {value!r}")
    return value


def _pos(name, value, low, high, low_open=True):
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SceneError(f"{name} must be a number in ({low:g}, {high:g}]; got {value!r}") from None
    if (
        isinstance(value, bool)
        or not math.isfinite(x)
        or (x <= low if low_open else x < low)
        or x > high
    ):
        raise SceneError(f"{name} must be in ({low:g}, {high:g}]; got {value!r}")
    return x


def _default_etol(method, rtol, step):
    return (2 * math.pi * step) ** 2 if method == "verlet" else max(1e3 * rtol, 1e-9)


def build_laws(alpha, beta, contact, eta, dr, structure, L_, ks_ratio, theta0, corner, v0):  # noqa: N803
    """Validated packed law arrays (cp, sp) and the derived kappa (nan if not plastic)."""
    scene = Scene(alpha, beta, 0.0, 2)
    k2 = scene.k2
    _choice("contact", contact, CONTACTS)
    _choice("structure", structure, STRUCTURES)
    kappa = math.nan
    if contact == "plastic":
        if scene.beta == 0.0:
            raise SceneError(
                "contact='plastic' needs beta > 0 (its unloading slope is k1 = k2/beta); got beta=0"
            )
        eta = laws.check_eta(eta)
        dr = laws.check_dr(dr, eta)
        kappa = laws.plastic_kappa(dr, eta, scene.k1, v0)
        cp = laws.contact_params(laws.C_PLASTIC, scene.k1, kappa, eta)
    elif scene.beta == 0.0:
        cp = laws.contact_params(laws.C_RIGID)
    else:
        cp = laws.contact_params(laws.C_LINEAR, scene.k1)
    if structure == "scissor":
        L_ = laws.check_L(L_)
        theta0 = laws.check_theta0(theta0)
        ks_ratio = laws.check_ks_ratio(ks_ratio, theta0)
        corner = laws.check_corner(corner)
        sp = laws.scissor_params(k2, ks_ratio * k2, L_, theta0, corner)
    else:
        sp = laws.linear_structure_params(k2)
    return cp, sp, kappa


def solve_nonlinear(
    alpha: float,
    beta: float = 0.01,
    xi: float = 0.0,
    contact: str = "linear",
    eta: float = 1.0,
    dr: float = 0.0,
    structure: str = "linear",
    L: float = 1.0,  # noqa: N803
    ks_ratio: float = 0.01,
    theta0: float = laws.THETA0_DEFAULT,
    corner: float = laws.CORNER_DEFAULT,
    v0: float = 1.0,
    method: str = "auto",
    step: float = 0.01,
    rtol: float = 1e-9,
    max_events: int = 10_000,
    history: bool = False,
    integrate_free: bool = False,
    energy_tol: float | None = None,
    account: dict | None = None,
) -> Result:
    """COR of a two-mass scene with plastic contact and/or the scissor structural spring.

    Parameters
    ----------
    alpha, beta, xi : float
        Mass ratio (0, 1e8], stiffness ratio k2/k1 [0, 1e6] (0: rigid wall), damping ratio.
    contact : {"linear", "plastic"}
        "plastic": power-law loading F = kappa*x**eta, linear unloading (laws.py); needs beta > 0.
    eta, dr : float
        Loading exponent in (0, 10] and nominal dissipation ratio in [0, 1) (>= (1-eta)/2).
    structure : {"linear", "scissor"}
    L, ks_ratio, theta0, corner : float
        Scissor bar length (> 0), ks/k2 in (0, tan(theta0)**2), rest half angle in (0, pi/2),
        stroke fraction at which the corner stiffening reaches the cap (laws.py).
    v0 : float
        Impact speed (the nonlinear laws are velocity dependent), in (0, 1e6].
    method : {"auto", "adaptive", "verlet", "reference"}
    step : float
        Verlet step as a fraction of the shortest local period, in (0, 0.25].
    rtol : float
        Relative tolerance of adaptive / reference, in [1e-14, 1e-2] (atol = rtol*v0).
    integrate_free : bool
        Integrate free flight numerically even with a linear structure (checks only).
    energy_tol : float, optional
        Energy account tolerance (default: 1e3*rtol, clipped to >= 1e-9, for adaptive/reference;
        (2*pi*step)**2 for Verlet, about 30 times its measured energy error).
    account : dict, optional
        Filled with the energy account at the final separation: kinetic, elastic,
        dissipated_contact, dissipated_dashpot, residual (fractions of the initial energy).
    """
    from .scene import check_xi

    xi = check_xi(xi)
    v0 = laws.check_v0(v0)
    _choice("method", method, NL_METHODS)
    cp, sp, kappa = build_laws(
        alpha, beta, contact, eta, dr, structure, L, ks_ratio, theta0, corner, v0
    )
    scene = Scene(alpha, beta, xi, 2)
    if (
        isinstance(max_events, bool)
        or not isinstance(max_events, (int, np.integer))
        or max_events < 1
    ):
        raise SceneError(f"max_events must be a positive integer; got {max_events!r}")
    rtol = _pos("rtol", rtol, 1e-14, 1e-2, low_open=False)
    step = _pos("step", step, 0.0, 0.25)
    if method == "auto" and contact == "linear" and structure == "linear" and not integrate_free:
        from .api import solve

        # linear scenes: the exact kernels (COR does not depend on v0 there)
        return solve(
            scene.alpha, scene.beta, scene.xi, 2, history=history, max_events=int(max_events)
        )
    chosen = "adaptive" if method == "auto" else method
    if chosen == "verlet" and scene.beta == 0.0:
        raise SceneError("method='verlet' needs beta > 0 (a finite contact spring); got beta=0")
    if energy_tol is None:
        energy_tol = _default_etol(chosen, rtol, step)
    acct = np.zeros(5)
    if chosen == "reference":
        from .reference import solve_reference

        out, hist = solve_reference(scene.alpha, v0, xi, cp, sp, rtol, max_events, acct, energy_tol)
        coarse, _ = solve_reference(
            scene.alpha, v0, xi, cp, sp, _coarser(rtol), max_events, np.zeros(5), energy_tol
        )
        _two_setting_estimate(out, coarse)
        hist = hist if history else None
    else:
        from .kernels.nonlinear import METHOD_ADAPTIVE, METHOD_VERLET, solve_scene

        hist = np.zeros((max_events if history else 0, LY.N_HIST))

        def run(code, tol, stp, free, rows, account_out):
            return solve_scene(
                scene.alpha, v0, xi, cp, sp, code, tol, stp, free, energy_tol, max_events, rows,
                account_out,
            )  # fmt: skip

        no_rows = np.zeros((0, LY.N_HIST))
        if chosen == "verlet":
            coarse = run(METHOD_VERLET, rtol, step, False, no_rows, np.zeros(5))
            out = run(METHOD_VERLET, rtol, step / 2, False, hist, acct)
            out[LY.OUT_ERR] = 0.0  # Verlet has no local estimate: the step change is all of it
        else:
            free = bool(integrate_free)
            coarse = run(METHOD_ADAPTIVE, _coarser(rtol), step, free, no_rows, np.zeros(5))
            out = run(METHOD_ADAPTIVE, rtol, step, free, hist, acct)
        _two_setting_estimate(out, coarse)
        hist = hist if history else None
    if account is not None:
        account.update(
            kinetic=acct[0],
            elastic=acct[1],
            dissipated_contact=acct[2],
            dissipated_dashpot=acct[3],
            residual=acct[4],
            kappa=kappa,
        )
    return Result.from_row(scene, out, chosen, hist)


def _coarser(rtol: float) -> float:
    return min(10.0 * rtol, 1e-2)


def _two_setting_estimate(out, coarse) -> None:
    """out's error estimate: at least |COR change| against the coarser setting; infinite (no
    estimate) when only the coarser run failed."""
    if out[LY.OUT_STATUS] != LY.STATUS_OK:
        return
    if coarse[LY.OUT_STATUS] != LY.STATUS_OK:
        out[LY.OUT_ERR] = math.inf
    else:
        out[LY.OUT_ERR] = max(out[LY.OUT_ERR], abs(out[LY.OUT_COR] - coarse[LY.OUT_COR]))


LAW_DEFAULTS = dict(
    beta=0.01,
    xi=0.0,
    contact="linear",
    eta=1.0,
    dr=0.0,
    structure="linear",
    L=1.0,
    ks_ratio=0.01,
    theta0=laws.THETA0_DEFAULT,
    corner=laws.CORNER_DEFAULT,
    v0=1.0,
)


def solve_nonlinear_many(frame, *, method="adaptive", rtol=1e-9, step=0.01, max_events=10_000):
    """Solve every row of a scene table (numba ``prange``); returns a copy with result columns.

    ``frame`` needs ``alpha``; the law columns of ``LAW_DEFAULTS`` are optional (as are their
    cells: NaN takes the default). ``method`` is "adaptive" or "verlet" for the whole table;
    error estimates as in ``solve_nonlinear``. Adds ``cor, n_collisions, omega_t_col,
    e_translational, e_vibrational, e_dissipated, method, status, error_estimate``. Every row is
    validated first (SceneError names the row).
    """
    import pandas as pd

    from .kernels.nonlinear import METHOD_ADAPTIVE, METHOD_VERLET, solve_scene_batch
    from .result import status_name
    from .scene import check_xi

    _choice("method", method, ("adaptive", "verlet"))
    rtol = _pos("rtol", rtol, 1e-14, 1e-2, low_open=False)
    step = _pos("step", step, 0.0, 0.25)
    if not isinstance(frame, pd.DataFrame) or "alpha" not in frame:
        raise SceneError("expected a pandas DataFrame with a column 'alpha'")
    n = len(frame)
    cols = {
        k: (frame[k].to_numpy() if k in frame else np.full(n, v, dtype=object))
        for k, v in LAW_DEFAULTS.items()
    }
    alpha = frame["alpha"].to_numpy()
    cps, sps = np.zeros((n, laws.N_CP)), np.zeros((n, laws.N_SP))
    xi, v0 = np.zeros(n), np.zeros(n)
    for i in range(n):
        try:
            # a missing cell (NaN/None, e.g. from a ragged table) takes the default
            row = {k: (LAW_DEFAULTS[k] if pd.isna(c[i]) else c[i]) for k, c in cols.items()}
            xi[i], v0[i] = check_xi(row["xi"]), laws.check_v0(row["v0"])
            cps[i], sps[i], _ = build_laws(
                alpha[i],
                row["beta"],
                row["contact"],
                row["eta"],
                row["dr"],
                row["structure"],
                row["L"],
                row["ks_ratio"],
                row["theta0"],
                row["corner"],
                v0[i],
            )
            if method == "verlet" and cps[i][0] == laws.C_RIGID:
                raise SceneError("method='verlet' needs beta > 0")
        except SceneError as e:
            raise SceneError(f"{e} (row {frame.index[i]!r})") from None
    code = METHOD_VERLET if method == "verlet" else METHOD_ADAPTIVE
    etol = _default_etol(method, rtol, step)

    def run(tol, stp):
        return solve_scene_batch(
            alpha.astype(float), v0, xi, cps, sps, code, tol, stp, etol, int(max_events)
        )

    if method == "verlet":
        coarse, out = run(rtol, step), run(rtol, step / 2)
        out[:, LY.OUT_ERR] = 0.0
    else:
        coarse, out = run(_coarser(rtol), step), run(rtol, step)
    for row, other in zip(out, coarse, strict=True):
        _two_setting_estimate(row, other)
    result = frame.copy()
    result["cor"] = out[:, LY.OUT_COR]
    result["n_collisions"] = out[:, LY.OUT_NCOL].astype(np.int64)
    result["omega_t_col"] = out[:, LY.OUT_TCOL]
    result["e_translational"] = out[:, LY.OUT_ETRANS]
    result["e_vibrational"] = out[:, LY.OUT_EVIB]
    result["e_dissipated"] = out[:, LY.OUT_EDISS]
    result["method"] = method
    result["status"] = [status_name(s) for s in out[:, LY.OUT_STATUS]]
    result["error_estimate"] = out[:, LY.OUT_ERR]
    return result


__all__ = ["LAW_DEFAULTS", "NL_METHODS", "build_laws", "solve_nonlinear", "solve_nonlinear_many"]
