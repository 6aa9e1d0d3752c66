# Shared helpers: configuration checks and the small functions rules use for inputs and params.
# No rules here (snakemake --lint wants rules and functions in separate files).

import ast
import math
import mimetypes
import os
import platform
import re
from pathlib import Path

import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

# The report attaches parquet tables; without a registered type it warns "assuming text/plain".
mimetypes.add_type("application/vnd.apache.parquet", ".parquet")

# OpenBLAS picks its kernels by CPU at run time, and the kernels of different CPUs round
# differently: the design searches of Fig. 8(b) end at other optima and the fits of Fig. 2(d) and
# 7(c) move pixels (2026-11-26: on an AMD Zen 5 machine, which OpenBLAS 0.3.31 gives its Haswell
# kernels, against the SkylakeX kernels of the machine the figures were last made on). Every job
# uses the Haswell kernels (any x86-64 CPU with AVX2 runs them), so the committed figures do not
# depend on the CPU; a value already set in the environment is kept.
if platform.machine().lower() in ("x86_64", "amd64"):
    os.environ.setdefault("OPENBLAS_CORETYPE", "Haswell")

SCHEMA = Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml"


# ---------------------------------------------------------------------------------------------
# Configuration: fail before any job runs, naming the key, the value and the allowed range.
# The checks are the package's own (restitution_workflow.config_check, plain Python); they also normalise
# the values (whole-number floats of integer keys become integers, numbers that --config hands
# over as text become numbers, defaults are filled in), so the jobs get what was checked.
# ---------------------------------------------------------------------------------------------
def check_config(config, schema_path=SCHEMA):
    """Check ``config`` in place; raise WorkflowError listing every problem."""
    from restitution_workflow.config_check import ConfigError
    from restitution_workflow.config_check import check_config as check

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


# ---------------------------------------------------------------------------------------------
# One console line per job. The profiles quiet the reason (`quiet: [reason]`); then each job's
# message is JOB_MESSAGE (targets: TARGET_MESSAGE) and snakemake prints "Job 12: design_fig8b,
# log logs/design/all/masses.log" instead of the input/output/wildcards block (40 lines with the
# code inputs). The log is where a long job reports its progress (tail -f it). A failing job
# still gets the full block and its log. Any --quiet that leaves the reason out, e.g.
# `snakemake -n all --quiet host`, brings back the full blocks with their reasons.
# ---------------------------------------------------------------------------------------------
def short_listing():
    """True when the reason is quieted (the profiles' default): one line per job."""
    settings = workflow.output_settings
    quiet = settings.quiet if settings is not None and settings.quiet else ()
    return any(str(q.name).lower() == "reason" for q in quiet)


JOB_MESSAGE = "{rule}, log {log}" if short_listing() else None
TARGET_MESSAGE = "target {rule}" if short_listing() else None


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


def paper_values(*keys):
    """The paper's printed values (config/paper_values.yaml, strings as printed) named by ``keys``.

    For captions that Snakemake renders itself (``report(caption="../report/...")``): they see
    only the job's config, params, input and output, so the rule passes the values as params.
    """
    values = yaml.safe_load(
        (Path(workflow.basedir) / "config" / "paper_values.yaml").read_text()
    )
    return {key: str(values[key]) for key in keys}


def beta_label(beta):
    """Path label of a beta value: short ('0', '0.001', '1e-05') yet exact when read back."""
    beta = float(beta)
    short = f"{beta:g}"
    return short if float(short) == beta else repr(beta)


