"""Timings of the general linear-chain kernel (a script, not a test).

Usage: OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_chain.py [--quick] [--big]

(OPENBLAS_NUM_THREADS=1: on a busy two-core machine OpenBLAS's own threads made the eigen
decomposition of an N = 128 chain 50 times slower, 10 s instead of 0.2 s.)

Prints, one thread, best of several repeats in one process after JIT warm-up:

1. the cost per contact of the finite-stiffness kernel at beta = 1e-3 for two masses (an alpha
   sweep; the contact count grows with alpha) and of the rigid wall (beta = 0), undamped
   (xi = 0), damped (xi = 0.3) and both, against the target of at most 1 us per contact at
   beta = 1e-3 (the target was set next to the rigid wall's 0.3 us per contact, an undamped
   figure, so it is read for xi = 0; the damped line is printed next to the rigid wall's own
   damped cost, 5-6 times its undamped one);
2. general chains (random masses, springs, dashpots on links 2..N-1) against the paper's uniform
   chain of the same N, rigid and beta = 1e-3, per contact, against the target ratio <= 1.
   Like with like: a scene costs a fixed part (above all the eigen-decompositions of its free
   and contact phases, done once per scene; printed on its own as "set-up") plus a part per
   contact, so "time / contacts" depends on how many contacts share the fixed part. A plain
   alpha sweep of uniform chains has ~2-3 times more contacts per scene than the random general
   chains, which made the general chains look up to 2x dearer per contact with the same cost
   per scene and per contact. The uniform family is therefore drawn to match the general one
   contact count for contact count: for each general scene, a uniform chain (alpha from a fine
   sweep 0.2..50, same beta, xi = 0.3 when damped) with the same number of contacts (the
   nearest count when none has it). Both families then have (nearly) the same contacts per
   scene, and the ratio of their times per contact compares like with like. Each line also
   gives the locator steps per contact of both families (every phase replayed through the
   locator) and their median rate spread max|lambda| / min|lambda|: the cost per contact follows
   the steps, and the steps the spread (bench_then_now.py compares the same general chains with
   the uniform chain as the code of the issue's day solved it);
3. the chatter grid alpha 5..200, xi 0.05..3 (rigid wall, dashpot on link 1), N = 2, 3, 5:
   statuses, how many needed the sticking limit, and the slowest scene;
4. with --big, the N = 128, alpha = 10, xi = 1 chatter scene (status and time).
"""

import argparse
import math
import time

import numba
import numpy as np
from numba import njit

from restitution.kernels.exact_chain import (
    PH_CONTACT,
    PH_FREE,
    WORK_MAX,
    _normalise,
    _run,
    _safe_model,
    solve_chain,
    solve_chain_batch,
)
from restitution.kernels.layout import (
    FLAG_STICKING,
    N_HIST,
    OUT_COR,
    OUT_FLAGS,
    OUT_NCOL,
    OUT_STATUS,
)
from restitution.kernels.locator import _locate
from restitution.kernels.paper_chain import _paper_chain

NOHIST = np.zeros((0, N_HIST))


def best_time(fn, repeat=5):
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def pad(scenes):
    """Padded batch arrays from a list of (m, k, c, kc)."""
    rows = len(scenes)
    nmax = max(s[0].size for s in scenes)
    M = np.ones((rows, nmax))
    K = np.ones((rows, nmax - 1))
    C = np.zeros((rows, nmax - 1))
    n = np.zeros(rows, np.int64)
    kc = np.zeros(rows)
    for i, (m, k, c, kci) in enumerate(scenes):
        n[i] = m.size
        M[i, : m.size], K[i, : k.size], C[i, : c.size], kc[i] = m, k, c, kci
    return M, K, C, n, kc


def per_contact(scenes, repeat):
    """(us per contact, contacts, statuses not ok) of a batch, one thread."""
    args = pad(scenes)
    out = solve_chain_batch(*args, 100_000)
    dt = best_time(lambda: solve_chain_batch(*args, 100_000), repeat)
    contacts = out[:, OUT_NCOL].sum()
    return dt / contacts * 1e6, int(contacts), int(np.sum(out[:, OUT_STATUS] != 0))


@njit
def _setup_batch(M, K, C, n, kc):
    """The eigen-decompositions the kernel does once per scene (free phase for N > 2, contact
    phase for a finite-stiffness wall), exactly as kernels.chain._run calls them."""
    s = 0.0
    for i in range(n.size):
        ni = n[i]
        m = np.ascontiguousarray(M[i, :ni])
        k = np.ascontiguousarray(K[i, : ni - 1])
        c = np.ascontiguousarray(C[i, : ni - 1])
        if ni > 2:
            s += _safe_model(m, k, c, 0.0, 0.0, True)[3]
        if kc[i] != math.inf:
            s += _safe_model(m, k, c, kc[i], 0.0, False)[3]
    return s


