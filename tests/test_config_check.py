"""restitution_workflow.config_check: the workflow's configuration checks, in plain Python.

The checks run on the real schema and configurations of the workflow (no snakemake here; the
workflow's use of them is tested in test_workflow.py).
"""

import ast
import copy
from pathlib import Path

import pytest
import yaml

from conftest import REPO
from restitution_workflow.config_check import MAX_JOBS, ConfigError, check_config

SCHEMA = yaml.safe_load((REPO / "workflow/schemas/config.schema.yaml").read_text())
PAPER = yaml.safe_load((REPO / "config/config.yaml").read_text())


def merged(**sections) -> dict:
    """The paper's configuration with ``sections`` merged over it (one level deep, as YAML)."""
    config = copy.deepcopy(PAPER)
    for key, value in sections.items():
        if isinstance(value, dict) and isinstance(config.get(key), dict):
            config[key].update(value)
        else:
            config[key] = value
    return config


def problems(config) -> list[str]:
    with pytest.raises(ConfigError) as info:
        check_config(config, SCHEMA)
    return info.value.problems


def test_shipped_configurations_pass_unchanged():
    checked = check_config(PAPER, SCHEMA)
    assert checked == PAPER | {"study": ""}  # every other key is in config.yaml already
    for name in ("small.yaml", "benchmarks-smoke.yaml"):
        extra = yaml.safe_load((REPO / "config" / name).read_text())
        config = merged(**extra)
        assert check_config(config, SCHEMA)["run"] == extra["run"] != "paper"


def test_defaults_are_filled_in():
    checked = check_config({}, SCHEMA)
    assert checked["run"] == "paper" and checked["max_events"] == 100000
    assert (
        checked["fig2a"]["n_alpha"]
        == SCHEMA["properties"]["fig2a"]["properties"]["n_alpha"]["default"]
    )


@pytest.mark.parametrize("value", [5e2, 500.0, "5e2", "500", " 500 "])
def test_integer_keys_take_whole_number_floats_and_text(value):
    checked = check_config(merged(max_events=value, fig2a={"n_alpha": value}), SCHEMA)
    for got in (checked["max_events"], checked["fig2a"]["n_alpha"]):
        assert got == 500 and type(got) is int


@pytest.mark.parametrize("value", [2.5, "2.5", "many", True, float("nan"), float("inf"), None])
def test_integer_keys_refuse_what_is_no_integer(value):
    found = problems(merged(max_events=value))
    assert found == [f"max_events = {value!r}: must be an integer >= 1 and <= 1e+08"]


def test_numbers_given_as_text_are_parsed():
    # What `--config "fig7={xis: [0.1, 0.5], beta: 1e-3}"` hands over (snakemake reads the
    # nested value with YAML's BaseLoader: every scalar is text).
    checked = check_config(merged(fig7={"xis": ["0.1", "0.5"], "beta": "1e-3"}), SCHEMA)
    assert checked["fig7"]["xis"] == [0.1, 0.5] and checked["fig7"]["beta"] == 0.001


def test_section_that_is_not_a_mapping():
    found = problems(merged(fig7=3))
    assert len(found) == 1 and found[0].startswith("fig7 = 3: must be a mapping"), found
    found = problems(merged(fig4={"sweep": [1, 2]}))
    assert found[0].startswith("fig4.sweep = [1, 2]: must be a mapping"), found


def test_every_problem_is_named_at_once():
    found = problems(
        merged(max_event=10, fig2a={"chunk_size": 0, "betas": [0.0, "stiff"]}, method="newton")
    )
    assert any(
        p.startswith("max_event = 10: unknown key (did you mean 'max_events'?)") for p in found
    )
    assert "method = 'newton': must be one of 'auto', 'impulsive', 'piecewise'" in found
    assert "fig2a.betas[1] = 'stiff': must be a number >= 0 and <= 1e+06" in found
    assert "fig2a.chunk_size = 0: must be an integer >= 2 and <= 1e+07" in found


def test_relations_between_keys():
    found = problems(merged(fig2a={"alpha_min": 10.0, "alpha_max": 1.0}))
    assert found == ["fig2a.alpha_max = 1.0: must be greater than fig2a.alpha_min = 10.0"]
    found = problems(merged(fig6={"sweep": {**PAPER["fig6"]["sweep"], "x_min": 5, "x_max": 1}}))
    assert found == ["fig6.sweep.x_max = 1: must be greater than fig6.sweep.x_min = 5"]
    found = problems(merged(method="piecewise"))
    assert "method = 'piecewise' does not fit fig2a.betas" in found[0]
    assert "'piecewise' needs beta > 0" in found[0]  # the solver table's own reason


def test_lists_are_bounded_and_unique():
    found = problems(merged(fig2a={"betas": [0.0, 0.0]}))
    assert found[0].startswith("fig2a.betas = [0.0, 0.0]: must be a list of a number"), found
    assert "no duplicates" in found[0]
    found = problems(merged(fig2a={"betas": [float(i) for i in range(101)]}))
    assert found[0].startswith("fig2a.betas has 101 items: must have at most 100"), found


def test_job_count_is_bounded_before_any_dag_is_built():
    # 1e7 grid points in chunks of 2 would be 5e6 jobs a beta: a dry run would never finish.
    found = problems(merged(fig2a={"n_alpha": 10**7, "chunk_size": 2}))
    assert len(found) == 1 and f"more than the bound of {MAX_JOBS}" in found[0], found
    assert found[0].startswith("fig2a.chunk_size = 2: makes 25000000 simulate jobs"), found
    # Exactly at the bound is fine: 5 betas x 400 chunks.
    check_config(merged(fig2a={"n_alpha": 401 * 10 - 9, "chunk_size": 10}), SCHEMA)


def test_scene_ranges_come_from_the_package():
    # The schema lets fig7.traces.alphas reach 1e5; alpha itself is allowed up to 1e8 by the
    # scene model, xi to 1e3: a schema wider than the package would be caught here.
    found = problems(merged(fig7={**PAPER["fig7"], "xis": [2000.0]}))
    assert found == ["fig7.xis[0] = 2000.0: must be a number >= 0 and <= 1000"], found


def test_run_names_are_folder_names():
    for bad in ("../x", "a/b", "", ".hidden", "x" * 65):
        found = problems(merged(run=bad))
        assert found[0].startswith(f"run = {bad!r}: must be a text matching"), found
    assert check_config(merged(run="trial_2.b"), SCHEMA)["run"] == "trial_2.b"


def test_unknown_schema_keyword_is_refused():
    with pytest.raises(ValueError, match=r"unsupported keyword\(s\) \['oneOf'\]"):
        check_config({"x": 1}, {"type": "object", "properties": {"x": {"oneOf": []}}})


def test_package_needs_no_jsonschema_nor_yaml():
    """Nothing under src/ imports jsonschema or snakemake; yaml only inside a function (reading a
    study file, with the workflow's dependencies), never when the package is imported."""
    for path in sorted((REPO / "src").rglob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            banned = {"jsonschema", "snakemake"}
            if node in tree.body:
                banned.add("yaml")
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names = [node.module or ""]
            else:
                continue
            for name in names:
                assert name.split(".")[0] not in banned, f"{Path(path).relative_to(REPO)}: {name}"