# ---------------------------------------------------------------------------------------------
# Code inputs: a rule's script and every module it can import are inputs of its jobs, so editing
# one reruns exactly the jobs that run it (Snakemake cannot see imports). The modules are found
# statically, never imported (no numba kernel is loaded to read the workflow): every import
# statement of the script, at module level or inside a function, is followed through the local
# helpers in workflow/scripts/ (_common.py, render_caption.py, ...) and the packages in src/
# (restitution, restitution_workflow), and so on through what those import. Importing
# restitution.x runs restitution/__init__.py first, so each package on the way counts with its
# __init__.py and whatever that imports. A rule that runs package code writes `code=script_code("<script>.py")`.
# ---------------------------------------------------------------------------------------------
SCRIPTS_DIR = Path(workflow.basedir) / "workflow" / "scripts"
PACKAGE_DIRS = [
    Path(workflow.basedir) / "src" / name
    for name in ("restitution", "restitution_workflow")
]
# Import statements are found without parsing whole files (ast.parse of the package takes ~0.5 s,
# too long for every snakemake call): strings and comments are matched first, so that an import
# written in a docstring is skipped; each statement found is then parsed on its own by ast.
_IMPORT_SCAN = re.compile(
    r'"{3}(?:\\.|[^\\])*?"{3}'  # triple-quoted strings
    r"|'{3}(?:\\.|[^\\])*?'{3}"
    r'|"(?:\\.|[^"\\\n])*"'  # one-line strings
    r"|'(?:\\.|[^'\\\n])*'"
    r"|#[^\n]*"  # comments
    r"|^[ \t]*(?P<statement>from[ \t]+[\w.]+[ \t]+import[ \t]*(?:\((?:#[^\n]*|[^)#])*\)|[^\n;#]*)"
    r"|import[ \t]+[^\n;#]*)",
    re.MULTILINE | re.DOTALL,
)
# Caches for one reading of the workflow: module name (tuple) -> file, for the package and the
# scripts' local helpers; file -> modules its imports run; script -> its code inputs.
_CODE = {}
_IMPORTS = {}
_SCRIPT_CODE = {}


def _code_index():
    """Module name (tuple of parts) -> file, for the packages in src/ and workflow/scripts."""
    if not _CODE:
        for package_dir in PACKAGE_DIRS:
            for path in package_dir.rglob("*.py"):
                parts = (
                    package_dir.name,
                    *path.relative_to(package_dir).with_suffix("").parts,
                )
                _CODE[parts[:-1] if parts[-1] == "__init__" else parts] = path
        # Snakemake puts the script's folder on sys.path: its modules import as top-level names.
        for path in SCRIPTS_DIR.glob("*.py"):
            _CODE.setdefault((path.stem,), path)
    return _CODE


def _import_nodes(path):
    """The import statements of ``path`` (module level and inside functions) as ast nodes."""
    text = path.read_text(encoding="utf-8")
    try:
        return [
            ast.parse(match["statement"]).body[0]
            for match in _IMPORT_SCAN.finditer(text)
            if match["statement"]
        ]
    except SyntaxError:
        # A statement the scan cut short (a backslash continuation): parse the whole file.
        tree = ast.parse(text, filename=str(path))
        return [
            n for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom))
        ]


def _direct_imports(path, package):
    """Files of the modules that the import statements of ``path`` run (parent packages too).

    ``package``: the package relative imports of ``path`` start from (empty for a script).
    """
    if path in _IMPORTS:
        return _IMPORTS[path]
    index = _code_index()
    names = []
    for node in _import_nodes(path):
        if isinstance(node, ast.Import):
            names += [tuple(alias.name.split(".")) for alias in node.names]
            continue
        if node.level > len(package):
            raise WorkflowError(f"{path}: relative import beyond the top-level package")
        base = package[: len(package) - node.level + 1] if node.level else ()
        target = (*base, *(node.module.split(".") if node.module else ()))
        names.append(target)
        # `from package import name` imports the submodule `name` if there is one.
        names += [(*target, alias.name) for alias in node.names if alias.name != "*"]
    found = set()
    for parts in names:
        # Importing restitution.a.b runs restitution/__init__.py and restitution/a/__init__.py.
        for depth in range(1, len(parts) + 1):
            if parts[:depth] in index:
                found.add(parts[:depth])
    _IMPORTS[path] = found
    return found