def setup_us(scenes, repeat):
    """Set-up per scene (the once-per-scene eigen-decompositions alone), us, one thread."""
    args = pad(scenes)
    _setup_batch(*args)
    return best_time(lambda: _setup_batch(*args), repeat) / len(scenes) * 1e6


def matched_uniform(general_scenes, n, beta, xi):
    """Uniform chains of N masses whose contact counts match those of ``general_scenes`` one
    for one (nearest count where none matches; each uniform scene used at most once while
    others are left)."""
    alphas = np.geomspace(0.2, 50.0, 400)
    cand = [paper(a, beta, xi, n) for a in alphas]
    counts = solve_chain_batch(*pad(cand), 100_000)[:, OUT_NCOL]
    used = np.zeros(len(cand), bool)
    chosen = []
    for scene in general_scenes:
        want = solve_chain(*scene, 100_000, NOHIST)[OUT_NCOL]
        dist = np.abs(counts - want) + 0.5 * used  # prefer exact, then unused
        j = int(np.argmin(dist))
        used[j] = True
        chosen.append(cand[j])
    return chosen


def locator_steps(scenes):
    """(locator steps per contact, median rate spread) of a family: every free and contact phase
    of every scene replayed through the kernel's locator from the phase starts the kernel
    recorded (the work a contact costs besides the fixed per-phase part; sticking phases, rare
    here, are not counted), and max/min |lambda| of the free and contact phase models."""
    steps = 0.0
    contacts = 0.0
    spreads = []
    info = np.zeros(4)
    for scene in scenes:
        m, k, c, kc = _normalise(*scene)
        n = m.size
        rec = np.zeros((100_000, 3 + 2 * n))
        out, nrec = _run(m, k, c, kc, 100_000, NOHIST, rec, WORK_MAX)
        contacts += out[OUT_NCOL]
        lamF, UF, PF, _ = _safe_model(m, k, c, 0.0, 0.0, True)
        rates = [np.abs(lamF)]
        if kc != math.inf:
            lamC, UC, PC, _ = _safe_model(m, k, c, kc, 0.0, False)
            rates.append(np.abs(lamC))
        rates = np.concatenate(rates)
        spreads.append(rates.max() / rates.min())
        for i in range(min(nrec, rec.shape[0])):
            u, v = rec[i, 3 : 3 + n], rec[i, 3 + n :]
            if rec[i, 1] == PH_FREE:
                X0, V = m @ u / m.sum(), m @ v / m.sum()
                z = PF @ np.concatenate([u - X0, v - V]).astype(complex)
                _locate(u[0], V, UF[0] * z, lamF, False, info)
            elif rec[i, 1] == PH_CONTACT:
                z = PC @ np.concatenate([u, v]).astype(complex)
                _locate(0.0, 0.0, -UC[0] * z, lamC, True, info)
            else:
                continue
            steps += info[3] + 1
    return steps / contacts, float(np.median(spreads))


def paper(alpha, beta, xi, n):
    return _paper_chain(alpha, beta, xi, n)


