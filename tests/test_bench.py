"""The work-precision harness (restitution_workflow.bench): records, errors, failures, config,
pipeline.

Reference values here are closed forms, never solver output: below the first grazing point
alpha*_1 = 0.697 a rigid-wall chain has a single contact and COR = (1 - x)/(1 + x) with
x = (N - 1) alpha (momentum after m1's reversal; paper Appendix), whatever the integration error;
equal masses (alpha = 1, rigid wall) have two contacts and COR = 1 (half a relative period after
the first reversal m1 is back at the wall at -V0 and m2 moves at +V0); just past the grazing point
alpha*_2 a third contact appears (definition of alpha*_n).
"""

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest
import yaml

from conftest import REPO, run_snakemake
from restitution import solve
from restitution.analysis.special_points import alpha_star
from restitution.model.ranges import SceneError
from restitution.tables.io import read_provenance, read_table
from restitution_workflow.bench import harness
from restitution_workflow.bench.harness import (
    BenchConfigError,
    Setting,
    check_config,
    run_scene_family,
)
from restitution_workflow.bench.ivp import TIME_BUDGET_STATUS, solve_ivp_scene
from restitution_workflow.bench.scaling import fit_exponents
from restitution_workflow.bench.scenes import Scene
from restitution_workflow.bench.summary import headline, summary

SINGLE = Scene(
    "single", "one contact, alpha = 0.5", 0.5, reference_cor=1 / 3, reference_contacts=1,
    reference_bound=1e-16, reference_source="closed form (1 - alpha)/(1 + alpha)",
)  # fmt: skip
CHAIN = Scene(
    "chain4", "N = 4, alpha = 0.1", 0.1, n_masses=4, reference_cor=0.7 / 1.3,
    reference_contacts=1, reference_bound=1e-16, reference_source="closed form (1 - x)/(1 + x)",
)  # fmt: skip
EQUAL = Scene("equal", "alpha = 1", 1.0, reference_cor=1.0, reference_contacts=2)
A2 = alpha_star(2, 1.0, 0.05)
PAST = Scene("past2", "just past alpha*_2", A2 * (1 + 1e-6), reference_contacts=3)
TINY = dict(
    adaptive_rtols=[1e-8], verlet_steps=[0.01], ivp_rtols=[1e-3, 1e-10], min_time=0.0,
    min_repeats=1, time_budget=30.0,
)  # fmt: skip


def cfg(**over):
    return check_config({**TINY, **over})


# --- the solve_ivp runner against closed forms ---------------------------------------------------


@pytest.mark.parametrize("method", ["RK45", "DOP853", "Radau", "LSODA"])
def test_solve_ivp_scene_two_masses_closed_form(method):
    r = solve_ivp_scene(0.5, method=method, rtol=1e-10)
    assert r.status == "ok" and r.n_collisions == 1
    assert abs(r.cor - 1 / 3) < 1e-7
    assert abs(r.e_translational + r.e_vibrational + r.e_dissipated - 1) < 1e-7


def test_solve_ivp_scene_chain_closed_form():
    r = solve_ivp_scene(0.1, n_masses=4, method="DOP853", rtol=1e-11)
    assert r.status == "ok" and r.n_collisions == 1
    assert abs(r.cor - 0.7 / 1.3) < 1e-8
    assert abs(r.e_translational + r.e_vibrational + r.e_dissipated - 1) < 1e-8


def test_solve_ivp_scene_time_budget_fails_loudly():
    r = solve_ivp_scene(200.0, beta=1e-3, method="Radau", rtol=1e-10, time_budget=0.05)
    assert r.status == TIME_BUDGET_STATUS and not r.success and math.isnan(r.cor)


def test_solve_ivp_scene_event_budget():
    r = solve_ivp_scene(50.0, method="DOP853", rtol=1e-8, max_events=3)
    assert r.status == "event_budget_exhausted" and r.n_collisions == 3


@pytest.mark.parametrize(
    "kwargs, word",
    [({"method": "Euler"}, "method"), ({"rtol": 0.0}, "rtol"), ({"time_budget": -1}, "time_budget"),
     ({"eta": 0.5, "contact": "plastic", "n_masses": 3}, "n_masses"), ({"colour": 1}, "colour")],
)  # fmt: skip
def test_solve_ivp_scene_bad_input_names_the_parameter(kwargs, word):
    with pytest.raises(SceneError, match=word):
        solve_ivp_scene(2.0, beta=kwargs.pop("beta", 0.01), **kwargs)


# --- harness records ------------------------------------------------------------------------------


