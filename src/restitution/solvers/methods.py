"""The solver table: every method, the scenes it applies to, its cost rank and its runner.

Shaped like the ``METHODS`` dict of scipy's ``integrate/_ivp/ivp.py``: a method is one entry of
``METHODS``; ``choose`` is the only dispatcher (``auto`` takes the cheapest exact method that
applies, else the cheapest numerical one; a forced method is checked against the scene here and
nowhere else). docs/guides/adding-a-method.md shows how to add one.

========== ===================================================================================
impulsive  rigid wall, linear links and dashpots: impulsive reversal of m1's velocity at each
           contact, closed-form motion between contacts (exact)
piecewise  linear contact spring, or a Kelvin-Voigt contact (spring and dashpot), linear links
           and dashpots: closed form per phase, exact switching times (exact)
adaptive   Dormand-Prince 8(5,3) (DOP853) with guaranteed event location, for the phases whose
           force law is nonlinear (any law)
verlet     the paper's velocity Verlet, fixed step (finite contact stiffness, any chain)
reference  scipy ``solve_ivp`` DOP853 with events: slow, for checks (two masses)
precise    linear contact and links: the exact event sequence at 40 digits (mpmath; 80 or 160
           where 40 do not agree with 20 more); for scenes double precision cannot resolve
           (``ill_conditioned``); never chosen by ``auto`` (seconds per scene)
========== ===================================================================================

A runner takes a validated ``Chain`` and ``Options`` and returns ``(out, hist)``: the kernel's
output row (``restitution.kernels.layout``; times are omega * t) and the contact history (or
None). ``label`` names what was used: ``impulsive+sticking`` when the kernel continued a Zeno
chatter by its sticking limit (bit 0 of ``OUT_FLAGS``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from restitution.kernels import layout as L
from restitution.kernels.constants import MAX_EVENTS_DEFAULT
from restitution.model.chain import Chain, SceneError, check
from restitution.model.ranges import HISTORY_MAX_EVENTS, _show
from restitution.model.units import kernel_time
from restitution.solvers import exact
from restitution.solvers.result import label

# Bit of out[OUT_FLAGS] set by the chain kernel when it used the sticking limit.
FLAG_STICKING = L.FLAG_STICKING
# Bit set by the chain kernel when a very stiff contact was solved as its rigid limit.
FLAG_RIGID_LIMIT = L.FLAG_RIGID_LIMIT
FLAG_EXTRAPOLATED = L.FLAG_EXTRAPOLATED


@dataclass(frozen=True)
class Options:
    """Settings of one solve (checked by ``options``)."""

    history: bool = False
    max_events: int = MAX_EVENTS_DEFAULT
    rtol: float = 1e-9
    step: float = 0.01


def check_history(history) -> bool:
    """``history`` as a bool: True or False (numpy's too); anything else is an error (the text
    "no" would be true)."""
    if not isinstance(history, (bool, np.bool_)):
        raise SceneError(f"history must be True or False; got {_show(history)}")
    return bool(history)


def check_events(max_events, history: bool) -> int:
    """The contact budget: RANGES["max_events"], and with a history at most
    HISTORY_MAX_EVENTS (its rows are allocated before the solve: 48 bytes per contact)."""
    n = check("max_events", max_events)
    if history and n > HISTORY_MAX_EVENTS:
        raise SceneError(
            f"max_events must be at most {HISTORY_MAX_EVENTS:,} with a history (one 48-byte "
            f"row per contact is allocated before the solve); got {_show(max_events)}"
        )
    return n


def options(history=False, max_events=MAX_EVENTS_DEFAULT, rtol=1e-9, step=0.01) -> Options:
    history = check_history(history)
    return Options(
        history, check_events(max_events, history), check("rtol", rtol), check("step", step)
    )


@dataclass(frozen=True)
class Method:
    """One row of the solver table.

    ``applies(chain)`` returns None when the method can solve the scene, else the reason (shown
    to the user when the method was forced); it reads only the scene's kind (linear or not, rigid
    wall or not, two masses or more, the contact law), so a choice holds for every scene of a kind.
    ``cost`` orders methods for ``auto`` (lower first); only ``exact`` methods or, when none
    applies, numerical ones are picked by ``auto``. ``settings`` names the numerical settings
    (``Options`` fields ``rtol``, ``step``) its runners read: any other one given is refused
    (``check_settings``), since it would do nothing. ``run(chain, options)`` solves one scene and
    ``run_many(table, rows, max_events, bar, block)`` the rows of a checked scene table
    (``restitution.tables.scene_table``); both return kernel rows (``run_many``: and {position in
    rows: error message} of rows whose kernel raised).
    """

    name: str
    exact: bool
    cost: int
    applies: Callable[[Chain], str | None]
    run: Callable[[Chain, Options], tuple]
    run_many: Callable
    doc: str
    settings: tuple[str, ...] = ()


# ----------------------------------------------------------------------------------------------
# Applicability
# ----------------------------------------------------------------------------------------------
def _impulsive_applies(ch: Chain) -> str | None:
    if not ch.linear:
        return "it needs linear contact and links; use 'adaptive' for nonlinear laws"
    if not ch.rigid:
        return "'impulsive' needs beta = 0 (a rigid wall, k_contact = inf); use 'piecewise'"
    return None


def _piecewise_applies(ch: Chain) -> str | None:
    if exact.kelvin_voigt(ch):
        return None  # piecewise linear: the force-zero end and the free stretch are events
    if not ch.linear:
        return (
            "it needs a linear or Kelvin-Voigt contact and linear links; use 'adaptive' for "
            "nonlinear laws"
        )
    if ch.rigid:
        return "'piecewise' needs beta > 0 (a finite k_contact); use 'impulsive'"
    return None


def _stepping_range(ch: Chain) -> str | None:
    """Why the stepping kernels cannot take ``ch`` (the laws' handled ranges and the frequency
    spread of ``laws.pack_chain``; a nonlinear Chain was packed when it was built), or None."""
    from restitution.solvers.numerical import packed

    try:
        packed(ch)
    except SceneError as e:
        return str(e)
    return None


def _adaptive_applies(ch: Chain) -> str | None:
    return _stepping_range(ch)  # any law, within the handled ranges


def _verlet_applies(ch: Chain) -> str | None:
    if ch.rigid:
        return "it needs a finite contact law (beta > 0), not a rigid wall"
    return _stepping_range(ch)


def _precise_applies(ch: Chain) -> str | None:
    if not ch.linear and not exact.kelvin_voigt(ch):
        return (
            "it needs a linear or Kelvin-Voigt contact and linear links (the event sequence is "
            "solved in closed form)"
        )
    return None


# The laws restitution.solvers.reference writes out itself (a law added to the model is refused
# here until it is written there too: docs/guides/adding-a-law.md).
REFERENCE_CONTACTS = ("rigid", "linear", "plastic")
REFERENCE_LINKS = ("linear", "scissor")


def _reference_applies(ch: Chain) -> str | None:
    if ch.n_masses != 2:
        return "it is implemented for two masses only (n_masses must be 2)"
    law = ch.contact_law["law"]
    if law not in REFERENCE_CONTACTS:
        return f"it does not implement the {law!r} contact law"
    for spec in ch.link_laws:
        if spec["law"] not in REFERENCE_LINKS:
            return f"it does not implement the {spec['law']!r} link law"
    return None


# ----------------------------------------------------------------------------------------------
# Runners
# ----------------------------------------------------------------------------------------------
def _run_numerical(name: str):
    """Single runner of a numerical method: the chain (two masses included) on the one
    nonlinear stack (``restitution.solvers.numerical``); ``reference`` on scipy."""

    def run(ch: Chain, opts: Options):
        from restitution.solvers import numerical

        if name == "reference":
            out, hist = numerical.solve_reference_chain(
                ch, opts.rtol, opts.max_events, opts.history
            )
        else:
            out, hist = numerical.solve_chain(
                ch, name, opts.rtol, opts.step, opts.max_events, opts.history
            )
        return numerical.result(ch, out, name, hist), None

    return run


def _numerical_many(name: str):
    """Batch runner of a stepping method: the rows grouped by their ``rtol`` / ``step``
    settings, each group in parallel blocks of one kernel call (``numerical.solve_chains``). If
    a block raises, its rows are solved one by one so that only the failing rows are lost (NaN
    with status ``kernel_error``)."""

    def run_many(table, rows, max_events, bar, block):
        from restitution.solvers import numerical

        groups: dict[tuple, list] = {}
        for j, i in enumerate(rows):
            s = table.settings(int(i))
            groups.setdefault((s.get("rtol"), s.get("step")), []).append(j)
        out = np.full((len(rows), L.N_OUT), np.nan)
        errors = {}
        for (rtol, step), members in groups.items():
            given = {k: v for k, v in (("rtol", rtol), ("step", step)) if v is not None}
            opts = options(False, max_events, **given)

            def solve(chains, opts=opts):
                return numerical.solve_chains(chains, name, opts.rtol, opts.step, max_events)

            for start in range(0, len(members), block):
                sel = np.asarray(members[start : start + block])
                chains = [table.chain(int(rows[j])) for j in sel]
                try:
                    done = solve(chains)
                except Exception:  # noqa: BLE001 - a kernel failure must not lose the table
                    done = np.full((len(sel), L.N_OUT), np.nan)
                    for j, ch in enumerate(chains):
                        try:
                            done[j] = solve([ch])[0]
                        except Exception as e:  # noqa: BLE001
                            errors[int(sel[j])] = f"kernel_error ({type(e).__name__}: {e})"
                out[sel, : done.shape[1]] = done
                bar.update(len(sel))
        return out, errors, {}

    return run_many


def row_by_row(name: str):
    """A batch runner that solves the rows one at a time with the method's single runner."""

    def run_many(table, rows, max_events, bar, block):
        out = np.full((len(rows), L.N_OUT), np.nan)
        results = {}
        for j, i in enumerate(rows):
            ch = table.chain(int(i))
            opts = options(False, max_events, **table.settings(int(i)))
            row, _ = METHODS[name].run(ch, opts)
            if isinstance(row, np.ndarray):
                out[j] = row
            else:  # a Result (the numerical runners)
                results[j] = row.with_scene(ch)
            bar.update(1)
        return out, {}, results

    return run_many


