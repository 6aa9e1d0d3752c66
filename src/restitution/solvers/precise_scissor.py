"""High-precision reference for chains with scissor links (mpmath Taylor series): the independent
check of the adaptive kernel's scissor scenes.

Nothing here uses the numba kernels or ``restitution.model.laws``: the scissor law (the paper's
Eq. 24 with its corner pads and tension cap, docs/general-chains.md) is written out again from
its definition, and its branch points (the pads' cap, the lock angle, the tension cap) are
computed in mpmath. The scene is a ``restitution.Chain`` (masses, springs, dashpots, a rigid
wall or a linear contact spring, linear or scissor links), taken in its own units.

Method. The motion is integrated by mpmath's Taylor-series ``odefun`` at ``dps`` digits, in
stretches over which every force is one analytic formula: each scissor link held on one branch,
the contact on or off. A stretch ends at the first event, a sign change of a linear function of
the positions (m1 reaching the wall or leaving it, a link extension reaching an end of its
branch) on a grid of 1/64 of the fastest period, and also at an event function's local minimum
below zero between two grid points (a shallow touch), found from its rate; the crossing is then
polished by bisection on the series. (A grid step is halved where the held formula leaves its
domain before the step's end: the bars' formula ends where they lie flat, a short way past the
tension cap.) The next stretch starts there with the new branch or
contact state. At a rigid wall m1's velocity is reversed. The sequence ends when the centre of
mass moves away and trails m1 by less than every link can stretch at the internal energy (the
energy never grows in free flight), so no contact can follow.

``solve_precise_scissor`` runs the sequence at ``dps`` and ``dps + 10`` digits and reports their
difference as the bound of the COR; scenes that need more than ``max_contacts`` contacts raise.
"""

from __future__ import annotations

import math

import mpmath

mp = mpmath.mp
GRID = 64  # grid points per fastest period on which events are looked for


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


class _Scene:
    def __init__(self, chain):
        self.m = [mp.mpf(float(x)) for x in chain.masses]
        self.n = len(self.m)
        self.k = [mp.mpf(float(x)) for x in chain.springs]
        self.c = [mp.mpf(float(x)) for x in chain.dashpots]
        self.rigid = not math.isfinite(chain.k_contact)
        self.kc = None if self.rigid else mp.mpf(float(chain.k_contact))
        self.v0 = mp.mpf(float(chain.v0))
        specs = chain.links or [{"law": "linear"}] * (self.n - 1)
        self.sc = [
            _Scissor(self.k[i], s) if s["law"] == "scissor" else None for i, s in enumerate(specs)
        ]
        if chain.contact is not None:
            raise ValueError("precise_scissor handles the rigid wall and the linear contact only")
        # grid: 1/GRID of the fastest period (Gershgorin, links at their cap slope)
        lam = mp.mpf(0)
        for i in range(self.n):
            row = (2 * self.k[i - 1] if i > 0 else 0) + (2 * self.k[i] if i < self.n - 1 else 0)
            if i == 0 and not self.rigid:
                row += self.kc
            lam = max(lam, row / self.m[i])
        self.h = 2 * mp.pi / mp.sqrt(lam) / GRID

    def accel(self, u, v, branches, contact):
        f = [mp.mpf(0)] * self.n
        for i in range(self.n - 1):
            x = u[i + 1] - u[i]
            s = self.k[i] * x if self.sc[i] is None else self.sc[i].force(x, branches[i])
            s += self.c[i] * (v[i + 1] - v[i])
            f[i] += s
            f[i + 1] -= s
        if contact:
            f[0] += self.kc * (-u[0])
        return [f[i] / self.m[i] for i in range(self.n)]

    def events(self, branches, contact):
        """(w, b, tag) of g = w.u + b, each falling through 0 at its event."""
        out = []
        w = [mp.mpf(0)] * self.n
        w[0] = mp.mpf(-1 if contact else 1)  # contact: -u1 falls to 0; free: u1 does
        out.append((w, mp.mpf(0), ("wall", 0, 0)))
        for i, sc in enumerate(self.sc):
            if sc is None:
                continue
            b = branches[i]
            for side, j in ((-1, b - 1), (1, b)):
                if 0 <= j < 3:
                    w = [mp.mpf(0)] * self.n
                    w[i + 1], w[i] = -side, side  # lower end: x - p; upper end: p - x
                    out.append((w, side * sc.points[j], ("branch", i, side)))
        return out

    def no_contact_possible(self, u, v):
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
        return xc - bound > 0


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


