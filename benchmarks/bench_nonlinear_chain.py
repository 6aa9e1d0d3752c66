"""Benchmark of the general nonlinear chain kernel (adaptive DOP853, every phase integrated).

Run as a script:
``NUMBA_CACHE_DIR=.cache/numba .venv/bin/python benchmarks/bench_nonlinear_chain.py``.
Prints, on one thread, the time per scene and per contact of ``stepping.solve_scene`` at rtol
1e-9 for the paper's plastic two-mass scene (free flight closed form, as the kernel runs it, and
integrated, ``free_closed=False``) and for chains N = 2, 4, 8 with Hertz and plastic contact.
Best of repeats, one process.
"""

import time

import numba
import numpy as np

from restitution.kernels.layout import OUT_NCOL, OUT_STATUS, STATUS_OK
from restitution.kernels.stepping import solve_scene
from restitution.model import laws
from restitution.model.laws import pack_chain

REPEAT = 7
H0 = np.zeros((0, 6))


def best(fun, repeat=REPEAT):
    fun()  # JIT warm-up / cache load
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fun()
        times.append(time.perf_counter() - t)
    return min(times), out


def main():
    numba.set_num_threads(1)
    rtol = 1e-9
    alpha, beta, eta, dr = 2.0, 0.1, 0.5, 0.5
    k2 = alpha / (1 + alpha)
    cp = laws.contact_params(laws.C_PLASTIC, k2 / beta, laws.plastic_kappa(dr, eta, k2 / beta), eta)
    sp = laws.linear_structure_params(k2)

    def paper_scene(free_closed):
        return solve_scene(
            np.array([1.0, alpha]), sp[None, :].copy(), np.zeros(1), cp, 1.0, 0, rtol, 0.01,
            1e-6, 10_000, 4e6, H0, np.zeros(5), free_closed,
        )  # fmt: skip

    t2, o2 = best(lambda: paper_scene(True))
    tc, oc = best(lambda: paper_scene(False))
    print(f"paper plastic scene (alpha 2, beta 0.1, eta 0.5, DR 0.5), rtol {rtol:g}:")
    print(f"  free flight closed form:  {t2 * 1e6:8.1f} us, {int(o2[1])} contacts")
    print(f"  free flight integrated:   {tc * 1e6:8.1f} us, {int(oc[1])} contacts")
    print("chains (masses 1, 0.5..2, springs 0.5..1.5, no dashpots), per scene / per contact:")
    rng = np.random.default_rng(3)
    for n in (2, 4, 8):
        m = np.concatenate([[1.0], rng.uniform(0.5, 2.0, n - 1)])
        k = rng.uniform(0.5, 1.5, n - 1)
        for contact in ({"law": "hertz", "k": 20.0}, {"law": "plastic", "k": 20.0, "eta": 1.5,
                                                       "dr": 0.3}):  # fmt: skip
            ms, lk, cs, cpc, _, _ = pack_chain(m, k, None, contact, None, 1.0)
            t, o = best(
                lambda ms=ms, lk=lk, cs=cs, cpc=cpc: solve_scene(
                    ms, lk, cs, cpc, 1.0, 0, rtol, 0.01, 1e-6, 10_000, 4e6, H0, np.zeros(5)
                )
            )
            assert o[OUT_STATUS] == STATUS_OK
            nc = int(o[OUT_NCOL])
            print(f"  N = {n} {contact['law']:8s}: {t * 1e3:7.2f} ms, {nc:3d} contacts, "
                  f"{t / nc * 1e6:7.1f} us per contact")  # fmt: skip


if __name__ == "__main__":
    main()
