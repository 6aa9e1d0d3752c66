"""The result of one scene, and the names of the kernels' status codes."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # imported where used (a single solve needs no pandas)
    import pandas as pd

from restitution.kernels import layout as L
from restitution.model.units import user_impulse, user_length, user_speed, user_time

# Status names by the layout constant that holds their code (a code the installed kernels do not
# define is simply absent).
_STATUS_NAMES = (
    ("STATUS_OK", "ok"),
    ("STATUS_EVENT_BUDGET", "event_budget_exhausted"),
    ("STATUS_ENERGY", "energy_account_open"),
    ("STATUS_ILL_CONDITIONED", "ill_conditioned"),
    ("STATUS_NONCONVERGED", "event_not_converged"),
    ("STATUS_PERMANENT_CONTACT", "permanent_contact"),
    ("STATUS_WORK_BUDGET", "work_budget_exhausted"),
    ("STATUS_INVALID", "invalid_parameters"),
    ("STATUS_NOT_RUN", "not_run"),
    ("STATUS_UNCHECKED", "unchecked"),
)
STATUS = {getattr(L, attr): name for attr, name in _STATUS_NAMES if hasattr(L, attr)}

MESSAGES = {
    "ok": "The contact sequence finished: no further contact is possible.",
    "event_budget_exhausted": "Stopped after max_events contacts; the sequence was NOT finished. "
    "Raise max_events.",
    "energy_account_open": "The independent energy account does not add up to 1 within the "
    "result's own error bound: do not trust this result; method='precise' solves a linear chain "
    "at high precision.",
    "ill_conditioned": (
        "Double precision cannot resolve this scene: an eigenbasis too ill-conditioned for a"
        " closed form, or round-off moves the result by more than 1e-4 (its replica check);"
        " method='precise' solves it at high precision."
    ),
    "event_not_converged": "An event root search did not converge within its step limit (a "
    "phase on rates many decades apart); the sequence was NOT finished. "
    "method='precise' solves a linear chain at high precision (mpmath: seconds to minutes).",
    "permanent_contact": "m1 never leaves the wall (proven): the chain comes to rest against it "
    "(cor 0, omega_t_col inf).",
    "work_budget_exhausted": "Stopped after the scene's work budget (counted in operations); the "
    "sequence was NOT finished. The exact solvers' budget grows with max_events above 100,000 "
    "(long chains need it); method='precise' solves a short linear chain at high precision "
    "(mpmath: seconds to minutes per scene).",
    "invalid_parameters": "The kernel refused parameters outside the range it handles.",
    "not_run": "The kernel did not finish this row.",
    "unchecked": "The contact sequence finished, but the method's second run, at the other "
    "setting that checks it, did not (its budget ran out): the COR has no error estimate "
    "(error_estimate inf). Raise max_events, or try another rtol (step for verlet).",
    "kernel_error": "The kernel raised an error on this row (its message is logged); no result.",
}

# A cause of an open account with the plastic contact (docs/physics.md): its kappa is
# fitted at the nominal depth, and a turn elsewhere can return more than the loading stored.
PLASTIC_ENERGY = (
    "With the plastic contact it can be the law itself creating energy: kappa is fitted at the "
    "depth of m1 alone at v0, and a turn at a depth x where k < (eta + 1)/2 kappa x**(eta - 1) "
    "returns more along the linear unloading than the loading stored (docs/physics.md; "
    "history=True gives each contact's depth)."
)


def _contact_law(scene) -> str | None:
    contact = getattr(scene, "contact", None)
    return contact.get("law") if contact is not None else None


RESULT_COLUMNS = (
    "cor",
    "n_collisions",
    "omega_t_col",
    "e_translational",
    "e_vibrational",
    "e_dissipated",
    "method",
    "status",
    "error_estimate",  # the method's own estimate of its COR error (0: exact up to round-off)
)
# Added to general-chain tables (user units; equal to omega_t_col for the paper's scenes).
T_COL = "t_col"

HISTORY_COLUMNS = ("omega_t_start", "omega_t_end", "v1_in", "v1_out", "x_max", "impulse")
# The same contacts in the scene's own units (Result.history, after HISTORY_COLUMNS): times, m1's
# velocity at the start and at the end of the contact, the deepest compression x = -u_1 and the
# wall's impulse. For the paper's non-dimensional scenes they equal the kernel-unit columns.
HISTORY_USER_COLUMNS = ("t_start", "t_end", "velocity_in", "velocity_out", "compression",
                        "wall_impulse")  # fmt: skip


_NOT_IN_DICT = ("history",)


def status_name(code: float) -> str:
    name = STATUS.get(code)  # float codes hash like their ints
    if name is not None:
        return name
    if not math.isfinite(code):
        return "not_run"
    return STATUS.get(int(code), f"unknown_status_{int(code)}")


@dataclass(frozen=True)
class Result:
    """COR and energy account of one scene.

    ``alpha, beta, xi`` summarise the scene (m2/m1, k_12/k_contact, c_12 omega/(2 k_12));
    ``omega_t_col`` is unit-free and ``t_col`` the same duration in the user's time unit
    (omega_t_col / omega). ``success`` is True when ``status == "ok"``; ``history`` (when
    requested) has one row per contact interval with the columns of ``HISTORY_COLUMNS`` (times
    omega*t, speeds / V0). ``scene`` is the ``restitution.Chain`` that was solved (for a
    paper-form solve built on first access: the paper's fast path builds no Chain).
    """

    alpha: float
    beta: float
    xi: float
    n_masses: int
    cor: float
    n_collisions: int
    omega_t_col: float
    e_translational: float
    e_vibrational: float
    e_dissipated: float
    method: str
    status: str
    error_estimate: float = 0.0
    history: pd.DataFrame | None = field(default=None, repr=False, compare=False)
    t_col: float = math.nan

    @property
    def scene(self):
        """The ``restitution.Chain`` that was solved (None for a row of no chain)."""
        d = self.__dict__
        ch = d.get("_scene")
        if ch is None and d.get("_paper"):  # a paper-form result: its Chain.paper, once
            from restitution.model.chain import Chain

            ch = d["_scene"] = Chain._paper(self.alpha, self.beta, self.xi, self.n_masses)
        return ch

    def with_scene(self, scene) -> Result:
        """This result with ``scene`` (a ``restitution.Chain``) attached."""
        self.__dict__["_scene"] = scene
        self.__dict__["_paper"] = False
        return self

    @property
    def success(self) -> bool:
        return self.status == "ok"

    @property
    def message(self) -> str:
        text = MESSAGES.get(self.status, self.status)
        if self.method == "precise":  # (not advice to use the method that gave it)
            text = re.sub(r"[ ;]*method='precise' solves[^.]*\.", ".", text).replace("..", ".")
        if self.status == "energy_account_open" and _contact_law(self.scene) == "plastic":
            text += " " + PLASTIC_ENERGY
        return text

    def plot(self, ax=None):
        """Draw the contact history: m_1's velocity at the start (open circle) and at the end
        (filled) of every contact against time, each contact a grey band from its start to its
        end (a line at a rigid wall's impact), and the centre of mass's final velocity
        ``cor * v0`` as a grey reference line; the scene's own units (the paper's scaled ones
        for its scenes). Returns the Axes (by default on a new single-column figure in the house
        style, ``restitution.plotting``). The motion itself: ``restitution.plotting.
        plot_trajectory(restitution.trajectory(result.scene, times))``.

        Needs the history: ``solve(..., history=True)``.
        """
        if self.history is None:
            raise ValueError("Result.plot draws the contact history: solve(..., history=True)")
        import matplotlib.style

        with matplotlib.style.context(_STYLE):
            if ax is None:
                from matplotlib.backends.backend_agg import FigureCanvasAgg
                from matplotlib.figure import Figure

                fig = Figure(figsize=(3.4, 3.4 * 0.76))
                FigureCanvasAgg(fig)
                ax = fig.add_subplot()
            _draw_history(ax, self)
        return ax

    def to_dict(self, history: bool = False) -> dict:
        d = {f.name: getattr(self, f.name) for f in fields(self) if f.name not in _NOT_IN_DICT}
        d["success"] = self.success
        d["message"] = self.message
        if self.scene is not None:
            d["scene"] = self.scene.to_dict()
        if history and self.history is not None:
            d["history"] = self.history.to_dict(orient="list")
        return d

    @classmethod
    def from_row(
        cls,
        scene,
        out: np.ndarray,
        method: str,
        hist: np.ndarray | None = None,
        passive: bool = False,
        lengths_of_v0: bool = True,
    ):
        """The Result of a kernel row of ``scene``: a ``restitution.Chain``, or the checked
        paper form (alpha, beta, xi, n_masses) of the fast path (its Chain is built only when
        ``Result.scene`` is read). ``method`` is completed from the row's OUT_FLAGS
        (``+sticking``, ``+rigid-limit``) by ``restitution.solvers.methods.label``. An unfinished
        row
        (``layout.UNFINISHED``; with ``passive``, a linear scene, an open energy account too)
        has NaN COR, duration and energies. ``lengths_of_v0``: the history's x_max is in units
        of V0 / omega (the exact kernels) or, if False, of the scene's speed unit / omega (the
        stepping kernels, where v0 enters as given)."""
        history = None
        if hist is not None:
            n = min(int(out[L.OUT_NEVENTS]), hist.shape[0])
            history = _history(hist[:n], scene, lengths_of_v0)
        row = out.tolist()  # Python floats, once
        unfinished = L.UNFINISHED_PASSIVE if passive else L.UNFINISHED
        if row[L.OUT_STATUS] in unfinished or row[L.OUT_STATUS] != row[L.OUT_STATUS]:
            for k in L.VOIDED:  # not a finished result: no COR, duration or energies
                row[k] = math.nan
        ncol, tcol = row[L.OUT_NCOL], row[L.OUT_TCOL]
        if len(row) > L.OUT_FLAGS and row[L.OUT_FLAGS]:  # NaN or a flag: let the table say
            method = label(method, out)
        # Built without the frozen dataclass's per-field __setattr__ (this is on the path of
        # every solve call, where the API's overhead is measured in microseconds).
        self = object.__new__(cls)
        paper = type(scene) is tuple
        if paper:
            (alpha, beta, xi, n_masses), omega, chain = scene, 1.0, None
        else:
            alpha, beta, xi, n_masses = scene.alpha, scene.beta, scene.xi, scene.n_masses
            omega = getattr(scene, "omega", 1.0)
            chain = scene if hasattr(scene, "to_dict") else None
        self.__dict__.update(
            alpha=alpha,
            beta=beta,
            xi=xi,
            n_masses=n_masses,
            cor=row[L.OUT_COR],
            n_collisions=int(ncol) if ncol == ncol else 0,
            omega_t_col=tcol,
            e_translational=row[L.OUT_ETRANS],
            e_vibrational=row[L.OUT_EVIB],
            e_dissipated=row[L.OUT_EDISS],
            method=method,
            status=status_name(row[L.OUT_STATUS]),
            error_estimate=row[L.OUT_ERR],
            history=history,
            t_col=user_time(tcol, omega),
            _scene=chain,
            _paper=paper,
        )
        return self


# The house style (restitution/restitution.mplstyle; restitution.plotting applies the same file).
_STYLE = str(Path(__file__).resolve().parents[1] / "restitution.mplstyle")


def _draw_history(ax, r: Result) -> None:
    h = r.history
    scene = r.scene
    scaled = scene is None or (scene.omega == 1.0 and scene.v0 == 1.0 and scene.masses[0] == 1.0)
    v0 = 1.0 if scene is None else float(scene.v0)
    ts, te = h["t_start"].to_numpy(), h["t_end"].to_numpy()
    vin, vout = h["velocity_in"].to_numpy(), h["velocity_out"].to_numpy()
    for k, (a, b) in enumerate(zip(ts, te, strict=True)):
        if b > a:
            ax.axvspan(a, b, color="0.88", lw=0, zorder=0, label="_contact" if k else "contact")
        else:
            ax.axvline(a, color="0.55", lw=0.6, ls=(0, (1, 1.5)), zorder=0,
                       label="_impact" if k else "impact")  # fmt: skip
        ax.plot([a, b], [vin[k], vout[k]], color="0.55", lw=0.6, zorder=1)
    ax.plot(ts, vin, color="#000000", marker="o", mfc="none", ls="none", label="start")
    ax.plot(te, vout, color="#000000", marker="o", ls="none", label="end")
    if math.isfinite(r.cor):
        ax.axhline(r.cor * v0, color="0.75", lw=2.4, zorder=0, label=r"$e\,V_0$")
    ax.axhline(0.0, color="0.3", lw=0.4, zorder=0)
    if scaled:
        ax.set_xlabel(r"time $\omega t$")
        ax.set_ylabel(r"velocity $v_1 / V_0$ of $m_1$")
    else:
        ax.set_xlabel("time $t$")
        ax.set_ylabel("velocity $v_1$ of $m_1$")
    ax.legend(loc="best")


def _history(hist: np.ndarray, scene, lengths_of_v0: bool) -> pd.DataFrame:
    """The history table: HISTORY_COLUMNS as the kernel recorded them, then
    HISTORY_USER_COLUMNS in the scene's units (``restitution.model.units``)."""
    import pandas as pd  # only with history=True: a plain solve imports no pandas

    if type(scene) is tuple:  # the paper's form: the kernel's units are the scene's
        omega, v0, m1 = 1.0, 1.0, 1.0
    else:
        omega = float(getattr(scene, "omega", 1.0))
        v0 = float(getattr(scene, "v0", 1.0))
        masses = getattr(scene, "masses", None)
        m1 = float(masses[0]) if masses is not None else 1.0
    # One float block handed to one DataFrame: inserting the user columns one by one cost
    # 0.5-1.7 ms per solve, most of a grazing evaluation in the design study's polish.
    k = len(HISTORY_COLUMNS)
    table = np.empty((hist.shape[0], k + len(HISTORY_USER_COLUMNS)))
    table[:, :k] = hist
    col = dict(zip(HISTORY_COLUMNS, table[:, :k].T, strict=True))
    table[:, k] = user_time(col["omega_t_start"], omega)
    table[:, k + 1] = user_time(col["omega_t_end"], omega)
    table[:, k + 2] = user_speed(col["v1_in"], v0)
    table[:, k + 3] = user_speed(col["v1_out"], v0)
    table[:, k + 4] = user_length(col["x_max"], omega, v0 if lengths_of_v0 else 1.0)
    table[:, k + 5] = user_impulse(col["impulse"], m1, v0)
    return pd.DataFrame(table, columns=list(HISTORY_COLUMNS + HISTORY_USER_COLUMNS), copy=False)


EXTRAPOLATED = "piecewise+extrapolated"
BRACKETED = "+critical-bracket"


def label(name: str, out) -> str:
    """The method recorded in a result: ``name``, plus ``+sticking`` when the kernel used the
    sticking limit (bit 0 of OUT_FLAGS), ``impulsive+rigid-limit`` for a contact solved as
    its rigid limit, ``piecewise+extrapolated`` for that limit corrected to the contact's
    stiffness by two finite-stiffness runs (kernels.exact_chain._extrapolated), or
    ``+critical-bracket`` for a scene next to critical damping solved as the mean of runs with
    its dashpots scaled around it (solvers.exact.bracketed)."""
    flags_at = getattr(L, "OUT_FLAGS", None)
    if flags_at is not None and len(out) > flags_at and math.isfinite(out[flags_at]):
        f = int(out[flags_at])
        if f & L.FLAG_RIGID_LIMIT:
            name = "impulsive+rigid-limit"
        if f & L.FLAG_EXTRAPOLATED:
            name = EXTRAPOLATED
        if f & L.FLAG_CRITICAL_BRACKET:
            name += BRACKETED
        if f & L.FLAG_STICKING:
            name += "+sticking"
    return name
