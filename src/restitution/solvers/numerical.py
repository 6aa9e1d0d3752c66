"""Runners of the numerical methods: any chain, two masses included, on the one nonlinear stack.

``solve_chain`` solves one validated ``Chain`` by ``adaptive`` (DOP853 with guaranteed event
location, the ends of power-law contacts in sigma = sqrt(x)) or ``verlet`` (the paper's fixed
step; the h/2 result is returned) on
``restitution.kernels.stepping.solve_scene``; ``solve_chains`` solves many with the same settings
in one parallel call of ``solve_scene_batch`` (numba ``prange``; rows independent, results
bit-identical to ``solve_chain`` and for any thread count); ``solve_reference_chain`` runs the
scipy reference (``restitution.solvers.reference``, two masses). The method is chosen by
``restitution.solvers.methods`` (``METHODS``), never here.

``error_estimate`` of a numerical method is the change of the COR between two settings:
|cor(h/2) - cor(h)| for ``verlet``; 4 |cor(rtol) - cor(rtol/100)| for ``adaptive``, at least
the sum of its local error estimates of the total momentum (/ M v0); |cor(rtol) - cor(rtol/10)|,
at least rtol, for ``reference``. All three return their finer run (``verlet`` h/2, ``adaptive``
rtol/100, ``reference`` rtol/10: local extrapolation, the accuracy of the run the estimate already
paid for); the estimate stays the one sized for the setting's run (the adaptive floor the larger
of the two runs' local-error sums). Where only the finer run failed, the setting's own run is
returned with the status ``unchecked`` and an infinite estimate (so is a row whose check run
alone failed): an ``ok`` row is a checked one. The checks run finer, not coarser: DOP853's
errors at rtol and 10 rtol were of one size and sign on long sequences (98 contacts: 2.2e-8 and
1.8e-8), so their difference fell below the error, while the finer run's error is a tenth of it; the
reference's plastic contacts at rtol >= 1e-8 were sized by its max_step (1/50 of a period), not
rtol (the same 2.47e-8 off at rtol 1e-6, 1e-7 and 1e-8), so its check at 10 rtol had left 7 of
80 random plastic rows outside the estimate at rtol 1e-8 (up to 2.5 times). The adaptive check
is two decades finer, not one (``ADAPTIVE_GAP``, measured there): one decade apart, the two runs
were often as far off as each other. Not
divided by the Richardson factor (3 for a second-order method, ~1 for DOP853 at proportional
tolerance): the hard-case suite (tests/test_hard.py) measured errors 1.5 to
6000 times above such asymptotic estimates, because contact events fall between steps and shallow
contacts appear or vanish with the setting, so convergence is not asymptotic there.
"""

from __future__ import annotations

import math

import numpy as np

from restitution.kernels import layout as LY
from restitution.kernels.constants import EPS, MAX_EVENTS_DEFAULT, ROUNDOFF_ULPS
from restitution.model import laws
from restitution.model.chain import Chain
from restitution.model.laws import pack_chain
from restitution.model.ranges import SceneError
from restitution.solvers.result import Result

STEPPING = ("adaptive", "verlet")  # the methods of the stepping kernels

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


def _coarser(rtol: float) -> float:
    return min(10.0 * rtol, 1e-2)


# The reference's check run is coarser in both settings, rtol (against rtol/10) and half the
# steps per period of its max_step (reference.STEPS_PER_PERIOD): where the max_step, not rtol,
# sizes the steps (plastic contacts at rtol >= 1e-8) two runs with one max_step share the error
# (one scene 2.47e-8 off at rtol 1e-6, 1e-7 and 1e-8 alike, another 1.12e-7 at both 1e-7 and
# 1e-8 under an estimate of 1e-7).


