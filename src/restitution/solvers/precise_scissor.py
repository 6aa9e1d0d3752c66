"""High-precision reference for chains with scissor links (mpmath Taylor series): the independent
check of the adaptive kernel's scissor scenes, with a rigid wall, a linear contact, Hertz's
contact or the paper's plastic law.

Nothing here uses the numba kernels or ``restitution.model.laws``: the scissor law (the paper's
Eq. 24 with its corner pads and tension cap, docs/general-chains.md) and the contact laws
(Hertz F = k x**1.5; the plastic law's power-law loading and linear unloading, its kappa from
the nominal dissipation ratio, docs/physics.md) are written out again from their definitions,
and the scissor's branch points (the pads' cap, the lock angle, the tension cap) are computed in
mpmath. The scene is a ``restitution.Chain`` (masses, springs, dashpots, links, contact), taken
in its own units.

Method. The motion is integrated by mpmath's Taylor-series ``odefun`` at ``dps`` digits, in
stretches over which every force is one analytic formula: each scissor link held on one branch,
the contact on or off and on one branch of its law. A stretch ends at the first event, a sign
change of a linear function of the state (m1 reaching the wall or its dent, or leaving it; a
power-law contact's turn, reload past its largest penetration or rise again; a link extension
reaching an end of its branch) on a grid of 1/64 of the fastest period, and also at an event
function's local minimum below zero between two grid points (a shallow touch), found from its
rate; the crossing is then polished by bisection on the series. (A grid step is halved where the
held formula leaves its domain before the step's end: the bars' formula ends where they lie
flat, a short way past the tension cap.) The next stretch starts there with the new branch or
contact state. At a rigid wall m1's velocity is reversed.

A power law F = kappa x**eta from x = 0 (Hertz at both ends of every contact, the plastic law's
first loading) makes the motion a series in powers of t**(eta + 2), not analytic in t at the
contact's ends. There the independent variable is sigma = sqrt(x) (x = -u1), as in
``benchmarks/mp_nonlinear.py``: u1 = -sigma**2 exactly, dt/dsigma = 2 sigma / x', analytic for eta
a multiple of 1/2 (others are refused). The entry runs in sigma up to a quarter of the depth at
which m1 alone would stop, the exit from a quarter of the depth at the last turn to x = 0 (the
separation itself); a sigma stretch ends early, on in time, where |x'| has fallen by half. The
scissor's branch points are located inside these stretches as everywhere else, on the series in
sigma (``crossings`` says where each was crossed).

The sequence ends when the centre of mass moves away and trails m1 (beyond the dent) by more
than every link can stretch at the internal energy (the energy never grows in free flight), so
no contact can follow. ``solve_precise_scissor`` runs the sequence at ``dps`` and ``dps + 10``
digits and reports their difference as the bound of the COR; scenes that need more than
``max_contacts`` contacts raise.
"""

from __future__ import annotations

import math

import mpmath

mp = mpmath.mp
GRID = 64  # grid points per fastest period on which events are looked for
SIGMA_GRID = 32  # grid points at least per stretch in sigma
ZONE = mp.mpf(1) / 4  # the sigma stretches: x up to ZONE x the depth scale (exact in binary)


