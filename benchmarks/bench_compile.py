"""First-call time of every kind of scene: numba compile with an empty cache, and cache load.

Run as a script: ``.venv/bin/python benchmarks/bench_compile.py [--jobs N]``. For each step of
``restitution warmup`` (one small scene of every kind the solvers dispatch to) two fresh Python
processes run that step alone: the first with an empty numba cache (its time is what a user's
first call of that kind waits in a fresh environment: the compile), the second with the cache
the first left (the load). A step that shares kernels with another compiles them too here, so
the cold column is each kind on its own; their sum is more than a whole warmup's. The import of
the package (numba, numpy, pandas) is timed apart and is not in either column.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

_CHILD = """
import json, sys, time
t0 = time.perf_counter()
import restitution.warmup as w
steps = dict(w._steps())
t1 = time.perf_counter()
steps[sys.argv[1]]()
t2 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "call": t2 - t1}))
"""


def run(label: str, cache: str) -> dict:
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    done = subprocess.run(
        [sys.executable, "-c", _CHILD, label], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="run only the steps whose label contains this text")
    args = parser.parse_args()
    from restitution.warmup import _steps

    labels = [label for label, _ in _steps() if not args.only or args.only in label]
    print(f"{'cold (s)':>9} {'warm (s)':>9} {'import (s)':>10}  kind of scene", flush=True)
    total = 0.0
    t0 = time.perf_counter()
    for label in labels:
        with tempfile.TemporaryDirectory(prefix="bench-compile-") as cache:
            cold = run(label, cache)
            warm = run(label, cache)
        total += cold["call"]
        print(
            f"{cold['call']:9.1f} {warm['call']:9.2f} {cold['import']:10.2f}  {label}", flush=True
        )
    print(f"{total:9.1f} {'':>9} {'':>10}  sum of the cold first calls", flush=True)
    print(f"(wall {time.perf_counter() - t0:.0f} s, load {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
