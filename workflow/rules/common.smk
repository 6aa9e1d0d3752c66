# Shared helpers: configuration checks and the small functions rules use for inputs and params.
# No rules here (snakemake --lint wants rules and functions in separate files).

import difflib
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
# ---------------------------------------------------------------------------------------------
def _allowed(subschema):
    """Plain-words description of what a schema node accepts, e.g. 'a number > 0 and <= 1e+08'."""
    if "enum" in subschema:
        return "one of " + ", ".join(repr(v) for v in subschema["enum"])
    kind = subschema.get("type", "value")
    words = {"number": "a number", "integer": "an integer", "string": "a string"}
    text = words.get(
        kind, f"a {kind}" if isinstance(kind, str) else f"one of types {kind}"
    )
    bounds = []
    for key, op in (
        ("minimum", ">="),
        ("exclusiveMinimum", ">"),
        ("maximum", "<="),
        ("exclusiveMaximum", "<"),
    ):
        if key in subschema:
            bounds.append(f"{op} {subschema[key]:g}")
    if bounds:
        text += " " + " and ".join(bounds)
    if kind == "array":
        items = subschema.get("items", {})
        text += f" of {_allowed(items)}" if items else ""
        if "minItems" in subschema:
            text += f", at least {subschema['minItems']} item(s)"
        if subschema.get("uniqueItems"):
            text += ", no duplicates"
    return text


def _key(path):
    text = ""
    for part in path:
        text += (
            f"[{part}]"
            if isinstance(part, int)
            else (f".{part}" if text else str(part))
        )
    return text or "<top level>"


