"""An independent high-precision reference for chains with a power-law contact (Hertz, or the
paper's plastic law) and linear links: mpmath, no numba kernel and no Runge-Kutta method.

Usage: .venv/bin/python benchmarks/mp_nonlinear.py [--dps 30] [--only NAME ...]

Prints, per scene of ``restitution_workflow.bench.scenes`` with a power-law contact (and a few
closed-form checks), the COR, contact count and separation time in ``--dps`` and ``--dps + 10``
digits; the bound is 10 x their difference plus half an ulp, to paste into bench/scenes.py.

Method. Free flight is linear: y(t0 + s) = expm(A s) y(t0) (mpmath ``expm``), scanned on a grid
of step 0.1 / |lambda|max with local minima of u1 polished (shallow contacts), ended by the
centre-of-mass proof of ``reference_values.py``. A contact phase is integrated by mpmath's
Taylor-series ``odefun`` (``dps`` digits): in time where the force is analytic, and in
sigma = sqrt(x) (x = -u1 the penetration) over the first and last stretch of a contact on the
power law F = kappa x**eta from x = 0, where y(t) is a series in t**(eta + 2) and so not analytic
in t, but analytic in sigma for half-integer eta (dt/dsigma = 2 sigma / x', u1 = -sigma**2
exactly). Events (turn: v1 = 0; reload past the largest penetration; separation) are sign
changes on a grid of 1/40 of the fastest period, polished by ``findroot`` on the series.
"""

from __future__ import annotations

import argparse
import sys

import mpmath

mp = mpmath.mp
ZONE = mp.mpf("0.3")  # the sigma stretch: x up to ZONE x the contact's depth scale


class Chain:
    """masses, springs, dashpots (mp numbers) and the contact law: ("hertz", k_h) or
    ("plastic", k1, kappa, eta)."""

    def __init__(self, masses, springs, dashpots, law):
        self.m = [mp.mpf(x) for x in masses]
        self.k = [mp.mpf(x) for x in springs]
        self.c = [mp.mpf(x) for x in (dashpots or [0.0] * len(springs))]
        self.n = len(self.m)
        self.law = law[0]
        self.par = [mp.mpf(x) for x in law[1:]]

    def links(self, u, v):
        """Force on each mass from the links and dashpots."""
        f = [mp.mpf(0)] * self.n
        for i in range(self.n - 1):
            s = self.k[i] * (u[i + 1] - u[i]) + self.c[i] * (v[i + 1] - v[i])
            f[i] += s
            f[i + 1] -= s
        return f

    def contact(self, x, mem):
        """Contact force at penetration x on the current branch (mem: branch, xmax, fmax)."""
        if self.law == "hertz":
            return self.par[0] * x * mp.sqrt(x)
        k1, kappa, eta = self.par
        if mem["branch"] == 1:
            return kappa * x**eta
        return mem["fmax"] - k1 * (mem["xmax"] - x)

    def accel(self, u, v, mem, in_contact):
        f = self.links(u, v)
        if in_contact:
            f[0] += self.contact(-u[0], mem)
        return [f[i] / self.m[i] for i in range(self.n)]

    def free_matrix(self):
        n = self.n
        A = mp.zeros(2 * n, 2 * n)
        for i in range(n):
            A[i, n + i] = 1
        for i in range(n - 1):
            for a_, b_, sg in ((i, i + 1, 1), (i + 1, i, 1)):
                A[n + a_, b_] += sg * self.k[i] / self.m[a_]
                A[n + a_, a_] -= self.k[i] / self.m[a_]
                A[n + a_, n + b_] += self.c[i] / self.m[a_]
                A[n + a_, n + a_] -= self.c[i] / self.m[a_]
        return A


def _spectral_radius(A):
    return max(abs(e) for e in mp.eig(A)[0])