class _Scissor:
    """One scissor link in mpmath: cap slope k2, ks, L, theta0, corner (Eq. 24 and its pads)."""

    def __init__(self, k2, spec):
        self.k2 = mp.mpf(k2)
        self.ks = mp.mpf(spec["ks"])
        self.L = mp.mpf(spec["L"])
        th0 = mp.mpf(spec.get("theta0", math.pi / 4))
        corner = mp.mpf(spec.get("corner", 1.0))
        self.s0, self.c0 = mp.sin(th0), mp.cos(th0)
        s_l = mp.cbrt(self.s0)  # lock: sin**3 = sin(theta0), the bars' slope 0
        c_l = mp.sqrt(1 - s_l**2)
        self.x_lock = 2 * self.L * (c_l - self.c0)
        self.f_lock = self.bars(self.x_lock)
        self.dc = corner * 2 * self.L * c_l  # pads' compression where their slope reaches k2
        self.kc = self.k2 / self.dc
        s_c = mp.cbrt(self.ks * self.s0 / (self.ks + self.k2))  # cap: the bars' slope = k2
        self.x_cap = 2 * self.L * (mp.sqrt(1 - s_c**2) - self.c0)
        self.f_cap = self.bars(self.x_cap)
        self.points = (self.x_lock - self.dc, self.x_lock, self.x_cap)
        self.x_flat = 2 * self.L * (1 - self.c0)  # the bars lie flat: their formula ends

    def bars(self, x):
        c = self.c0 + x / (2 * self.L)
        return 2 * self.ks * self.L * c * (self.s0 / mp.sqrt(1 - c * c) - 1)

    def force(self, x, branch):
        """Force (> 0 in tension) by the formula of ``branch`` (0 flat, 1 pads, 2 bars, 3 cap)."""
        if branch == 3:
            return self.f_cap + self.k2 * (x - self.x_cap)
        if branch == 2:
            return self.bars(x)
        d = self.x_lock - x
        if branch == 1:
            return self.f_lock - self.kc * d * d / 2
        return self.f_lock - self.k2 * self.dc / 2 - self.k2 * (d - self.dc)

    def branch(self, x, xd):
        """Branch of extension x; on a point itself, the one x moves into."""
        b = sum(1 for p in self.points if x > p or (x == p and xd >= 0))
        return b

    def energy(self, x):
        """Potential, the force integrated from 0 (closed form on every branch)."""
        b = self.branch(x, 0)
        if b >= 2:
            xb = min(x, self.x_cap)
            c = self.c0 + xb / (2 * self.L)
            u = 2 * self.ks * self.L**2 * (mp.sqrt(1 - c * c) - self.s0) ** 2
            e = x - xb
            return u + (self.f_cap * e + self.k2 * e * e / 2 if b == 3 else 0)
        c = self.c0 + self.x_lock / (2 * self.L)
        u_lock = 2 * self.ks * self.L**2 * (mp.sqrt(1 - c * c) - self.s0) ** 2
        d = min(self.x_lock - x, self.dc)
        u = u_lock - (self.f_lock * d - self.kc * d**3 / 6)
        e = self.x_lock - x - d
        f_dc = self.f_lock - self.k2 * self.dc / 2
        return u - (f_dc * e - self.k2 * e * e / 2)

    def extent(self, e):
        """Largest extension with energy <= e (the energy grows monotonically with x > 0)."""
        hi = mp.mpf(1)
        while self.energy(hi) < e:
            hi *= 2
        lo = mp.mpf(0)
        for _ in range(60):  # a bound, not a value: 2**-60 of the bracket is ample
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if self.energy(mid) < e else (lo, mid)
        return hi


class _Contact:
    """The contact's state: on or off, the power law's branch (1 loading, 0 unloading), the
    plastic law's memory (largest penetration xmax and force fmax, the dent xp), this contact's
    deepest penetration and the penetration (``zone``) below which a Hertz contact's exit goes
    over to sigma."""

    def __init__(self):
        self.on = False
        self.branch = 1
        self.xmax = self.fmax = self.xp = mp.mpf(0)
        self.deepest = self.zone = mp.mpf(0)


