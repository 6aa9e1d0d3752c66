"""What one grazing evaluation of the design polish costs, part by part (Fig. 8(b)).

Run as a script: ``NUMBA_CACHE_DIR=.cache/numba .venv/bin/python benchmarks/bench_grazing.py``.
The chain is the free masses-and-springs design N = 7 of Fig. 8(b) (ratios to 6 digits), at a
rigid wall. Prints the best of repeated runs, per call, of
``restitution.analysis.cormap.grazing`` as the polish calls it (``check=False``: the kernel's
first run without its replica check) and checked (``check=True``, as the Fig. 8(a) map calls it),
and of its parts: the contact times (``analysis.scaled.contact_times``), the documented path it
stands in for (``solve_scaled(history=True)``), the chain's modes and the first minimum (scan
and Brent). On 2026-11-28 (quiet 2-core machine) the polish's evaluation took 220 us, 511 us
before that day's change (a checked solve with its history table, the modes twice, the modal
coordinates at every velocity evaluation).
"""

import math
import time

import numpy as np

from restitution.analysis import cormap
from restitution.analysis.scaled import contact_times, solve_scaled

MASSES = [1.0, 0.630717, 0.012922, 0.133085, 0.0207922, 0.0207792, 0.128457]
SPRINGS = [1.0, 0.419266, 0.285529, 0.0651642, 99.9721, 0.0100089]


def best(fn, repeats=5, inner=300) -> float:
    """Best time of ``repeats`` runs of ``inner`` calls of fn, per call (seconds)."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(inner):
            fn()
        times.append((time.perf_counter() - t0) / inner)
    return min(times)


def main() -> None:
    m, k, kc = MASSES, SPRINGS, math.inf
    res, ts, te = contact_times(m, k, kc, max_events=10_000, check=False)
    modes = cormap._modes(np.asarray(m), k, kc)
    _, _, u, v = cormap.chain_states(m, k, kc, (ts, te), 1, modes)[0]
    free = modes[0]
    slow = math.sqrt(float(free.w2[free.w2 > 0].min()))
    rows = [
        ("grazing, as the polish (check=False)", lambda: cormap.grazing(m, k, kc, 1, "new",
                                                                        check=False)),
        ("grazing, checked", lambda: cormap.grazing(m, k, kc, 1, "new")),
        ("  contact times, unchecked", lambda: contact_times(m, k, kc, max_events=10_000,
                                                             check=False)),
        ("  contact times, checked", lambda: contact_times(m, k, kc, max_events=10_000)),
        ("  solve_scaled(history=True) (what they stand in for)",
         lambda: solve_scaled(m, k, kc, history=True, max_events=10_000)),
        ("  the chain's modes", lambda: cormap._modes(np.asarray(m), k, kc)),
        ("  first minimum (scan and Brent)",
         lambda: cormap.first_minimum(free, u, v, 2.0 * math.pi / slow * 1.05)),
    ]  # fmt: skip
    print(f"free masses and springs N = 7 at a rigid wall: {res.n_collisions} contact(s)")
    for label, fn in rows:
        print(f"{best(fn) * 1e6:9.1f} us  {label}")


if __name__ == "__main__":
    main()