def _stretch(sc, z0, branches, contact, start_tag, tol, t_cap):
    """Integrate from z0 to the first event; returns (time, state, tag) or (None, state, None)
    when the free flight provably ends (at a grid point)."""
    n = sc.n
    sol = mp.odefun(
        lambda s, z: list(z[n:]) + sc.accel(z[:n], z[n:], branches, contact), 0, list(z0)
    )
    evs = sc.events(branches, contact)

    def g(k, s):
        w, b, _ = evs[k]
        z = sol(s)
        return sum(wj * zj for wj, zj in zip(w, z[:n], strict=True)) + b

    def gd(k, s):
        w, _, _ = evs[k]
        z = sol(s)
        return sum(wj * zj for wj, zj in zip(w, z[n:], strict=True))

    s = mp.mpf(0)
    step = sc.h
    while s < t_cap:
        s2 = s + step
        if any(isinstance(q, mpmath.mpc) for q in sol(s2)):
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
            return r, list(sol(r)), tag
        s = s2
        step = min(sc.h, 2 * step)
        z = sol(s)
        if not contact and sc.no_contact_possible(z[:n], z[n:]):
            return None, list(z), None
    raise RuntimeError("precise_scissor: time cap reached")


def solve_cor(chain, dps=30, max_contacts=200, t_cap=1e4):
    """COR (an mpmath number), contact count and the set of branch points reached (0 the pads'
    cap, 1 the lock, 2 the tension cap) of the chain at ``dps`` digits."""
    with mp.workdps(dps):
        sc = _Scene(chain)
        tol = mp.mpf(10) ** (-(dps - 4))
        n = sc.n
        z = [mp.mpf(0)] * n + [-sc.v0] * n
        branches = [s.branch(mp.mpf(0), mp.mpf(0)) if s is not None else -1 for s in sc.sc]
        contact = not sc.rigid
        ncol = 1
        crossed = set()  # branch points reached (0 the pads' cap, 1 the lock, 2 the tension cap)
        tag = ("wall", 0, 0)  # m1 starts on the wall surface
        if sc.rigid:
            z[n] = -z[n]
        t = mp.mpf(0)
        while True:
            r, z, tag = _stretch(sc, z, branches, contact, tag, tol, t_cap - t)
            if r is None:
                break
            t += r
            kind, i, side = tag
            if kind == "branch":
                crossed.add(branches[i] + (0 if side > 0 else -1))
                branches[i] += side
                tag = ("branch", i, -side)  # it starts on the other end of its new branch
                continue
            z[0] = mp.mpf(0)  # on the wall surface (the kernels project there too)
            if contact:
                contact = False
                tag = ("wall", 0, 0)
                continue
            ncol += 1
            if ncol > max_contacts:
                raise RuntimeError("precise_scissor: too many contacts")
            if sc.rigid:
                z[n] = -z[n]
                tag = ("wall", 0, 0)
            else:
                contact = True
                tag = ("wall", 0, 0)
        mt = sum(sc.m)
        cor = sum(mi * vi for mi, vi in zip(sc.m, z[n:], strict=True)) / (mt * sc.v0)
        return +cor, ncol, crossed


def solve_precise_scissor(chain, dps=30, max_contacts=200):
    """COR (float), contact count, the bound |COR(dps) - COR(dps + 10)| (float) and the branch
    points reached; raises when the two precisions disagree on the events."""
    cor, ncol, crossed = solve_cor(chain, dps, max_contacts)
    cor2, ncol2, crossed2 = solve_cor(chain, dps + 10, max_contacts)
    if ncol != ncol2 or crossed != crossed2:
        raise RuntimeError(f"precise_scissor: {dps} and {dps + 10} digits disagree on the events")
    return float(cor2), ncol2, float(abs(cor2 - cor)), crossed2
