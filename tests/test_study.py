"""A user's own study (restitution_workflow.study and the workflow's `study` target).

The checks name the key, the value and what is allowed, before any work; the refinement finds
cusps and smooth minima (against closed forms); the target runs a small study end to end in a
scratch copy of the workflow, into the report.
"""

import json
import math
import re

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
import yaml

import restitution
import restitution_workflow.study as study_module
from conftest import REPO, copy_workflow, load_script, run_snakemake
from restitution_workflow.study import (
    STUDY_SCHEMA,
    StudyError,
    check_study,
    load_study,
    solve_curve,
)

PAPER = {
    "name": "demo",
    "scene": {"beta": 0.0},
    "axes": [{"param": "alpha", "logspace": {"start": 0.5, "stop": 1.5, "num": 9}}],
    "refine_steps": 40,
}
CHAIN = {
    "name": "chain",
    "scene": {"masses": [1.0, 0.5, 2.0], "springs": [0.3, 1.2], "dashpots": [0.0, 0.05]},
    "axes": [
        {"param": "masses[2]", "linspace": {"start": 0.5, "stop": 3.0, "num": 6}},
        {"param": "k_contact", "values": [10.0, 1e6]},
    ],
}


def problems(data, **patch) -> list[str]:
    with pytest.raises(StudyError) as info:
        check_study({**data, **patch})
    return info.value.problems


def test_schema_file_is_the_package_schema():
    text = (REPO / "workflow" / "schemas" / "study.schema.yaml").read_text()
    assert yaml.safe_load(text) == STUDY_SCHEMA


def test_example_study_is_valid():
    study = load_study(REPO / "config" / "study-example.yaml")
    assert study.axes[0].param == "alpha" and study.axes[0].log
    assert len(study.curves) == 4 and study.n_chunks == 2


def test_studies_of_the_docs_are_valid():
    """Every YAML study of docs/study.md passes the checks, as written."""
    text = (REPO / "docs" / "study.md").read_text()
    found = re.findall(r"^```yaml\n(.*?)^```", text, re.S | re.M)
    assert len(found) >= 2
    for block in found:
        check_study(yaml.safe_load(block))


def test_defaults_and_grid():
    study = check_study(PAPER)
    assert study.outputs == ("cor", "n_collisions") and study.method == "auto"
    np.testing.assert_allclose(study.axes[0].values, np.geomspace(0.5, 1.5, 9))
    assert math.isnan(study.curves[0]) and study.n_chunks == 1


@pytest.mark.parametrize(
    "patch, expected",
    [
        ({"nmae": "x"}, "nmae = 'x': unknown key (did you mean 'name'?)"),
        ({"name": "a/b"}, "name = 'a/b': must be a text matching"),
        ({"outputs": ["cor", "energy"]}, "outputs[1] = 'energy': must be one of 'cor'"),
        ({"refine_steps": 2.5}, "refine_steps = 2.5: must be an integer >= 0 and <= 60"),
        ({"scene": [1, 2]}, "scene = [1, 2]: must be a mapping of keys to values"),
        (
            {"scene": {"alpha": -1.0}, "axes": [{"param": "beta", "values": [0.0, 0.1]}]},
            "scene.alpha = -1.0: alpha must be in [1e-8, 1e8]",
        ),
        ({"scene": {"beta": 0.0, "n_masses": 1}}, "scene.n_masses = 1: must be an integer >= 2"),
        ({"axes": []}, "axes = []: must be a list of a mapping of keys to values"),
        (
            {"axes": [{"param": "gamma", "values": [1.0, 2.0]}]},
            "axes[0].param = 'gamma': must be a text matching",
        ),
        (
            {"axes": [{"param": "alpha", "values": [1.0, 2.0],
                       "linspace": {"start": 1, "stop": 2, "num": 3}}]},
            "axes[0]: give exactly one of values, linspace, logspace",
        ),
        (
            {"axes": [{"param": "alpha", "logspace": {"start": 0.0, "stop": 1.0, "num": 5}}]},
            "axes[0].logspace.start = 0.0: must be > 0 (a log axis)",
        ),
        (
            {"axes": [{"param": "alpha", "linspace": {"start": 2.0, "stop": 1.0, "num": 5}}]},
            "axes[0].linspace.stop = 1.0: must be greater than start = 2.0",
        ),
        (
            {"axes": [{"param": "xi", "values": [0.0, 2000.0]}]},
            "axis xi = 2000.0: xi must be in [0, 1e3]",
        ),
        ({"scene": {"alpha": 1.0, "beta": 0.0}}, "axes: param = 'alpha' is also fixed in scene"),
        # values compared as numbers (their reprs differ), generated values checked distinct
        (
            {"axes": [{"param": "alpha", "values": [1.0, 2.0]},
                      {"param": "xi", "values": [0, 0.0, -0.0]}]},
            "axes[1].values = [0, 0.0, -0.0]: must be",
        ),
        (
            {"axes": [{"param": "alpha",
                       "linspace": {"start": 1, "stop": 1.0000000000000002, "num": 100}}]},
            "axes[0].linspace: its 100 values are not distinct (2 different ones",
        ),
        (
            {"axes": [{"param": "alpha",
                       "logspace": {"start": 1, "stop": 1.0000000000000002, "num": 3}}]},
            "axes[0].logspace: its 3 values are not distinct",
        ),
        (
            {"axes": [{"param": "alpha", "logspace": {"start": 0.1, "stop": 1, "num": 100000}}],
             "chunk_size": 2},
            "chunk_size = 2: makes 50000 jobs",
        ),
    ],
)  # fmt: skip
def test_bad_study_is_named(patch, expected):
    found = problems(PAPER, **patch)
    assert any(p.startswith(expected) for p in found), found


