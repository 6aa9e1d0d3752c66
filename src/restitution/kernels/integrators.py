"""Integrators written once for any chain and any force law: velocity Verlet and Dormand-Prince
5(4).

A chain is its masses ``m[n]`` (m[0] at the wall), one link law per neighbouring pair (rows of
``lk``, each a ``structure_params`` array), dashpots ``c[n-1]``, the contact law ``cp`` and its
mutable memory ``mem``. The force laws enter only through these packed parameters: ``rhs`` /
``accel_verlet`` below dispatch on the law codes of ``restitution.model.laws``, so any law added
there is integrated by the same code. (Passing the law as a numba function argument would defeat
numba's on-disk cache: a minute of compilation per process.) Two masses are the chain n = 2;
there is no separate two-mass stack.

State y = [u_1..u_n, v_1..v_n, W, D] (length 2n + 2): lab-frame displacements and velocities,
W = integral of the contact force times d(penetration) (work done on the contact), D = dashpot
loss. mem = [phase, branch, xmax, fmax, xp, spare...]: phase 1 = in contact, branch 1 =
loading/rising, xmax/fmax the largest penetration and force so far (plastic), xp the residual
dent (m1 touches iff x = -u1 > xp).

Event location (DP5(4)). Every event of these scenes is a *linear* functional g(y) = w.y + b of
the state (a penetration, a velocity), so on an accepted step g along the dense output is a
polynomial of degree 4 in theta in [0, 1]. Its first root is found with certainty by Bernstein
bounds (convex-hull property: all Bernstein coefficients > 0 => no root) and left-first
subdivision, not by endpoint signs: a shallow contact or a reload past the previous maximum that
enters and leaves within one step is found. An event that starts the phase at g = 0 (leaving the
surface) is handled exactly by dividing out the zero leading coefficients (theta**k), which the
dense output reproduces exactly because its linear coefficient is h*f(y0).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from restitution.model.laws import (
    C_PLASTIC,
    C_RIGID,
    contact_force,
    contact_hysteretic,
    structure_energy,
    structure_extent,
    structure_force,
)

# Dormand-Prince 5(4) tableau and the 4th-order dense output (Shampine; as in scipy's RK45).
DP_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0])
DP_A = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [1 / 5, 0.0, 0.0, 0.0, 0.0],
        [3 / 40, 9 / 40, 0.0, 0.0, 0.0],
        [44 / 45, -56 / 15, 32 / 9, 0.0, 0.0],
        [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0],
        [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
    ]
)
DP_B = np.array([35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84])
DP_E = np.array([-71 / 57600, 0.0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40])
DP_P = np.array(
    [
        [1.0, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
        [0.0, 0.0, 0.0, 0.0],
        [0.0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799],
        [0.0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
        [0.0, 127303824393 / 49829197408, -318862633887 / 49829197408, 701980252875 / 199316789632],
        [0.0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
        [0.0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
    ]
)

_BINOM = np.array(
    [[1.0, 0, 0, 0, 0], [1, 1, 0, 0, 0], [1, 2, 1, 0, 0], [1, 3, 3, 1, 0], [1, 4, 6, 4, 1]]
)

M_PHASE, M_BRANCH, M_XMAX, M_FMAX, M_XP = 0, 1, 2, 3, 4
N_MEM = 8


@njit(cache=True, error_model="numpy")
def dent(cp, mem):
    if cp[0] == C_PLASTIC and mem[M_FMAX] > 0.0:
        return mem[M_XMAX] - mem[M_FMAX] / cp[1]
    return 0.0


# rk_phase return codes
EV_STOP = -1  # the stop test passed (e.g. no further contact possible)
EV_FAIL = -2  # step size underflow or step budget exhausted
# rk_phase stop tests
STOP_NEVER = 0
STOP_NO_CONTACT = 1


@njit(cache=True, error_model="numpy")
def event_poly(K, h, y0, w, b, coef):
    """Monomial coefficients (degree 4 in theta) of w.y(theta) + b along the dense output."""
    n = y0.shape[0]
    g0 = b
    for i in range(n):
        g0 += w[i] * y0[i]
    coef[0] = g0
    for j in range(4):
        acc = 0.0
        for s in range(7):
            if DP_P[s, j] != 0.0:
                wk = 0.0
                for i in range(n):
                    wk += w[i] * K[s, i]
                acc += wk * DP_P[s, j]
        coef[j + 1] = h * acc


@njit(cache=True, error_model="numpy")
def dense_state(y0, K, h, theta, out):
    n = y0.shape[0]
    for i in range(n):
        acc = 0.0
        tp = 1.0
        for j in range(4):
            tp *= theta
            q = 0.0
            for s in range(7):
                q += K[s, i] * DP_P[s, j]
            acc += q * tp
        out[i] = y0[i] + h * acc


@njit(cache=True, error_model="numpy")
def poly_val(c, n, t):
    acc = 0.0
    for k in range(n, -1, -1):
        acc = acc * t + c[k]
    return acc


@njit(cache=True, error_model="numpy")
def _bernstein_min(c, n, a, b):
    """Smallest Bernstein coefficient of the degree-n polynomial c restricted to [a, b]."""
    # Taylor shift to a, then scale by (b - a)**k: monomials in s in [0, 1].
    d = np.empty(n + 1)
    for k in range(n + 1):
        d[k] = c[k]
    for i in range(n):
        for k in range(n - 1, i - 1, -1):
            d[k] += a * d[k + 1]
    sc = 1.0
    for k in range(n + 1):
        d[k] *= sc
        sc *= b - a
    # monomial -> Bernstein: b_i = sum_j C(i,j)/C(n,j) d_j
    m = math.inf
    for i in range(n + 1):
        acc = 0.0
        for j in range(i + 1):
            acc += _BINOM[i, j] / _BINOM[n, j] * d[j]
        m = min(m, acc)
    return m


@njit(cache=True, error_model="numpy")
def first_root(c, n, strip):
    """First theta in (0, 1] where the polynomial goes from > 0 to <= 0; -1.0 if none.

    ``strip`` leading coefficients are known to be exactly zero (the event starts on its surface);
    they are divided out. Returns 0.0 if the function moves to the negative side at once.
    """
    q = np.zeros(n + 1)
    m = n - strip
    for k in range(m + 1):
        q[k] = c[k + strip]
    if q[0] <= 0.0:
        return 0.0
    if m == 0:
        return -1.0
    stack_a = np.empty(128)
    stack_b = np.empty(128)
    top = 0
    stack_a[0], stack_b[0] = 0.0, 1.0
    top = 1
    while top > 0:
        top -= 1
        a, b = stack_a[top], stack_b[top]
        if poly_val(q, m, b) <= 0.0:
            # bracketed: p(a) > 0 >= p(b); Illinois-safeguarded bisection to round-off
            for _ in range(200):
                mid = 0.5 * (a + b)
                if mid <= a or mid >= b:
                    break
                fm = poly_val(q, m, mid)
                if fm > 0.0:
                    a = mid
                else:
                    b = mid
            return b
        if _bernstein_min(q, m, a, b) > 0.0 or b - a < 1e-13 or top > 120:
            continue  # provably no root here (or a tangency below round-off)
        mid = 0.5 * (a + b)
        stack_a[top], stack_b[top] = mid, b
        stack_a[top + 1], stack_b[top + 1] = a, mid
        top += 2
    return -1.0


@njit(cache=True, error_model="numpy")
def rhs(y, m, lk, c, cp, mem, dy):
    """Equations of motion of the chain with the current contact branch."""
    n = m.shape[0]
    for i in range(n):
        dy[i] = y[n + i]
        dy[n + i] = 0.0
    fc = 0.0
    if mem[M_PHASE] == 1.0:
        fc = contact_force(cp, int(mem[M_BRANCH]), mem[M_XMAX], mem[M_FMAX], -y[0])
    dy[n] = fc
    d = 0.0
    for i in range(n - 1):
        f = structure_force(lk[i], y[i + 1] - y[i])
        dv = y[n + i + 1] - y[n + i]
        fd = c[i] * dv
        dy[n + i] += f + fd
        dy[n + i + 1] -= f + fd
        d += fd * dv
    for i in range(n):
        dy[n + i] /= m[i]
    dy[2 * n] = -fc * y[n]
    dy[2 * n + 1] = d


@njit(cache=True, error_model="numpy")
def dp_step(y, f0, h, rtol, atol, m, lk, c, cp, mem, K, ynew, tmp):
    """One DP5(4) step from y (with f0 = f(y)); fills K (7 x len(y)) and ynew; returns the
    error norm."""
    n = y.shape[0]
    K[0, :] = f0
    for s in range(1, 6):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += DP_A[s, j] * K[j, i]
            tmp[i] = y[i] + h * acc
        rhs(tmp, m, lk, c, cp, mem, K[s])
    for i in range(n):
        acc = 0.0
        for j in range(6):
            acc += DP_B[j] * K[j, i]
        ynew[i] = y[i] + h * acc
    rhs(ynew, m, lk, c, cp, mem, K[6])
    err = 0.0
    for i in range(n):
        e = 0.0
        for j in range(7):
            e += DP_E[j] * K[j, i]
        sc = atol + rtol * max(abs(y[i]), abs(ynew[i]))
        err += (h * e / sc) ** 2
    return math.sqrt(err / n)


@njit(cache=True, error_model="numpy")
def internal_energy(y, m, lk):
    """Energy of the motion relative to the centre of mass: relative kinetic + link potentials."""
    n = m.shape[0]
    mt = 0.0
    p = 0.0
    ek = 0.0
    for i in range(n):
        mt += m[i]
        p += m[i] * y[n + i]
        ek += 0.5 * m[i] * y[n + i] * y[n + i]
    e = ek - 0.5 * p * p / mt
    for i in range(n - 1):
        e += structure_energy(lk[i], y[i + 1] - y[i])
    return max(e, 0.0)


@njit(cache=True, error_model="numpy")
def no_contact_possible(y, m, lk, xp):
    """True when m1 provably never reaches the contact surface u1 = -xp again (free flight).

    The centre of mass X moves at the constant V (no wall force). m1 trails it by
    X - u1 = sum_i mu_i r_i (r_i = u_{i+1} - u_i, mu_i = mass beyond link i / total mass), and the
    internal energy E (relative kinetic + link potentials) never grows in free flight (dashpots
    only dissipate), so every r_i stays within U_i(r_i) <= E. Linear links together: by
    Cauchy-Schwarz sum mu_i r_i <= sqrt(2 E sum mu_i**2/k_i); any other link: mu_i times its
    extent at energy E. With V > 0, X + xp - that bound > 0 now stays > 0 for ever.
    """
    n = m.shape[0]
    mt = 0.0
    p = 0.0
    q = 0.0
    for i in range(n):
        mt += m[i]
        p += m[i] * y[n + i]
        q += m[i] * y[i]
    if p <= 0.0:
        return False
    e = internal_energy(y, m, lk)
    beyond = mt
    lin = 0.0
    bound = 0.0
    for i in range(n - 1):
        beyond -= m[i]
        mu = beyond / mt
        if lk[i, 0] == 0.0:  # S_LINEAR
            lin += mu * mu / lk[i, 1]
        else:
            bound += mu * structure_extent(lk[i], e, 1.0)
    bound += math.sqrt(2.0 * e * lin)
    return q / mt + xp - bound > 0.0


@njit(cache=True, error_model="numpy")
def rk_phase(y, t, h, hmax, rtol, atol, m, lk, c, cp, mem, W, B, strip, nev, stop, work, err_acc):
    """Integrate with DP5(4) until the first event (or ``stop``); y is updated in place.

    W[k], B[k], strip[k] (k < nev) define the events g_k = W[k].y + B[k] (trigger: > 0 -> <= 0);
    ``strip`` applies to the first step only (leading zeros of an event that starts on its own
    surface). Returns (code, t, h_next) with code = event index, EV_STOP or EV_FAIL.
    stop = STOP_NO_CONTACT ends the phase when ``no_contact_possible`` after an accepted step.
    ``work[0]`` counts right-hand-side evaluations left for the whole scene (a budget in
    operations: results do not depend on the machine or thread count); EV_FAIL when it runs
    out or the step underflows.
    ``err_acc[0]`` accumulates the local error estimates of the total momentum.
    """
    n = y.shape[0]
    nm = m.shape[0]
    K = np.empty((7, n))
    ynew = np.empty(n)
    tmp = np.empty(n)
    f0 = np.empty(n)
    coef = np.empty(5)
    rhs(y, m, lk, c, cp, mem, f0)
    first = True
    while work[0] > 0.0:
        work[0] -= 6.0
        h = min(h, hmax)
        if not (h >= 1e-14 * max(1.0, abs(t)) and h < math.inf):  # also catches NaN
            return EV_FAIL, t, h
        err = dp_step(y, f0, h, rtol, atol, m, lk, c, cp, mem, K, ynew, tmp)
        if not err <= 1.0:  # also catches NaN
            fac = 0.2 if not err == err else max(0.2, 0.9 * err**-0.2)
            h *= fac
            continue
        best = 2.0
        which = -1
        for k in range(nev):
            event_poly(K, h, y, W[k], B[k], coef)
            s = 0
            if first and strip[k] > 0:
                coef[0] = 0.0
                s = strip[k]
                while s < 4 and coef[s] == 0.0:
                    s += 1
            th = first_root(coef, 4, s)
            if th >= 0.0 and th < best:
                best, which = th, k
        em = 0.0
        for j in range(7):
            mom = 0.0
            for i in range(nm):
                mom += m[i] * K[j, nm + i]
            em += DP_E[j] * mom
        err_acc[0] += abs(h * em)
        hn = h * min(10.0, max(0.2, 0.9 * max(err, 1e-10) ** -0.2))
        if which >= 0:
            dense_state(y, K, h, best, tmp)
            y[:] = tmp
            return which, t + best * h, max(h * best, 0.1 * h)
        y[:] = ynew
        f0[:] = K[6]
        t += h
        h = hn
        first = False
        if stop == STOP_NO_CONTACT and no_contact_possible(y, m, lk, mem[M_XP]):
            return EV_STOP, t, h
    return EV_FAIL, t, h


@njit(cache=True, error_model="numpy")
def accel_verlet(y, m, lk, c, cp, mem, acc):
    """Accelerations (acc[:n]) for Verlet with the path-following contact law; returns
    (contact force, dashpot power)."""
    n = m.shape[0]
    fc = 0.0
    if cp[0] != C_RIGID:
        fc, xm, fm = contact_hysteretic(cp, mem[M_XMAX], mem[M_FMAX], -y[0])
        mem[M_XMAX], mem[M_FMAX] = xm, fm
    for i in range(n):
        acc[i] = 0.0
    acc[0] = fc
    pw = 0.0
    for i in range(n - 1):
        f = structure_force(lk[i], y[i + 1] - y[i])
        dv = y[n + i + 1] - y[n + i]
        fd = c[i] * dv
        acc[i] += f + fd
        acc[i + 1] -= f + fd
        pw += fd * dv
    for i in range(n):
        acc[i] /= m[i]
    return fc, pw


@njit(cache=True, error_model="numpy")
def verlet_step(y, acc, h, m, lk, c, cp, mem, damped):
    """One velocity-Verlet step; acc has n + 2 entries (accelerations, contact force, dashpot
    power) and enters with a(y), leaves with a(y_new). With a dashpot (``damped``) the new
    acceleration depends on the new velocity: it is evaluated at the predictor v + h*a, then once
    more at the corrected velocity (a fixed-point pass, which keeps the scheme second order).
    W (contact work) and D (dashpot loss) use the trapezoidal rule."""
    n = m.shape[0]
    x_old = -y[0]
    f_old = acc[n]
    p_old = acc[n + 1]
    for i in range(n):
        vh = y[n + i] + 0.5 * h * acc[i]
        y[i] += h * vh
        y[n + i] = vh
    vhalf = y[n : 2 * n].copy()
    for i in range(n):
        y[n + i] = vhalf[i] + 0.5 * h * acc[i]
    fc, pw = accel_verlet(y, m, lk, c, cp, mem, acc)
    for i in range(n):
        y[n + i] = vhalf[i] + 0.5 * h * acc[i]
    if damped:
        fc, pw = accel_verlet(y, m, lk, c, cp, mem, acc)
        for i in range(n):
            y[n + i] = vhalf[i] + 0.5 * h * acc[i]
    y[2 * n] += 0.5 * (f_old + fc) * (-y[0] - x_old)
    y[2 * n + 1] += 0.5 * h * (p_old + pw)
    acc[n] = fc
    acc[n + 1] = pw