# The adaptive method's check run is ADAPTIVE_GAP times finer than the setting, and it is the run
# returned. One decade apart (the rule until 2026-11-27) the two runs often shared their error: a
# two-mass Hertz chain was 1.60e-6 and 1.43e-6 off at rtol 1e-6 and 1e-7, then 8.4e-8 at 1e-8.
# On 36,488 random chains of 2-4 masses (Hertz, plastic, linear and Hunt-Crossley contacts,
# scissor links on a quarter, dashpots; against the rtol 1e-14 run, rows whose reference estimate
# is below a tenth of theirs) the result was outside its estimate on 21 rows at rtol 1e-4 (up to
# 15.9 times), 37 at 1e-6 (up to 144 times), 2 at 1e-9 (1.37 times), none at 1e-11. Two decades
# apart: 4 (2.1 times), 1 (3.6 times), none, none. The pair costs 1 + 1.8 runs at the setting
# (DOP853's work grows like rtol**(-1/8)) instead of 1 + 1.33, for the rtol/100 run's result: at
# equal error it is cheaper than the old pair was (1.33 + 1.8). Measured on 3,650 such rows per
# call of solve_many: 0-13 % longer at equal rtol (rtol 1e-4..1e-14).
ADAPTIVE_GAP = 100.0
FINEST_RTOL = 1e-15  # the finest check run, still above DOP853's round-off floor
# The work budget of both adaptive runs, in units of ``max_work``: the finer run's work is about
# 10**(2/8) = 1.8 times the setting's (DOP853). With one budget, a long scissor sequence (alpha
# 1.9e4, L = 57, 2026-11-27) finished at rtol 1e-9 and ran out at 1e-11, so the row lost its
# estimate; the check run has the same budget, so that a scene whose finer run finishes is never
# left without one (a plastic scene at alpha 1.2e4 ran out at rtol 1e-9 only).
FINER_WORK = 2.0


def _work_budget(method: str, max_work=None) -> float:
    """The work budget of each of a method's runs: ``max_work`` (default
    ``stepping.MAX_WORK_DEFAULT``), FINER_WORK times it for ``adaptive``."""
    base = float(_kernels().MAX_WORK_DEFAULT if max_work is None else max_work)
    return base * (FINER_WORK if method == "adaptive" else 1.0)


def _finer(rtol: float) -> float:
    """The adaptive method's check setting, the run it returns: rtol / ADAPTIVE_GAP, at least
    FINEST_RTOL (the declared floor 1e-14 checks at 1e-15)."""
    return max(rtol / ADAPTIVE_GAP, FINEST_RTOL)


# The two adaptive runs differ in their free flights' step cap too (stepping.HMAX_FREE, in units
# of 1/w_free, for the run returned): the run at the setting's rtol takes steps up to
# (rtol / _finer(rtol))**(1/8) times longer, the ratio of DOP853's steps between the two rtol.
# Where a flight's steps were the cap's, not the error control's (a flight on soft links, whose
# stiffest slope sets w_free), the two runs took the same steps and their COR change said
# nothing about the cap's truncation error, which the summed local errors of the momentum do
# not see either (a free flight keeps the momentum): two masses at a rigid wall on the paper's
# scissor link (alpha = 2, rtol 1e-2) gave the same COR at rtol 1e-2 and 1e-4 to 1e-15, an
# estimate of 2.8e-14 and an error of 1.9e-8 (2026-12-07). The returned run is unchanged.
def _check_cap(rtol: float) -> float:
    """The free-flight step cap of the adaptive method's run at the setting ``rtol``."""
    return _kernels().HMAX_FREE * (rtol / _finer(rtol)) ** 0.125


# Where that run fails while the finer one finishes, it is run again with the returned run's cap:
# the longer steps can break a creep out of a guarded contact into a chatter (a damped scissor
# scene at rtol 1e-5, tests/test_contact_rest.py: 51,674 contacts until the work budget ran out,
# 12 with the cap), and a row with a finite estimate (as before the longer steps) is worth more
# than an unchecked one.
def _retry_check(out, check) -> bool:
    """True where the check run (longer free-flight steps) must be run again with the cap of
    the returned run: it failed and the returned run finished."""
    return out[LY.OUT_STATUS] == LY.STATUS_OK and check[LY.OUT_STATUS] != LY.STATUS_OK


# Verlet's convergence in the step is erratic (contacts fall between steps): |cor(h) - cor(h/2)|
# alone was up to 93 times below the actual error of cor(h/2) on 120 random linear-contact
# chains (against the exact kernels); 2 max(|cor(h) - cor(h/2)|, |cor(h/2) - cor(h/4)|) up to
# 1.35 times. 4 times the larger change then missed 6 of 5,100 rows of 1,750 random two-mass scenes
# (alpha 0.1-100, beta 1e-4-1, xi 0 or 0.01-10; steps 0.01, 0.005, 0.002), by up to 2.67 times:
# there the three runs shared an error of 1e-6 that did not shrink from h to h/4 (it did at
# h/8). VERLET_SAFETY (16) covers that sample with the worst at 0.67 (2026-11-27). An empirical
# factor, not a proof (docs/solvers.md).
VERLET_SAFETY = 16.0