def script_code(script):
    """Code inputs of the rules running workflow/scripts/``script``, i.e. it and all it imports.

    Paths relative to the repository root (under runs/<run>/ reached through its links), or
    absolute under `snakemake --directory` (make bench-smoke), where the working directory is
    elsewhere.
    """
    if script not in _SCRIPT_CODE:
        start = SCRIPTS_DIR / script
        if not start.is_file():
            raise WorkflowError(f"script_code: no such script {start}")
        index = _code_index()
        seen, todo = {start}, [(start, ())]
        while todo:
            path, package = todo.pop()
            for name in _direct_imports(path, package):
                found = index[name]
                if found not in seen:
                    seen.add(found)
                    # A package's __init__ imports relative to itself, a module to its parent.
                    is_package = found.name == "__init__.py"
                    todo.append((found, name if is_package else name[:-1]))
        root = Path(workflow.basedir)
        _SCRIPT_CODE[script] = sorted(str(p.relative_to(root)) for p in seen)
    if workflow.overwrite_workdir is not None:
        return [str(Path(workflow.basedir) / p) for p in _SCRIPT_CODE[script]]
    return _SCRIPT_CODE[script]


def solver_settings():
    """The solver part of the config (params of every simulation rule)."""
    return {"method": config["method"], "max_events": config["max_events"]}


def fig2a_grid():
    """The alpha-grid part of config['fig2a'] (not the betas: adding a beta reruns nothing)."""
    keys = ("alpha_min", "alpha_max", "n_alpha", "chunk_size", "refine_steps")
    return {key: config["fig2a"][key] for key in keys}


def fig2a_n_chunks():
    """Chunk k holds grid indices k*chunk_size .. (k+1)*chunk_size (shared boundary point)."""
    from restitution_workflow.config_check import n_chunks

    grid = config["fig2a"]
    return n_chunks(grid["n_alpha"], grid["chunk_size"])


def fig2a_chunk_tables():
    return expand(
        "results/fig2a/beta~{beta}/chunk_{chunk}.parquet",
        beta=[beta_label(b) for b in config["fig2a"]["betas"]],
        chunk=range(fig2a_n_chunks()),
    )


# Fig. 8(b) designs (rules/design.smk): warm starts and the config check of the two seeds.
DESIGNS = config["fig8"]["design"]
if DESIGNS["restart_seed"] == DESIGNS["seed"]:
    raise WorkflowError(
        "Invalid configuration: fig8.design.restart_seed must differ from fig8.design.seed "
        f"(both {DESIGNS['seed']}): the second start of every design must be independent"
    )
#: Families whose optima a family contains at the same N (its warm starts, design_fig8b.py).
CONTAINS = {
    "masses": ["uniform", "tapered_decreasing", "tapered_increasing"],
    "masses_springs": ["masses"],
    "robust": ["masses"],
}


def design_tables(group):
    """The family tables of one group of designs (`all` or `extra`), one per family it lists."""
    return [
        f"results/design/{group}/{f}.parquet" for f, ns in DESIGNS[group].items() if ns
    ]


def design_warm_tables(wildcards):
    """The tables holding the warm starts of one family's designs: the families it contains at
    each of its N, and itself at N - 1 where its own job does not design that N (`all` first
    where both groups design one)."""
    family, group = wildcards.family, wildcards.group
    ns = DESIGNS[group][family]
    wanted = [(f, n) for n in ns for f in CONTAINS.get(family, [])]
    if family in CONTAINS:
        wanted += [(family, n - 1) for n in ns if n - 1 not in ns]
    tables = []
    for f, n in wanted:
        for source in ("all", "extra"):
            if n in DESIGNS[source].get(f, []):
                tables.append(f"results/design/{source}/{f}.parquet")
                break
    return sorted(set(tables))


# Benchmarks (rules/benchmarks.smk).
def ivp_settings():
    """The solve_ivp settings the work-precision diagram states (its baseline). Every family but
    the package's own (exact, adaptive, verlet) is a solve_ivp method (the schema's enum); not
    imported from restitution_workflow.bench.ivp, which would load scipy at every workflow parse.
    """
    keys = ("ivp_rtols", "ivp_atol_over_rtol", "ivp_steps_per_period", "max_events")
    own = ("exact", "adaptive", "verlet")
    methods = [f for f in config["benchmarks"]["families"] if f not in own]
    return {"methods": methods, **{key: config["benchmarks"][key] for key in keys}}
