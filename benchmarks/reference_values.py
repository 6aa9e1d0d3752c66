"""Reference values of the hard scenes (``restitution_workflow.bench.scenes``), from independent
methods.

Usage: .venv/bin/python benchmarks/reference_values.py [--only NAME ...] [--dps 40] [--grazing]

Needs ``mpmath`` (``pip install mpmath``; only this script uses it, the tests use the pasted
constants). Prints, per scene, the reference COR, contact count, absolute bound and source, and
the ``Scene(...)`` reference keywords to paste into ``src/restitution_workflow/bench/scenes.py``.

Methods (none of them calls the numba kernels):

* two-mass linear scenes (any beta >= 0, xi >= 0): ``mp_two_mass``, the exact piecewise-linear
  motion in ``--dps``-digit arithmetic. In each phase (free / in contact) the state obeys
  y' = A y, so y(t0 + s) = expm(A s) y(t0) (mpmath ``expm``: no eigenbasis, so xi = 1 exactly,
  where the free phase is defective, needs no special case). The phase is scanned on a grid of
  step h = 0.1 / max|eig(A)| (propagator expm(A h) applied repeatedly); a contact start is a sign
  change of u1 or a local minimum of u1 (sign change of v1 from - to +) whose polished value is
  negative, so shallow (grazing) contacts are found without relying on sign changes at samples.
  Roots are polished by bracketed Newton to 1e-30. A sequence ends by proof: centre-of-mass
  velocity V > 0 and X - (alpha/(1+alpha)) sqrt(2 E_rel / k2) > 0 (E_rel, the relative
  energy, does not grow in free flight), so u1 can never return to zero. The grid cannot hide
  two sign changes of v1 within one step unless v1 and its derivative nearly vanish together
  (h |lambda|max = 0.1); the run reports the shallowest contact and the nearest miss so that
  such a case would show. Bound: the result is recomputed at dps and dps + 10 digits; the bound
  is 10 x their difference plus half an ulp (rounding to float64).
* N-mass chain: scipy ``solve_ivp`` DOP853 per phase with a small ``max_step`` (1/125 of the
  fastest period) and terminal events, at rtol 1e-11, 1e-12, 1e-13 (atol 1e-2 x rtol); the value
  at 1e-13 is the reference, bound = 10 x its largest difference to the other two (a tolerance
  sweep), floored at 1e-12.
* the plastic contact: ``restitution.solvers.reference`` (scipy DOP853 with the force laws
  evaluated in Python, independent of the numba integrators) at rtol 1e-11, 1e-12, 1e-13; bound
  as for the chain (bench/scenes.py pastes benchmarks/mp_nonlinear.py's value instead);
* the scissor spring: ``restitution.solvers.precise_scissor`` (mpmath Taylor series, branch points
  and contacts located on the series) at 30 and 40 digits, bound 10 x their difference plus half
  an ulp.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

# ------------------------------------------------------------------------------------------------
# Two masses, piecewise linear, in mpmath
# ------------------------------------------------------------------------------------------------


def _two_mass_matrices(mp, alpha, beta, xi):
    """(A_free, A_contact or None, k2) in the units of docs/physics.md, exact from the floats."""
    a = mp.mpf(alpha)
    k2 = a / (1 + a)
    c = 2 * mp.mpf(xi) * k2
    k1 = None if beta == 0 else k2 / mp.mpf(beta)

    def mat(kc):
        # rows: u1' = v1, u2' = v2, m1 v1' = -k2 (u1 - u2) - c (v1 - v2) - kc u1, m2 v2' = ...
        return mp.matrix(
            [
                [0, 0, 1, 0],
                [0, 0, 0, 1],
                [-(k2 + kc), k2, -c, c],
                [k2 / a, -k2 / a, c / a, -c / a],
            ]
        )

    return mat(0), (None if k1 is None else mat(k1)), k2


def _spectral_radius(mp, A):
    ev = mp.eig(A, left=False, right=False)
    return max(abs(e) for e in ev)


class _Phase:
    """y(t0 + s) = expm(A s) y0 with a grid propagator; bracketed Newton on u1 or v1."""

    def __init__(self, mp, A, y0, t0, h):
        self.mp, self.A, self.y0, self.t0 = mp, A, y0, t0
        self.h = h
        self.P = mp.expm(A * h)

    def at(self, s):
        return self.mp.expm(self.A * s) * self.y0

    def root(self, comp, lo, hi, tol):
        """Root of component ``comp`` (0: u1, 2: v1) of y(s) on [lo, hi] (values of opposite sign).

        Bracketed Newton: the derivative of u1 is v1, that of v1 is (A y)[2].
        """
        f_lo = self.at(lo)[comp]
        s = (lo + hi) / 2
        for _ in range(400):
            y = self.at(s)
            f = y[comp]
            if f == 0:
                return s
            if (f < 0) == (f_lo < 0):
                lo, f_lo = s, f
            else:
                hi = s
            d = y[comp + 2] if comp == 0 else (self.A * y)[2]
            s_new = s - f / d if d != 0 else (lo + hi) / 2
            if not (lo < s_new < hi) or abs(s_new - s) > (hi - lo) / 2:
                s_new = (lo + hi) / 2
            if abs(s_new - s) < tol or hi - lo < tol:
                return s_new
            s = s_new
        raise RuntimeError("root not converged")


def mp_two_mass(alpha, beta=0.0, xi=0.0, dps=40, max_contacts=1000, stop_after=None):
    """Exact two-mass run for the float inputs in ``dps`` digits.

    Returns dict(cor, contacts, t_col, e_trans, e_vib, shallowest (min depth of a contact, as
    the minimum of u1 reached), nearest_miss (smallest positive minimum of u1 in free flight
    before a later contact or the end)).

    ``stop_after=n`` (rigid wall): return instead the signed value of u1's first minimum in the
    free flight after the n-th contact (< 0: a further contact follows); its root in alpha is
    alpha*_n (``grazing_alpha``).
    """
    import mpmath

    mp = mpmath.mp
    mp.dps = dps  # a script: the global context is ours
    a = mp.mpf(alpha)
    A_free, A_con, k2 = _two_mass_matrices(mp, alpha, beta, xi)
    tol = mp.mpf(10) ** (-(dps - 8))
    hs = {}
    for name, A in (("free", A_free), ("contact", A_con)):
        if A is not None:
            hs[name] = mp.mpf("0.1") / _spectral_radius(mp, A)
    y = mp.matrix([0, 0, -1, -1])
    t = mp.mpf(0)
    n = 1
    shallowest = mp.inf
    nearest_miss = mp.inf
    if beta == 0:
        y[2] = -y[2]
        in_contact = False
    else:
        in_contact = True
    t_sep = mp.mpf(0) if beta == 0 else None
    while True:
        if in_contact:
            ph = _Phase(mp, A_con, y, t, hs["contact"])
            s, yk = mp.mpf(0), y
            depth = mp.mpf(0)
            while True:
                yn = ph.P * yk
                depth = min(depth, yn[0])
                if yn[0] >= 0:  # u1 back to zero from below: separation
                    s_end = ph.root(0, s, s + ph.h, tol)
                    break
                s, yk = s + ph.h, yn
            y = ph.at(s_end)
            y[0] = mp.mpf(0)
            t = t + s_end
            t_sep = t
            shallowest = min(shallowest, -depth) if n > 1 else shallowest
            in_contact = False
            continue
        # Free flight: next contact, or proof that there is none.
        ph = _Phase(mp, A_free, y, t, hs["free"])
        s, yk = mp.mpf(0), y
        found = None
        while True:
            u1, u2, v1, v2 = yk
            V = (v1 + a * v2) / (1 + a)
            X = (u1 + a * u2) / (1 + a)
            erel = a / (1 + a) * (v2 - v1) ** 2 / 2 + k2 * (u2 - u1) ** 2 / 2
            if V > 0 and X - a / (1 + a) * mp.sqrt(2 * erel / k2) > 0:
                break
            yn = ph.P * yk
            if yn[0] < 0 and stop_after != n:
                found = ph.root(0, s, s + ph.h, tol)
            elif yk[2] < 0 < yn[2] or (yk[2] < 0 and yn[2] == 0):
                smin = ph.root(2, s, s + ph.h, tol) if yn[2] != 0 else s + ph.h
                umin = ph.at(smin)[0]
                if stop_after == n:
                    return umin
                if umin < 0:
                    found = ph.root(0, s, smin, tol)
                    shallowest = min(shallowest, -umin)
                elif s > 0 or yk[0] > 0:
                    nearest_miss = min(nearest_miss, umin)
            if found is not None:
                break
            s, yk = s + ph.h, yn
        if found is None:
            break
        n += 1
        if n > max_contacts:
            raise RuntimeError(f"more than {max_contacts} contacts")
        y = ph.at(found)
        y[0] = mp.mpf(0)
        t = t + found
        if beta == 0:
            y[2] = -y[2]
            t_sep = t
        else:
            in_contact = True
    u1, u2, v1, v2 = y
    M = 1 + a
    V = (v1 + a * v2) / M
    e_trans = V * V  # fraction of the initial kinetic energy M/2
    e_vib = (a / M * (v2 - v1) ** 2 + k2 * (u2 - u1) ** 2) / M
    return dict(
        cor=V,
        contacts=n,
        t_col=t_sep,
        e_trans=e_trans,
        e_vib=e_vib,
        shallowest=shallowest,
        nearest_miss=nearest_miss,
    )


def grazing_alpha(n, lo, hi, dps=40):
    """alpha*_n in ``dps`` digits (root of the signed gap minimum after the n-th contact)."""
    import mpmath

    mpmath.mp.dps = dps
    f = lambda a: mp_two_mass(a, 0.0, 0.0, dps, stop_after=n)  # noqa: E731
    root = mpmath.findroot(f, (mpmath.mpf(lo), mpmath.mpf(hi)), solver="anderson")
    mpmath.mp.dps = dps
    return root


def float_below(x):
    """The largest float64 <= the mpmath number x."""
    f = float(x)
    return float(np.nextafter(f, -np.inf)) if f > x else f


def two_mass_reference(alpha, beta, xi, dps):
    t0 = time.perf_counter()
    lo = mp_two_mass(alpha, beta, xi, dps)
    hi = mp_two_mass(alpha, beta, xi, dps + 10)
    if lo["contacts"] != hi["contacts"]:
        raise RuntimeError(f"contact count depends on precision: {lo} vs {hi}")
    diff = abs(float(lo["cor"] - hi["cor"]))
    bound = 10 * diff + 0.5 * math.ulp(float(hi["cor"]))  # + rounding to float64
    # Relative condition |d cor / d ln alpha|, one-sided from below (at a grazing point the
    # branch below is the smooth one): sets the round-off bound of float64 solvers.
    delta = 1e-10
    import mpmath

    mpmath.mp.dps = dps
    below = mp_two_mass(mpmath.mpf(alpha) * (1 - mpmath.mpf(delta)), beta, xi, dps)
    kappa = abs(float((lo["cor"] - below["cor"]) / delta))
    hi["condition"] = kappa
    info = (
        f"shallowest contact depth {float(hi['shallowest']):.3g}, nearest miss "
        f"{float(hi['nearest_miss']):.3g}, e_vib {float(hi['e_vib']):.6g}, "
        f"omega t_col {float(hi['t_col']):.12g}, kappa {kappa:.3g}, "
        f"{time.perf_counter() - t0:.0f} s"
    )
    return float(hi["cor"]), hi["contacts"], bound, f"mpmath {dps + 10} digits", info, hi


# ------------------------------------------------------------------------------------------------
# N-mass chain: scipy DOP853 per phase (after tests/test_linear.py::reference)
# ------------------------------------------------------------------------------------------------


def ivp_chain(alpha, beta, xi, n, rtol, max_contacts=5000):
    """(cor, contacts) of an N-mass chain by solve_ivp DOP853 with terminal events."""
    from restitution_workflow.bench.ivp import chain_matrices

    m, K, C, k1 = chain_matrices(alpha, beta, xi, n)
    mt = m.sum()
    Kc = K.copy()
    Kc[0, 0] += k1

    def max_step(kk):  # ~125 steps per period of the fastest mode of the phase
        return 0.05 / math.sqrt(max(np.max(np.abs(np.linalg.eigvals(kk / m[:, None]))), 1.0))

    step_free, step_contact = max_step(K), max_step(Kc)
    # |u1 - X| <= sqrt(2 E_rel g) with g = max u1^2 / u'Ku over zero-momentum displacements.
    Q = np.linalg.svd(m[None, :])[2][1:].T
    g = Q[0] @ np.linalg.solve(Q.T @ K @ Q, Q[0])

    def rhs(kc):
        def f(t, y):
            u, v = y[:n], y[n:]
            acc = -(K @ u + C @ v) / m
            acc[0] -= kc * u[0] / m[0]
            return np.concatenate([v, acc])

        return f

    def hit(t, y):
        return y[0]

    hit.terminal = True
    y = np.concatenate([np.zeros(n), -np.ones(n)])
    t, count = 0.0, 1
    opts = dict(method="DOP853", rtol=rtol, atol=1e-2 * rtol, events=hit)
    contact = True
    while count <= max_contacts:
        if contact:
            hit.direction = 1.0
            y[0] = -1e-300
            sol = solve_ivp(rhs(k1), (t, t + 1e4), y, max_step=step_contact, **opts)
            t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
            y[0] = 0.0
            contact = False
            continue
        hit.direction = -1.0
        done = False
        while True:
            u, v = y[:n], y[n:]
            V, X = m @ v / mt, m @ u / mt
            erel = 0.5 * (m @ (v - V) ** 2) + 0.5 * u @ K @ u
            if V > 0 and X - math.sqrt(2 * erel * g) > 1e-12:
                done = True
                break
            y[0] = max(y[0], 1e-300)
            sol = solve_ivp(rhs(0.0), (t, t + 20.0), y, max_step=step_free, **opts)
            if sol.t_events[0].size:
                t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
                y[0] = 0.0
                break
            t, y = sol.t[-1], sol.y[:, -1].copy()
        if done:
            break
        count += 1
        contact = True
    return float(m @ y[n:] / mt), count


def sweep_reference(fn, rtols=(1e-11, 1e-12, 1e-13), floor=1e-12):
    """Reference = fn(rtol) at the tightest rtol; bound = 10 x spread over the sweep (floored)."""
    t0 = time.perf_counter()
    runs = [fn(r) for r in rtols]
    counts = {c for _, c in runs}
    if len(counts) != 1:
        raise RuntimeError(f"contact count changes over the tolerance sweep: {runs}")
    cor = runs[-1][0]
    spread = max(abs(c - cor) for c, _ in runs[:-1])
    info = "sweep " + ", ".join(f"{r:g}: {c!r}" for r, (c, _) in zip(rtols, runs, strict=True))
    return cor, runs[-1][1], max(10 * spread, floor), info + f"; {time.perf_counter() - t0:.0f} s"


def nonlinear_run(sc, rtol):
    import restitution

    r = restitution.solve(**sc.solve_kwargs(), method="reference", rtol=rtol)
    if r.status != "ok":
        raise RuntimeError(f"{sc.name}: reference status {r.status} at rtol {rtol}")
    return r.cor, r.n_collisions


def scissor_reference(sc):
    """The scissor scene by ``restitution.solvers.precise_scissor`` at 30 and 40 digits: bound =
    10 x their difference plus half an ulp."""
    from restitution.model.chain import paper_with_laws
    from restitution.solvers.precise_scissor import solve_precise_scissor

    chain, _ = paper_with_laws(sc.alpha, sc.beta, sc.xi, sc.n_masses, dict(sc.law))
    cor, n, diff, points = solve_precise_scissor(chain, dps=30)
    bound = 10.0 * diff + 0.5 * math.ulp(cor)
    return (
        cor,
        n,
        bound,
        f"30/40 digits differ by {diff:.1e}; branch points reached {sorted(points)}",
    )


def scissor_peak_ratio(sc):
    """Peak compression of the scissor spring / its lock extension (linear elastic contact).

    Checks the scene's claim "near its lock angle"; a plain solve_ivp of the two-mass equations
    with the scissor force of ``laws.structure_force`` (max_step 0.02, rtol 1e-10).
    """
    from restitution.model import laws

    law = dict(sc.law)
    k2 = sc.alpha / (1 + sc.alpha)
    k1 = k2 / sc.beta
    theta0 = law.get("theta0", laws.THETA0_DEFAULT)
    sp = laws.scissor_params(k2, law["ks_ratio"] * k2, law["L"], theta0)

    def f(t, y):
        f2 = laws.structure_force(sp, y[1] - y[0])
        return [y[2], y[3], k1 * max(0.0, -y[0]) + f2, -f2 / sc.alpha]

    sol = solve_ivp(
        f, (0, 120), [0, 0, -1, -1], method="DOP853", rtol=1e-10, atol=1e-12, max_step=0.02
    )
    return float(np.min(sol.y[1] - sol.y[0]) / sp[laws.SP_XLOCK])


# ------------------------------------------------------------------------------------------------


def main(argv=None):
    from restitution_workflow.bench.scenes import SCENES

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--only", nargs="*", help="scene names (default: all)")
    p.add_argument("--dps", type=int, default=40, help="mpmath digits (the check uses dps + 10)")
    p.add_argument(
        "--grazing", action="store_true", help="also recompute ALPHA_STAR_2 and ALPHA_STAR_5"
    )
    args = p.parse_args(argv)
    if args.grazing:
        for n, lo, hi in ((2, 2.0700, 2.0701), (5, 7.1516, 7.1517)):
            a = grazing_alpha(n, lo, hi, args.dps)
            print(f"ALPHA_STAR_{n} = {float_below(a)!r}  # alpha*_{n} = {a}", flush=True)
    for sc in SCENES:
        if args.only and sc.name not in args.only:
            continue
        extra = ""
        if sc.linear and sc.n_masses == 2:
            cor, n, bound, source, info, hi = two_mass_reference(sc.alpha, sc.beta, sc.xi, args.dps)
            kappa = float(f"{hi['condition']:.2g}")
            extra = f", reference_condition={kappa!r}"
        elif sc.linear:
            cor, n, bound, info = sweep_reference(
                lambda r, sc=sc: ivp_chain(sc.alpha, sc.beta, sc.xi, sc.n_masses, r)
            )
            source = "scipy DOP853 per phase, rtol 1e-13, max_step 1/125 period"
        elif sc.law.get("structure") == "scissor":
            cor, n, bound, info = scissor_reference(sc)
            source = "restitution.solvers.precise_scissor (mpmath Taylor series), 30 and 40 digits"
            info += f"; peak compression / x_lock = {scissor_peak_ratio(sc):.4f}"
        else:
            cor, n, bound, info = sweep_reference(lambda r, sc=sc: nonlinear_run(sc, r))
            source = "restitution.solvers.reference (scipy DOP853), rtol 1e-13"
        print(f"# {sc.name}: {info}", file=sys.stderr)
        print(
            f"{sc.name}: reference_cor={cor!r}, reference_contacts={n}, "
            f"reference_bound={bound:.1e}, reference_source={source!r}{extra}",
            flush=True,
        )


if __name__ == "__main__":
    main()