def _unchecked(out) -> None:
    """Mark a finished row whose check run did not finish: status ``unchecked``, no estimate
    (inf). It is not ``ok``: an ok row is a checked result."""
    out[LY.OUT_ERR] = math.inf
    out[LY.OUT_STATUS] = LY.STATUS_UNCHECKED


def _verlet_estimate(out, coarse, fine) -> None:
    """Verlet's error estimate for out = cor(h/2): VERLET_SAFETY * max(|cor(h) - cor(h/2)|,
    |cor(h/2) - cor(h/4)|); ``unchecked`` when only a check run failed."""
    if out[LY.OUT_STATUS] != LY.STATUS_OK:
        return
    if coarse[LY.OUT_STATUS] != LY.STATUS_OK or fine[LY.OUT_STATUS] != LY.STATUS_OK:
        _unchecked(out)
        return
    change = max(abs(out[LY.OUT_COR] - coarse[LY.OUT_COR]), abs(out[LY.OUT_COR] - fine[LY.OUT_COR]))
    out[LY.OUT_ERR] = VERLET_SAFETY * change


# The adaptive method's error estimate is ADAPTIVE_SAFETY x its COR change against _finer(rtol)
# (tests/test_accuracy.py checks it against the exact kernels on random linear-contact chains).
ADAPTIVE_SAFETY = 4.0


def _two_setting_estimate(out, check, safety=1.0, both_floors=False) -> None:
    """out's error estimate: at least ``safety`` x |COR change| against the check setting (and,
    with ``both_floors``, at least the check run's own estimate too); ``unchecked`` when only
    the check run failed."""
    if out[LY.OUT_STATUS] != LY.STATUS_OK:
        return
    if check[LY.OUT_STATUS] != LY.STATUS_OK:
        _unchecked(out)
    else:
        change = abs(out[LY.OUT_COR] - check[LY.OUT_COR])
        floor = max(out[LY.OUT_ERR], check[LY.OUT_ERR]) if both_floors else out[LY.OUT_ERR]
        out[LY.OUT_ERR] = max(floor, safety * change, roundoff_floor(out))


def roundoff_floor(out) -> float:
    """The least error estimate of an integrated row: ROUNDOFF_ULPS ulps per contact, as the
    exact kernels' floor. The local-error sums do not see round-off: a Hunt-Crossley contact of
    light masses (COR 1 - 2e-15) gave 0.9999999999999976 at rtol 1e-8 and ...953 at 1e-12,
    under estimates of 4.5e-16 and 8.9e-16 that cannot both hold."""
    return ROUNDOFF_ULPS * EPS * max(1.0, float(out[LY.OUT_NCOL]))


def _closed_form_only(ms, lk, cp) -> bool:
    """True where the adaptive kernel solves the scene in closed form throughout: two masses on a
    linear link at a rigid wall (impulsive contacts, ``stepping.free_flight_linear``). Its runs
    at rtol and rtol/100 are then one result, so their change says nothing (``_replica_check``)."""
    return ms.size == 2 and cp[0] == laws.C_RIGID and lk[0, laws.SP_KIND] == laws.S_LINEAR


def _replica_scene(ms, lk, cs, r: int) -> tuple:
    """Replica ``r`` of a two-mass scene in kernel units: masses, link stiffness and dashpot
    moved by JITTER relative, as the exact kernels' replicas move theirs
    (``restitution.kernels.replica``)."""
    from restitution.kernels.replica import JITTER, REPLICA_SEED, weyl

    seed = r * REPLICA_SEED
    mr = np.array([x * (1.0 + JITTER * weyl(seed + i)) for i, x in enumerate(ms)])
    lkr = lk.copy()
    lkr[0, laws.SP_K2] *= 1.0 + JITTER * weyl(seed + 2)
    cr = cs * (1.0 + JITTER * weyl(seed + 3))
    return mr, lkr, cr


