"""Summary tables of a work-precision run (``harness.run_suite`` records).

``summary``: per scene and family, the fastest setting reaching ``target`` COR error with the right
contact count, and the most accurate setting costing at most ``time_limit`` seconds per scene.
``headline``: per scene, the exact solver against the fastest solve_ivp setting reaching the
target (time ratio = how many times faster the exact solver is).
"""

from __future__ import annotations

import math

import pandas as pd

from restitution_workflow.bench.ivp import IVP_METHODS

SUMMARY_COLUMNS = (
    "scene",
    "family",
    "criterion",
    "method",
    "setting_name",
    "setting",
    "cor_error",
    "contacts_ok",
    "energy_error",
    "time_s",
    "note",
)


def _valid(records: pd.DataFrame) -> pd.DataFrame:
    return records[(records["status"] == "ok") & records["cor_error"].notna()]


def _pick(scene, family, criterion, rows: pd.DataFrame, key: str, note: str) -> dict:
    if rows.empty:
        out = dict.fromkeys(SUMMARY_COLUMNS, math.nan)
        out.update(scene=scene, family=family, criterion=criterion, note=note, contacts_ok=False)
        out.update(method="", setting_name="")
        return out
    best = rows.sort_values([key, "time_s"]).iloc[0]
    out = {c: best[c] for c in SUMMARY_COLUMNS if c in best.index}
    out.update(criterion=criterion, note="")
    return out


def summary(records: pd.DataFrame, target: float, time_limit: float) -> pd.DataFrame:
    """Two rows per (scene, family): fastest to ``target``; most accurate within ``time_limit``."""
    rows = []
    valid = _valid(records)
    fast = f"fastest to error <= {target:g} with the right contact count"
    accurate = f"most accurate within {time_limit:g} s per scene"
    for (scene, family), group in records.groupby(["scene", "family"], sort=False):
        g = valid[(valid["scene"] == scene) & (valid["family"] == family)]
        if group["status"].eq("not_applicable").all():
            continue
        reached = g[(g["cor_error"] <= target) & g["contacts_ok"]]
        rows.append(_pick(scene, family, fast, reached, "time_s", "no setting reached it"))
        cheap = g[g["time_s"] <= time_limit]
        rows.append(_pick(scene, family, accurate, cheap, "cor_error", "no setting that fast"))
    return pd.DataFrame(rows, columns=list(SUMMARY_COLUMNS))


def headline(records: pd.DataFrame, target: float) -> pd.DataFrame:
    """Per scene: our solver vs the fastest solve_ivp setting reaching ``target``.

    "Ours" is the exact solver where one exists (linear laws), else the fastest ``adaptive``
    setting reaching ``target`` with the right contact count (what ``method="auto"`` runs for a
    nonlinear law); ``speedup`` = solve_ivp time / our time.
    """
    valid = _valid(records)
    rows = []
    for scene in dict.fromkeys(records["scene"]):
        here = valid[valid["scene"] == scene]
        reached = here[(here["cor_error"] <= target) & here["contacts_ok"]]
        ours = here[here["family"] == "exact"]
        if ours.empty:
            ours = reached[reached["family"] == "adaptive"].sort_values("time_s")
        ivp = reached[reached["family"].isin(IVP_METHODS)].sort_values("time_s")
        row = dict(scene=scene)
        if not ours.empty:
            o = ours.iloc[0]
            row.update(
                ours=o["family"],
                ours_setting=o["setting"],
                ours_error=o["cor_error"],
                ours_contacts_ok=bool(o["contacts_ok"]),
                ours_time_s=o["time_s"],
            )
        else:
            row.update(ours="none reached the target")
        if not ivp.empty:
            b = ivp.iloc[0]
            row.update(
                ivp_method=b["family"],
                ivp_rtol=b["setting"],
                ivp_error=b["cor_error"],
                ivp_time_s=b["time_s"],
            )
        else:
            row.update(ivp_method="none reached the target")
        if "ours_time_s" in row and "ivp_time_s" in row:
            row["speedup"] = row["ivp_time_s"] / row["ours_time_s"]
        rows.append(row)
    cols = [
        "scene",
        "ours",
        "ours_setting",
        "ours_error",
        "ours_contacts_ok",
        "ours_time_s",
        "ivp_method",
        "ivp_rtol",
        "ivp_error",
        "ivp_time_s",
        "speedup",
    ]
    return pd.DataFrame(rows).reindex(columns=cols)