def test_every_problem_at_once_and_missing_keys():
    found = problems({"axes": [{"values": [1.0]}], "colour": "red"})
    assert "name: required key missing" in found
    assert "axes[0].param: required key missing" in found
    assert any(p.startswith("colour = 'red': unknown key") for p in found), found


def test_every_problem_at_once_across_the_stages():
    """A schema problem (unknown key), a grid problem (log axis from 0), a scene value out of
    range, a bad axis text and a job count too large: one StudyError lists them all (each stage
    used to stop the check, so a user saw them in three passes)."""
    found = problems(
        PAPER,
        colour="red",
        scene={"beta": 0.0, "xi": 2000.0},
        axes=[
            {"param": "alpha", "logspace": {"start": 0.0, "stop": 1.0, "num": 5}},
            {"param": "n_masses", "values": [2, 1000], "label": "N $\\foo$"},
        ],
    )
    expected = [
        "colour = 'red': unknown key",
        "axes[0].logspace.start = 0.0: must be > 0",
        "scene.xi = 2000.0: xi must be in [0, 1e3]",
        "axis n_masses = 1000.0: n_masses must be an integer in [2, 512]",
        "axes[1].label = 'N $\\\\foo$': matplotlib cannot draw it as mathtext (Unknown symbol",
    ]
    for text in expected:
        assert any(p.startswith(text) for p in found), (text, found)
    # A grid problem and a chain problem together (the chain's own checks need its lists whole).
    axes = [{"param": "masses[1]", "linspace": {"start": 2.0, "stop": 1.0, "num": 3}},
            {"param": "dashpots[0]", "values": [0.0, -0.1]}]  # fmt: skip
    found = problems(CHAIN, axes=axes, refine_steps=99)
    for text in ("refine_steps = 99: must be an integer",
                 "axes[0].linspace.stop = 1.0: must be greater than start = 2.0",
                 "axis dashpots[0] = -0.1: dashpots must be >= 0"):  # fmt: skip
        assert any(p.startswith(text) for p in found), (text, found)