def _replica_check(out, ms, lk, cs, cp, v0, y0, settings) -> None:
    """Fold the replicas of a closed-form-only scene into its row ``out`` (``replica.combine``,
    in place): its estimate becomes at least REPLICA_SAFETY times their spread, or the row
    ill-conditioned. ``settings`` = (code, rtol, step, etol, max_events, work) of the kernel
    run that ``out`` is. (Without it the row's estimate was only the flights' rounding, however
    sensitive the contact sequence.)"""
    from restitution.kernels.replica import REPLICAS, combine

    if out[LY.OUT_STATUS] != LY.STATUS_OK:
        return
    st = _kernels()
    rows = np.zeros((0, LY.N_HIST))
    cap = st.HMAX_FREE  # (no integrated flight here; the returned run's)

    def acct():
        return np.zeros(st.N_ACCT)

    reps = [
        st.solve_scene(
            *_replica_scene(ms, lk, cs, r), cp, v0, *settings, rows, acct(), True, y0, cap
        )
        for r in range(REPLICAS)
    ]
    combine(out, np.array(reps))


def _fall_back(fine, setting) -> bool:
    """True where the adaptive result must be the setting's own run: the finer run (returned
    otherwise) did not finish while the setting's did (e.g. its work budget ran out)."""
    return fine[LY.OUT_STATUS] != LY.STATUS_OK and setting[LY.OUT_STATUS] == LY.STATUS_OK


def packed(ch: Chain, numerical: bool = True) -> tuple:
    """(m, lk, c, cp, omega, kappa) of a validated chain in kernel units (``laws.pack_chain``;
    the arrays a nonlinear Chain packed when it was checked, if it kept them; never written).
    ``numerical``: within the ranges the numerical methods handle (SceneError naming the
    range otherwise); False only for an exact runner (a Kelvin-Voigt chain's ``kv_row``)."""
    kept = getattr(ch, "_packed", None)
    speed = ch.law_speed  # (v0, or the energy's speed from a given state)
    if kept is not None and kept[0] == speed and (kept[2] or not numerical):
        return kept[1]
    return pack_chain(ch.masses, ch.springs, ch.dashpots, ch.contact_law, ch.link_laws, speed)


def _kernels():
    from restitution.kernels import stepping

    return stepping


def _check_stepping(method: str) -> str:
    if method not in STEPPING:
        raise SceneError(f"method must be one of {', '.join(map(repr, STEPPING))}; got {method!r}")
    return method


