"""Work-precision harness: every method on every scene of the suite, timed and scored.

One record per (family, method, setting, scene): the COR error against the scene's independent
reference, whether the contact count is right, the energy error (final translational +
vibrational + dissipated energy over the initial energy, minus 1), the time per scene and the
status. Families:

========= ============================================================================
exact     ``restitution.solve(method="auto")`` on linear scenes (exact kernels)
adaptive  ``method="adaptive"`` (DOP853 with event location) over an rtol sweep; two masses
verlet    ``method="verlet"`` (the paper's method) over a step sweep; two masses, beta > 0
RK45 ...  ``solve_ivp`` with events (``restitution_workflow.bench.ivp``) over an rtol sweep
========= ============================================================================

Timing (single thread, ``numba.set_num_threads(1)``): per (family, scene) the first call is a
warm-up (numba compile or cache load, scipy imports) reported as ``first_call_s``; then each
setting is called once, and if that took less than ``min_time`` it is repeated ``min_repeats``
times in loops of ``number`` calls long enough to fill ``min_time`` in all; ``time_s`` is the
median per-call time. A warm-up call that exhausts the time budget is recorded as it is (not
rerun). A setting that exhausts the budget after a looser setting of the same family finished
makes the tighter settings on that scene ``skipped`` (they would only take longer).
"""

from __future__ import annotations

import math
import os
import platform
import statistics
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from restitution.model.ranges import SceneError
from restitution_workflow.bench.ivp import IVP_METHODS, TIME_BUDGET_STATUS, solve_ivp_scene

FAMILIES = ("exact", "adaptive", "verlet", *IVP_METHODS)
RECORD_COLUMNS = (
    "scene",
    "family",
    "method",
    "setting_name",
    "setting",
    "cor",
    "n_collisions",
    "reference_cor",
    "reference_contacts",
    "reference_bound",
    "cor_error",
    "contacts_ok",
    "energy_error",
    "time_s",
    "first_call_s",
    "repeats",
    "calls_per_repeat",
    "status",
    "message",
)