def _describe(error):
    """One line per jsonschema error: key = value: must be <allowed range>."""
    key = _key(error.absolute_path)
    if error.validator == "additionalProperties":
        known = list(error.schema.get("properties", {}))
        lines = []
        for name in sorted(set(error.instance) - set(known)):
            where = f"{key}.{name}" if error.absolute_path else name
            close = difflib.get_close_matches(name, known, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            lines.append(
                f"{where} = {error.instance[name]!r}: unknown key{hint}; "
                f"allowed keys here: {', '.join(known)}"
            )
        return lines
    if error.validator == "required":
        return [f"{key}: {error.message}"]
    return [
        f"{key} = {error.instance!r}: must be {_allowed(error.schema)} ({error.message})"
    ]


def check_config(config, schema_path=SCHEMA):
    """Validate ``config`` against the schema; raise WorkflowError listing every problem."""
    import jsonschema

    schema = yaml.safe_load(Path(schema_path).read_text())
    validator = jsonschema.Draft202012Validator(schema)
    problems = []
    for error in sorted(
        validator.iter_errors(config), key=lambda e: list(map(str, e.path))
    ):
        problems.extend(_describe(error))
    fig2a = config.get("fig2a", {})
    lo, hi = fig2a.get("alpha_min"), fig2a.get("alpha_max")
    if isinstance(lo, (int, float)) and isinstance(hi, (int, float)) and not lo < hi:
        problems.append(
            f"fig2a.alpha_max = {hi!r}: must be greater than fig2a.alpha_min = {lo!r}"
        )
    betas = fig2a.get("betas", [])
    numeric = [
        b for b in betas if isinstance(b, (int, float)) and not isinstance(b, bool)
    ]
    method = config.get("method", "auto")
    if method == "impulsive" and any(b > 0 for b in numeric):
        problems.append(
            f"method = 'impulsive' needs a rigid wall, but fig2a.betas = {betas!r} has beta > 0: "
            "use 'auto' (or 'piecewise' with every beta > 0)"
        )
    if method == "piecewise" and any(b == 0 for b in numeric):
        problems.append(
            f"method = 'piecewise' needs beta > 0, but fig2a.betas = {betas!r} contains 0: "
            "use 'auto' (or 'impulsive' with betas [0])"
        )
    fig4 = config.get("fig4", {})
    for name, panel in sorted(fig4.items()):
        if name == "sweep" or not isinstance(panel, dict):
            continue
        etas = panel.get("etas", [panel.get("eta")])
        drs = panel.get("drs", [panel.get("dr")])
        for eta in etas:
            for dr in drs:
                if isinstance(eta, (int, float)) and isinstance(dr, (int, float)):
                    if dr < (1 - eta) / 2:
                        problems.append(
                            f"fig4.{name}: DR = {dr!r} with eta = {eta!r}: DR must be >= "
                            f"(1 - eta)/2 = {(1 - eta) / 2:g} (the residual dent would be negative)"
                        )
    for key in ("sweep",):
        grid = fig4.get(key, {})
        lo, hi = grid.get("alpha_min"), grid.get("alpha_max")
        if (
            isinstance(lo, (int, float))
            and isinstance(hi, (int, float))
            and not lo < hi
        ):
            problems.append(
                f"fig4.{key}.alpha_max = {hi!r}: must exceed alpha_min = {lo!r}"
            )
    fig5 = config.get("fig5", {})
    spring, grid5 = fig5.get("spring", {}), fig5.get("b", {})
    try:
        ratio = spring["ks_over_k1"] / spring["beta"]
        cap = math.tan(math.radians(spring["theta0_deg"])) ** 2
        if not ratio < cap:
            problems.append(
                f"fig5.spring: ks_over_k1/beta = {ratio:g} must be < tan(theta0)**2 = {cap:g} "
                "(the scissor's rest slope must stay below the cap k2)"
            )
    except (KeyError, TypeError, ZeroDivisionError):
        pass
    lo, hi = grid5.get("alpha_min"), grid5.get("alpha_max")
    if isinstance(lo, (int, float)) and isinstance(hi, (int, float)) and not lo < hi:
        problems.append(f"fig5.b.alpha_max = {hi!r}: must exceed alpha_min = {lo!r}")
    fig7 = config.get("fig7", {})
    lo, hi = fig7.get("alpha_min"), fig7.get("alpha_max")
    if isinstance(lo, (int, float)) and isinstance(hi, (int, float)) and not lo < hi:
        problems.append(f"fig7.alpha_max = {hi!r}: must exceed fig7.alpha_min = {lo!r}")
    for where, lo_key, hi_key in (
        ("fig3.sweep", "beta_min", "beta_max"),
        ("fig6.sweep", "x_min", "x_max"),
    ):
        section = config
        for part in where.split("."):
            section = section.get(part, {}) if isinstance(section, dict) else {}
        lo, hi = section.get(lo_key), section.get(hi_key)
        if (
            isinstance(lo, (int, float))
            and isinstance(hi, (int, float))
            and not lo < hi
        ):
            problems.append(
                f"{where}.{hi_key} = {hi!r}: must exceed {where}.{lo_key} = {lo!r}"
            )
    bracket = config.get("fig3", {}).get("compression", {}).get("marginal_bracket")
    if isinstance(bracket, list) and len(bracket) == 2 and not bracket[0] < bracket[1]:
        problems.append(
            f"fig3.compression.marginal_bracket = {bracket!r}: must be [low, high] with low < high"
        )
    if problems:
        raise WorkflowError(
            "Invalid configuration (config/config.yaml plus any --configfile/--config):\n  "
            + "\n  ".join(problems)
        )


check_config(config)
# snakemake's own validation fills in the schema's defaults for keys the config leaves out.
validate(config, schema="../schemas/config.schema.yaml")


wildcard_constraints:
    beta=r"\d+(\.\d+)?(e[+-]?\d+)?",
    chunk=r"\d+",


# ---------------------------------------------------------------------------------------------
# Helpers for rules
# ---------------------------------------------------------------------------------------------
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
    grid = config["fig2a"]
    return math.ceil((grid["n_alpha"] - 1) / grid["chunk_size"])


def fig2a_chunk_tables():
    return expand(
        "results/fig2a/beta~{beta}/chunk_{chunk}.parquet",
        beta=[beta_label(b) for b in config["fig2a"]["betas"]],
        chunk=range(fig2a_n_chunks()),
    )