def general(rng, n, beta, damped):
    m = 10 ** rng.uniform(-0.7, 0.7, n)
    m[0] = 1.0
    k = 10 ** rng.uniform(-0.7, 0.7, n - 1)
    c = np.zeros(n - 1)
    if damped:
        for i in range(1, n - 1):  # not on link 1: at a rigid wall that chatters
            if rng.random() < 0.5:
                mred = m[i] * m[i + 1] / (m[i] + m[i + 1])
                c[i] = 2 * rng.uniform(0, 0.5) * math.sqrt(k[i] * mred)
    # same non-dimensional units as the paper's scenes: m1 = 1, omega = 1
    w2 = k[0] / m[0] + k[0] / m[1]
    k, c = k / w2, c / math.sqrt(w2)
    kc = math.inf if beta == 0 else k[0] / beta
    return m, k, c, kc


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer scenes and repeats")
    ap.add_argument("--big", action="store_true", help="also the N = 128 chatter scene")
    args = ap.parse_args()
    numba.set_num_threads(1)
    repeat = 3 if args.quick else 7
    rng = np.random.default_rng(1)
    per_contact([paper(2.0, 1e-3, 0.3, 3), paper(2.0, 0.0, 0.0, 2)], 1)  # JIT warm-up
    for scene in (paper(2.0, 0.0, 0.3, 2), paper(2.0, 1e-3, 0.3, 3)):
        solve_chain(*scene, 10, NOHIST)

    print("1. two masses, cost per contact (alpha sweep 0.5..200; undamped, damped, both)")
    alphas = np.geomspace(0.5, 200.0, 50 if args.quick else 200)
    for beta in (1e-3, 0.0):
        for label, xis in (("xi = 0", (0.0,)), ("xi = 0.3", (0.3,)), ("both", (0.0, 0.3))):
            scenes = [paper(a, beta, xi, 2) for a in alphas for xi in xis]
            us, nc, bad = per_contact(scenes, repeat)
            # The 1 us sits next to "0.3 us at the rigid wall", the undamped figure.
            target = "  (target <= 1 us)" if beta > 0 and label == "xi = 0" else ""
            print(
                f"   beta = {beta:g}, {label}: {us:.3f} us per contact ({nc} contacts, "
                f"{bad} not ok){target}"
            )

    print(
        "2. general chain vs uniform chain of the same N and the same contact counts, us per "
        "contact (set-up us per scene, contacts), target ratio <= 1"
    )
    for n in (3, 5, 8):
        for beta, damped in ((0.0, False), (1e-3, False), (1e-3, True)):
            # like for like: undamped against undamped; dashpots (on links 2.. of the general
            # chain, xi = 0.3 on link 1 of the uniform one at the finite-stiffness wall)
            xi = 0.3 if damped else 0.0
            gen = [general(rng, n, beta, damped) for _ in range(20)]
            uni = matched_uniform(gen, n, beta, xi)
            u_us, u_nc, u_bad = per_contact(uni, repeat)
            g_us, g_nc, g_bad = per_contact(gen, repeat)
            u_set = setup_us(uni, repeat)
            g_set = setup_us(gen, repeat)
            u_st, u_spread = locator_steps(uni)
            g_st, g_spread = locator_steps(gen)
            print(
                f"   N = {n}, beta = {beta:g}{' damped' if damped else ''}: "
                f"uniform {u_us:.2f} us ({u_set:.0f} us, {u_nc} contacts), "
                f"general {g_us:.2f} us ({g_set:.0f} us, {g_nc} contacts), "
                f"ratio {g_us / u_us:.2f}"
                + (f"  [not ok: {u_bad} + {g_bad}]" if u_bad + g_bad else "")
                + f"\n      locator steps per contact: uniform {u_st:.2f}, general {g_st:.2f} "
                f"(ratio {g_st / u_st:.2f}); median rate spread {u_spread:.1f} / {g_spread:.1f}"
            )

    print("3. chatter grid (rigid wall, dashpot on link 1), one scene at a time")
    alphas = [5.0, 10.0, 20.0, 50.0, 100.0, 150.0, 200.0]
    xis = [0.05, 0.1, 0.3, 0.5, 1.0, 2.0, 3.0]
    for n in (2, 3, 5):
        worst = (0.0, None)
        statuses = {}
        stick = 0
        for a in alphas:
            for xi in xis:
                m, k, c, kc = paper(a, 0.0, xi, n)
                t0 = time.perf_counter()
                out = solve_chain(m, k, c, kc, 100_000, NOHIST)
                dt = time.perf_counter() - t0
                st = int(out[OUT_STATUS])
                statuses[st] = statuses.get(st, 0) + 1
                stick += bool(int(out[OUT_FLAGS]) & FLAG_STICKING)
                if dt > worst[0]:
                    worst = (dt, (a, xi, int(out[OUT_NCOL])))
        print(
            f"   N = {n}: statuses {statuses} (0 = ok), sticking limit in {stick} of "
            f"{len(alphas) * len(xis)}, slowest {worst[0]:.3f} s at (alpha, xi, contacts) = "
            f"{worst[1]}"
        )

    if args.big:
        m, k, c, kc = paper(10.0, 0.0, 1.0, 128)
        t0 = time.perf_counter()
        out = solve_chain(m, k, c, kc, 100_000, NOHIST)
        print(
            f"4. N = 128, alpha = 10, xi = 1: status {int(out[OUT_STATUS])}, "
            f"{int(out[OUT_NCOL])} contacts, cor {out[OUT_COR]:.9f}, flags "
            f"{int(out[OUT_FLAGS])}, {time.perf_counter() - t0:.1f} s"
        )


if __name__ == "__main__":
    main()