def test_records_measure_error_against_the_reference():
    conf = cfg()
    scenes = [SINGLE, CHAIN, EQUAL]
    frame = harness.run_suite(scenes, conf, families=["exact", "adaptive", "DOP853"])
    assert list(frame.columns) == list(harness.RECORD_COLUMNS)
    # exact: 3 scenes; adaptive: 1 setting x 3 scenes; DOP853: 2 settings x 3 scenes
    assert len(frame) == 3 + 3 + 6
    ran = frame[frame["status"] == "ok"]
    ref = ran["scene"].map({"single": 1 / 3, "chain4": 0.7 / 1.3, "equal": 1.0})
    np.testing.assert_array_equal(ran["cor_error"], (ran["cor"] - ref).abs())
    assert (ran["time_s"] > 0).all() and (ran["repeats"] >= 1).all()
    exact = frame[frame["family"] == "exact"]
    assert (exact["cor_error"] < 1e-14).all() and exact["contacts_ok"].all()
    assert (exact["first_call_s"] > 0).all()
    tight = ran[(ran["family"] == "DOP853") & (ran["setting"] == 1e-10)]
    assert (tight["cor_error"] < 1e-7).all() and tight["contacts_ok"].all()
    # two contacts: the second depends on the integration, so a loose rtol shows its error
    equal = ran[(ran["family"] == "DOP853") & (ran["scene"] == "equal")].set_index("setting")
    assert equal.loc[1e-3, "cor_error"] > 1e-6 > 1e-8 > equal.loc[1e-10, "cor_error"]
    chain_adaptive = frame[(frame["family"] == "adaptive") & (frame["scene"] == "chain4")]
    assert chain_adaptive["status"].tolist() == ["not_applicable"]
    # the energy error is measured: round-off for the exact solvers, shrinking with rtol
    assert (exact["energy_error"].abs() < 1e-12).all()
    assert abs(equal.loc[1e-10, "energy_error"]) < 1e-8 < abs(equal.loc[1e-3, "energy_error"])


def test_missed_shallow_contact_is_recorded():
    conf = cfg(ivp_rtols=[1e-4])
    exact = run_scene_family(PAST, "exact", conf)
    assert exact[0]["n_collisions"] == 3 and exact[0]["contacts_ok"]
    missed = run_scene_family(PAST, "DOP853", conf)[0]
    assert missed["status"] == "ok" and missed["n_collisions"] == 2 and not missed["contacts_ok"]


def test_time_budget_failure_recorded_not_rerun():
    conf = cfg(ivp_rtols=[1e-8], time_budget=0.05)
    many = Scene("many", "alpha = 200, beta = 1e-3", 200.0, beta=1e-3)
    rows = run_scene_family(many, "Radau", conf)
    assert rows[0]["status"] == TIME_BUDGET_STATUS and rows[0]["repeats"] == 1
    assert math.isnan(rows[0]["cor_error"]) and not rows[0]["contacts_ok"]
    assert "time budget" in rows[0]["message"]


def test_tighter_settings_skipped_only_after_a_looser_one_finished(monkeypatch):
    done = solve(alpha=1.0)
    # rtol 1e-2 times out, 1e-4 finishes, 1e-6 times out, 1e-8 is skipped
    status = {1e-2: TIME_BUDGET_STATUS, 1e-4: "ok", 1e-6: TIME_BUDGET_STATUS, 1e-8: "ok"}
    monkeypatch.setattr(
        harness,
        "runner",
        lambda scene, s, conf: lambda: dataclasses.replace(done, status=status[s.setting]),
    )
    rows = run_scene_family(EQUAL, "RK45", cfg(ivp_rtols=[1e-2, 1e-4, 1e-6, 1e-8]))
    assert [r["status"] for r in rows] == [*list(status.values())[:3], "skipped"]


def test_crashing_method_recorded_as_error(monkeypatch):
    def boom(scene, setting, conf):
        def run():
            raise FloatingPointError("overflow in the integrator")

        return run

    monkeypatch.setattr(harness, "runner", boom)
    rows = run_scene_family(SINGLE, "exact", cfg())
    assert rows[0]["status"] == "error" and "overflow" in rows[0]["message"]


def test_not_applicable_families():
    plastic = Scene("p", "plastic", 5.0, beta=0.01, law={"contact": "plastic", "eta": 0.5,
                                                         "dr": 0.3})  # fmt: skip
    assert run_scene_family(plastic, "exact", cfg())[0]["status"] == "not_applicable"
    assert run_scene_family(SINGLE, "verlet", cfg())[0]["status"] == "not_applicable"


def test_time_call_repeats_fast_calls_to_fill_min_time():
    calls = []
    _, seconds, repeats, number = harness.time_call(lambda: calls.append(1), 0.01, 3)
    assert repeats == 3 and number > 1 and len(calls) == 1 + 3 * number and seconds > 0