class _Scene:
    def __init__(self, chain):
        self.m = [mp.mpf(float(x)) for x in chain.masses]
        self.n = len(self.m)
        self.k = [mp.mpf(float(x)) for x in chain.springs]
        self.c = [mp.mpf(float(x)) for x in chain.dashpots]
        self.v0 = mp.mpf(float(chain.v0))
        specs = chain.links or [{"law": "linear"}] * (self.n - 1)
        self.sc = [
            _Scissor(self.k[i], s) if s["law"] == "scissor" else None for i, s in enumerate(specs)
        ]
        self.law = "rigid" if not math.isfinite(chain.k_contact) else "linear"
        self.rigid = self.law == "rigid"
        self.kc = None if self.rigid else mp.mpf(float(chain.k_contact))
        if chain.contact is not None:
            self._power_law(chain.contact)
        # grid: 1/GRID of the fastest period (Gershgorin, links at their cap slope, the contact
        # at its largest slope: a power law's at twice the depth where M alone would stop)
        kw = mp.mpf(0) if self.rigid else self.kc
        if self.law in ("hertz", "plastic"):
            x1 = ((self.eta + 1) * sum(self.m) * self.v0**2 / (2 * self.kappa)) ** (
                1 / (self.eta + 1)
            )
            kw = self.eta * self.kappa * (2 * x1) ** (self.eta - 1)
            kw = max(kw, self.k1) if self.law == "plastic" else kw
        lam = mp.mpf(0)
        for i in range(self.n):
            row = (2 * self.k[i - 1] if i > 0 else 0) + (2 * self.k[i] if i < self.n - 1 else 0)
            if i == 0:
                row += kw
            lam = max(lam, row / self.m[i])
        self.h = 2 * mp.pi / mp.sqrt(lam) / GRID

    def _power_law(self, spec):
        """Hertz F = k x**1.5, or the paper's plastic law: loading F = kappa x**eta, unloading
        and reloading on the line of slope k from the largest force reached (docs/physics.md).
        Its kappa gives m1 alone hitting the wall at v0 the rebound speed v0 sqrt(1 - dr): the
        loading stores m1 v0**2 / 2 = fmax xmax / (eta + 1), the line returns
        fmax**2 / (2 k) = (1 - dr) m1 v0**2 / 2."""
        law = spec.get("law")
        if law == "hertz":
            self.law, self.kappa, self.eta = "hertz", mp.mpf(float(spec["k"])), mp.mpf(1.5)
        elif law == "plastic":
            self.law, self.k1, self.eta = "plastic", mp.mpf(float(spec["k"])), mp.mpf(spec["eta"])
            m1, dr = self.m[0], mp.mpf(float(spec["dr"]))
            fmax = self.v0 * mp.sqrt((1 - dr) * self.k1 * m1)
            xmax = (self.eta + 1) * m1 * self.v0**2 / (2 * fmax)
            self.kappa = fmax / xmax**self.eta
        else:
            raise ValueError(
                f"precise_scissor handles the rigid wall, the linear contact, Hertz and the "
                f"plastic law; got the contact law {law!r}"
            )
        if 2 * self.eta != int(2 * self.eta):
            # x**eta = sigma**(2 eta) is analytic at the contact's ends only for these
            raise ValueError(
                f"precise_scissor: the power law's eta must be a multiple of 1/2; got "
                f"{spec['eta']!r}"
            )
        self.p2 = int(2 * self.eta)

    def contact_force(self, x, cs, sg=None):
        """Force on m1 at penetration x (= sg**2 in a sigma stretch) on the contact's branch."""
        if self.law == "linear":
            return self.kc * x
        if self.law == "plastic" and cs.branch == 0:
            return cs.fmax - self.k1 * (cs.xmax - x)
        return self.kappa * (sg**self.p2 if sg is not None else x**self.eta)

    def accel(self, u, v, branches, cs, sg=None):
        f = [mp.mpf(0)] * self.n
        for i in range(self.n - 1):
            x = u[i + 1] - u[i]
            s = self.k[i] * x if self.sc[i] is None else self.sc[i].force(x, branches[i])
            s += self.c[i] * (v[i + 1] - v[i])
            f[i] += s
            f[i + 1] -= s
        if cs.on:
            f[0] += self.contact_force(-u[0], cs, sg)
        return [f[i] / self.m[i] for i in range(self.n)]

    def _row(self, j, value):
        w = [mp.mpf(0)] * (2 * self.n)
        w[j] = mp.mpf(value)
        return w

    def events(self, branches, cs, contact_events=True):
        """(w, b, tag) of g = w.(u, v) + b, each falling through 0 at its event: the contact's
        (``contact_events``; none inside a sigma stretch, which ends at its own sigma) and every
        scissor link's ends of its branch."""
        n = self.n
        out = []
        if not contact_events:
            pass
        elif not cs.on:  # m1 reaches the wall (its dent): u1 + xp falls to 0
            out.append((self._row(0, 1), cs.xp, ("wall", 0, 0)))
        elif self.law == "linear":  # -u1 falls to 0
            out.append((self._row(0, -1), mp.mpf(0), ("wall", 0, 0)))
        elif cs.branch == 1:  # the turn: x' = -v1 falls to 0
            out.append((self._row(n, -1), mp.mpf(0), ("turn", 0, 0)))
        elif self.law == "hertz":
            out.append((self._row(0, -1), -cs.zone, ("zone", 0, 0)))  # x falls to the zone
            out.append((self._row(n, 1), mp.mpf(0), ("rise", 0, 0)))  # x' rises through 0
        else:
            out.append((self._row(0, -1), -cs.xp, ("wall", 0, 0)))  # separation at the dent
            out.append((self._row(0, 1), cs.xmax, ("reload", 0, 0)))  # past the largest x
        for i, sc in enumerate(self.sc):
            if sc is None:
                continue
            b = branches[i]
            for side, j in ((-1, b - 1), (1, b)):
                if 0 <= j < 3:
                    w = [mp.mpf(0)] * (2 * n)
                    w[i + 1], w[i] = -side, side  # lower end: x - p; upper end: p - x
                    out.append((w, side * sc.points[j], ("branch", i, side)))
        return out

    def no_contact_possible(self, u, v, xp):
        mt = sum(self.m)
        vc = sum(mi * vi for mi, vi in zip(self.m, v, strict=True)) / mt
        if vc <= 0:
            return False
        e = sum(mi * (vi - vc) ** 2 for mi, vi in zip(self.m, v, strict=True)) / 2
        for i in range(self.n - 1):
            x = u[i + 1] - u[i]
            e += self.k[i] * x * x / 2 if self.sc[i] is None else self.sc[i].energy(x)
        beyond, bound = mt, mp.mpf(0)
        for i in range(self.n - 1):
            beyond -= self.m[i]
            ext = mp.sqrt(2 * e / self.k[i]) if self.sc[i] is None else self.sc[i].extent(e)
            bound += beyond / mt * ext
        xc = sum(mi * ui for mi, ui in zip(self.m, u, strict=True)) / mt
        return xc + xp - bound > 0