def test_axis_labels_and_units():
    """Axis texts: the study's label and unit, else the parameter's name; units only where the
    quantity has one (a general chain's), one line each."""
    study = check_study(PAPER)
    assert study.axes[0].title == r"mass ratio $\alpha = m_2/m_1$" and study.units == ""
    chain = check_study(
        {**CHAIN, "units": "SI: kg, N/m, N s/m; V0 = 1 m/s",
         "axes": [{"param": "masses[2]", "values": [0.5, 3.0], "label": "rear mass $m_3$",
                   "unit": "kg"},
                  {"param": "k_contact", "values": [10.0, math.inf], "unit": "N/m"}]}
    )  # fmt: skip
    first, second = chain.axes
    assert first.title == "rear mass $m_3$ [kg]" and chain.units.startswith("SI")
    assert second.title == "contact stiffness k_contact [N/m]"
    assert second.curve_text(10.0) == "k_contact = 10 N/m" and second.curve_text(math.inf) == (
        "rigid wall"
    )
    assert check_study(CHAIN).axes[0].title == "mass $m_{3}$ (masses[2])"
    assert check_study(PAPER).axes[0].curve_text(0.5) == r"$\alpha = 0.5$"

    axes = [{**PAPER["axes"][0], "unit": "kg"}]
    assert any(p.startswith("axes[0].unit = 'kg': alpha is a ratio") for p in problems(
        PAPER, axes=axes))  # fmt: skip
    assert any(p.startswith("units = 'SI': the paper's scene is non-dimensional") for p in problems(
        PAPER, units="SI"))  # fmt: skip
    axes = [{**PAPER["axes"][0], "label": "two\nlines"}]
    assert any(p.startswith("axes[0].label = 'two\\nlines': must be a text matching")
               for p in problems(PAPER, axes=axes))  # fmt: skip
    axes = [{**PAPER["axes"][0], "label": "costs $5"}]
    assert any("an odd number of $" in p for p in problems(PAPER, axes=axes))


def test_plots_take_the_axis_texts_of_the_study():
    """study_plot: the x axis reads 'label [unit]', each curve 'label = value unit'."""
    import logging

    study_plot = load_script("study_plot")
    study = check_study(
        {**CHAIN, "units": "SI",
         "axes": [{"param": "masses[2]", "values": [0.5, 1.0, 3.0], "label": "rear mass $m_3$",
                   "unit": "kg"},
                  {"param": "k_contact", "values": [10.0, math.inf], "unit": "N/m"}]}
    )  # fmt: skip
    table = pd.DataFrame(
        {"masses[2]": [0.5, 1.0, 3.0] * 2, "cor": 0.5, "n_collisions": 1, "status": "ok",
         "curve": [10.0] * 3 + [math.inf] * 3, "curve_index": [0] * 3 + [1] * 3}
    )  # fmt: skip
    fig = study_plot.draw(table, study, "cor", logging.getLogger("test"))
    ax = fig.axes[0]
    assert ax.get_xlabel() == "rear mass $m_3$ [kg]"
    assert [line.get_label() for line in ax.lines] == ["k_contact = 10 N/m", "rigid wall"]


def test_a_key_given_twice_is_refused_naming_it_and_its_lines(tmp_path):
    """(YAML kept the last value silently: the first name, or beta 0.0, was dropped.)"""
    path = tmp_path / "twice.yaml"
    path.write_text("name: first\nscene: {beta: 0.0}\naxes:\n"
                    "  - {param: alpha, values: [1.0, 2.0]}\nname: second\n")  # fmt: skip
    with pytest.raises(StudyError, match=r"key 'name' is given twice .*\(lines 1 and 5\)"):
        load_study(path)
    path.write_text("name: s\nscene: {beta: 0.0, beta: 0.1}\naxes:\n"
                    "  - {param: alpha, values: [1.0, 2.0]}\n")  # fmt: skip
    with pytest.raises(StudyError, match=r"key 'beta' is given twice .*\(lines 2 and 2\)"):
        load_study(path)
    path.write_text("name: s\nscene: {beta: 0.0}\naxes:\n"
                    "  - {param: alpha, values: [1.0, 2.0]}\n")  # fmt: skip
    assert load_study(path).scene == {"beta": 0.0}


