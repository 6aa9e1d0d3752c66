"""High-precision event sequence of a linear chain (mpmath): the independent reference of the
exact kernels, and the opt-in ``precise`` method for scenes that double precision cannot resolve.

Nothing here uses the numba kernels or their modal models. The scene (masses ``m``, link springs
``k``, link dashpots ``c``, contact stiffness ``kc``, ``math.inf`` for a rigid wall) is taken
exactly as given (every binary float is converted to mpmath exactly) and solved at ``dps``
decimal digits:

* every phase is the linear system ``y' = A y`` of its own matrices, solved through the eigen-
  decomposition of ``A`` (mpmath.eig); a free flight is split into the centre of mass (moving as
  ``X0 + V t`` exactly) and the N - 1 relative coordinates ``q_j = u_{j+1} - X`` (their mass,
  stiffness and damping matrices are the chain's projected onto the motions with no momentum),
  so that no phase has the defective zero eigenvalue of the rigid mode;
* the gap of a phase, ``g(t) = c0 + c1 t + Re sum_q b_q exp(lam_q t)``, is stepped from its
  start by the largest step that its quadratic lower bound ``g + g' s - M2 s^2 / 2`` proves free
  of roots (``M2 >= |g''|`` on the rest of the phase, from the decay of every term), so no
  crossing can be stepped over, however shallow; the steps converge onto the first root from the
  side where ``g > 0``. A free flight ends for good once ``c0 + c1 t - sum |b_q| exp(Re lam_q t)``
  is positive with ``c1 >= 0`` (no later contact is possible);
* at a rigid wall m1's velocity is reversed; with a contact spring the contact phase ends where
  m1 returns to the wall;
* a Kelvin-Voigt contact (``cc`` > 0: a dashpot in parallel with the contact spring) adds cc to
  the contact phase's damping matrix at m1; its contact ends where the force
  ``kc x + cc x'`` (x = -u1, the penetration, x' = -v1, both read off the phase's own state
  eigenvectors) returns to 0, with x > 0 in general; m1 then flies free inside the penetration
  until that force rises through 0 again (a new contact, counted as one) or x falls to 0 (the
  free flight), whichever root comes first (each located as above, the second only up to the
  first).

``solve_precise`` runs the whole sequence twice, at ``dps`` and at ``dps + 20`` digits, and reports
how many digits of the COR agree (``digits``) and their difference (``error_estimate``): the
sequence is chaotic in general, so the precision needed is measured, never assumed. Zeno chatter
(a rigid wall with a dashpot on the first link) is outside its scope: its sticking limit is a
model of the kernels, and such a scene ends with ``status = 'event_budget_exhausted'``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mpmath

MAX_STEPS = 200_000  # locator steps per phase before a phase is given up (never seen on the suite)


@dataclass(frozen=True)
class PreciseResult:
    """COR and sequence of one scene at high precision (times in the scene's units)."""

    cor: float
    n_collisions: int
    t_col: float
    status: str
    digits: float
    error_estimate: float
    contact_times: tuple = ()
    cor_mp: object = None
    e_translational: float = math.nan
    e_vibrational: float = math.nan
    approach_speeds: tuple = ()


class _Phase:
    """y' = A y for one phase: eigenvalues lam, eigenvectors V and z0 = V^-1 y0 on demand."""

    def __init__(self, A):
        lam, V = mpmath.eig(A)
        self.lam = lam
        self.V = V
        self.Vinv = mpmath.inverse(V)
        self.n = A.rows

    def modal(self, y0):
        return self.Vinv * y0

    def state(self, z, t):
        e = mpmath.matrix([z[q] * mpmath.exp(self.lam[q] * t) for q in range(self.n)])
        y = self.V * e
        return [mpmath.re(y[i]) for i in range(self.n)]


def _matrices(m, k, c, ground):
    n = len(m)
    K = mpmath.zeros(n, n)
    C = mpmath.zeros(n, n)
    for i in range(n - 1):
        for A, a in ((K, k[i]), (C, c[i])):
            A[i, i] += a
            A[i + 1, i + 1] += a
            A[i, i + 1] -= a
            A[i + 1, i] -= a
    K[0, 0] += ground
    return K, C


def _state_matrix(M, K, C):
    n = M.rows
    Minv = mpmath.inverse(M)
    A = mpmath.zeros(2 * n, 2 * n)
    MK = Minv * K
    MC = Minv * C
    for i in range(n):
        A[i, n + i] = 1
        for j in range(n):
            A[n + i, j] = -MK[i, j]
            A[n + i, n + j] = -MC[i, j]
    return A


def _first_root(c0, c1, b, lam, tol, never_check, t_stop=None):
    """First t > 0 where g(t) = c0 + c1 t + Re sum b_q e^{lam_q t} returns to 0, g starting at
    (about) 0 and rising; None if ``never_check`` proves there is none, or if it lies beyond
    ``t_stop``. Steps of the quadratic lower bound: each lands where the bound
    g + g's - M2 s^2/2 first reaches 0."""
    t = mpmath.mpf(0)
    decay = [min(mpmath.re(x), 0) for x in lam]
    absb = [abs(x) for x in b]
    lam2 = [abs(x) ** 2 for x in lam]
    for _ in range(MAX_STEPS):
        if t_stop is not None and t > t_stop:
            return None
        g = c0 + c1 * t
        g1 = c1
        m2 = 0
        bound = 0
        for q in range(len(b)):
            e = b[q] * mpmath.exp(lam[q] * t)
            g += mpmath.re(e)
            g1 += mpmath.re(lam[q] * e)
            w = absb[q] * mpmath.exp(decay[q] * t)
            m2 += w * lam2[q]
            bound += w
        if never_check and c1 >= 0 and c0 + c1 * t - bound > 0:
            return None
        if m2 == 0:  # no oscillating terms: g is linear
            if c1 >= 0:
                return None
            return t + max(g, 0) / -c1
        gp = max(g, 0)
        s = (g1 + mpmath.sqrt(g1 * g1 + 2 * m2 * gp)) / m2
        if s <= tol * (1 + t) and g1 <= 0:
            return t + s
        t += s
    raise RuntimeError("no root found within MAX_STEPS steps")


def _start(mp, u0, v0):
    """(u, v) at t = 0: the uniform approach at -1 (u0 None), or the given state (floats
    exact in mpmath)."""
    n = len(mp)
    if u0 is None:
        return [mpmath.mpf(0)] * n, [mpmath.mpf(-1)] * n
    return [mpmath.mpf(x) for x in u0], [mpmath.mpf(x) for x in v0]


def _sequence(m, k, c, kc, dps, max_events, u0=None, v0=None, cc=0.0):
    with mpmath.workdps(dps):
        mp = [mpmath.mpf(x) for x in m]
        kp = [mpmath.mpf(x) for x in k]
        cp = [mpmath.mpf(x) for x in c]
        rigid = math.isinf(kc)
        n = len(mp)
        mt = sum(mp)
        tol = mpmath.mpf(10) ** (-(dps - 8))
        M = mpmath.diag(mp)
        # Free flight: relative coordinates q_j = u_{j+1} - X (j = 1..N-1), u_1 - X =
        # -sum_j (m_{j+1} / m_1) q_j; T maps q to u - X.
        T = mpmath.zeros(n, n - 1)
        for j in range(n - 1):
            T[j + 1, j] = 1
            T[0, j] = -mp[j + 1] / mp[0]
        K, C = _matrices(mp, kp, cp, 0)
        free = _Phase(_state_matrix(T.T * M * T, T.T * K * T, T.T * C * T))
        contact = None
        kv = cc > 0 and not rigid  # a Kelvin-Voigt contact
        kcp = mpmath.mpf(kc) if not rigid else None
        ccp = mpmath.mpf(cc)
        if not rigid:
            Kc, Cc = _matrices(mp, kp, cp, kcp)
            Cc[0, 0] += ccp  # the contact's dashpot (0: the linear contact spring)
            contact = _Phase(_state_matrix(M, Kc, Cc))
        u, v = _start(mp, u0, v0)
        # the momentum and energy before: -mt and mt / 2 for the uniform approach at -1
        p0 = sum(mi * vi for mi, vi in zip(mp, v, strict=True))
        e0 = sum(mi * vi**2 for mi, vi in zip(mp, v, strict=True)) / 2
        e0 += sum(kp[i] * (u[i + 1] - u[i]) ** 2 for i in range(n - 1)) / 2
        t = mpmath.mpf(0)
        times = [t]
        speeds = [-v[0]]  # m1's approach speed at each contact start
        ncol = 1
        in_contact = not rigid
        if v[0] > 0:  # m1 leaves the wall at t = 0: a free flight comes first
            times, speeds, ncol, in_contact = [], [], 0, False
        elif rigid:
            v[0] = -v[0]
        t_last = t
        inside = False  # (Kelvin-Voigt) m1 free inside the penetration
        row = [-mp[j + 1] / mp[0] for j in range(n - 1)]
        while True:
            if in_contact:
                z = contact.modal(mpmath.matrix(u + v))
                if kv:  # the force kc x + cc x' = -(kc u1 + cc v1) returns to 0
                    V_ = contact.V
                    b = [-(kcp * V_[0, q] + ccp * V_[n, q]) * z[q] for q in range(2 * n)]
                else:
                    b = [-contact.V[0, q] * z[q] for q in range(2 * n)]
                te = _first_root(0, 0, b, contact.lam, tol, False)
                y = contact.state(z, te)
                u, v = y[:n], y[n:]
                if kv and u[0] < 0:
                    inside = True  # the force is 0 inside the penetration
                else:
                    u[0] = mpmath.mpf(0)
                t += te
                t_last = t
                in_contact = False
                continue
            X0 = sum(mi * ui for mi, ui in zip(mp, u, strict=True)) / mt
            V = sum(mi * vi for mi, vi in zip(mp, v, strict=True)) / mt
            q0 = [u[j + 1] - X0 for j in range(n - 1)] + [v[j + 1] - V for j in range(n - 1)]
            z = free.modal(mpmath.matrix(q0))
            b = [sum(row[j] * free.V[j, q] for j in range(n - 1)) * z[q] for q in range(2 * n - 2)]
            recontact = False
            left = False
            if inside:
                # u1 = X0 + V t + Re sum b e^{lam t}, v1 = V + Re sum bv e^{lam t}
                bv = [
                    sum(row[j] * free.V[n - 1 + j, q] for j in range(n - 1)) * z[q]
                    for q in range(2 * n - 2)
                ]
                tx = _first_root(-X0, -V, [-x for x in b], free.lam, tol, True)  # x falls to 0
                bg = [kcp * b[q] + ccp * bv[q] for q in range(2 * n - 2)]
                # -(kc x + cc x') = kc u1 + cc v1 falls to 0: the force rises through 0
                tg = _first_root(kcp * X0 + ccp * V, kcp * V, bg, free.lam, tol, True, tx)
                if tx is None and tg is None:
                    raise RuntimeError("m1 stays inside the penetration for ever")
                recontact = tg is not None and (tx is None or tg < tx)
                te = tg if recontact else tx
                left = not recontact
                inside = False
            else:
                te = _first_root(X0, V, b, free.lam, tol, True)
                if te is None:
                    break
            y = free.state(z, te)
            qv = y[: n - 1]
            qd = y[n - 1 :]
            X = X0 + V * te
            u = [X + sum(row[j] * qv[j] for j in range(n - 1))] + [X + x for x in qv]
            v = [V + sum(row[j] * qd[j] for j in range(n - 1))] + [V + x for x in qd]
            if not recontact:
                u[0] = mpmath.mpf(0)
            t += te
            if left:  # m1 left the penetration at x = 0: on to the free flight
                continue
            ncol += 1
            times.append(t)
            speeds.append(-v[0])
            if ncol > max_events:
                return None, ncol, t_last, tuple(times), None, None, ()
            if rigid:
                v[0] = -v[0]
                t_last = t
            else:
                in_contact = True
        vc = sum(mi * vi for mi, vi in zip(mp, v, strict=True)) / mt
        # Vibrational energy after the final separation (relative kinetic + springs) / e0.
        evib = sum(mi * (vi - vc) ** 2 for mi, vi in zip(mp, v, strict=True))
        evib += sum(kp[i] * (u[i + 1] - u[i]) ** 2 for i in range(n - 1))
        sp = tuple(speeds)
        if u0 is None:
            return vc, ncol, t_last, tuple(times), evib / mt, vc**2, sp
        # the centre of mass's velocity after over its approach speed before
        return vc * mt / -p0, ncol, t_last, tuple(times), evib / 2 / e0, mt * vc**2 / 2 / e0, sp


def solve_precise(
    m,
    k,
    c=None,
    kc=math.inf,
    *,
    dps=40,
    max_events=2000,
    velocities=None,
    stretches=None,
    v0=1.0,
    cc=0.0,
) -> PreciseResult:
    """COR of the chain (m, k, c, kc) at ``dps`` digits, checked at ``dps + 20``.

    Parameters
    ----------
    m, k, c : sequence of float
        Masses (m[0] at the wall), link springs and link dashpots (default none), any units;
        every mass starts at -1 (V0 = 1), every spring unstretched, m[0] touching the wall.
    kc : float
        Contact spring stiffness, ``math.inf`` for a rigid wall.
    cc : float
        A Kelvin-Voigt contact's dashpot (in parallel with kc, finite; the units of c): the
        contact ends where kc x + cc x' returns to 0 (module docstring). 0: the linear contact.
    velocities, stretches : sequence of float, optional
        A given initial state (``restitution.Chain``): N velocities, positive towards the wall
        (m[0] hits the wall at t = 0 if velocities[0] > 0, leaves it if < 0), and N - 1 link
        extensions. The COR is then the centre of mass's velocity after over its approach speed
        before, the energies fractions of the initial kinetic + spring energy. Time and length
        units: ``v0`` is the unit of speed (the uniform approach's speed when velocities is
        None), so t_col is in the units of m, k.
    v0 : float
        With stretches but no velocities, every mass approaches at v0.
    dps : int
        Decimal digits of the first run (the check runs at dps + 20).
    max_events : int
        Contacts before the sequence is given up (status 'event_budget_exhausted').

    Returns
    -------
    PreciseResult
        ``cor`` rounded to float, ``digits`` (how many decimal digits of the COR the two
        precisions share), ``error_estimate`` (their difference), ``n_collisions``, ``t_col`` (time
        from first contact to final separation, the scene's units), ``status``, the contact start
        times, the COR as an mpmath number at dps + 20 digits (``cor_mp``), the final
        translational and vibrational energies as fractions of the initial kinetic energy and
        m1's approach speed at each contact start (``approach_speeds``, units of V0).

    Examples
    --------
    >>> r = solve_precise([1.0, 0.5], [1 / 3])  # alpha = 0.5: one contact, COR 1/3
    >>> r.n_collisions, round(r.cor, 12), r.digits >= 30
    (1, 0.333333333333, True)
    """
    c = [0.0] * (len(m) - 1) if c is None else list(c)
    u0 = w0 = None
    if velocities is not None or stretches is not None:
        n = len(m)
        w0 = [-float(x) for x in velocities] if velocities is not None else [-float(v0)] * n
        u0 = [0.0] * n
        if stretches is not None:  # u_{i+1} = u_i + stretches[i], summed exactly in mpmath
            with mpmath.workdps(dps + 60):
                acc = mpmath.mpf(0)
                u0 = [acc]
                for x in stretches:
                    acc += mpmath.mpf(float(x))
                    u0.append(acc)
    cc = float(cc)
    lo = _sequence(m, k, c, kc, dps, max_events, u0, w0, cc)
    hi = _sequence(m, k, c, kc, dps + 20, max_events, u0, w0, cc)
    if lo[0] is None or hi[0] is None:
        return PreciseResult(math.nan, hi[1], math.nan, "event_budget_exhausted", 0.0, math.inf)
    with mpmath.workdps(dps + 20):
        diff = abs(hi[0] - lo[0])
        same = lo[1] == hi[1]
        digits = float(-mpmath.log10(diff)) if diff > 0 else float(dps + 20)
        status = "ok" if same else "ill_conditioned"
        return PreciseResult(
            float(hi[0]),
            hi[1],
            float(hi[2]),
            status,
            digits if same else 0.0,
            float(diff) if same else math.inf,
            tuple(float(x) for x in hi[3]),
            hi[0],
            float(hi[5]),
            float(hi[4]),
            tuple(float(x) for x in hi[6]),
        )