def test_settings_loosest_first():
    s = harness.settings(check_config({"ivp_rtols": [1e-8, 1e-3, 1e-5]}), ["LSODA"])
    assert [x.setting for x in s] == [1e-3, 1e-5, 1e-8]
    assert s[0] == Setting("LSODA", "rtol", 1e-3) and s[0].method == "solve_ivp:LSODA"


def test_machine_info():
    info = harness.machine_info()
    assert info["cpu_count"] >= 1 and info["cpu_model"]


# --- configuration --------------------------------------------------------------------------------


BAD_KEYS = [
    ({"ivp_rtols": [2.0]}, "benchmarks.ivp_rtols"),
    ({"families": ["Euler"]}, "benchmarks.families"),
    ({"scenes": ["nope"]}, "benchmarks.scenes"),
    ({"min_repeats": 0}, "benchmarks.min_repeats"),
    ({"ivp_steps_per_period": 0.5}, "benchmarks.ivp_steps_per_period"),
    ({"verlet_step": [0.1]}, "verlet_step"),
]


@pytest.mark.parametrize("bad, key", BAD_KEYS)
def test_bad_config_names_the_key(bad, key):
    with pytest.raises(BenchConfigError, match=key.replace(".", r"\.")):
        check_config(bad, ["single"])


# --- summary and fits -----------------------------------------------------------------------------


def _rec(scene, family, setting, err, ok, t, status="ok"):
    return dict(scene=scene, family=family, method=family, setting_name="rtol",
                setting=setting, cor_error=err, contacts_ok=ok, energy_error=0.0, time_s=t,
                status=status)  # fmt: skip


def test_summary_and_headline_pick_the_right_rows():
    records = pd.DataFrame([
        _rec("s", "exact", math.nan, 1e-16, True, 1e-5),
        _rec("s", "DOP853", 1e-4, 1e-3, True, 1e-3),
        _rec("s", "DOP853", 1e-7, 5e-7, False, 2e-3),  # wrong contact count: not eligible
        _rec("s", "DOP853", 1e-8, 1e-8, True, 4e-2),
        _rec("s", "RK45", 1e-8, 2e-7, True, 3e-2),
        _rec("s", "LSODA", 1e-8, math.nan, False, 1.0, status="time_budget_exhausted"),
    ])  # fmt: skip
    table = summary(records, 1e-6, 0.01)
    fast = table[table["criterion"].str.startswith("fastest")].set_index("family")
    assert fast.loc["DOP853", "setting"] == 1e-8 and fast.loc["RK45", "setting"] == 1e-8
    assert fast.loc["LSODA", "note"] == "no setting reached it"
    cheap = table[table["criterion"].str.startswith("most")].set_index("family")
    assert cheap.loc["DOP853", "setting"] == 1e-7  # most accurate within 10 ms (count ignored)
    assert cheap.loc["RK45", "note"] == "no setting that fast"
    head = headline(records, 1e-6).iloc[0]
    assert head["ours"] == "exact" and head["ivp_method"] == "RK45"
    assert head["speedup"] == pytest.approx(3e-2 / 1e-5)
    nonlinear = records[records["family"] != "exact"].assign(scene="n")
    nonlinear = pd.concat(
        [
            nonlinear,
            pd.DataFrame(
                [
                    _rec("n", "adaptive", 1e-6, 1e-4, True, 1e-5),
                    _rec("n", "adaptive", 1e-9, 1e-9, True, 1e-4),
                ]
            ),
        ]
    )
    head = headline(nonlinear, 1e-6).iloc[0]  # no exact solver: the adaptive setting reaching 1e-6
    assert head["ours"] == "adaptive" and head["ours_setting"] == 1e-9


def test_fit_exponents_recovers_a_power_law():
    x = np.array([10.0, 30, 100, 300, 1000])
    table = pd.DataFrame(dict(kind="alpha", family="exact", x=x, threads=1, n_scenes=1,
                              n_collisions=np.round(2 * x**0.8), time_s=3e-6 * x**0.8,
                              time_per_scene_s=3e-6 * x**0.8, status="ok"))  # fmt: skip
    fits = fit_exponents(table, 10.0, 8, 1000).set_index("quantity")
    assert fits.loc["time_s", "exponent"] == pytest.approx(0.8, abs=1e-12)
    assert fits.loc["time_s", "prefactor"] == pytest.approx(3e-6, rel=1e-9)
    assert fits.loc["n_collisions", "exponent"] == pytest.approx(0.8, abs=0.01)


# --- the workflow ---------------------------------------------------------------------------------


def _snakemake(*args, timeout=900):
    return run_snakemake(*args, cwd=REPO, timeout=timeout)