def test_bad_yaml_file(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("name: [unclosed\n")
    with pytest.raises(StudyError, match=r"study file .*broken.yaml:\n  not valid YAML"):
        load_study(path)
    with pytest.raises(StudyError, match="cannot read it"):
        load_study(tmp_path / "missing.yaml")


def test_general_chain_checks():
    """Lengths, element indices and element ranges, checked without solving anything."""
    study = check_study(CHAIN)
    assert study.general and len(study.curves) == 2
    table = study_module.scene_table(study, np.array([0.5, 3.0]), 10.0)
    assert table["masses"].tolist() == [[1.0, 0.5, 0.5], [1.0, 0.5, 3.0]]
    assert table["springs"].tolist() == [[0.3, 1.2]] * 2 and (table["k_contact"] == 10.0).all()
    assert table["masses[2]"].tolist() == [0.5, 3.0]

    axes = [{"param": "masses[3]", "values": [1.0, 2.0]}]
    assert any("index must be < 3" in p for p in problems(CHAIN, axes=axes))
    scene = {**CHAIN["scene"], "springs": [0.3]}
    assert any(p.startswith("scene.springs = [0.3]: must have 2 items") for p in problems(
        CHAIN, scene=scene))  # fmt: skip
    axes = [{"param": "dashpots[0]", "values": [0.0, -0.1]}]
    assert "axis dashpots[0] = -0.1: dashpots must be >= 0" in problems(CHAIN, axes=axes)
    axes = [{"param": "alpha", "values": [1.0, 2.0]}]
    assert any("alpha is a parameter of the paper's scene" in p for p in problems(CHAIN, axes=axes))


def test_general_chain_rows_are_the_scenes_they_name():
    """Element addressing: each row of a general-chain study is the chain restitution.solve gets
    with masses[2] and k_contact set to the row's axis values."""
    study = check_study({**CHAIN, "refine_steps": 3})
    for curve in study.curves:
        table = solve_curve(study, curve)
        assert (table["status"] == "ok").all() and len(table) > 6
        for _, row in table.iloc[::3].iterrows():
            masses = [1.0, 0.5, row["masses[2]"]]
            alone = restitution.solve(
                masses=masses, springs=[0.3, 1.2], dashpots=[0.0, 0.05], k_contact=curve
            )
            assert row["masses"] == masses and row["k_contact"] == curve
            assert row["cor"] == alone.cor and row["n_collisions"] == alone.n_collisions


def test_refinement_finds_count_steps_and_smooth_minima():
    """_refine against closed forms: a step at x = 2 and a smooth minimum at x = 1.234."""

    def evaluate(x):
        x = np.asarray(x, dtype=float)
        return pd.DataFrame(
            {"x": x, "n_collisions": np.where(x > 2.0, 2, 1), "cor": (np.log(x / 1.234)) ** 2,
             "status": "ok"}
        )  # fmt: skip

    grid = evaluate(np.geomspace(0.5, 4.0, 12))
    new = study_module._refine(grid, evaluate, "x", 40, log=True)
    steps = new[new["n_collisions"] == 2]["x"].min(), new[new["n_collisions"] == 1]["x"].max()
    assert steps[0] / 2.0 - 1 < 1e-10 and 1 - steps[1] / 2.0 < 1e-10
    best = new.loc[new["cor"].idxmin(), "x"]
    assert abs(best / 1.234 - 1) < 1e-9  # the grid alone is ~10% off


def test_first_rigid_wall_cusp_is_resolved():
    """Paper Eqs. 10-11: the first COR minimum at a rigid wall, alpha* = 0.697123,
    e = 0.178465; the 9-point grid alone misses its depth by 0.028."""
    table = solve_curve(check_study(PAPER), math.nan)
    assert (table["status"] == "ok").all() and table["refined"].any()
    best = table.loc[table["cor"].idxmin()]
    assert best["alpha"] == pytest.approx(0.697123, abs=1e-6)
    assert best["cor"] == pytest.approx(0.178465, abs=2e-6)
    assert table.loc[~table["refined"], "cor"].min() > best["cor"] + 0.02


def test_minima_closer_than_the_tolerance_are_one():
    """minima.csv lists each minimum once: a cluster of local minima within round-off of each
    other (closed form plus wiggles of 1e-15) is one minimum, the deepest; minima further apart
    than MINIMA_MERGE of the axis' span stay apart."""
    aggregate = load_script("study_aggregate")
    axis = check_study(PAPER).axes[0]  # alpha, logspace 0.5..1.5
    x = np.geomspace(0.5, 1.5, 41)
    cluster = 0.7 * (1 + np.array([-2, -1, 0, 1, 2]) * 5e-9)
    # 3 tolerances either side of 1.2 (the log span is ln 3), a bump between: two minima.
    apart = 1.2 * np.exp(np.array([-3, 0, 3]) * study_module.MINIMA_MERGE * np.log(3.0))
    x = np.concatenate([x, cluster, apart])
    cor = 0.2 + np.log(x / 0.7) ** 2 * np.log(x / 1.2) ** 2
    cor[41:46] = 0.2 + np.array([3, 0, 2, 1, 3]) * 1e-15  # two local minima inside the cluster
    cor[46:] = 0.2 + np.array([0, 5, 1]) * 1e-15
    table = pd.DataFrame(dict(alpha=x, cor=cor, n_collisions=1, curve=math.nan, curve_index=0,
                              status="ok"))  # fmt: skip
    found = aggregate.minima(table, axis)
    assert found["alpha"].tolist() == [cluster[1], apart[0], apart[2]]
    assert found["minimum"].tolist() == [1, 2, 3] and (found["cor"] <= 0.2 + 1e-15).all()


def test_round_off_minima_of_a_smooth_minimum_are_listed_once():
    """beta = 1: a smooth COR minimum (one contact) near alpha = 0.677. Its pattern search leaves
    several local minima of the same depth within ~1e-8 (round-off); minima.csv lists one, at the
    minimum of an independent reference (scipy's DOP853 through the contact, rtol 1e-13)."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import minimize_scalar

    def reference_cor(alpha):
        k2 = alpha / (1 + alpha)  # k1 = k2 / beta = k2

        def force(t, y):
            u1, u2, v1, v2 = y
            return [v1, v2, -k2 * u1 + k2 * (u2 - u1), -k2 * (u2 - u1) / alpha]

        def separation(t, y):
            return y[0]

        separation.terminal, separation.direction = True, 1
        end = solve_ivp(force, (0, 100), [0, 0, -1, -1], method="DOP853", rtol=1e-13,
                        atol=1e-15, events=separation).y_events[0][0]  # fmt: skip
        return (end[2] + alpha * end[3]) / (1 + alpha)

    best = minimize_scalar(reference_cor, bounds=(0.6, 0.75), method="bounded",
                           options={"xatol": 1e-10})  # fmt: skip
    axis = {"param": "alpha", "logspace": {"start": 0.5, "stop": 0.9, "num": 9}}
    study = check_study({"name": "smooth", "scene": {"beta": 1.0}, "axes": [axis]})
    table = solve_curve(study, math.nan).assign(curve_index=0)
    cor = table.sort_values("alpha")["cor"].to_numpy()
    raw = np.flatnonzero((cor[1:-1] < cor[:-2]) & (cor[1:-1] <= cor[2:]))
    assert len(raw) > 1  # the round-off cluster this test is about
    found = load_script("study_aggregate").minima(table, study.axes[0])
    assert len(found) == 1 and found["n_collisions"].iloc[0] == 1
    assert found["alpha"].iloc[0] == pytest.approx(best.x, rel=1e-7)
    assert found["cor"].iloc[0] == pytest.approx(best.fun, abs=1e-12)


# --- the workflow's study target ------------------------------------------------------------

TINY = {
    "name": "tiny",
    "scene": {"beta": 0.0},
    "axes": [
        {"param": "alpha", "logspace": {"start": 0.5, "stop": 3.0, "num": 11}},
        {"param": "xi", "values": [0.0, 0.3]},
    ],
    "refine_steps": 30,
    "chunk_size": 5,
}


@pytest.mark.pipeline
def test_study_target_end_to_end(tmp_path):
    work = copy_workflow(tmp_path)
    (work / "tiny.yaml").write_text(yaml.safe_dump(TINY))
    result = run_snakemake("-c2", "study", "--config", "study=tiny.yaml", cwd=work, timeout=900)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-5000:]
    out = work / "results" / "studies" / "tiny"
    chunks = sorted(out.glob("curve~*/chunk_*.parquet"))
    assert len(chunks) == 2 * 2  # two curves, ceil((11 - 1) / 5) = 2 chunks each
    meta = json.loads(pq.read_schema(out / "sweep.parquet").metadata[b"restitution"])
    assert meta["config"]["study"]["name"] == "tiny" and meta["git_commit"]
    sweep = pq.read_table(out / "sweep.parquet").to_pandas()
    assert set(sweep["curve"]) == {0.0, 0.3} and (sweep["status"] == "ok").all()
    minima = pd.read_csv(out / "minima.csv")
    first = minima[(minima["curve"] == 0.0) & (minima["minimum"] == 1)].iloc[0]
    assert first["alpha"] == pytest.approx(0.697123, abs=1e-6)  # paper Eq. 10
    for name in ("cor", "n_collisions"):
        png = work / "figures" / "studies" / "tiny" / f"{name}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    report = run_snakemake(
        "study", "--config", "study=tiny.yaml", "--report", "report.html", cwd=work
    )
    assert report.returncode == 0, report.stderr[-3000:]
    html = (work / "report.html").read_text()
    assert "Studies" in html
    # The study's own front page (not the paper's, whose links it lacks): scene, units, axes.
    page = json.loads(re.search(r'var workflow_desc = (".*?");\n', html, re.S).group(1))
    assert "System Message" not in page and "A reproduction of" not in page, page
    for text in ("<strong>Study tiny.</strong>", "non-dimensional, the paper",
                 "beta = 0, n_masses = 2, alpha from the first axis, xi from the curves",
                 "11 values log-spaced from 0.5 to 3", "values 0, 0.3"):  # fmt: skip
        assert text in page, (text, page)
    # Each minimum once (a cluster of round-off minima would be ~1e-8 apart).
    assert minima.groupby("curve")["alpha"].apply(lambda x: x.diff().min()).min() > 1e-3


def test_study_target_refuses_bad_files_before_any_job(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump({**TINY, "axes": [{"param": "alpha", "values": [0.5, -1.0]}]}))
    result = run_snakemake("-n", "study", "--config", f"study={bad}")
    text = result.stdout + result.stderr
    assert result.returncode != 0
    assert "axis alpha = -1.0: alpha must be in [1e-8, 1e8]" in text, text
    assert "Job stats" not in text

    result = run_snakemake("-n", "study")
    text = result.stdout + result.stderr
    assert result.returncode != 0
    assert "target `study` needs a study file: snakemake -c2 study --config study=" in text


# ----------------------------------------------------------------------------------------------
# Bounded reading (issue 29)
# ----------------------------------------------------------------------------------------------
def _levels(n: int) -> str:
    """A study whose axis values are n levels of nine aliases each ('billion laughs')."""
    lines = ["name: bomb", "x0: &x0 [1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    for i in range(1, n):
        lines.append(f"x{i}: &x{i} [" + ", ".join([f"*x{i - 1}"] * 9) + "]")
    lines.append(f"axes: [{{param: alpha, values: *x{n - 1}}}]")
    return "\n".join(lines) + "\n"


def test_alias_bomb_is_refused_before_it_is_built(tmp_path):
    path = tmp_path / "bomb.yaml"
    path.write_text(_levels(8))  # 9**8 = 43 million values from 300 bytes
    with pytest.raises(StudyError, match="expands to more than"):
        load_study(path)


def test_aliases_and_size_are_bounded(tmp_path):
    many = tmp_path / "aliases.yaml"
    many.write_text(
        "name: a\nv: &v 0.5\naxes: [{param: alpha, values: ["
        + ", ".join(["*v"] * (study_module.MAX_ALIASES + 1))
        + "]}]\n"
    )
    with pytest.raises(StudyError, match="aliases"):
        load_study(many)
    big = tmp_path / "big.yaml"
    big.write_text("name: big\n# " + "x" * study_module.MAX_STUDY_BYTES + "\n")
    with pytest.raises(StudyError, match="at most"):
        load_study(big)
    loop = tmp_path / "loop.yaml"
    loop.write_text("name: loop\naxes: &a [*a]\n")
    with pytest.raises(StudyError):
        load_study(loop)


def test_a_few_aliases_are_fine(tmp_path):
    path = tmp_path / "ok.yaml"
    path.write_text(
        "name: ok\nscene: {beta: &b 0.01}\n"
        "axes: [{param: alpha, values: [0.5, 1.0]}, {param: xi, values: [*b, 0.1]}]\n"
    )
    assert load_study(path).scene == {"beta": 0.01}


def test_general_chain_ratios_are_checked_when_read(tmp_path):
    path = tmp_path / "g.yaml"
    path.write_text(
        "name: g\nscene: {masses: [1.0, 1.0, 1.0], springs: [1.0, 1.0]}\n"
        "axes: [{param: 'masses[1]', logspace: {start: 1.0e-10, stop: 10, num: 20}}]\n"
    )
    with pytest.raises(StudyError, match=r"masses\[i\]/masses\[0\]"):
        load_study(path)
