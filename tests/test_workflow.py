"""The Snakemake workflow: configuration checks, dry runs, lint, and a tiny end-to-end run.

Bad configuration must stop snakemake before any job runs, with a message naming the key, the
value and the allowed range. The end-to-end test (marker ``pipeline``) runs the whole Fig. 2(a)
chain on a tiny configuration in a temporary copy of the workflow.
"""

import importlib.util
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
import yaml

from conftest import REPO, copy_workflow, run_snakemake


def write_config(path: Path, config: dict) -> Path:
    path.write_text(yaml.safe_dump(config))
    return path


# --- bad configuration fails before any job runs, naming key, value and range -----------------

BAD_CONFIGS = {
    "negative alpha_min": (
        {"fig2a": {"alpha_min": -1.0}},
        ["fig2a.alpha_min", "-1.0", "> 0"],
    ),
    "unknown method": (
        {"method": "newton"},
        ["method", "'newton'", "'auto'", "'impulsive'", "'piecewise'"],
    ),
    "string in betas": (
        {"fig2a": {"betas": [0.0, 0.01, "stiff"]}},
        ["fig2a.betas[2]", "'stiff'", "a number >= 0"],
    ),
    "misspelt key": (
        {"fig2a": {"alpah_min": 0.5}},
        ["fig2a.alpah_min", "0.5", "unknown key", "did you mean 'alpha_min'"],
    ),
    "method that does not fit the betas": (
        {"method": "impulsive"},
        ["method = 'impulsive' does not fit", "fig2a.betas = [0.0, 0.001", "needs beta = 0"],
    ),
    "alpha range reversed": (
        {"fig2a": {"alpha_min": 10.0, "alpha_max": 1.0}},
        ["fig2a.alpha_max", "1.0", "greater than fig2a.alpha_min = 10.0"],
    ),
    "chain range reversed": (
        {"fig6": {"sweep": {"x_min": 5.0, "x_max": 1.0}}},
        ["fig6.sweep.x_max = 1.0: must be greater than fig6.sweep.x_min = 5.0"],
    ),
    "section that is not a mapping": (
        {"fig7": [0.1, 0.3]},
        ["fig7 = [0.1, 0.3]: must be a mapping of keys to values"],
    ),
    "fractional integer": (
        {"max_events": 2.5},
        ["max_events = 2.5: must be an integer >= 1"],
    ),
    "grid too large for the DAG": (
        {"fig2a": {"n_alpha": 10000000, "chunk_size": 2}},
        ["fig2a.chunk_size = 2: makes 25000000 simulate jobs", "more than the bound of 2000"],
    ),
    "plastic DR below (1 - eta)/2": (
        {"fig4": {"b": {"drs": [0.1]}}},
        ["fig4.b", "DR = 0.1 with eta = 0.5", "(1 - eta)/2 = 0.25"],
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_CONFIGS))
def test_bad_config_fails_before_any_job(case, tmp_path):
    config, expected = BAD_CONFIGS[case]
    bad = write_config(tmp_path / "bad.yaml", config)
    result = run_snakemake("-n", "--configfile", str(bad))
    text = result.stdout + result.stderr
    assert result.returncode != 0, text
    assert "Invalid configuration" in text, text
    for fragment in expected:
        assert fragment in text, f"{fragment!r} missing from:\n{text}"
    assert "Job stats" not in text  # failed while parsing, before building any job


def test_every_problem_is_listed_at_once(tmp_path):
    bad = write_config(tmp_path / "bad.yaml", {"max_event": 10, "fig2a": {"chunk_size": 0}})
    result = run_snakemake("-n", "--configfile", str(bad))
    text = result.stdout + result.stderr
    assert result.returncode != 0
    assert "max_event = 10: unknown key (did you mean 'max_events'?)" in text, text
    assert "fig2a.chunk_size = 0: must be an integer >= 2" in text, text