@pytest.mark.parametrize(
    "bad, words",
    [({"min_repeats": 0}, ["benchmarks.min_repeats", ">= 1"]),
     ({"scenes": ["nope"]}, ["benchmarks.scenes", "nope"]),
     ({"families": ["Euler"]}, ["benchmarks.families", "Euler"])],
)  # fmt: skip
def test_workflow_rejects_bad_benchmarks_config(tmp_path, bad, words):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"benchmarks": bad}))
    result = _snakemake("-n", "benchmarks", "--configfile", str(path), "--directory", str(tmp_path))
    assert result.returncode != 0
    for word in words:
        assert word in result.stderr + result.stdout


def test_benchmarks_not_part_of_all():
    result = _snakemake("-n", "all", "--forceall", "--quiet", "rules")
    assert result.returncode == 0, result.stderr
    assert "bench_run" not in result.stdout and "bench_run" not in result.stderr


@pytest.mark.pipeline
def test_smoke_benchmarks_end_to_end(tmp_path):
    result = _snakemake("-c2", "benchmarks", "--configfile",
                        str(REPO / "config" / "benchmarks-smoke.yaml"), "--directory",
                        str(tmp_path))  # fmt: skip
    assert result.returncode == 0, result.stderr[-4000:]
    smoke = yaml.safe_load((REPO / "config" / "benchmarks-smoke.yaml").read_text())["benchmarks"]
    records = read_table(tmp_path / "results/benchmarks/workprecision.parquet")
    assert set(records["scene"]) == set(smoke["scenes"])
    assert set(records["family"]) == set(smoke["families"])
    assert records["status"].isin(["ok", "not_applicable", "skipped", TIME_BUDGET_STATUS]).all()
    prov = read_provenance(tmp_path / "results/benchmarks/workprecision.parquet")
    assert prov["machine"]["cpu_count"] >= 1 and "scipy" in prov["libraries"]
    for name in ("summary.csv", "headline.csv", "scaling_exponents.csv"):
        assert not pd.read_csv(tmp_path / "results/benchmarks" / name).empty
    for name in ("workprecision", "scaling"):
        for ext in ("png", "pdf"):
            assert (tmp_path / "figures/benchmarks" / f"{name}.{ext}").stat().st_size > 1000


def test_scaling_times_solve_ivp_at_matched_accuracy():
    """The scaling panel's solve_ivp setting is the loosest rtol whose COR is within the match
    error of the exact one (same contact count): it meets that, and the next looser does not."""
    import restitution
    from restitution_workflow.bench.scaling import matched_setting

    rtols = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]
    exact = restitution.solve(alpha=10.0)
    rtol, err, r, matched = matched_setting(10.0, 0.0, exact, "DOP853", rtols, 1e-6, 30.0)
    assert matched and err <= 1e-6 and r.n_collisions == exact.n_collisions
    assert err == abs(r.cor - exact.cor)
    looser = [t for t in rtols if t > rtol]
    if looser:
        q = solve_ivp_scene(10.0, 0.0, method="DOP853", rtol=min(looser), atol=min(looser))
        assert q.n_collisions != exact.n_collisions or abs(q.cor - exact.cor) > 1e-6
    # An unreachable match returns the tightest rtol tried, not matched.
    rtol, err, _, matched = matched_setting(10.0, 0.0, exact, "DOP853", [1e-3], 1e-15, 30.0)
    assert not matched and rtol == 1e-3 and err > 1e-15


def test_rule_timings_marks_cpu_sums_of_sparsely_sampled_jobs(tmp_path):
    """Snakemake samples a job's CPU every 0.5 s for 15 s, then every 30 s: a longer job's CPU
    time is as of its last sample, so its group's CPU sum is shown as a lower bound."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "rule_timings", REPO / "benchmarks" / "rule_timings.py"
    )
    rt = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(rt)
    head = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"
    jobs = {"design/all/masses.tsv": (42.7, 14.7), "fig2a/beta~0/chunk_0.tsv": (0.9, 0.7),
            "fig2a/beta~1/chunk_0.tsv": (1.1, 0.8)}  # fmt: skip
    for name, (wall, cpu) in jobs.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(head + f"{wall}\t0:00:01\t300\t0\t0\t0\t0\t0\t50\t{cpu}\n")
    lines = rt.table(rt.load(tmp_path)).splitlines()
    rows = {line.split("|")[1].strip(): line.split("|")[5].strip() for line in lines[2:]}
    assert rows["`design/all/masses`"] == ">= 14.7"
    assert rows["`fig2a/*/*`"] == "1.5"
    assert rows["**all jobs**"] == ">= 16.2"