def _bisect(f, a, b, tol):
    """Root of f in [a, b] with f(a) > 0 >= f(b), to tol."""
    while b - a > tol:
        mid = (a + b) / 2
        a, b = (mid, b) if f(mid) > 0 else (a, mid)
    return b


def _bracket(g, gd, s, s2, tol, on_surface):
    """(a, b) with g(a) > 0 >= g(b) around the first crossing of g in (s, s2], or (None, None).
    g > 0 at s unless the stretch starts on this event's surface (``on_surface``), where it
    moves away first; a crossing and return between grid points is found at g's minimum."""
    if on_surface:
        if g(s2) > 0:
            return None, None
        a = _bisect(gd, s, s2, tol)  # g's maximum: the rate falls through 0 there
        return (a, s2) if g(a) > 0 else (None, None)  # else a touch within round-off
    if g(s2) <= 0:
        return s, s2
    if gd(s) < 0 < gd(s2):  # a minimum between grid points: a shallow crossing?
        smin = _bisect(lambda q: -gd(q), s, s2, tol)
        if g(smin) <= 0:
            return s, smin
    return None, None


class _TimeFlow:
    """The motion in time from the state y = (u, v) with the branches and contact held."""

    def __init__(self, sc, y, branches, cs):
        n = sc.n
        self.sc, self.branches, self.cs = sc, branches, cs
        self.sol = mp.odefun(
            lambda s, z: list(z[n:]) + sc.accel(z[:n], z[n:], branches, cs), 0, list(y)
        )

    def state(self, s):
        """(u, v) and the time elapsed at s."""
        return list(self.sol(s)), s

    def xrate(self, y, i):
        """Rate of link i's extension in the flow's variable (time)."""
        n = self.sc.n
        return y[n + i + 1] - y[n + i]

    def rate(self, y, w):
        """Time derivative of w.(u, v) at y (the acceleration only where w needs it)."""
        n = self.sc.n
        r = sum(wj * vj for wj, vj in zip(w[:n], y[n:], strict=True))
        if any(w[n:]):
            a = self.sc.accel(y[:n], y[n:], self.branches, self.cs)
            r += sum(wj * aj for wj, aj in zip(w[n:], a, strict=True))
        return r


