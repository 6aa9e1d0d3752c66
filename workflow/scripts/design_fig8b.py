"""Fig. 8(b) designs, one job a family: its minimum-COR chains for every N of its group (the
config's ``fig8.design.all`` or ``extra``), smallest N first, into one table.

Families (``restitution.analysis.design``): ``uniform`` (the paper's Fig. 6 chain, best alpha),
``tapered_decreasing`` / ``tapered_increasing`` (geometric masses, best ratio), ``masses`` (every
mass ratio free), ``masses_springs`` (springs k_i/k_12 free too) and ``robust`` (masses free,
worst COR over independent mass errors of +-tolerance).

Two independent starts per design (issue 26):

* **warm**: seed ``seed``; the first population holds the optima this family contains (warm
  starts, the input tables): for ``masses`` the uniform and both tapered chains of the same N and
  the free-mass chain of N - 1 extended by one mass (equal to its last, and a light end mass at
  the lower bound); for ``masses_springs`` the free-mass chain of N and its own N - 1 design
  extended, and split: one of its masses halved into two joined by the stiffest spring the
  bounds allow, whose halves move nearly together: nearly the N - 1 design's COR, where an end
  mass at the lower bound need not be light next to the design's own light masses; for
  ``robust`` the same for its family. A family's search then starts at most at about the COR of
  the chains it contains.
* **cold**: seed ``restart_seed``, no warm start, the same search settings.

The row is the better of the two; ``cor_warm`` and ``cor_cold`` (robust: their worst CORs) and
``restart_spread`` say whether the two starts agree. Each design is re-solved by
``restitution.solve`` (column ``cor_resolved``) and marked ``ok`` only if that agrees.
"""

import math
import time

import numpy as np
import pandas as pd


def extend(masses, springs, n: int, end_mass=None):
    """The chain of ``n`` masses that continues a shorter one: one more mass equal to the last
    (or ``end_mass``, a ratio to m_1) on a spring k_12, repeated until it has ``n`` masses."""
    m, k = list(masses), list(springs)
    while len(m) < n:
        m.append(m[-1] if end_mass is None else end_mass)
        k.append(1.0)
    return np.array(m), np.array(k)


def split(masses, springs, j: int, stiff: float):
    """The chain with mass j (j >= 1: m_1 is the unit) halved into two masses joined by a spring
    ``stiff`` (a ratio to k_12): one more mass, nearly the same motion."""
    m, k = list(masses), list(springs)
    return np.array(m[:j] + [m[j] / 2, m[j] / 2] + m[j + 1 :]), np.array(k[:j] + [stiff] + k[j:])


def warm_starts(rows, n: int, light: float, stiff: float = math.inf) -> tuple:
    """([(masses, springs)], [source]) of the warm-start designs (table rows): one of this N
    as it is; one of N - 1 extended twice, by a mass equal to its last and by a light end mass
    ``light`` (the lower bound: nearly the N - 1 chain, so the search can start from that
    chain's COR), and, for a design with free springs, split at each mass whose halves stay
    within the bounds (``split`` with the upper bound ``stiff``)."""
    starts, sources = [], []
    for row in rows:
        name = f"{row['family']} N={int(row['n_masses'])}"
        if int(row["n_masses"]) == n:
            starts.append(extend(row["masses"], row["springs"], n))
            sources.append(name)
            continue
        for end, how in ((None, "last mass repeated"), (light, f"end mass {light:g}")):
            starts.append(extend(row["masses"], row["springs"], n, end))
            sources.append(f"{name} + {how}")
        if row["family"] == "masses_springs" and math.isfinite(stiff):
            for j in range(1, len(row["masses"])):
                if row["masses"][j] / 2 >= light:
                    starts.append(split(row["masses"], row["springs"], j, stiff))
                    sources.append(f"{name} split at m_{j + 1}")
    return starts, sources


def run(family: str, n: int, d: dict, seed: int, starts, progress):
    from restitution.analysis import design

    robust = family == "robust"
    popsize = d["robust_popsize"] if robust else d["popsize"]
    maxiter = d["robust_maxiter"] if robust else d["maxiter"]
    common = dict(beta=d["beta"], bounds=tuple(d["bounds"]), seed=seed, popsize=popsize,
                  maxiter=maxiter, max_events=d["max_events"], progress=progress,
                  warm_starts=starts)  # fmt: skip
    if family == "uniform":
        return design.best_uniform(n, **common)
    if family.startswith("tapered_"):
        return design.best_tapered(n, direction=family.split("_")[1], **common)
    if family == "masses":
        return design.minimize_cor(n, **common)
    if family == "masses_springs":
        return design.minimize_cor(n, vary="masses+springs", **common)
    if family == "robust":
        return design.minimize_cor(n, tolerance=d["tolerance"], **common)
    raise ValueError(f"unknown design family {family!r}")


