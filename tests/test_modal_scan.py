"""restitution.kernels.modal_scan.first_rise against the scan it replaced: numpy's velocity on
the whole grid (Modes.first, positions and accelerations included) and its first - to + sign
change."""

import math

import numpy as np
import pytest

from restitution.analysis import cormap
from restitution.kernels.modal_scan import ANCHOR, first_rise


def _whole_grid(modes, u, v, t, sign):
    vel = sign * modes.first(u, v, t)[1]
    idx = np.flatnonzero((vel[:-1] < 0.0) & (vel[1:] >= 0.0))
    return int(idx[0]) if idx.size else -1


def _rise(modes, u, v, t, sign):
    q0, p0 = modes.coords(u, v)
    return first_rise(t, q0, p0, np.sqrt(modes.w2), np.ascontiguousarray(modes.phi[0]), sign)


def _random_chain(rng, trial):
    n = int(rng.integers(2, 9))
    m = np.exp(rng.uniform(np.log(0.01), np.log(100.0), n))
    m[0] = 1.0
    k = np.exp(rng.uniform(np.log(0.01), np.log(100.0), n - 1))
    kc = 0.0 if trial % 2 else float(np.exp(rng.uniform(-2.0, 7.0)))  # free (rigid mode) or not
    return cormap.Modes.of(m, cormap.stiffness(k, kc)), n


def test_the_same_interval_as_the_whole_grid_on_random_chains():
    rng = np.random.default_rng(11)
    rises = 0
    for trial in range(600):
        modes, n = _random_chain(rng, trial)
        u, v = rng.normal(size=n), rng.normal(size=n)
        wmax = math.sqrt(float(modes.w2.max()))
        # grids of the design's density (24 a fastest period) and coarser ones, past ANCHOR
        t = np.linspace(0.0, rng.uniform(0.5, 60.0) * 2 * math.pi / wmax,
                        int(rng.integers(2, 40 * ANCHOR)))  # fmt: skip
        for sign in (1.0, -1.0):
            want = _whole_grid(modes, u, v, t, sign)
            assert _rise(modes, u, v, t, sign) == want
            rises += want >= 0
    assert rises > 600  # most scans find a rise: the comparison is not of -1s


def test_a_grid_point_on_a_tangency_and_rises_at_the_ends():
    """One mode (v = cos t): grid values within round-off of 0 (cos(pi/2) = 6e-17,
    cos(3 pi/2) = -1.8e-16), a rise in the grid's last interval, none at all; a rigid-body
    mode alone."""
    one = cormap.Modes.of(np.array([1.0]), np.array([[1.0]]))  # v = cos t (u = 0, v = 1)
    u, v = np.zeros(1), np.ones(1)
    t = np.linspace(0.0, 2 * math.pi, 9)  # steps of pi/4
    assert _rise(one, u, v, t, 1.0) == _whole_grid(one, u, v, t, 1.0) == 6  # from -1.8e-16
    assert _rise(one, u, v, t, -1.0) == _whole_grid(one, u, v, t, -1.0) == 2  # from -6e-17
    short = np.linspace(0.0, 1.0, 5)
    assert _rise(one, u, v, short, 1.0) == -1  # cos > 0 throughout
    last = np.linspace(0.0, 1.5 * math.pi + 1e-3, 2 * ANCHOR + 1)
    assert _rise(one, u, v, last, 1.0) == _whole_grid(one, u, v, last, 1.0) == 2 * ANCHOR - 1
    rigid = cormap.Modes.of(np.array([1.0, 1.0]), cormap.stiffness([1.0]))
    assert _rise(rigid, np.zeros(2), -np.ones(2), np.linspace(0, 9, 100), 1.0) == -1  # v = -1


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_near_tangent_minima_are_decided_by_fresh_values(sign):
    """A grid value off the anchors moved to within 1e-13 of 0 (a constant added through a
    rigid-body mode): the whole grid's interval; moved to within round-off (0, 1e-15): the same
    interval unless the two evaluations round that value to opposite signs."""
    modes = cormap.Modes.of(np.array([1.0, 0.3]), cormap.stiffness([2.0]))
    rng = np.random.default_rng(5)
    for _ in range(200):
        u, v = rng.normal(size=2), rng.normal(size=2)
        t = np.linspace(0.0, 40.0, 3001)
        vel = sign * modes.first(u, v, t)[1]
        j = int(rng.integers(ANCHOR + 1, 3000))  # a point off the anchors
        if j % ANCHOR == 0:
            j += 1
        # shift the velocity by a constant (a rigid-body mode's) so that v(t_j) is ~1e-14
        q0, p0 = modes.coords(u, v)
        w = np.sqrt(np.append(modes.w2, 0.0))
        phi = np.append(modes.phi[0], 1.0)
        for eps in (0.0, 1e-15, -1e-15, 1e-13, -1e-13):
            shift = -vel[j] * sign + eps
            q = np.append(q0, 0.0)
            p = np.append(p0, shift)
            got = first_rise(t, q, p, w, phi, sign)
            grid = sign * (modes.first(u, v, t)[1] + shift)
            idx = np.flatnonzero((grid[:-1] < 0.0) & (grid[1:] >= 0.0))
            want = int(idx[0]) if idx.size else -1
            if abs(eps) >= 1e-13 or want == got:
                assert got == want
            else:  # only where the two evaluations round a value within 1e-14 of 0 apart
                k = min(want if want >= 0 else got, got if got >= 0 else want)
                assert min(abs(grid[k]), abs(grid[k + 1])) < 1e-14
