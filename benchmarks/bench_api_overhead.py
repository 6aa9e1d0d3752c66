"""What the public API adds to the bare kernels (checks, dispatch, result assembly).

Run as a script: ``NUMBA_CACHE_DIR=.cache/numba .venv/bin/python benchmarks/bench_api_overhead.py``.
Every figure is a best-of-repeats time taken in this one process, API and kernel interleaved so
that a busy machine slows both alike; the targets are printed next to the figures:

* ``solve_many`` on 20,000 scalar rigid-wall rows: at most 1.2 x the bare batch kernel;
* ``solve_many`` on 100 rows: at most 1 ms per call;
* one ``solve`` call: at most 5 us above its kernel call;
* list columns (general chains): the extra cost per row, reported.
"""

import math
import time

import numpy as np
import pandas as pd

import restitution
from restitution.kernels import layout as L

REPEATS = 7


def best(fn, repeats=REPEATS, inner=1):
    """Best time of ``repeats`` runs of ``inner`` calls of fn, per call (seconds)."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(inner):
            fn()
        times.append((time.perf_counter() - t0) / inner)
    return min(times)


def interleaved(a, b, repeats=REPEATS, inner=1):
    """Best times of a and b measured alternately."""
    ta, tb = [], []
    for _ in range(repeats):
        ta.append(best(a, 1, inner))
        tb.append(best(b, 1, inner))
    return min(ta), min(tb)


def main():
    from restitution.kernels.exact_chain import solve_chain_batch
    from restitution.kernels.paper_chain import solve_linear
    from restitution.kernels.rigid2 import rigid2, rigid2_batch

    print(f"restitution {restitution.__version__}; best of {REPEATS}, interleaved")

    # 1. 20,000 scalar rigid-wall rows
    alpha = np.geomspace(0.01, 200.0, 20_000)
    frame = pd.DataFrame({"alpha": alpha, "beta": 0.0, "xi": 0.0, "n_masses": 2})
    xi = np.zeros(len(alpha))
    restitution.solve_many(frame.iloc[:10])
    kernel, api = interleaved(
        lambda: rigid2_batch(alpha, xi, 100_000), lambda: restitution.solve_many(frame)
    )
    print(
        f"solve_many 20,000 rigid rows   {api * 1e3:8.2f} ms   bare kernel {kernel * 1e3:8.2f} ms"
        f"   ratio {api / kernel:5.2f}  (target <= 1.20)"
    )

    # 2. 100 rows
    small = frame.iloc[::200].reset_index(drop=True)
    kernel, api = interleaved(
        lambda: rigid2_batch(small["alpha"].to_numpy(), xi[:100], 100_000),
        lambda: restitution.solve_many(small),
        inner=20,
    )
    print(
        f"solve_many 100 rows            {api * 1e3:8.3f} ms   bare kernel {kernel * 1e3:8.3f} ms"
        f"   overhead {(api - kernel) * 1e3:6.3f} ms  (target: call <= 1 ms)"
    )

    # 3. one solve call (rigid wall, two masses; linear contact, chain of 3)
    hist = np.zeros((0, L.N_HIST))
    for label, call, bare in (
        ("solve(alpha=2)               ", lambda: restitution.solve(2.0),
         lambda: rigid2(2.0, 0.0, 100_000, np.zeros((0, L.N_HIST)))),
        ("solve(alpha=2, beta=0.01, N=3)", lambda: restitution.solve(2.0, 0.01, 0.0, 3),
         lambda: solve_linear(2.0, 0.01, 0.0, 3, 100_000, np.zeros((0, L.N_HIST)))),
    ):  # fmt: skip
        call()
        bare()
        kernel, api = interleaved(bare, call, inner=2000)
        print(
            f"{label} {api * 1e6:8.2f} us   bare kernel {kernel * 1e6:8.2f} us   "
            f"overhead {(api - kernel) * 1e6:5.2f} us  (target <= 5 us)"
        )
    del hist

    # 4. list columns: general chains (not of the paper's form), N = 4
    rng = np.random.default_rng(1)
    rows = 2000
    masses = rng.uniform(0.5, 2.0, (rows, 4))
    springs = rng.uniform(0.5, 2.0, (rows, 3))
    general = pd.DataFrame({"masses": list(masses), "springs": list(springs)})
    as_text = pd.DataFrame(
        {
            "masses": [";".join(map(str, m)) for m in masses],
            "springs": [";".join(map(str, k)) for k in springs],
        }
    )
    w2 = springs[:, 0] / masses[:, 0] + springs[:, 0] / masses[:, 1]
    m = masses / masses[:, :1]
    k = springs / (masses[:, :1] * w2[:, None])
    c = np.zeros_like(k)
    n = np.full(rows, 4, dtype=np.int64)
    kc = np.full(rows, math.inf)
    restitution.solve_many(general.iloc[:5])
    solve_chain_batch(m[:5], k[:5], c[:5], n[:5], kc[:5], 100_000)
    kernel, api = interleaved(
        lambda: solve_chain_batch(m, k, c, n, kc, 100_000),
        lambda: restitution.solve_many(general),
        repeats=5,
    )
    text = best(lambda: restitution.solve_many(as_text), repeats=3)
    print(
        f"solve_many {rows} list rows (N=4) {api * 1e3:8.1f} ms   "
        f"bare kernel {kernel * 1e3:8.1f} ms"
        f"   extra {(api - kernel) / rows * 1e6:6.1f} us/row (list cells), "
        f"{(text - kernel) / rows * 1e6:6.1f} us/row (';' text cells)"
    )


if __name__ == "__main__":
    main()