def solve_chain(
    ch: Chain,
    method: str = "adaptive",
    rtol: float = 1e-9,
    step: float = 0.01,
    max_events: int = MAX_EVENTS_DEFAULT,
    history: bool = False,
    *,
    max_work: int | None = None,
    energy_tol: float | None = None,
    account: dict | None = None,
    free_closed: bool = True,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Kernel row (kernels/layout.py, times omega*t) and history (or None) of one chain.

    ``ch`` is a validated ``Chain`` and the settings are checked by the caller
    (``methods.options``). ``max_work`` is the work budget in right-hand-side evaluations
    (default ``stepping.MAX_WORK_DEFAULT``; each adaptive run gets FINER_WORK times it);
    ``energy_tol`` the energy-account tolerance (default ``_default_etol``); ``account``, if
    given, is filled with the energy account at the final separation: kinetic, elastic,
    dissipated_contact, dissipated_dashpot, residual (fractions of the initial energy) and the
    plastic law's kappa (kernel units; nan for other laws). ``free_closed`` = False integrates
    the free flight of two masses with a linear link, and the plastic law's elastic line on an
    undamped one, instead of their closed forms (checks only).
    """
    st = _kernels()
    _check_stepping(method)
    ms, lk, cs, cp, _, kappa = packed(ch)
    if method == "verlet" and cp[0] == laws.C_RIGID:
        raise SceneError("method='verlet' needs a finite contact law (beta > 0), not a rigid wall")
    etol = _default_etol(method, rtol, step) if energy_tol is None else float(energy_tol)
    work = _work_budget(method, max_work)
    v0 = float(ch.v0)
    hist = np.zeros((max_events if history else 0, LY.N_HIST))
    no_rows = np.zeros((0, LY.N_HIST))
    acct = np.zeros(st.N_ACCT)
    code = st.METHOD_VERLET if method == "verlet" else st.METHOD_ADAPTIVE
    # a given initial state in the stepping kernels' units: speeds as given, lengths * omega
    y0 = ch.initial_state(1.0 / ch.omega, 1.0)

    def run(tol, stp, rows, acc, cap=st.HMAX_FREE):
        return st.solve_scene(
            ms, lk, cs, cp, v0, code, tol, stp, etol, max_events, work, rows, acc, free_closed,
            y0, cap,
        )  # fmt: skip

    if method == "verlet":
        coarse = run(rtol, step, no_rows, np.zeros(st.N_ACCT))
        out = run(rtol, step / 2, hist, acct)
        _verlet_estimate(out, coarse, run(rtol, step / 4, no_rows, np.zeros(st.N_ACCT)))
    else:
        check = run(rtol, step, no_rows, np.zeros(st.N_ACCT), _check_cap(rtol))
        out = run(_finer(rtol), step, hist, acct)
        if _retry_check(out, check):
            check = run(rtol, step, no_rows, np.zeros(st.N_ACCT))
        if _fall_back(out, check):  # the finer run failed: the setting's own, no estimate
            out = run(rtol, step, hist, acct, _check_cap(rtol))
            _unchecked(out)
        else:
            # the estimate sized for the setting's run, as before the finer run was returned:
            # its floor is the larger local-error sum (on one random linear chain the finer
            # run was as far off as the setting's, 0.8 of an estimate floored by its own sum)
            _two_setting_estimate(out, check, ADAPTIVE_SAFETY, both_floors=True)
        if free_closed and _closed_form_only(ms, lk, cp):
            settings = (code, _finer(rtol), step, etol, max_events, work)
            _replica_check(out, ms, lk, cs, cp, v0, y0, settings)
    if account is not None:
        account.update(_account(acct, kappa))
    return out, (hist if history else None)


def _account(acct, kappa) -> dict:
    return dict(
        kinetic=acct[0],
        elastic=acct[1],
        dissipated_contact=acct[2],
        dissipated_dashpot=acct[3],
        residual=acct[4],
        kappa=kappa,
    )


def pad(chains) -> tuple:
    """The batch kernel's padded input of validated chains: m (rows, nmax), lk (rows, nmax-1,
    N_SP), c (rows, nmax-1), n (rows,), cp (rows, N_CP), v0 (rows,)."""
    rows = len(chains)
    packs = [packed(ch) for ch in chains]
    nmax = max([p[0].size for p in packs], default=2)
    m = np.ones((rows, nmax))
    lk = np.zeros((rows, nmax - 1, laws.N_SP))
    lk[:, :, laws.SP_K2] = 1.0
    c = np.zeros((rows, nmax - 1))
    n = np.zeros(rows, dtype=np.int64)
    cp = np.zeros((rows, laws.N_CP))
    v0 = np.zeros(rows)
    for i, (ms, lki, cs, cpi, _, _) in enumerate(packs):
        k = ms.size
        m[i, :k], lk[i, : k - 1], c[i, : k - 1], n[i], cp[i] = ms, lki, cs, k, cpi
        v0[i] = float(chains[i].v0)
    return m, lk, c, n, cp, v0


def solve_chains(
    chains,
    method: str = "adaptive",
    rtol: float = 1e-9,
    step: float = 0.01,
    max_events: int = MAX_EVENTS_DEFAULT,
    *,
    max_work: int | None = None,
) -> np.ndarray:
    """Kernel rows (rows, N_OUT) of many validated chains with the same settings, in one
    parallel batch (``stepping.solve_scene_batch``); each row as ``solve_chain`` gives it, bit
    for bit. Rows the kernel did not finish are NaN with their status (never unset)."""
    st = _kernels()
    _check_stepping(method)
    given = [j for j, ch in enumerate(chains) if ch.initial]
    if given:  # chains with a given initial state one by one (the batch kernel starts uniform)
        out = np.full((len(chains), LY.N_OUT), np.nan)
        for j in given:
            out[j] = solve_chain(chains[j], method, rtol, step, max_events, max_work=max_work)[0]
        rest = [j for j in range(len(chains)) if not chains[j].initial]
        if rest:
            out[rest] = solve_chains([chains[j] for j in rest], method, rtol, step, max_events,
                                     max_work=max_work)  # fmt: skip
        return out
    m, lk, c, n, cp, v0 = pad(chains)
    if method == "verlet" and (cp[:, 0] == laws.C_RIGID).any():
        raise SceneError("method='verlet' needs a finite contact law (beta > 0), not a rigid wall")
    etol = _default_etol(method, rtol, step)
    work = _work_budget(method, max_work)
    code = st.METHOD_VERLET if method == "verlet" else st.METHOD_ADAPTIVE

    def run(tol, stp, cap=st.HMAX_FREE):
        return st.solve_scene_batch(
            m, lk, c, n, cp, v0, code, tol, stp, etol, max_events, work, cap
        )

    if method == "verlet":
        coarse, out, fine = run(rtol, step), run(rtol, step / 2), run(rtol, step / 4)
        for row, c_, f in zip(out, coarse, fine, strict=True):
            _verlet_estimate(row, c_, f)
    else:
        check, out = run(rtol, step, _check_cap(rtol)), run(_finer(rtol), step)
        again = [j for j in range(len(chains)) if _retry_check(out[j], check[j])]
        if again:
            check[again] = st.solve_scene_batch(
                m[again], lk[again], c[again], n[again], cp[again], v0[again], code, rtol, step,
                etol, max_events, work, st.HMAX_FREE,
            )  # fmt: skip
        for j, (row, other) in enumerate(zip(out, check, strict=True)):
            if _fall_back(row, other):
                out[j] = other
                _unchecked(out[j])
            else:
                _two_setting_estimate(row, other, ADAPTIVE_SAFETY, both_floors=True)
        settings = (code, _finer(rtol), step, etol, max_events, work)
        for j in range(len(chains)):
            ms, lkj, cs, cpj = m[j, : n[j]], lk[j, : n[j] - 1], c[j, : n[j] - 1], cp[j]
            if _closed_form_only(ms, lkj, cpj):
                _replica_check(out[j], ms, lkj, cs, cpj, float(v0[j]), None, settings)
    return out


def solve_reference_chain(
    ch: Chain,
    rtol: float = 1e-9,
    max_events: int = MAX_EVENTS_DEFAULT,
    history: bool = False,
    *,
    energy_tol: float | None = None,
    account: dict | None = None,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Kernel row and history of a two-mass chain by the scipy reference (DOP853 with events):
    the rtol/10 run, with the error estimate max(rtol, |cor(rtol) - cor(rtol/10)|) sized for the
    setting's run, as ``adaptive``, the check also at half the steps per period
    (``reference.STEPS_PER_PERIOD``); where rtol/10 is below scipy's floor 100 eps: the rtol
    run, checked against 10 rtol."""
    from restitution.solvers.reference import SCIPY_RTOL_FLOOR, STEPS_PER_PERIOD, solve_reference

    ms, lk, cs, cp, _, kappa = packed(ch)
    if ms.size != 2:
        raise SceneError("the 'reference' method is implemented for two masses only")
    alpha, v0, sp = float(ms[1]), float(ch.v0), lk[0]
    xi = float(cs[0]) / (2.0 * float(sp[laws.SP_K2]))
    etol = _default_etol("reference", rtol, 0.0) if energy_tol is None else float(energy_tol)
    acct = np.zeros(5)
    y0 = ch.initial_state(1.0 / ch.omega, 1.0)  # (kernel units of the stepping kernels)

    def run(tol, account_of_run, steps=STEPS_PER_PERIOD):
        return solve_reference(
            alpha, v0, xi, cp, sp, tol, max_events, account_of_run, etol, y0=y0,
            steps_per_period=steps,
        )  # fmt: skip

    finer = max(rtol / 10.0, SCIPY_RTOL_FLOOR)
    if finer < rtol:
        check, _ = run(rtol, np.zeros(5), STEPS_PER_PERIOD / 2)
        out, hist = run(finer, acct)
        if _fall_back(out, check):  # the finer run failed: the setting's own, no estimate
            out, hist = run(rtol, acct)
            _unchecked(out)
        else:
            _two_setting_estimate(out, check, both_floors=True)
    else:
        out, hist = run(rtol, acct)
        _two_setting_estimate(out, run(_coarser(rtol), np.zeros(5), STEPS_PER_PERIOD / 2)[0])
    if account is not None:
        account.update(_account(acct, kappa))
    return out, (hist if history else None)


def result(ch: Chain, out: np.ndarray, method: str, hist=None) -> Result:
    """The Result of a numerical kernel row (alpha, beta = k_12/k with k the contact's ``k``,
    xi from the chain, as docs/general-chains.md says). A row whose energy account is open keeps
    its COR (``Result.from_row`` without ``passive``): the status says not to trust it."""
    return Result.from_row(ch, out, method, hist, lengths_of_v0=False)


__all__ = [
    "STEPPING",
    "packed",
    "result",
    "solve_chain",
    "solve_chains",
    "solve_reference_chain",
]
