"""Compile every kernel once, so that later first calls load it from numba's cache.

``restitution warmup`` (and ``make env``, which runs it) calls each entry point on one small
scene of every kind the solvers dispatch to and reports the seconds each took: with a cold cache
that is the kernel's compile time, with a warm one the time to load it. The cache is the one
every entry point shares (``restitution.kernels.compiling``).

The steps come in two groups that compile different kernel stacks: the exact chain kernels
(``exact_chain`` and the paper chain over it) and the rest (the two-mass closed form and the
stepping kernels of the nonlinear laws). With ``jobs`` >= 2 each group runs in a process of its
own, so a 2-core machine compiles both at once; a step that needs a kernel the other process
compiled loads it from the cache (the paper-chain table, last in the second group, finds the
paper chain's kernel cached by then). Within a group the order is fixed: a step reuses the
kernels an earlier step of its process compiled.
"""

from __future__ import annotations

import multiprocessing
import time
from collections.abc import Callable
from queue import Empty


def _groups() -> list[list[tuple[str, Callable[[], object]]]]:
    import pandas as pd

    import restitution as r

    chain = {"masses": [1.0, 0.5, 2.0], "springs": [0.3, 1.2]}
    hertz = {"law": "hertz", "k": 50.0}
    general = pd.DataFrame({"masses": [chain["masses"]] * 2, "springs": [chain["springs"]] * 2})
    paper_table = pd.DataFrame({"alpha": [1.0], "beta": [0.1], "n_masses": [3]})
    hertz_table = general.assign(contact=['{"law": "hertz", "k": 50}'] * 2)
    exact = [
        ("paper chain, contact spring (piecewise)", lambda: r.solve(alpha=2.0, beta=0.1)),
        ("general linear chain", lambda: r.solve(**chain, k_contact=50.0)),
        ("table: general chains", lambda: r.solve_many(general)),
        ("trajectory, paper chain", lambda: r.trajectory(alpha=2.0, beta=0.1, times=[0.5])),
        ("trajectory, general chain", lambda: r.trajectory(**chain, times=[0.5])),
        (
            "Kelvin-Voigt contact (piecewise)",
            lambda: r.solve(**chain, contact={"law": "kelvin_voigt", "k": 50.0, "c": 0.5}),
        ),
    ]
    rest = [
        ("two masses, rigid wall (impulsive)", lambda: r.solve(alpha=2.0)),
        ("table: two masses, rigid wall", lambda: r.solve_many(pd.DataFrame({"alpha": [1.0]}))),
        (
            "plastic contact (adaptive)",
            lambda: r.solve(alpha=2.0, beta=0.1, contact="plastic", eta=1.5, dr=0.3),
        ),
        ("Hertz contact, chain (adaptive)", lambda: r.solve(**chain, contact=hertz)),
        ("Verlet", lambda: r.solve(alpha=2.0, beta=0.1, method="verlet")),
        (
            "trajectory, Hertz contact (adaptive sampler)",
            lambda: r.trajectory(**chain, contact=hertz, times=[0.5]),
        ),
        ("table: nonlinear chains (adaptive)", lambda: r.solve_many(hertz_table)),
        ("table: paper chains", lambda: r.solve_many(paper_table)),
        ("grazing scan (design study, Fig. 8)", _grazing_scan),
    ]
    return [exact, rest]


def _grazing_scan() -> None:
    from restitution.analysis import cormap

    cormap.grazing([1.0, 2.0], [2.0 / 3.0], float("inf"), 1, "new")


def _steps() -> list[tuple[str, Callable[[], object]]]:
    """Every step, one group after the other (the order of a one-process warmup)."""
    return [step for group in _groups() for step in group]


def _run_group(index: int, queue) -> None:
    """Child process: run group ``index``, putting (label, seconds) or (label, error) on
    ``queue`` after each step and None at the end."""
    from restitution.kernels import compiling

    # The parent says what runs; a notice from each process would print the same line twice.
    compiling._announced = True
    try:
        for label, step in _groups()[index]:
            t0 = time.perf_counter()
            try:
                step()
            except Exception as exc:  # reported by the parent, which fails
                queue.put((label, f"{type(exc).__name__}: {exc}"))
                return
            queue.put((label, time.perf_counter() - t0))
    finally:
        queue.put(None)


def warmup(
    report: Callable[[str, float], None] | None = None, jobs: int = 1
) -> list[tuple[str, float]]:
    """Run every step (see the module docstring); ``report(label, seconds)`` after each.
    ``jobs`` >= 2 runs the two groups in two processes at once. Returns the (label, seconds)
    of every step in the order they finished; a step that fails raises RuntimeError."""
    if jobs < 1:
        raise ValueError(f"jobs must be >= 1, got {jobs}")
    times = []
    if jobs == 1:
        for label, step in _steps():
            t0 = time.perf_counter()
            step()
            times.append((label, time.perf_counter() - t0))
            if report is not None:
                report(*times[-1])
        return times
    # spawn: a fresh interpreter per group (no fork of a process that may hold numba threads)
    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    workers = [context.Process(target=_run_group, args=(i, queue)) for i in range(2)]
    for worker in workers:
        worker.start()
    running = len(workers)
    failure = None
    while running:
        try:
            item = queue.get(timeout=5.0)
        except Empty:  # a process killed outright never sends its end mark: do not wait for it
            if not any(worker.is_alive() for worker in workers):
                break
            continue
        if item is None:
            running -= 1
            continue
        label, value = item
        if isinstance(value, str):
            failure = failure or f"warmup step {label!r} failed: {value}"
            continue
        times.append((label, value))
        if report is not None:
            report(label, value)
    for worker in workers:
        worker.join()
    if failure is None and any(worker.exitcode != 0 for worker in workers):
        failure = "a warmup process ended with an error (its traceback is above)"
    if failure is not None:
        raise RuntimeError(failure)
    return times


__all__ = ["warmup"]
