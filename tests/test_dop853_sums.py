"""kernels/dop853_sums.py: the generated DOP853 stage sums are the generator's output and give
the bits of the plain loops over the tableau (DOP853 itself is checked against the exact kernels
and the references elsewhere)."""

from pathlib import Path

import numpy as np

from restitution.kernels import dop853_sums as S
from restitution.kernels import dop853_tableau as T


def test_the_module_is_the_generators_output():
    assert Path(S.__file__).read_text() == T.sums_source()


def _loop_sum(coef, K, i):
    acc = 0.0
    for j, c in enumerate(coef):
        if c != 0.0:
            acc += c * K[j, i]
    return acc


def test_sums_are_the_plain_loops_bit_for_bit():
    rng = np.random.default_rng(5)
    for trial in range(200):
        n = int(rng.integers(1, 12))
        K = rng.normal(size=(T.N_STAGES_EXTENDED, n)) * 10.0 ** rng.uniform(-12, 12, (1, n))
        y = rng.normal(size=n)
        h = 10.0 ** rng.uniform(-8, 1)
        out = np.empty(n)
        for s in range(1, T.N_STAGES_EXTENDED):
            S.stage_state(y, K, h, s, out)
            want = [y[i] + h * _loop_sum(T.A[s, :s], K, i) for i in range(n)]
            assert out.tobytes() == np.array(want).tobytes(), (trial, s)
        S.solution(y, K, h, out)
        want = [y[i] + h * _loop_sum(T.B, K, i) for i in range(n)]
        assert out.tobytes() == np.array(want).tobytes(), trial
        F = np.zeros((T.INTERPOLATOR_POWER, n))
        S.dense_rows(K, h, F)
        for k in range(T.D.shape[0]):
            want = [_loop_sum(T.D[k], K, i) * h for i in range(n)]
            assert F[3 + k].tobytes() == np.array(want).tobytes(), (trial, k)
