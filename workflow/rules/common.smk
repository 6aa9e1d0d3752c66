# Shared helpers: configuration checks and the small functions rules use for inputs and params.
# No rules here (snakemake --lint wants rules and functions in separate files).

import math
import mimetypes
from pathlib import Path

import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

# The report attaches parquet tables; without a registered type it warns "assuming text/plain".
mimetypes.add_type("application/vnd.apache.parquet", ".parquet")

SCHEMA = Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml"


# ---------------------------------------------------------------------------------------------
# Configuration: fail before any job runs, naming the key, the value and the allowed range.
# The checks are the package's own (restitution.config_check, plain Python); they also normalise
# the values (whole-number floats of integer keys become integers, numbers that --config hands
# over as text become numbers, defaults are filled in), so the jobs get what was checked.
# ---------------------------------------------------------------------------------------------
def check_config(config, schema_path=SCHEMA):
    """Check ``config`` in place; raise WorkflowError listing every problem."""
    from restitution.config_check import ConfigError
    from restitution.config_check import check_config as check

    schema = yaml.safe_load(Path(schema_path).read_text())
    try:
        checked = check(config, schema)
    except ConfigError as error:
        raise WorkflowError(
            "Invalid configuration (config/config.yaml plus any --configfile/--config):\n  "
            + "\n  ".join(error.problems)
        ) from None
    config.clear()
    config.update(checked)


check_config(config)
# snakemake's own validation (jsonschema) as a second opinion on the normalised configuration.
validate(config, schema="../schemas/config.schema.yaml")


# ---------------------------------------------------------------------------------------------
# Runs keep to their own folders: the paper's run (run: paper) writes results/, figures/ and
# logs/ at the top of the repository; any other run writes the same tree under runs/<run>/.
# The Snakefile makes that folder the working directory (workdir:); the rules' inputs from the
# repository (src/restitution/..., workflow/scripts/...) and the config files the report reads
# are reached there through the links runs/<run>/{src,workflow,config} -> ../../{same}.
# `snakemake --directory DIR` (e.g. make bench-smoke) overrides both.
# ---------------------------------------------------------------------------------------------
RUN = config["run"]
# A study file named on the command line is relative to where snakemake was started: resolved
# before the working directory changes (workflow/rules/study.smk reads it).
STUDY_FILE = Path(config["study"]).absolute() if config["study"] else None
RUN_DIR = None
if RUN != "paper" and workflow.overwrite_workdir is None:
    RUN_DIR = Path(workflow.basedir) / "runs" / RUN
    RUN_DIR.mkdir(parents=True, exist_ok=True)
    for _name in ("src", "workflow", "config"):
        _link = RUN_DIR / _name
        if not _link.exists():
            if _link.is_symlink():  # a dangling link left by a moved checkout
                _link.unlink()
            _link.symlink_to(Path("..") / ".." / _name, target_is_directory=True)


wildcard_constraints:
    beta=r"\d+(\.\d+)?(e[+-]?\d+)?",
    chunk=r"\d+",


# ---------------------------------------------------------------------------------------------
# Helpers for rules
# ---------------------------------------------------------------------------------------------
TABLES = Path(workflow.basedir) / "workflow" / "tables.yaml"


def result_tables():
    """The result tables of target `all` (workflow/tables.yaml; the ones without {wildcards}).

    `all` requests each, so a deleted table is rebuilt (docs/tables.md is generated from the
    same list, and tests/test_tables_list.py holds the list against the workflow's outputs).
    """
    entries = yaml.safe_load(TABLES.read_text())["tables"]
    return [e["path"] for e in entries if "{" not in e["path"]]


def no_study_given(wildcards):
    """Input of target `study` when no study file is named: stops with how to name one."""
    raise WorkflowError(
        "target `study` needs a study file: snakemake -c2 study --config study=my_study.yaml "
        "(docs/study.md; config/study-example.yaml is an example)"
    )


def beta_label(beta):
    """Path label of a beta value: short ('0', '0.001', '1e-05') yet exact when read back."""
    beta = float(beta)
    short = f"{beta:g}"
    return short if float(short) == beta else repr(beta)


# Package modules each stage runs are inputs of its jobs, so editing one reruns exactly what uses it
# (Snakemake cannot see imports). Plotting code is never listed, so restyling reruns no simulation.
EXACT_SOLVER_MODULES = (
    "__init__.py",
    "api.py",
    "io.py",
    "result.py",
    "scene.py",
    "sweeps.py",
    "kernels/__init__.py",
    "kernels/layout.py",
    "kernels/rigid2.py",
    "kernels/linear.py",
)
APPROX_MODULES = ("special_points.py", "approx.py", "fitting.py")


def package_sources(*extra):
    """Sorted paths of the exact-solver modules plus ``extra`` (names under src/restitution)."""
    src = Path(workflow.basedir) / "src" / "restitution"
    names = sorted(set(EXACT_SOLVER_MODULES) | set(extra))
    missing = [n for n in names if not (src / n).is_file()]
    if missing:
        raise WorkflowError(f"package_sources: no such module(s) {missing} under {src}")
    return [str((src / n).relative_to(workflow.basedir)) for n in names]


def solver_settings():
    """The solver part of the config (params of every simulation rule)."""
    return {"method": config["method"], "max_events": config["max_events"]}


def fig2a_grid():
    """The alpha-grid part of config['fig2a'] (not the betas: adding a beta reruns nothing)."""
    keys = ("alpha_min", "alpha_max", "n_alpha", "chunk_size", "refine_steps")
    return {key: config["fig2a"][key] for key in keys}


def fig2a_n_chunks():
    """Chunk k holds grid indices k*chunk_size .. (k+1)*chunk_size (shared boundary point)."""
    from restitution.config_check import n_chunks

    grid = config["fig2a"]
    return n_chunks(grid["n_alpha"], grid["chunk_size"])


def fig2a_chunk_tables():
    return expand(
        "results/fig2a/beta~{beta}/chunk_{chunk}.parquet",
        beta=[beta_label(b) for b in config["fig2a"]["betas"]],
        chunk=range(fig2a_n_chunks()),
    )