class _SigmaFlow:
    """The motion of a power-law contact's end over sigma = sqrt(x) (x = -u1 the penetration)
    from s_a to s_b, parametrized by tau = |sigma - s_a|: z = (u2..un, v1..vn, t), dz/dsigma =
    dz/dt * dt/dsigma with dt/dsigma = 2 sigma / x' and u1 = -sigma**2 exactly. Near x = 0 the
    force kappa x**eta makes the motion a series in powers of t**(eta + 2), not analytic in t;
    in sigma it is (for eta a multiple of 1/2), so the Taylor series converge up to x = 0.
    Valid while x' stays away from 0 (the stretch ends where it has fallen by half)."""

    def __init__(self, sc, y, branches, cs, s_a, s_b):
        n = sc.n
        self.sc, self.branches, self.cs = sc, branches, cs
        self.s_a, self.sign = s_a, (1 if s_b > s_a else -1)

        def f(tau, z):
            sg = s_a + self.sign * tau
            u = [-sg * sg] + list(z[: n - 1])
            v = list(z[n - 1 : 2 * n - 1])
            a = sc.accel(u, v, branches, cs, sg)
            dtds = self.sign * 2 * sg / (-v[0])
            return [q * dtds for q in v[1:] + a] + [dtds]

        self.sol = mp.odefun(f, 0, list(y[1:n]) + list(y[n:]) + [mp.mpf(0)])

    def state(self, tau):
        n = self.sc.n
        z = self.sol(tau)
        sg = self.s_a + self.sign * tau
        return [-sg * sg] + list(z[: 2 * n - 1]), z[2 * n - 1]

    def xrate(self, y, i):
        """Rate of link i's extension in tau: its rate in time times dt/dtau = 2 sigma / |x'|."""
        n = self.sc.n
        return (y[n + i + 1] - y[n + i]) * 2 * mp.sqrt(-y[0]) / abs(y[n])

    def rate(self, y, w):
        """w.(u, v)'s rate in time: the sign of its rate in tau (dt/dtau > 0); u-only rows."""
        n = self.sc.n
        return sum(wj * vj for wj, vj in zip(w[:n], y[n:], strict=True))


def _stretch(flow, evs, start_tag, tol, h, end, stop=None, left=None):
    """Follow ``flow`` from 0 to the first event of ``evs`` on a grid of step h; returns
    (elapsed time, state, tag): tag "end" at ``end`` (no event before), "left" where ``left``
    holds at a grid point, None where ``stop`` holds at a grid point (free flight that provably
    ends), else the event's tag, its crossing polished by bisection on the series."""

    def g(k, s):
        w, b, _ = evs[k]
        return sum(wj * zj for wj, zj in zip(w, flow.state(s)[0], strict=True)) + b

    def gd(k, s):
        return flow.rate(flow.state(s)[0], evs[k][0])

    def room(y):
        """The grid step from y: at most a quarter of the way to where a link held on the bars'
        formula would reach its end (they lie flat) at its present rate. Beyond it the series
        converge ever more slowly towards the formula's branch point (a step of the grid past
        the tension cap of a short scissor took minutes before it met the complex values)."""
        out = h
        for i, sc in enumerate(flow.sc.sc):
            if sc is not None and flow.branches[i] == 2:
                r = abs(flow.xrate(y, i))
                if r > 0:
                    out = min(out, (sc.x_flat - (y[i + 1] - y[i])) / (4 * r))
        return out

    s = mp.mpf(0)
    y = flow.state(s)[0]
    step = room(y)
    while True:
        s2 = min(s + step, end)
        if any(isinstance(q, mpmath.mpc) for q in flow.state(s2)[0]):
            # the held formula has left its domain before s2 (the bars' formula ends where they
            # lie flat, a short way past the tension cap): the event lies before, look closer
            step /= 2
            if step < tol:
                raise RuntimeError("precise_scissor: no event before a formula's end")
            continue
        hits = []
        for k, (_, _, tag) in enumerate(evs):
            a, b = _bracket(lambda q, k=k: g(k, q), lambda q, k=k: gd(k, q), s, s2, tol,
                            s == 0 and tag == start_tag)  # fmt: skip
            if a is not None:
                hits.append((_bisect(lambda q, k=k: g(k, q), a, b, tol), tag))
        if hits:
            r, tag = min(hits, key=lambda p: p[0])
            y, dt = flow.state(r)
            return dt, y, tag
        s = s2
        y, dt = flow.state(s)
        if s == end:
            return dt, y, "end"
        if left is not None and left(y):
            return dt, y, "left"
        if stop is not None and stop(y):
            return dt, y, None
        step = min(room(y), 2 * step)