# Digits of the 'precise' method: each run is checked at 20 more; where the two disagree (a
# sequence chaotic enough to need more) the next, up to the last.
PRECISE_DPS = (40, 80, 160)


def _run_precise(ch: Chain, opts: Options):
    """The linear chain as given (user units, every float exact in mpmath) at the first of
    PRECISE_DPS whose run agrees with one at 20 more digits. The error estimate is their
    difference (at least half an ulp of the COR, the rounding to float); e_dissipated is the
    remainder of the energy account, not an independent integral (the two runs are the check).
    A damped scene whose run does not finish (at critical damping its eigenbasis is singular
    even in mpmath: the root search stalls) is extrapolated from runs with its dashpots scaled
    by 1 -+ d, 1 -+ 2 d (``exact.off_critical``, d = PRECISE_BRACKET)."""
    if opts.history:
        raise SceneError("history is not recorded by the 'precise' method; use history=False")
    c = ch.dashpots
    cc = float(ch.contact["c"]) if exact.kelvin_voigt(ch) else 0.0  # (the user's units)
    out = _precise_row(ch, c, cc, opts)
    failed = out[L.OUT_STATUS] in (L.STATUS_NONCONVERGED, L.STATUS_ILL_CONDITIONED)
    if failed and (c.any() or cc > 0.0):
        out = exact.off_critical(
            lambda s, h: _precise_row(ch, c * (1.0 + s), cc * (1.0 + s), opts),
            out,
            exact.NO_HIST,
            steps=(PRECISE_BRACKET,),
        )
    return out, None


