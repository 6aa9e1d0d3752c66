"""Where one kind of scene's first call spends its compile time, function by function.

Usage: .venv/bin/python benchmarks/compile_profile.py "plastic contact" [--top 30]

Runs the ``restitution warmup`` step whose label contains the text in a fresh Python process with
an empty numba cache, and listens to numba's ``numba:compile`` events: each compiled function's
time exclusive of the functions it compiled on the way (its own typing, lowering and LLVM work,
which includes optimising again the code of every callee numba links into its module), and how
often it was compiled. Prints the total, the number of functions, the ``--top`` largest, and
what the functions under 0.3 s add up to (numba's fixed cost per function). This is how the
compile work of 2026-11-27 found the thin kernels worth inlining and the slice assignments that
compiled numpy's error formatting (docs/install.md, "First calls").
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

_CHILD = """
import collections, json, sys, time
from numba.core import event

rec = []


class Listener(event.Listener):
    def on_start(self, ev):
        rec.append((1, ev.data["dispatcher"].py_func.__qualname__, time.perf_counter()))

    def on_end(self, ev):
        rec.append((0, ev.data["dispatcher"].py_func.__qualname__, time.perf_counter()))


event.register("numba:compile", Listener())
import restitution.warmup as w

step = [s for label, s in w._steps() if sys.argv[1] in label][0]
t0 = time.perf_counter()
step()
total = time.perf_counter() - t0
own, count, stack, last = collections.Counter(), collections.Counter(), [], 0.0
for start, name, t in rec:
    if stack:
        own[stack[-1]] += t - last
    if start:
        stack.append(name)
        count[name] += 1
    else:
        stack.pop()
    last = t
print(json.dumps({"total": total, "own": own, "count": count}))
"""


def profile(label: str) -> dict:
    """{total, own: {function: seconds}, count: {function: compiles}} of one warmup step."""
    with tempfile.TemporaryDirectory(prefix="compile-profile-") as cache:
        done = subprocess.run(
            [sys.executable, "-c", _CHILD, label],
            env={**os.environ, "NUMBA_CACHE_DIR": cache},
            capture_output=True,
            text=True,
            check=True,
        )
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("label", help="text in the label of a `restitution warmup` step")
    parser.add_argument("--top", type=int, default=30, help="functions to list (default 30)")
    args = parser.parse_args(argv)
    from restitution.warmup import _steps

    labels = [label for label, _ in _steps() if args.label in label]
    if not labels:
        known = "; ".join(label for label, _ in _steps())
        parser.error(f"no warmup step's label contains {args.label!r}; the steps: {known}")
    print(f"{labels[0]}: compiling from an empty cache ...", flush=True)
    p = profile(args.label)
    own, count = p["own"], p["count"]
    print(
        f"first call {p['total']:.1f} s: {len(own)} functions compiled {sum(count.values())} times"
    )
    print(f"{'own (s)':>8} {'times':>5}  function")
    for name, seconds in sorted(own.items(), key=lambda kv: -kv[1])[: args.top]:
        print(f"{seconds:8.2f} {count[name]:5d}  {name}")
    small = [s for s in own.values() if s < 0.3]
    print(f"{sum(small):8.2f} {len(small):5d}  functions under 0.3 s each, together")
    return 0


if __name__ == "__main__":
    sys.exit(main())