# Defaults of the config section `benchmarks` (workflow/schemas/config.schema.yaml documents them).
DEFAULTS = {
    "scenes": [],
    "families": list(FAMILIES[:3]) + ["RK45", "DOP853", "Radau", "LSODA"],
    "adaptive_rtols": [1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
    "verlet_steps": [0.05, 0.02, 0.01, 0.005, 0.002, 0.001],
    "ivp_rtols": [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10],
    "ivp_atol_over_rtol": 1.0,
    "ivp_steps_per_period": 0,  # 0: no max_step
    "min_time": 0.2,
    "min_repeats": 3,
    "time_budget": 20.0,
    "max_events": 100_000,
}


class BenchConfigError(ValueError):
    """A `benchmarks` configuration value is out of range; the message names the key."""


@dataclass(frozen=True)
class Setting:
    """One configuration of one method: ``family``, ``setting_name`` (rtol/step/-), value."""

    family: str
    setting_name: str
    setting: float

    @property
    def method(self) -> str:
        if self.family in IVP_METHODS:
            return f"solve_ivp:{self.family}"
        return "auto" if self.family == "exact" else self.family


def _numbers(cfg, key, low, high):
    values = cfg[key]
    if not isinstance(values, list) or not values:
        raise BenchConfigError(f"benchmarks.{key} must be a non-empty list; got {values!r}")
    for v in values:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not low <= v <= high:
            raise BenchConfigError(
                f"benchmarks.{key}: every value must be a number in [{low:g}, {high:g}]; got {v!r}"
            )
    return [float(v) for v in values]


def check_config(cfg: Mapping | None, scene_names: Iterable[str] = ()) -> dict:
    """The `benchmarks` section with defaults filled in; BenchConfigError naming a bad key."""
    cfg = dict(cfg or {})
    # Keys used by the workflow's summary and scaling rules, checked there and by the schema.
    unknown = sorted(set(cfg) - set(DEFAULTS) - {"scaling", "target_error", "time_limit"})
    if unknown:
        raise BenchConfigError(f"benchmarks: unknown key(s) {unknown}; allowed: {sorted(DEFAULTS)}")
    out = {**DEFAULTS, **{k: v for k, v in cfg.items() if k in DEFAULTS}}
    names = list(scene_names)
    bad = [s for s in out["scenes"] if s not in names] if names else []
    if bad:
        raise BenchConfigError(f"benchmarks.scenes: unknown scene(s) {bad}; known: {names}")
    bad = [f for f in out["families"] if f not in FAMILIES]
    if bad or not out["families"]:
        raise BenchConfigError(
            f"benchmarks.families: unknown or empty {bad or out['families']!r}; allowed: "
            f"{list(FAMILIES)}"
        )
    out["adaptive_rtols"] = _numbers(out, "adaptive_rtols", 1e-14, 1e-2)
    out["verlet_steps"] = _numbers(out, "verlet_steps", 1e-6, 0.25)
    out["ivp_rtols"] = _numbers(out, "ivp_rtols", 1e-14, 1e-1)
    for key, low, high in (
        ("ivp_atol_over_rtol", 1e-6, 1e6),
        ("min_time", 0.0, 60.0),
        ("time_budget", 1e-3, 3600.0),
    ):
        v = out[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not low <= v <= high:
            raise BenchConfigError(f"benchmarks.{key} must be a number in [{low:g}, {high:g}]")
    spp = out["ivp_steps_per_period"]
    if isinstance(spp, bool) or not isinstance(spp, (int, float)) or not (spp == 0 or spp >= 1):
        raise BenchConfigError(
            f"benchmarks.ivp_steps_per_period must be 0 (no max_step) or a number >= 1; got {spp!r}"
        )
    for key, low in (("min_repeats", 1), ("max_events", 1)):
        v = out[key]
        if isinstance(v, bool) or not isinstance(v, int) or v < low:
            raise BenchConfigError(f"benchmarks.{key} must be an integer >= {low}; got {v!r}")
    return out


def settings(cfg: Mapping, families: Iterable[str] | None = None) -> list[Setting]:
    """Every (family, setting) of a checked config, loosest first within a family."""
    out = []
    for family in families or cfg["families"]:
        if family == "exact":
            out.append(Setting("exact", "-", math.nan))
        elif family == "adaptive":
            out += [Setting(family, "rtol", r) for r in sorted(cfg["adaptive_rtols"], reverse=True)]
        elif family == "verlet":
            out += [Setting(family, "step", s) for s in sorted(cfg["verlet_steps"], reverse=True)]
        elif family in IVP_METHODS:
            out += [Setting(family, "rtol", r) for r in sorted(cfg["ivp_rtols"], reverse=True)]
        else:
            raise BenchConfigError(f"benchmarks.families: unknown family {family!r}")
    return out


def applicable(scene, family: str) -> str:
    """'' when ``family`` can run ``scene``, else the reason it cannot (recorded as status)."""
    if family == "exact" and not scene.linear:
        return "no exact solver for a nonlinear law"
    if family in ("adaptive", "verlet") and scene.n_masses != 2:
        return f"{family} exists for two masses only"
    if family == "verlet" and scene.beta == 0.0:
        return "verlet needs a finite contact stiffness (beta > 0)"
    return ""


def runner(scene, setting: Setting, cfg: Mapping) -> Callable[[], object]:
    """A no-argument callable returning the ``Result`` of one (scene, setting)."""
    from restitution.api import solve

    kw = scene.solve_kwargs()
    max_events = int(cfg["max_events"])
    if setting.family == "exact":
        return lambda: solve(**kw, method="auto", max_events=max_events)
    if setting.family == "adaptive":
        return lambda: solve(**kw, method="adaptive", rtol=setting.setting, max_events=max_events)
    if setting.family == "verlet":
        return lambda: solve(**kw, method="verlet", step=setting.setting, max_events=max_events)
    rtol = setting.setting
    return lambda: solve_ivp_scene(
        **kw,
        method=setting.family,
        rtol=rtol,
        atol=rtol * cfg["ivp_atol_over_rtol"],
        steps_per_period=cfg["ivp_steps_per_period"] or None,
        time_budget=cfg["time_budget"],
        max_events=max_events,
    )


def time_call(fn: Callable[[], object], min_time: float, min_repeats: int):
    """(result, median seconds per call, repeats, calls per repeat) -- see the module docstring."""
    t0 = time.perf_counter()
    result = fn()
    first = time.perf_counter() - t0
    if first >= min_time:
        return result, first, 1, 1
    number = max(1, math.ceil(min_time / max(first, 1e-7) / min_repeats))
    times = []
    for _ in range(min_repeats):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t0) / number)
    return result, statistics.median(times), min_repeats, number


