"""Plain-Python entry point for nonlinear scenes (Sections 3.1, 3.2) and forced methods.

``solve_nonlinear`` validates every parameter (SceneError naming it and its range), packs the laws
(``laws.py``) and calls the numba kernel (``kernels/stepping.py``) or the scipy reference.

Methods: ``auto`` = adaptive DP5(4) for nonlinear laws, the exact kernels
(``restitution.api.solve``: ``impulsive`` / ``piecewise``) when contact and structure are
both
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

from restitution.kernels import layout as LY
from restitution.model import laws
from restitution.model.laws import pack_chain
from restitution.model.scene import Scene, SceneError
from restitution.solvers.result import Result

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


# The loosest energy account a numerical row may have and still be ``ok``. The method's own
# tolerance (below) follows its accuracy setting, and at loose settings it allowed accounts that
# no longer support the reported energies: rtol = 1e-2 gave 1e3 * rtol = 10 and a row whose
# fractions summed to 1.076 passed as ok, Verlet at step 0.25 gave (2 pi step)**2 = 2.5.
ENERGY_TOL_MAX = 1e-3


def _default_etol(method, rtol, step):
    """Energy-account tolerance of a numerical row: its method's accuracy, 1e3 * rtol (at least
    1e-9) for adaptive and reference, (2 pi step)**2 for Verlet (measured sums were off by at
    most 255 rtol and 0.25 step**2 over plastic, scissor and damped scenes at rtol 1e-12..1e-2,
    step 1e-3..0.25), never looser than ENERGY_TOL_MAX."""
    own = (2 * math.pi * step) ** 2 if method == "verlet" else max(1e3 * rtol, 1e-9)
    return min(own, ENERGY_TOL_MAX)


def build_laws(alpha, beta, contact, eta, dr, structure, L_, ks_ratio, theta0, corner, v0):  # noqa: N803
    """Validated packed law arrays (cp, sp) and the derived kappa (nan if not plastic)."""
    scene = Scene(alpha, beta, 0.0, 2)
    k2 = scene.k2
    _choice("contact", contact, CONTACTS)
    _choice("structure", structure, STRUCTURES)
    kappa = math.nan
    nonlinear = contact != "linear" or structure != "linear"
    if nonlinear and not laws.ALPHA_NL_MIN <= scene.alpha <= laws.ALPHA_NL_MAX:
        raise SceneError(
            f"alpha must be in [{laws.ALPHA_NL_MIN:g}, {laws.ALPHA_NL_MAX:g}] for the nonlinear "
            f"laws (the numerical methods' handled range); got {alpha!r}"
        )
    if nonlinear and scene.beta != 0.0:
        laws.check_contact_ratio("beta", scene.beta, "stiffness k1")
    if contact == "plastic":
        if scene.beta == 0.0:
            raise SceneError(
                "contact='plastic' needs beta > 0 (its unloading slope is k1 = k2/beta); got beta=0"
            )
        eta = laws.check_eta(eta)
        dr = laws.check_dr(dr, eta)
        laws.check_contact_ratio(
            "contact='plastic'", k2 / laws.plastic_loading_secant(dr, eta, scene.k1),
            "loading secant 2 (1 - dr) k1/(eta + 1)",
        )  # fmt: skip
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
        Mass ratio [1e-8, 1e8], stiffness ratio k2/k1 [0, 1e6] (0: rigid wall), damping ratio.
    contact : {"linear", "plastic"}
        "plastic": power-law loading F = kappa*x**eta, linear unloading (laws.py); needs beta > 0.
    eta, dr : float
        Loading exponent in (0, 10] and nominal dissipation ratio in [0, 1) (>= (1-eta)/2).
    structure : {"linear", "scissor"}
    L, ks_ratio, theta0, corner : float
        Scissor bar length (> 0), ks/k2 in (0, tan(theta0)**2), rest half angle in (0, pi/2),
        stroke fraction at which the corner stiffening reaches the cap (laws.py).
    v0 : float
        Impact speed (the nonlinear laws are velocity dependent), in [1e-6, 1e6].
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
    from restitution.model.scene import check_xi

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
        # Linear scenes: the exact kernels, as restitution.solve runs them (the COR does not
        # depend on v0 there). Called here directly, not through the API, which depends on this
        # module (through restitution.solvers.methods).
        from restitution.kernels.paper_chain import solve_linear
        from restitution.kernels.rigid2 import rigid2
        from restitution.model.chain import Chain

        hist = np.zeros((int(max_events) if history else 0, LY.N_HIST))
        if scene.beta == 0.0:
            out, name = rigid2(scene.alpha, scene.xi, int(max_events), hist), "impulsive"
        else:
            out = solve_linear(scene.alpha, scene.beta, scene.xi, 2, int(max_events), hist)
            name = "piecewise"
        ch = Chain._paper(scene.alpha, scene.beta, scene.xi, 2)
        return Result.from_row(ch, out, name, hist if history else None, passive=True)
    chosen = "adaptive" if method == "auto" else method
    if chosen == "verlet" and scene.beta == 0.0:
        raise SceneError("method='verlet' needs beta > 0 (a finite contact spring); got beta=0")
    if energy_tol is None:
        energy_tol = _default_etol(chosen, rtol, step)
    acct = np.zeros(5)
    if chosen == "reference":
        from restitution.solvers.reference import solve_reference

        out, hist = solve_reference(scene.alpha, v0, xi, cp, sp, rtol, max_events, acct, energy_tol)
        coarse, _ = solve_reference(
            scene.alpha, v0, xi, cp, sp, _coarser(rtol), max_events, np.zeros(5), energy_tol
        )
        _two_setting_estimate(out, coarse)
        hist = hist if history else None
    else:
        from restitution.kernels.stepping import METHOD_ADAPTIVE, METHOD_VERLET, solve_scene

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
            fine = run(METHOD_VERLET, rtol, step / 4, False, no_rows, np.zeros(5))
            _verlet_estimate(out, coarse, fine)
        else:
            free = bool(integrate_free)
            coarse = run(METHOD_ADAPTIVE, _coarser(rtol), step, free, no_rows, np.zeros(5))
            out = run(METHOD_ADAPTIVE, rtol, step, free, hist, acct)
            _two_setting_estimate(out, coarse, ADAPTIVE_SAFETY)
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


# Verlet's convergence in the step is erratic (contacts fall between steps): |cor(h) - cor(h/2)|
# alone was up to 93 times below the actual error of cor(h/2) on 120 random linear-contact
# chains (against the exact kernels); 2 max(|cor(h) - cor(h/2)|, |cor(h/2) - cor(h/4)|) up to
# 1.35 times, so the estimate is VERLET_SAFETY (4) times the larger change.
VERLET_SAFETY = 4.0


def _verlet_estimate(out, coarse, fine) -> None:
    """Verlet's error estimate for out = cor(h/2): VERLET_SAFETY * max(|cor(h) - cor(h/2)|,
    |cor(h/2) - cor(h/4)|); infinite when only a check run failed."""
    if out[LY.OUT_STATUS] != LY.STATUS_OK:
        return
    if coarse[LY.OUT_STATUS] != LY.STATUS_OK or fine[LY.OUT_STATUS] != LY.STATUS_OK:
        out[LY.OUT_ERR] = math.inf
        return
    change = max(abs(out[LY.OUT_COR] - coarse[LY.OUT_COR]), abs(out[LY.OUT_COR] - fine[LY.OUT_COR]))
    out[LY.OUT_ERR] = VERLET_SAFETY * change


# The adaptive method's COR change against 10 x rtol was up to 1.03 times below its actual error
# on random linear-contact chains (tests/test_accuracy.py, against the exact kernels).
ADAPTIVE_SAFETY = 4.0


def _two_setting_estimate(out, coarse, safety=1.0) -> None:
    """out's error estimate: at least ``safety`` x |COR change| against the coarser setting;
    infinite (no estimate) when only the coarser run failed."""
    if out[LY.OUT_STATUS] != LY.STATUS_OK:
        return
    if coarse[LY.OUT_STATUS] != LY.STATUS_OK:
        out[LY.OUT_ERR] = math.inf
    else:
        change = abs(out[LY.OUT_COR] - coarse[LY.OUT_COR])
        out[LY.OUT_ERR] = max(out[LY.OUT_ERR], safety * change)


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

    from restitution.kernels.stepping import METHOD_ADAPTIVE, METHOD_VERLET, solve_scene_batch
    from restitution.model.scene import check_xi
    from restitution.solvers.result import status_name

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
        coarse, out, fine = run(rtol, step), run(rtol, step / 2), run(rtol, step / 4)
        for row, c, f in zip(out, coarse, fine, strict=True):
            _verlet_estimate(row, c, f)
    else:
        coarse, out = run(_coarser(rtol), step), run(rtol, step)
        for row, other in zip(out, coarse, strict=True):
            _two_setting_estimate(row, other, ADAPTIVE_SAFETY)
    LY.void_unfinished(out)
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


# ------------------------------------------------------------------------------------------------
# General chains with any contact law and link laws (issue 13)
# ------------------------------------------------------------------------------------------------

CHAIN_METHODS = ("auto", "adaptive", "verlet")


def _chain_result(ms, ks, cs, cp, n, out, method, hist, omega):
    """Result of a chain row: alpha = m2/m1, beta = k1/k_contact (0 rigid; nan nonlinear),
    xi = c1/(2 k1) in kernel units (the paper's parameters where they apply)."""
    import dataclasses
    from types import SimpleNamespace

    kind = int(cp[0])
    beta = 0.0 if kind == laws.C_RIGID else (ks[0] / cp[1] if kind == laws.C_LINEAR else math.nan)
    scene = SimpleNamespace(
        alpha=float(ms[1]), beta=float(beta), xi=float(cs[0] / (2.0 * ks[0])), n_masses=n
    )
    r = Result.from_row(scene, out, method, hist)
    names = {f.name for f in dataclasses.fields(Result)}
    if "t_col" in names:  # the general API's field in user units
        r = dataclasses.replace(r, t_col=float(out[LY.OUT_TCOL]) / omega)
    return r


def solve_nonlinear_chain(
    m,
    k,
    c=None,
    contact_law="rigid",
    link_laws=None,
    v0: float = 1.0,
    method: str = "adaptive",
    rtol: float = 1e-9,
    max_events: int = 10_000,
    history: bool = False,
    *,
    step: float = 0.01,
    max_work: int | None = None,
    energy_tol: float | None = None,
    account: dict | None = None,
) -> Result:
    """COR of any one-dimensional chain with nonlinear contact and/or link laws.

    Parameters
    ----------
    m, k, c : sequences of float
        Masses m_1..m_N (m_1 touches the wall; N in [2, 512]), the springs k_i (> 0) and dashpots
        c_i (>= 0, default none) between neighbours, in any consistent units.
    contact_law : mapping or str
        {"law": "rigid"}, {"law": "linear", "k": k_contact}, {"law": "plastic", "k": unloading
        slope, "eta": ..., "dr": ...} (Section 3.1) or {"law": "hertz", "k": k_h} (F = k_h x**1.5).
    link_laws : list of mapping or str, optional
        One per spring: {"law": "linear"} (stiffness k_i) or {"law": "scissor", "L": ..., "ks":
        ..., "theta0": pi/4, "corner": 1.0} (Eq. 24, with k_i as the cap slope). Default linear.
    v0 : float
        Approach speed in [1e-6, 1e6] (user units; the nonlinear laws make the COR depend on it).
    method : {"auto", "adaptive", "verlet"}
        "auto" = "adaptive": DP5(4) with guaranteed event location for every phase; "verlet":
        the paper's fixed step (``step`` x the shortest period bound), the h/2 result returned.
    rtol : float
        Relative tolerance in [1e-14, 1e-2] (atol = rtol*v0).
    max_events, max_work : int
        Contact budget; work budget in right-hand-side evaluations (default
        kernels.nonlinear.MAX_WORK_DEFAULT): status ``work_budget_exhausted`` when it runs out.
    history : bool
        Attach the per-contact history (times in kernel units, omega*t).

    Returns
    -------
    Result
        ``method`` "adaptive" or "verlet"; ``error_estimate`` as for ``solve_nonlinear``; alpha =
        m2/m1, beta = k1/k_contact (0: rigid, nan: nonlinear contact), xi = c1/(2 sqrt(...)) in
        the paper's sense only for its scenes.
    """
    from restitution.kernels.stepping import (
        MAX_WORK_DEFAULT,
        METHOD_ADAPTIVE,
        METHOD_VERLET,
        solve_chain_scene,
    )

    _choice("method", method, CHAIN_METHODS)
    chosen = "adaptive" if method == "auto" else method
    rtol = _pos("rtol", rtol, 1e-14, 1e-2, low_open=False)
    step = _pos("step", step, 0.0, 0.25)
    max_events = _count("max_events", max_events)
    max_work = _count("max_work", MAX_WORK_DEFAULT if max_work is None else max_work)
    ms, lk, cs, cp, omega, kappa = pack_chain(m, k, c, contact_law, link_laws, v0)
    v0 = float(v0)
    if chosen == "verlet" and cp[0] == laws.C_RIGID:
        raise SceneError("method='verlet' needs a finite contact law, not 'rigid'")
    if energy_tol is None:
        energy_tol = _default_etol(chosen, rtol, step)
    n = ms.size
    hist = np.zeros((max_events if history else 0, LY.N_HIST))
    no_rows = np.zeros((0, LY.N_HIST))
    acct = np.zeros(5)
    code = METHOD_VERLET if chosen == "verlet" else METHOD_ADAPTIVE

    def run(tol, stp, rows, acc):
        return solve_chain_scene(
            ms, lk, cs, cp, v0, code, tol, stp, energy_tol, max_events, float(max_work), rows, acc
        )

    if chosen == "verlet":
        coarse = run(rtol, step, no_rows, np.zeros(5))
        out = run(rtol, step / 2, hist, acct)
        _verlet_estimate(out, coarse, run(rtol, step / 4, no_rows, np.zeros(5)))
    else:
        coarse = run(_coarser(rtol), step, no_rows, np.zeros(5))
        out = run(rtol, step, hist, acct)
        _two_setting_estimate(out, coarse, ADAPTIVE_SAFETY)
    if account is not None:
        account.update(
            kinetic=acct[0],
            elastic=acct[1],
            dissipated_contact=acct[2],
            dissipated_dashpot=acct[3],
            residual=acct[4],
            kappa=kappa,
        )
    ks = np.array([row[laws.SP_K2] for row in lk])
    return _chain_result(ms, ks, cs, cp, n, out, chosen, hist if history else None, omega)


def _count(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise SceneError(f"{name} must be a positive integer; got {value!r}")
    return int(value)


def solve_nonlinear_chain_many(
    masses,
    springs,
    dashpots=None,
    contact=None,
    links=None,
    v0=1.0,
    *,
    method: str = "adaptive",
    rtol: float = 1e-9,
    step: float = 0.01,
    max_events: int = 10_000,
    max_work: int | None = None,
):
    """``solve_nonlinear_chain`` over rows, in parallel (numba prange); returns a DataFrame.

    ``masses``, ``springs`` (and ``dashpots``, ``links``: None = none / all linear) are sequences
    with one list per row; ``contact`` one law spec per row or one for all (None = rigid);
    ``v0`` one number per row or one for all. Every row is checked first (SceneError names the
    row and the parameter). Columns: cor, n_collisions, omega_t_col, t_col (user units),
    e_translational, e_vibrational, e_dissipated, method, status, error_estimate. Failed rows
    have NaN cor and a status naming what failed; no row is ``ok`` unless finished and checked.
    """
    import pandas as pd

    from restitution.kernels.stepping import (
        MAX_WORK_DEFAULT,
        METHOD_ADAPTIVE,
        METHOD_VERLET,
        solve_chain_scene_batch,
    )
    from restitution.solvers.result import status_name

    _choice("method", method, CHAIN_METHODS)
    chosen = "adaptive" if method == "auto" else method
    rtol = _pos("rtol", rtol, 1e-14, 1e-2, low_open=False)
    step = _pos("step", step, 0.0, 0.25)
    max_events = _count("max_events", max_events)
    max_work = _count("max_work", MAX_WORK_DEFAULT if max_work is None else max_work)
    rows = len(masses)
    if len(springs) != rows:
        raise SceneError(f"springs has {len(springs)} rows, masses {rows}")

    def per_row(name, value, default):
        if value is None:
            return [default] * rows
        if isinstance(value, (str, dict, int, float)):
            return [value] * rows
        if len(value) != rows:
            raise SceneError(f"{name} has {len(value)} rows, masses {rows}")
        return [default if v is None else v for v in value]

    dash = per_row("dashpots", dashpots, None)
    cont = per_row("contact", contact, "rigid")
    link = per_row("links", links, None)
    speeds = per_row("v0", v0, 1.0)
    packed = []
    for i in range(rows):
        try:
            packed.append(pack_chain(masses[i], springs[i], dash[i], cont[i], link[i], speeds[i]))
            if chosen == "verlet" and packed[-1][3][0] == laws.C_RIGID:
                raise SceneError("method='verlet' needs a finite contact law, not 'rigid'")
        except SceneError as e:
            raise SceneError(f"{e} (row {i})") from None
    nmax = max([p[0].size for p in packed], default=2)
    m = np.ones((rows, nmax))
    lk = np.zeros((rows, nmax - 1, laws.N_SP))
    lk[:, :, laws.SP_K2] = 1.0
    c = np.zeros((rows, nmax - 1))
    n = np.zeros(rows, dtype=np.int64)
    cp = np.zeros((rows, laws.N_CP))
    vv = np.zeros(rows)
    omega = np.zeros(rows)
    for i, (ms, lki, cs, cpi, w, _) in enumerate(packed):
        k_ = ms.size
        m[i, :k_], lk[i, : k_ - 1], c[i, : k_ - 1], n[i], cp[i] = ms, lki, cs, k_, cpi
        vv[i], omega[i] = float(speeds[i]), w
    code = METHOD_VERLET if chosen == "verlet" else METHOD_ADAPTIVE
    etol = _default_etol(chosen, rtol, step)

    def run(tol, stp):
        return solve_chain_scene_batch(
            m, lk, c, n, cp, vv, code, tol, stp, etol, max_events, float(max_work)
        )

    if chosen == "verlet":
        coarse, out, fine = run(rtol, step), run(rtol, step / 2), run(rtol, step / 4)
        for row, c_, f in zip(out, coarse, fine, strict=True):
            _verlet_estimate(row, c_, f)
    else:
        coarse, out = run(_coarser(rtol), step), run(rtol, step)
        for row, other in zip(out, coarse, strict=True):
            _two_setting_estimate(row, other, ADAPTIVE_SAFETY)
    LY.void_unfinished(out)
    ok = out[:, LY.OUT_STATUS] == LY.STATUS_OK
    return pd.DataFrame(
        {
            "cor": out[:, LY.OUT_COR],
            "n_collisions": out[:, LY.OUT_NCOL].astype(np.int64),
            "omega_t_col": out[:, LY.OUT_TCOL],
            "t_col": np.where(ok, out[:, LY.OUT_TCOL] / omega, np.nan),
            "e_translational": out[:, LY.OUT_ETRANS],
            "e_vibrational": out[:, LY.OUT_EVIB],
            "e_dissipated": out[:, LY.OUT_EDISS],
            "method": chosen,
            "status": [status_name(s) for s in out[:, LY.OUT_STATUS]],
            "error_estimate": out[:, LY.OUT_ERR],
        }
    )


__all__ = [
    "CHAIN_METHODS",
    "LAW_DEFAULTS",
    "NL_METHODS",
    "build_laws",
    "pack_chain",
    "solve_nonlinear",
    "solve_nonlinear_chain",
    "solve_nonlinear_chain_many",
    "solve_nonlinear_many",
]