def _free_flight(ch, y, xp, tol):
    """Next contact time (s from now) and state, or None when no contact can follow."""
    n = ch.n
    A = ch.free_matrix()
    mt = sum(ch.m)
    h = P = None

    def at(s):
        return mp.expm(A * s) * y

    def root(idx, a, b, shift=0):
        return mp.findroot(lambda s: at(s)[idx] + shift, (a, b), solver="anderson", tol=tol)

    s, yk = mp.mpf(0), y
    while True:
        u = [yk[i] for i in range(n)]
        v = [yk[n + i] for i in range(n)]
        V = sum(ch.m[i] * v[i] for i in range(n)) / mt
        X = sum(ch.m[i] * u[i] for i in range(n)) / mt
        erel = sum(ch.m[i] * (v[i] - V) ** 2 for i in range(n)) / 2
        erel += sum(ch.k[i] * (u[i + 1] - u[i]) ** 2 for i in range(n - 1)) / 2
        beyond, lin = mt, mp.mpf(0)
        for i in range(n - 1):
            beyond -= ch.m[i]
            lin += (beyond / mt) ** 2 / ch.k[i]
        if V > 0 and X + xp - mp.sqrt(2 * erel * lin) >= 0:
            return None
        if h is None:
            h = mp.mpf("0.1") / _spectral_radius(A)
            P = mp.expm(A * h)
        yn = P * yk
        if yn[0] + xp < 0:
            return root(0, s, s + h, xp)
        if yk[n] < 0 < yn[n]:  # a local minimum of u1 inside: polish it
            smin = root(n, s, s + h)
            if at(smin)[0] + xp < 0:
                return root(0, s, smin, xp)
        s, yk = s + h, yn


def _sigma_stretch(ch, y, t, s_a, s_b, mem):
    """Integrate the contact from x = s_a**2 to x = s_b**2 in sigma; returns (y, t)."""
    n = ch.n
    sign = 1 if s_b > s_a else -1

    def F(tau, z):
        sg = s_a + sign * tau
        u = [-sg * sg] + list(z[: n - 1])
        v = list(z[n - 1 : 2 * n - 1])
        a = ch.accel(u, v, mem, True)
        dtds = 2 * sg / (-v[0])
        d = [v[i] * dtds for i in range(1, n)] + [a[i] * dtds for i in range(n)] + [dtds]
        return [sign * q for q in d]

    z0 = [y[i] for i in range(1, n)] + [y[n + i] for i in range(n)] + [mp.mpf(0)]
    sol = mp.odefun(F, 0, z0)
    z = sol(abs(s_b - s_a))
    y2 = mp.matrix([-s_b * s_b] + list(z[: n - 1]) + list(z[n - 1 : 2 * n - 1]))
    return y2, t + z[2 * n - 1]


def _time_stretch(ch, y, t, mem, events, h, tol):
    """Integrate in time until the first of ``events`` (functions of (u, v) that start > 0)
    falls to 0; returns (index, y, t)."""
    n = ch.n

    def F(s, z):
        u, v = z[:n], z[n:]
        return list(v) + ch.accel(u, v, mem, True)

    sol = mp.odefun(F, 0, [y[i] for i in range(2 * n)])

    def g(k, s):
        z = sol(s)
        return events[k](z[:n], z[n:])

    s = mp.mpf(0)
    while True:
        s2 = s + h
        vals = [g(k, s2) for k in range(len(events))]
        hit = [k for k in range(len(events)) if vals[k] <= 0]
        if hit:
            best = None
            for k in hit:
                r = mp.findroot(lambda q, k=k: g(k, q), (s, s2), solver="anderson", tol=tol)
                if best is None or r < best[1]:
                    best = (k, r)
            k, r = best
            z = sol(r)
            return k, mp.matrix(list(z)), t + r
        s = s2