# The precise method's bracket: mpmath's 40 digits keep about 30 at a basis condition of 1e10,
# and the extrapolation's error, O(d^4), is far below them (the kernels' d = 1e-5 would leave
# an estimate of about 1e-11 where this one leaves round-off).
PRECISE_BRACKET = 1e-10


def _precise_row(ch: Chain, c, cc: float, opts: Options) -> np.ndarray:
    """Kernel-layout row of ``solve_precise`` on ch with the dashpots c (and a Kelvin-Voigt
    contact's cc)."""
    from restitution.solvers.precise import solve_precise

    out = np.full(L.N_OUT, math.nan)
    out[L.OUT_FLAGS] = 0.0
    try:
        for dps in PRECISE_DPS:
            r = solve_precise(
                ch.masses,
                ch.springs,
                c,
                ch.k_contact,
                cc=cc,
                dps=dps,
                max_events=opts.max_events,
                velocities=ch.velocities,
                stretches=ch.stretches,
                v0=ch.v0,
            )
            if r.status != "ill_conditioned":
                break
    except RuntimeError:  # a phase whose end its root search did not reach (never ending)
        out[L.OUT_STATUS] = L.STATUS_NONCONVERGED
        return out
    out[L.OUT_NCOL] = out[L.OUT_NEVENTS] = r.n_collisions
    if r.status == "event_budget_exhausted":
        out[L.OUT_STATUS] = L.STATUS_EVENT_BUDGET
        return out
    out[L.OUT_STATUS] = L.STATUS_OK if r.status == "ok" else L.STATUS_ILL_CONDITIONED
    out[L.OUT_COR] = r.cor
    out[L.OUT_TCOL] = kernel_time(r.t_col, ch.omega)
    out[L.OUT_ETRANS] = r.e_translational
    out[L.OUT_EVIB] = r.e_vibrational
    out[L.OUT_EDISS] = 1.0 - r.e_translational - r.e_vibrational
    out[L.OUT_ERR] = max(r.error_estimate, 0.5 * math.ulp(r.cor))
    return out


