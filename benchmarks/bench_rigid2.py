"""Benchmark of the exact impulsive two-mass kernel (beta = 0, xi = 0) on one thread.

Run as a script: ``NUMBA_CACHE_DIR=.cache/numba .venv/bin/python benchmarks/bench_rigid2.py``.
Prints the sweep time for 20,000 log-spaced alpha in [0.01, 200], per scene and per contact,
and the largest COR deviation from the independent reference of tests/test_rigid2.py on a
subsample.
"""

import sys
import time
from pathlib import Path

import numba
import numpy as np

from restitution.kernels.layout import OUT_COR, OUT_NCOL, OUT_STATUS
from restitution.kernels.rigid2 import rigid2_batch

N_SCENES = 20_000
N_REPEAT = 5
N_REF = 60  # reference solves (slow: pure Python)


def main():
    numba.set_num_threads(1)
    alpha = np.geomspace(0.01, 200.0, N_SCENES)
    xi = np.zeros(N_SCENES)
    rigid2_batch(alpha[:10], xi[:10], 10_000)  # JIT warm-up / cache load
    times = []
    cpu = []
    for _ in range(N_REPEAT):
        t0 = time.perf_counter()
        c0 = time.process_time()
        out = rigid2_batch(alpha, xi, 10_000)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    best = min(times)
    contacts = int(out[:, OUT_NCOL].sum())
    print(f"scenes                 {N_SCENES}")
    print(f"threads                {numba.get_num_threads()}")
    print(f"total contacts         {contacts}")
    print(f"max contacts / scene   {int(out[:, OUT_NCOL].max())} (alpha = {alpha[-1]:g})")
    print(f"statuses               {np.unique(out[:, OUT_STATUS]).astype(int).tolist()}")
    med = np.median(times)
    print(f"sweep time (best of {N_REPEAT}) {best * 1e3:.2f} ms   (median {med * 1e3:.2f} ms)")
    print(f"CPU time (best)        {min(cpu) * 1e3:.2f} ms   (robust to a busy machine)")
    print(f"time per scene         {best / N_SCENES * 1e9:.0f} ns")
    print(f"time per contact       {best / contacts * 1e9:.0f} ns")

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from test_rigid2 import reference  # noqa: PLC0415  (independent slow solver)

    idx = np.unique(np.linspace(0, N_SCENES - 1, N_REF).astype(int))
    dev = 0.0
    cnt = 0
    t0 = time.perf_counter()
    for i in idx:
        ref = reference(alpha[i], 0.0, max_contacts=10_000)
        dev = max(dev, abs(ref["cor"] - out[i, OUT_COR]))
        cnt += ref["n"] != int(out[i, OUT_NCOL])
    print(f"reference subsample    {len(idx)} scenes in {time.perf_counter() - t0:.1f} s")
    print(f"max |COR - reference|  {dev:.2e}")
    print(f"contact-count mismatch {cnt}")


if __name__ == "__main__":
    main()