def solve(ch, v0, dps=30, max_contacts=200):
    """COR, contact count and last separation time of the chain hitting the wall at v0."""
    mp.dps = dps
    n = ch.n
    tol = mp.mpf(10) ** (-(dps - 6))
    v0 = mp.mpf(v0)
    y = mp.matrix([0] * n + [-v0] * n)
    t = mp.mpf(0)
    # time grid of the contact phases: 1/40 of the fastest period with the contact's slope at
    # the deepest penetration m1 alone would reach
    kmax = 0
    mem = dict(branch=1, xmax=mp.mpf(0), fmax=mp.mpf(0), xp=mp.mpf(0))
    mt = sum(ch.m)
    if ch.law == "hertz":
        x1 = (mp.mpf(5) / 4 * mt * v0**2 / ch.par[0]) ** mp.mpf("0.4")
        kmax = mp.mpf("1.5") * ch.par[0] * mp.sqrt(x1)
    else:
        kmax = ch.par[0]
    A = ch.free_matrix()
    A[n, 0] -= kmax / ch.m[0]
    h = 2 * mp.pi / _spectral_radius(A) / 40
    ncol = 1
    t_sep = None
    while True:
        # ---- a contact phase: y[0] = -xp, m1 moving in
        entry_power = ch.law == "hertz" or mem["fmax"] == 0
        if entry_power:
            mem["branch"] = 1
            xd = -y[n]
            eta = mp.mpf("1.5") if ch.law == "hertz" else ch.par[2]
            kappa = ch.par[0] if ch.law == "hertz" else ch.par[1]
            depth = ((eta + 1) * ch.m[0] * xd**2 / (2 * kappa)) ** (1 / (eta + 1))
            s1 = mp.sqrt(ZONE * depth)
            y, t = _sigma_stretch(ch, y, t, mp.mpf(0), s1, mem)
            assert -y[n] > xd / 2, "sigma entry: x' fell by half (shallow contact)"
        else:
            mem["branch"] = 0
        xmax_c = -y[0]
        while True:
            if mem["branch"] == 1:  # loading / rising: the turn, v1 from < 0 to 0
                k, y, t = _time_stretch(ch, y, t, mem, [lambda u, v: -v[0]], h, tol)
                x = -y[0]
                y[n] = 0
                xmax_c = max(xmax_c, x)
                if ch.law == "plastic" and x >= mem["xmax"]:
                    k1, kappa, eta = ch.par
                    mem["xmax"], mem["fmax"] = x, kappa * x**eta
                    mem["xp"] = x - mem["fmax"] / k1
                mem["branch"] = 0
                continue
            if ch.law == "hertz":
                x_sw = ZONE * xmax_c
                evs = [lambda u, v, x_sw=x_sw: -u[0] - x_sw, lambda u, v: v[0]]
            else:
                xm, xp = mem["xmax"], mem["xp"]
                evs = [lambda u, v, xp=xp: -u[0] - xp, lambda u, v, xm=xm: xm + u[0]]
            k, y, t = _time_stretch(ch, y, t, mem, evs, h, tol)
            if k == 1:  # rising again (Hertz) / reload past xmax (plastic)
                if ch.law == "hertz":
                    y[n] = 0
                else:
                    y[0] = -mem["xmax"]
                mem["branch"] = 1
                continue
            if ch.law == "hertz":
                xd = -y[n]
                y, t = _sigma_stretch(ch, y, t, mp.sqrt(x_sw), mp.mpf(0), mem)
                assert -y[n] < xd / 2, "sigma exit: x' fell by half"
                y[0] = 0
            else:
                y[0] = -mem["xp"]
            break
        t_sep = t
        nxt = _free_flight(ch, y, mem["xp"], tol)
        if nxt is None:
            break
        y = mp.expm(ch.free_matrix() * nxt) * y
        y[0] = -mem["xp"]
        t += nxt
        ncol += 1
        if ncol > max_contacts:
            raise RuntimeError("too many contacts")
    cor = sum(ch.m[i] * y[n + i] for i in range(n)) / (mt * v0)
    return dict(cor=cor, contacts=ncol, t_col=t_sep)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dps", type=int, default=30)
    args = ap.parse_args(argv)
    # closed-form check: one mass on Hertz
    from scipy.special import beta as beta_fn

    for k_h, v0, m in ((1.0, 1.0, 1.0), (2.0, 7.0, 3.5)):
        r = solve(Chain([m], [], None, ("hertz", k_h)), v0, args.dps)
        c = 2 * 0.4 * beta_fn(0.4, 0.5) * 1.25**0.4 * (m / k_h) ** 0.4 * v0**-0.2
        print(f"single mass k_h={k_h} v0={v0} m={m}: cor-1 = {mp.nstr(r['cor'] - 1, 3)}, "
              f"t_c rel = {mp.nstr(r['t_col'] / c - 1, 3)} (closed form to float64)")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