def _exact_many(table, rows, max_events, bar, block):
    out, errors = exact.run_many(table, rows, max_events, bar, block)
    return out, errors, {}


METHODS: dict[str, Method] = {
    "impulsive": Method(
        "impulsive", True, 0, _impulsive_applies, exact.run, _exact_many, "rigid wall, exact"
    ),
    "piecewise": Method(
        "piecewise",
        True,
        1,
        _piecewise_applies,
        exact.run,
        _exact_many,
        "linear or Kelvin-Voigt contact, exact",
    ),  # fmt: skip
    "adaptive": Method(
        "adaptive",
        False,
        10,
        _adaptive_applies,
        _run_numerical("adaptive"),
        _numerical_many("adaptive"),
        "DOP853, any chain",
        settings=("rtol",),
    ),  # fmt: skip
    "verlet": Method(
        "verlet",
        False,
        20,
        _verlet_applies,
        _run_numerical("verlet"),
        _numerical_many("verlet"),
        "velocity Verlet",
        settings=("step",),
    ),  # fmt: skip
    "reference": Method(
        "reference",
        False,
        30,
        _reference_applies,
        _run_numerical("reference"),
        row_by_row("reference"),
        "scipy DOP853",
        settings=("rtol",),
    ),  # fmt: skip
    # exact=False and the highest cost: 'auto' never picks it (seconds per scene).
    "precise": Method(
        "precise",
        False,
        40,
        _precise_applies,
        _run_precise,
        row_by_row("precise"),
        "exact at 40+ digits (mpmath)",
    ),  # fmt: skip
}
NAMES = ("auto", *METHODS)


def check_method(value) -> str:
    """``value`` if it names a method (or 'auto'); else SceneError listing them."""
    if not isinstance(value, str) or (value != "auto" and value not in METHODS):
        raise SceneError(f"method must be one of {', '.join(NAMES)}; got {value!r}")
    return value


def check_settings(method: Method, given) -> None:
    """SceneError naming the first of the settings ``given`` (names) that ``method`` does not
    read: it would do nothing. The one check of solve, trajectory and the scene tables."""
    for name in given:
        if name not in method.settings:
            reads = " and ".join(method.settings) or "no numerical setting"
            raise SceneError(
                f"{name} would do nothing: the method {method.name!r} that solves this scene "
                f"reads {reads} (leave {name} out, or choose a method that reads it)"
            )


def choose(ch: Chain, method: str = "auto") -> Method:
    """The method that solves ``ch``: the forced one if it applies, else the cheapest exact
    one, else the cheapest numerical one. The one place a method is chosen or checked."""
    check_method(method)
    if method != "auto":
        m = METHODS[method]
        reason = m.applies(ch)
        if reason is not None:
            raise SceneError(f"method {method!r} does not fit this scene: {reason}")
        return m
    ranked = sorted(METHODS.values(), key=lambda m: (not m.exact, m.cost))
    reasons = []
    for m in ranked:
        reason = m.applies(ch)
        if reason is None:
            return m
        reasons.append(f"{m.name}: {reason}")
    raise SceneError("no method applies to this scene (" + "; ".join(reasons) + ")")


def choose_paper(beta: float, n_masses: int, method: str = "auto") -> Method:
    """``choose`` for a checked linear scene of the paper's form, without building its Chain
    (the per-call overhead of ``solve`` matters): ``choose`` asked once per kind (rigid wall or
    not, two masses or more) and method, with a representative Chain of that kind."""
    if type(method) is not str:
        check_method(method)  # raises: not a method's name (and not hashable for the cache)
    return _choose_kind(beta == 0.0, n_masses == 2, method)


@functools.cache
def _choose_kind(rigid: bool, two: bool, method: str) -> Method:
    return choose(Chain._paper(1.0, 0.0 if rigid else 1.0, 0.0, 2 if two else 3), method)


__all__ = [
    "METHODS",
    "NAMES",
    "Method",
    "Options",
    "check_method",
    "check_settings",
    "choose",
    "choose_paper",
    "label",
    "options",
    "row_by_row",
]