def objective(row: dict) -> float:
    """What the family minimises: the worst COR of a robust design, else the COR."""
    return row["worst_cor"] if row["family"] == "robust" else row["cor"]


def recheck(row: dict) -> float:
    """The design's COR from a fresh general-form restitution.solve call (user units: ratios)."""
    import restitution
    from restitution.analysis import design

    m, k, kc = design.scaled_chain(row["masses"], row["springs"], row["beta"])
    return restitution.solve(masses=list(m), springs=list(k), k_contact=kc).cor


def known_designs(tables) -> dict:
    """{(family, N): row} of the designs in ``tables`` (the first table holding one wins)."""
    from restitution.tables.io import read_table

    known = {}
    for path in tables:
        for _, row in read_table(path).iterrows():
            known.setdefault((row["family"], int(row["n_masses"])), row)
    return known


def one_design(params, family: str, n: int, logger, known: dict) -> dict:
    """The row of one design: warm and cold starts, the better one, re-solved."""
    d = dict(params.design)
    wanted = [(f, n) for f in params.contains]
    if params.contains:  # a family that contains others also starts from its own N - 1
        wanted.append((family, n - 1))
    given = [known[key] for key in wanted if key in known]
    starts, sources = warm_starts(given, n, float(d["bounds"][0]), float(d["bounds"][1]))
    rows = {}
    for start, seed, warm in (("warm", d["seed"], starts), ("cold", d["restart_seed"], [])):
        result = run(family, n, d, seed, warm, progress=logger.info)
        row = result.row()
        row["family"] = family
        rows[start] = row
        logger.info("%s N=%d, %s start (seed %d, %d warm starts): objective %.12g, %s", family, n,
                    start, seed, len(warm), objective(row), row["active"])  # fmt: skip
    warm, cold = objective(rows["warm"]), objective(rows["cold"])
    best = "cold" if cold < warm else "warm"
    row = dict(rows[best])
    row["start"] = best
    row["warm_from"] = "; ".join(sources)
    row["cor_warm"], row["cor_cold"] = warm, cold
    row["restart_spread"] = abs(warm - cold)
    row["evaluations"] = rows["warm"]["evaluations"] + rows["cold"]["evaluations"]
    row["cor_resolved"] = recheck(row)
    agree = abs(row["cor_resolved"] - row["cor"]) <= 1e-12
    row["status"] = "ok" if agree and math.isfinite(row["cor"]) else "recheck_differs"
    logger.info("%s N=%d: COR %.12g (re-solved %.12g; warm %.12g, cold %.12g), %s, %s, active: "
                "%s; %d solver calls", family, n, row["cor"], row["cor_resolved"], warm, cold,
                row["method"], row["bounds_hit"] or "no bound near", row["active"],
                row["evaluations"])  # fmt: skip
    return row


def main(params, output_path, family: str, logger, tables=(), progress=False) -> pd.DataFrame:
    """Every design of ``family`` at ``params.ns`` (ascending: each may warm-start the next),
    written to ``output_path`` only when all are done; ``progress``: a bar over the N (a
    family's job runs up to a minute, its log has the details)."""
    from restitution.tables.io import write_table

    known = known_designs(tables)
    out = []
    ns = sorted(params.ns)
    if progress:
        from tqdm.auto import tqdm

        ns = tqdm(ns, desc=f"design {family}", unit="N")
    for n in ns:
        if progress:
            ns.set_postfix(N=n)
        start = time.perf_counter()
        row = one_design(params, family, n, logger, known)
        logger.info("%s N=%d: %.2f s", family, n, time.perf_counter() - start)
        known[(family, n)] = pd.Series(row)
        out.append(row)
    table = pd.DataFrame(out)
    config = {"fig8": {"design": dict(params.design)}, "family": family, "n": list(params.ns)}
    write_table(table, output_path, config=config)
    return table


if __name__ == "__main__":
    from _common import Timer, setup, show_progress

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "designs"):
        main(
            snakemake.params,  # noqa: F821
            snakemake.output.table,  # noqa: F821
            family=snakemake.wildcards.family,  # noqa: F821
            logger=log,
            tables=list(snakemake.input.warm),  # noqa: F821
            progress=show_progress(),
        )