def _record(scene, setting: Setting, **values) -> dict:
    row = dict.fromkeys(RECORD_COLUMNS, math.nan)
    row.update(
        scene=scene.name,
        family=setting.family,
        method=setting.method,
        setting_name=setting.setting_name,
        setting=setting.setting,
        reference_cor=math.nan if scene.reference_cor is None else scene.reference_cor,
        reference_contacts=-1 if scene.reference_contacts is None else scene.reference_contacts,
        reference_bound=math.nan if scene.reference_bound is None else scene.reference_bound,
        n_collisions=-1,
        contacts_ok=False,
        repeats=0,
        calls_per_repeat=0,
        status="",
        message="",
    )
    row.update(values)
    return row


def run_scene_family(scene, family: str, cfg: Mapping, log=None) -> list[dict]:
    """Records of every setting of ``family`` on ``scene`` (warm-up first, then timed runs)."""
    rows = []
    reason = applicable(scene, family)
    sets = settings(cfg, [family])
    if reason:
        return [_record(scene, s, status="not_applicable", message=reason) for s in sets]
    first_call = math.nan
    skip = ""
    finished = False  # a looser setting of this family finished on this scene
    for i, s in enumerate(sets):
        if skip:
            rows.append(_record(scene, s, status="skipped", message=skip))
            continue
        fn = runner(scene, s, cfg)
        try:
            warm = None
            if i == 0:  # warm-up: numba compile / cache load, first scipy calls
                t0 = time.perf_counter()
                warm = fn()
                first_call = time.perf_counter() - t0
            if warm is not None and warm.status == TIME_BUDGET_STATUS:
                result, seconds, repeats, number = warm, first_call, 1, 1  # not rerun
            else:
                result, seconds, repeats, number = time_call(
                    fn, cfg["min_time"], cfg["min_repeats"]
                )
        except SceneError as e:
            rows.append(_record(scene, s, status="error", message=str(e)))
            continue
        except Exception as e:  # noqa: BLE001 - a crashing method is a benchmark result
            rows.append(_record(scene, s, status="error", message=f"{type(e).__name__}: {e}"))
            continue
        energy = result.e_translational + result.e_vibrational + result.e_dissipated - 1.0
        row = _record(
            scene,
            s,
            cor=result.cor,
            n_collisions=result.n_collisions,
            energy_error=energy,
            time_s=seconds,
            first_call_s=first_call if i == 0 else math.nan,
            repeats=repeats,
            calls_per_repeat=number,
            status=result.status,
            message="" if result.success else result.message,
        )
        if result.status == TIME_BUDGET_STATUS:
            row["message"] = f"no result within the time budget of {cfg['time_budget']:g} s"
            if finished:
                skip = f"a looser setting already exhausted the time budget ({s.setting:g})"
        finished = finished or result.status == "ok"
        if scene.reference_cor is not None and math.isfinite(result.cor):
            row["cor_error"] = abs(result.cor - scene.reference_cor)
        if scene.reference_contacts is not None:
            row["contacts_ok"] = bool(result.n_collisions == scene.reference_contacts)
        rows.append(row)
        if log is not None:
            log.info(
                "%s %s %s=%g: cor error %.2e, contacts %d (%s), %.3g s/scene, %s",
                scene.name,
                family,
                s.setting_name,
                s.setting,
                row["cor_error"],
                row["n_collisions"],
                "ok" if row["contacts_ok"] else "WRONG",
                seconds,
                row["status"],
            )
    return rows


def run_suite(scenes, cfg: Mapping, families: Iterable[str] | None = None, log=None):
    """DataFrame of records for every family x setting x scene (single numba thread)."""
    import numba

    numba.set_num_threads(1)
    rows = []
    for family in families or cfg["families"]:
        for scene in scenes:
            rows += run_scene_family(scene, family, cfg, log)
    frame = pd.DataFrame(rows, columns=list(RECORD_COLUMNS))
    frame["contacts_ok"] = frame["contacts_ok"].astype(bool)
    for c in ("n_collisions", "reference_contacts", "repeats", "calls_per_repeat"):
        frame[c] = frame[c].astype(np.int64)
    return frame


def machine_info() -> dict:
    """CPU model, core counts and platform, for the provenance of every benchmark table."""
    model = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    try:
        load = os.getloadavg()
    except OSError:
        load = (math.nan,) * 3
    return {
        "cpu_model": model,
        "cpu_count": os.cpu_count(),
        "usable_cores": usable,
        "load_average_1_5_15min": [round(x, 2) for x in load],
        "platform": platform.platform(),
        "python": platform.python_version(),
    }
