"""The first rise of a sum of modal velocities on a time grid, with early exit (the scans of
``restitution.analysis.cormap.first_minimum``, the design study's grazing conditions).

v(t) = sum_j phi_j (p_j cos(w_j t) - q_j w_j sin(w_j t)), w_j >= 0 (a rigid-body mode, w = 0,
gives its constant p_j). ``first_rise`` returns the first grid interval [t_i, t_i+1] where
sign * v goes from < 0 to >= 0. numpy evaluated v on the whole grid (up to 2.5e5 times, every
mode's sine and cosine) although the first rise is usually found before the grid's end; here the
scan stops there, and between anchors the modes' (cos, sin) advance by a rotation through
w_j h (four products a mode) instead of two library calls.

Every ANCHOR points the sines and cosines are evaluated afresh at the grid's own time, so the
rotation's round-off stays a few ulps of the amplitudes (ANCHOR rotations). A rotated value
decides nothing where that round-off could flip its sign: within ROTATION_TOL of the amplitudes
of 0, or where the sign changes, v is evaluated afresh. So the interval is the one numpy's scan of
the whole grid found, unless a grid value lies within round-off of 0 (where that scan's sign was
the library's rounding too).
"""

import math

import numpy as np

from restitution.jit import njit

ANCHOR = 64  # fresh sines and cosines every ANCHOR grid points
# |v| below this multiple of sum_j |phi_j| (|p_j| + |q_j| w_j): a rotated value's sign is not
# trusted (64 rotations drift by ~1e-14 of the amplitudes).
ROTATION_TOL = 1e-12


@njit(cache=True, error_model="numpy")
def _fresh(t, q, p, w, phi, c, s):
    """v(t) from fresh cos and sin, which it leaves in c and s."""
    v = 0.0
    for j in range(w.size):
        c[j] = math.cos(w[j] * t)
        s[j] = math.sin(w[j] * t)
        v += phi[j] * (p[j] * c[j] - q[j] * w[j] * s[j])
    return v


@njit(cache=True, error_model="numpy")
def first_rise(t, q, p, w, phi, sign):
    """Index i of the first i with sign * v(t[i]) < 0 <= sign * v(t[i + 1]); -1 if none.
    ``t`` is a uniform grid (np.linspace)."""
    n = t.size
    m = w.size
    if n < 2:
        return -1
    c = np.empty(m)
    s = np.empty(m)
    rc = np.empty(m)  # the rotation through one grid step
    rs = np.empty(m)
    h = (t[n - 1] - t[0]) / (n - 1)
    amp = 0.0
    for j in range(m):
        rc[j] = math.cos(w[j] * h)
        rs[j] = math.sin(w[j] * h)
        amp += abs(phi[j]) * (abs(p[j]) + abs(q[j]) * w[j])
    tol = ROTATION_TOL * amp
    prev = sign * _fresh(t[0], q, p, w, phi, c, s)
    for i in range(1, n):
        if i % ANCHOR == 0:
            cur = sign * _fresh(t[i], q, p, w, phi, c, s)
        else:
            v = 0.0
            for j in range(m):
                cj = c[j] * rc[j] - s[j] * rs[j]
                s[j] = s[j] * rc[j] + c[j] * rs[j]
                c[j] = cj
                v += phi[j] * (p[j] * cj - q[j] * w[j] * s[j])
            cur = sign * v
            if abs(cur) < tol or (cur < 0.0) != (prev < 0.0):
                cur = sign * _fresh(t[i], q, p, w, phi, c, s)  # the sign decides: fresh
        if prev < 0.0 and cur >= 0.0:
            return i - 1
        prev = cur
    return -1
