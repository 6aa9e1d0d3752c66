"""Kelvin-Voigt contact: the exact method (``piecewise``, kernels.exact_chain) against
``adaptive`` at rtol 1e-12, both against the mpmath reference (``solve_precise`` with the
contact's dashpot, 40 digits checked at 60).

Run as a script: ``NUMBA_CACHE_DIR=.cache/numba .venv/bin/python benchmarks/bench_kelvin_voigt.py``.
Per scene it prints the contact count, the time per solve (best of a few, both methods in this
one process, interleaved), the COR error of each method against the reference and each
method's own error estimate. The kernels are compiled (and the reference run) before timing.
"""

import math
import time

import restitution
from restitution.solvers.precise import solve_precise

KV = "kelvin_voigt"
REPEATS = 5

# (masses, springs, dashpots, k, c): a chain of the paper's kind, a re-contact from inside the
# penetration, an overdamped contact, a longer damped chain and a stiff lightly damped contact.
SCENES = [
    ([1.0, 2.0, 2.0], [1.0, 1.0], [0.1, 0.0], 10.0, 2.0),
    ([1.0, 3.0], [0.3], None, 100.0, 40.0),
    ([1.0, 0.7, 2.0], [1.0, 0.5], None, 5.0, 2.0 * 3.0 * math.sqrt(5.0)),
    (
        [1.0, 0.5, 2.0, 1.0, 3.0, 0.8],
        [1.0, 0.4, 2.0, 0.7, 1.5],
        [0.05, 0.0, 0.02, 0.0, 0.1],
        30.0,
        0.5,
    ),  # fmt: skip
    ([1.0, 1.0, 1.0, 1.0], [1.0, 1.0, 1.0], None, 1e3, 2.0 * 0.01 * math.sqrt(1e3)),
]


def best(fn):
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        r = fn()
        times.append(time.perf_counter() - t0)
    return min(times), r


def main():
    print(f"{'scene':>5} {'N':>2} {'ncol':>4} {'t exact':>10} {'t adaptive':>11} {'ratio':>6} "
          f"{'err exact':>10} {'est exact':>10} {'err adapt':>10} {'est adapt':>10}")  # fmt: skip
    worst = [0.0, 0.0]
    for i, (m, k, c, kc, cc) in enumerate(SCENES):
        kw = dict(masses=m, springs=k, dashpots=c, contact={"law": KV, "k": kc, "c": cc})

        def exact(kw=kw):
            return restitution.solve(**kw)

        def adaptive(kw=kw):
            return restitution.solve(**kw, method="adaptive", rtol=1e-12)

        exact()
        adaptive()  # compiled before timing
        ref = solve_precise(m, k, c, kc, cc=cc)
        te, re = best(exact)
        ta, ra = best(adaptive)
        assert re.method == "piecewise" and ra.method == "adaptive"
        assert re.n_collisions == ref.n_collisions == ra.n_collisions
        ee, ea = abs(re.cor - ref.cor), abs(ra.cor - ref.cor)
        worst = [max(worst[0], ee), max(worst[1], ea)]
        print(f"{i:>5} {len(m):>2} {re.n_collisions:>4} {te * 1e3:>8.3f}ms {ta * 1e3:>9.3f}ms "
              f"{ta / te:>6.1f} {ee:>10.1e} {re.error_estimate:>10.1e} {ea:>10.1e} "
              f"{ra.error_estimate:>10.1e}")  # fmt: skip
    print(f"largest COR error: exact {worst[0]:.1e}, adaptive (rtol 1e-12) {worst[1]:.1e}")


if __name__ == "__main__":
    main()