def test_bad_config_on_the_command_line():
    result = run_snakemake("-n", "--config", "max_events=-5")
    text = result.stdout + result.stderr
    assert result.returncode != 0
    assert "max_events = -5: must be an integer >= 1" in text, text


def test_bad_nested_override_on_the_command_line():
    # snakemake hands a nested --config value over as text: 'x' is no number, '0.5' is one.
    result = run_snakemake("-n", "fig7a", "--config", "fig7={xis: [0.5, x]}")
    text = result.stdout + result.stderr
    assert result.returncode != 0
    assert "fig7.xis[1] = 'x': must be a number >= 0 and <= 1000" in text, text
    assert "Job stats" not in text


def test_valid_overrides_reach_the_jobs_with_their_types(tmp_path):
    """A whole-number float for an integer key and a nested override (handed over as text) pass
    the check and reach the job as the numbers they name: one tiny simulate job runs."""
    work = copy_workflow(tmp_path)
    chunk = "results/fig2a/beta~0/chunk_0.parquet"
    grid = "fig2a={n_alpha: 5, chunk_size: 4, betas: [0], refine_steps: 2.0}"
    result = run_snakemake("-c1", chunk, "--config", "max_events=5e2", grid, cwd=work)
    assert result.returncode == 0, result.stdout + result.stderr[-3000:]
    config = json.loads(pq.read_schema(work / chunk).metadata[b"restitution"])["config"]
    assert config["solver"]["max_events"] == 500 and config["grid"]["refine_steps"] == 2
    assert config["grid"]["n_alpha"] == 5 and config["grid"]["alpha_min"] == 0.1


def test_default_config_dry_run():
    # --forceall: list every job even when the figures are up to date (e.g. after make all).
    result = run_snakemake("-n", "--forceall", "all")
    assert result.returncode == 0, result.stdout + result.stderr
    # The default profile's short listing: one line per job (the rules' `message:`, the reason
    # quieted), not the rule block with its input, output and wildcards lists.
    jobs = re.findall(r"^Job \d+: (\w+), log (\S+)$", result.stdout, re.M)
    listed = {rule for rule, _log in jobs}
    for rule in ("simulate_fig2a", "aggregate_fig2a", *PANELS):
        assert rule in listed, rule
    assert ("all", None) not in jobs and "Job 0: target all" in result.stdout.splitlines()
    n_jobs = int(re.search(r"^total\s+(\d+)$", result.stdout, re.M).group(1))
    assert len(jobs) == n_jobs - 1  # every job but the target `all`
    for block_line in ("    input:", "    output:", "    wildcards:", "    reason:"):
        assert block_line not in result.stdout, block_line


def test_small_run_keeps_to_its_folder(tmp_path):
    """A run of config/small.yaml (two drawn panels, no simulation) writes under runs/small/
    only; the paper's figures/ at the top stays byte for byte as it was."""
    work = copy_workflow(tmp_path)
    paper_figure = work / "figures" / "fig1.png"
    paper_figure.parent.mkdir()
    paper_figure.write_bytes(b"the paper's figure")
    small = str(work / "config" / "small.yaml")
    result = run_snakemake("-c1", "fig1", "fig6a", "--configfile", small, cwd=work)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert sorted(p.name for p in (work / "figures").iterdir()) == ["fig1.png"]
    assert paper_figure.read_bytes() == b"the paper's figure"
    assert not (work / "logs").exists() and not (work / "results").exists()
    run = work / "runs" / "small"
    for name in ("fig1.png", "fig1.pdf", "fig6a.png", "fig6a.pdf"):
        assert (run / "figures" / name).read_bytes()[:4] in (b"\x89PNG", b"%PDF"), name
    assert (run / "logs" / "fig1" / "render.log").is_file()
    assert (run / "src").resolve() == (REPO / "src").resolve()
    # Its report: Snakemake reads the config files by their relative paths from the run folder.
    report = run_snakemake("fig1", "fig6a", "--configfile", small, "--report", "r.html", cwd=work)
    assert report.returncode == 0, report.stdout[-3000:] + report.stderr[-3000:]
    assert (run / "r.html").stat().st_size > 0