def _sigma_run(sc, y, branches, cs, target, start_tag, tol, xd_ref):
    """One sigma stretch from x = -u1 towards x = target**2: (time, state, tag) as ``_stretch``;
    "left" where |x'| fell below half of ``xd_ref`` (its value where sigma began)."""
    n = sc.n
    s_a = mp.sqrt(max(-y[0], mp.mpf(0)))
    flow = _SigmaFlow(sc, y, branches, cs, s_a, target)
    span = abs(target - s_a)
    # a grid step of at most the time grid's (the stretch lasts < 2 |x**2 ends| / |x'|)
    t_est = 2 * abs(target**2 - s_a**2) / abs(y[n])
    steps = max(SIGMA_GRID, int(mp.ceil(t_est / sc.h)))
    return _stretch(
        flow, sc.events(branches, cs, False), start_tag, tol, span / steps, span,
        left=lambda z: not (-z[n] * xd_ref > xd_ref * xd_ref / 2),
    )  # fmt: skip


def _run(chain, dps, max_contacts, t_cap):
    """The sequence at ``dps`` digits: (COR, contacts, [(branch point, where crossed)]) with
    where "free", "contact" (a stretch in time) or "sigma" (a power-law contact's end)."""
    with mp.workdps(dps):
        sc = _Scene(chain)
        tol = mp.mpf(10) ** (-(dps - 4))
        n = sc.n
        power = sc.law in ("hertz", "plastic")
        y = [mp.mpf(0)] * n + [-sc.v0] * n
        branches = [s.branch(mp.mpf(0), mp.mpf(0)) if s is not None else -1 for s in sc.sc]
        cs = _Contact()
        ncol = 1
        log = []
        tag = ("wall", 0, 0)  # m1 starts on the wall surface
        mode = "time"  # or "enter" / "exit": a power-law contact's end in sigma
        if sc.rigid:
            y[n] = -y[n]
        else:
            cs.on = True
            mode = "enter" if power else "time"
        t = mp.mpf(0)
        target = xd_ref = None
        while True:
            if t > t_cap:
                raise RuntimeError("precise_scissor: time cap reached")
            if mode == "enter" and target is None:  # sigma up to ZONE x m1 alone's depth
                xd_ref = -y[n]
                depth = ((sc.eta + 1) * sc.m[0] * xd_ref**2 / (2 * sc.kappa)) ** (1 / (sc.eta + 1))
                target = mp.sqrt(ZONE * depth)
            if mode != "time":
                dt, y, tag = _sigma_run(sc, y, branches, cs, target, tag, tol, xd_ref)
                where = "sigma"
            else:
                flow = _TimeFlow(sc, y, branches, cs)
                stop = None if cs.on else (lambda z: sc.no_contact_possible(z[:n], z[n:], cs.xp))
                dt, y, tag = _stretch(flow, sc.events(branches, cs), tag, tol, sc.h, t_cap - t,
                                      stop=stop)  # fmt: skip
                where = "contact" if cs.on else "free"
                if tag == "end":
                    raise RuntimeError("precise_scissor: time cap reached")
            t += dt
            if tag is None:
                break
            kind, i, side = tag if isinstance(tag, tuple) else (tag, 0, 0)
            if kind == "branch":
                point = branches[i] + (0 if side > 0 else -1)
                log.append((point, where))
                branches[i] += side
                tag = ("branch", i, -side)  # it starts on the other end of its new branch
                continue
            if kind in ("end", "left"):
                if mode == "exit" and kind == "end":  # x = 0: the separation itself
                    y[0] = mp.mpf(0)
                    cs.on, mode, tag = False, "time", ("wall", 0, 0)
                    continue
                if mode == "exit":  # x' fell by half: on in time to a zone nearer the wall
                    cs.zone = ZONE * -y[0]
                mode, target, tag = "time", None, None
                continue
            if kind == "turn":  # the deepest point: unloading
                y[n] = mp.mpf(0)
                x = -y[0]
                cs.deepest = max(cs.deepest, x)
                cs.branch = 0
                tag = ("rise", 0, 0)
                if sc.law == "plastic":
                    tag = ("reload", 0, 0) if x >= cs.xmax else None
                    if x >= cs.xmax:
                        cs.xmax, cs.fmax = x, sc.kappa * x**sc.eta
                        cs.xp = x - cs.fmax / sc.k1
                cs.zone = ZONE * x  # below the turn (the deepest point may lie deeper)
                continue
            if kind == "rise":  # Hertz, x rising again: loading
                y[n] = mp.mpf(0)
                cs.branch, tag = 1, ("turn", 0, 0)
                continue
            if kind == "reload":  # plastic, past the largest penetration: on the power law
                y[0] = -cs.xmax
                cs.branch, tag = 1, None
                continue
            if kind == "zone":  # Hertz, the exit in sigma from here to x = 0
                mode, target, xd_ref, tag = "exit", mp.mpf(0), -y[n], None
                continue
            # kind == "wall": a separation, or a new contact
            y[0] = -cs.xp  # on the wall surface (the kernels project there too)
            tag = ("wall", 0, 0)
            if cs.on:
                cs.on = False
                continue
            ncol += 1
            if ncol > max_contacts:
                raise RuntimeError("precise_scissor: too many contacts")
            if sc.rigid:
                y[n] = -y[n]
                continue
            cs.on, cs.deepest = True, cs.xp
            if sc.law == "hertz" or (sc.law == "plastic" and cs.fmax == 0):
                cs.branch, mode, target, tag = 1, "enter", None, None
            elif sc.law == "plastic":
                cs.branch = 0  # on the line from the dent
        mt = sum(sc.m)
        cor = sum(mi * vi for mi, vi in zip(sc.m, y[n:], strict=True)) / (mt * sc.v0)
        return +cor, ncol, log