# One target per panel of the paper, named by the figure (Fig. 1-7).
PANELS = (
    "fig1",
    "fig2a",
    "fig2b",
    "fig2c",
    "fig2d",
    "fig3a",
    "fig3b",
    "fig4a",
    "fig4b",
    "fig4c",
    "fig4d",
    "fig5a",
    "fig5b",
    "fig6a",
    "fig6b",
    "fig7a",
    "fig7b",
    "fig7c",
    "fig7d",
)


@pytest.mark.parametrize("extra", [(), ("--config", "study=config/study-example.yaml")])
def test_lint_is_clean(extra):
    result = run_snakemake("--lint", *extra)  # with a study, its rules are linted too
    assert result.returncode == 0, result.stdout + result.stderr


def test_schema_documents_every_key():
    schema = yaml.safe_load((REPO / "workflow/schemas/config.schema.yaml").read_text())

    def walk(node, where):
        assert node.get("additionalProperties") is False, where
        for key, sub in node["properties"].items():
            for field in ("description", "type", "default"):
                assert field in sub, f"{where}.{key} lacks {field}"
            if sub["type"] == "object":
                walk(sub, f"{where}.{key}")
            elif sub["type"] in ("number", "integer"):
                assert {"minimum", "exclusiveMinimum"} & set(sub), f"{where}.{key}: no lower bound"
                assert {"maximum", "exclusiveMaximum"} & set(sub), f"{where}.{key}: no upper bound"
            elif sub["type"] == "string":
                assert {"enum", "pattern"} & set(sub), f"{where}.{key}: no enum or pattern"
            elif sub["type"] == "array":
                assert {"minItems", "maxItems", "items"} <= set(sub), f"{where}.{key}"

    walk(schema, "config")


# --- pieces of the scripts ----------------------------------------------------------------------


def _load_script(name):
    path = REPO / "workflow" / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"workflow_script_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("n_alpha, chunk_size", [(600, 300), (601, 300), (10, 3), (2, 2), (7, 50)])