def solve_cor(chain, dps=30, max_contacts=200, t_cap=1e4):
    """COR (an mpmath number), contact count and the set of branch points reached (0 the pads'
    cap, 1 the lock, 2 the tension cap) of the chain at ``dps`` digits."""
    cor, ncol, log = _run(chain, dps, max_contacts, t_cap)
    return cor, ncol, {p for p, _ in log}


def crossings(chain, dps=30, max_contacts=200, t_cap=1e4):
    """The branch points crossed, in order: (point, where), where "free", "contact" (a contact
    stretch in time) or "sigma" (the sigma = sqrt(x) stretch at a power-law contact's end)."""
    return _run(chain, dps, max_contacts, t_cap)[2]


def reference(chain, dps=30, max_contacts=200):
    """The sequence at ``dps`` and ``dps + 10`` digits: a dict of the COR (float, the finer run's),
    the contact count, the bound |COR(dps) - COR(dps + 10)| and ``crossed``, the branch points
    crossed in order with where (as ``crossings``); raises when the two disagree on the events."""
    cor, ncol, log = _run(chain, dps, max_contacts, 1e4)
    cor2, ncol2, log2 = _run(chain, dps + 10, max_contacts, 1e4)
    if ncol != ncol2 or log != log2:
        raise RuntimeError(f"precise_scissor: {dps} and {dps + 10} digits disagree on the events")
    return dict(cor=float(cor2), contacts=ncol2, bound=float(abs(cor2 - cor)), crossed=log2)


def solve_precise_scissor(chain, dps=30, max_contacts=200):
    """COR (float), contact count, the bound |COR(dps) - COR(dps + 10)| (float) and the branch
    points reached; raises when the two precisions disagree on the events."""
    r = reference(chain, dps, max_contacts)
    return r["cor"], r["contacts"], r["bound"], {p for p, _ in r["crossed"]}