def test_chunks_cover_the_grid_with_shared_boundaries(n_alpha, chunk_size):
    sim = _load_script("_common")
    grid = {"alpha_min": 0.1, "alpha_max": 100.0, "n_alpha": n_alpha, "chunk_size": chunk_size}
    n_chunks = -(-(n_alpha - 1) // chunk_size)  # the formula of common.smk's fig2a_n_chunks
    chunks = [sim.chunk_alphas(grid, k) for k in range(n_chunks)]
    full = np.geomspace(grid["alpha_min"], grid["alpha_max"], n_alpha)
    np.testing.assert_array_equal(np.unique(np.concatenate(chunks)), full)
    for left, right in zip(chunks, chunks[1:], strict=False):
        assert left[-1] == right[0]  # a change of contact count between chunks is not missed
    with pytest.raises(ValueError, match="outside the grid"):
        sim.chunk_alphas(grid, n_chunks)


def test_figures_are_deterministic(tmp_path):
    from restitution import plotting

    def render(stem):
        fig = plotting.new_figure()
        ax = fig.add_subplot()
        ax.plot([0.1, 1, 10], [0.3, 1.0, 0.9], label=plotting.beta_text(1e-3))
        plotting.log_axis(ax)
        ax.legend()
        return plotting.save_figure(fig, stem, formats=("png", "pdf", "svg"))

    first = render(tmp_path / "a")
    second = render(tmp_path / "b")
    for a, b in zip(first, second, strict=True):
        assert a.read_bytes() == b.read_bytes(), f"{a.suffix} output differs between renders"
    assert b"CreationDate" not in first[1].read_bytes()


# --- end to end on a tiny configuration -----------------------------------------------------------

TINY = {
    "fig2a": {
        "alpha_min": 0.5,
        "alpha_max": 1.5,
        "n_alpha": 13,
        "betas": [0.0, 0.1],
        "chunk_size": 6,
        "refine_steps": 30,
    }
}


def run_tiny_pipeline(work: Path):
    """The workflow copied to ``work`` (package code shared through a symlink), run on TINY."""
    copy_workflow(work)
    tiny = write_config(work / "tiny.yaml", TINY)
    profile = ("--workflow-profile", "workflow/profiles/default")
    return run_snakemake("-c2", *profile, "--configfile", str(tiny), cwd=work, timeout=1200)


@pytest.mark.pipeline
def test_tiny_pipeline_end_to_end(tmp_path):
    """One run (one test, so pytest-xdist never runs it twice) checked from several sides."""
    result = run_tiny_pipeline(tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr[-5000:]

    # Figures and logs.
    assert (tmp_path / "figures" / "fig2a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "figures" / "fig2a.pdf").read_bytes()[:5] == b"%PDF-"
    for log in ("aggregate", "render"):
        assert "INFO" in (tmp_path / "logs" / "fig2a" / f"{log}.log").read_text()

    # Every table carries its provenance.
    sweep_path = tmp_path / "results" / "fig2a" / "sweep.parquet"
    chunks = sorted((tmp_path / "results" / "fig2a").glob("beta~*/chunk_*.parquet"))
    assert len(chunks) == 2 * 2  # two betas, ceil((13 - 1) / 6) = 2 chunks each
    for path in [sweep_path, *chunks]:
        meta = pq.read_schema(path).metadata
        assert b"restitution" in meta, path
        provenance = json.loads(meta[b"restitution"])
        assert provenance["config_hash"] and provenance["git_commit"], path
    sweep = pq.read_table(sweep_path).to_pandas()
    assert set(sweep["beta"]) == {0.0, 0.1}
    assert (sweep["status"] == "ok").all()
    assert not sweep.duplicated(["beta", "alpha"]).any()

    # Refinement resolves the first cusp: alpha* = 0.69712, COR = 0.178465 (paper Eqs. 10-11),
    # whose depth the 13-point grid alone misses by ~0.03.
    rigid = sweep[sweep["beta"] == 0.0]
    assert rigid["refined"].any()
    grid_min = rigid.loc[~rigid["refined"], "cor"].min()
    best = rigid.loc[rigid["cor"].idxmin()]
    assert best["cor"] == pytest.approx(0.178465, abs=2e-5)
    assert best["alpha"] == pytest.approx(0.697123, abs=1e-4)
    assert grid_min > best["cor"] + 0.01
    minima = pd.read_csv(tmp_path / "results" / "fig2a" / "minima.csv")
    first = minima[(minima["beta"] == 0.0) & (minima["minimum"] == 1)].iloc[0]
    assert first["cor"] == pytest.approx(best["cor"]) and first["n_collisions"] == 1


def test_simulate_and_render_rules_have_benchmark_and_log():
    """Per-rule cost (benchmark:) and logs (log:) exist for every simulate and render rule."""
    blocks = {}
    for path in sorted((REPO / "workflow" / "rules").glob("*.smk")):
        text = path.read_text()
        starts = [(m.start(), m.group(1)) for m in re.finditer(r"^rule (\w+):", text, re.M)]
        for (start, name), (end, _) in zip(starts, [*starts[1:], (len(text), "")], strict=False):
            blocks[name] = text[start:end]
    checked = [n for n in blocks if n.startswith(("simulate", "fig", "render"))]
    assert {"simulate_fig2a", "fig2b", "fig7d"} <= set(checked)
    for name in checked:
        assert "\n    log:" in blocks[name], f"rule {name} has no log:"
        assert "\n    benchmark:" in blocks[name], f"rule {name} has no benchmark:"
