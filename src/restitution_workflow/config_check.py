"""Range checks of the workflow configuration, in plain Python (no jsonschema needed).

The workflow describes its configuration by a schema (``workflow/schemas/config.schema.yaml``:
types, ranges, defaults, one description per key). :func:`check_config` reads that schema as a
plain mapping and checks a configuration against it, then adds the checks a schema cannot
express (one key against another, the package's scene ranges, the number of jobs a sweep makes).
Every problem is reported at once, one line each, naming the key, the value and what is allowed::

    fig2a.alpha_min = -1.0: must be a number > 0 and <= 1e+08

Values are normalised on the way, so that what passes the check is what the jobs receive:

- an integer key given a whole-number float (``max_events: 5.0e2``) gets the integer 500; a
  fractional value (2.5) is rejected;
- a number given as text gets the number: ``--config`` hands nested values over as text
  (``--config "fig7={xis: [0.1, 0.5]}"`` arrives as ``{'xis': ['0.1', '0.5']}``) and YAML reads
  ``5e2`` (no dot) as text;
- keys left out get the schema's default.

Only the schema keywords the workflow uses are understood: ``type`` (object, array, number,
integer, string, boolean), ``properties``, ``additionalProperties: false``, ``required``,
``default``, ``enum``, ``pattern``, ``minimum``, ``maximum``, ``exclusiveMinimum``,
``exclusiveMaximum``, ``items``, ``minItems``, ``maxItems``, ``uniqueItems`` (and the
annotations ``title``, ``examples``, ``$comment``). Any other keyword raises ``ValueError`` (a
schema edit must not silently turn a check off).
"""

from __future__ import annotations

import copy
import difflib
import math
import re
from collections.abc import Callable, Mapping
from functools import partial

from restitution.model.chain import Chain, SceneError, check

__all__ = ["MAX_JOBS", "ConfigError", "allowed_text", "check_config", "check_value"]

# Most jobs one sweep (or a study) may make: a DAG of this size builds in seconds; a larger one
# (e.g. n_alpha = 1e7 with chunk_size = 2) would make even a dry run hang.
MAX_JOBS = 2000

_KNOWN = {
    "$schema",
    "$comment",
    "title",
    "examples",
    "description",
    "type",
    "properties",
    "additionalProperties",
    "required",
    "default",
    "enum",
    "pattern",
    "minimum",
    "maximum",
    "exclusiveMinimum",
    "exclusiveMaximum",
    "items",
    "minItems",
    "maxItems",
    "uniqueItems",
}
_BOUNDS = (
    ("minimum", ">="),
    ("exclusiveMinimum", ">"),
    ("maximum", "<="),
    ("exclusiveMaximum", "<"),
)


class ConfigError(ValueError):
    """The configuration has problems; ``problems`` lists them, one line each."""

    def __init__(self, problems: list[str]):
        self.problems = list(problems)
        super().__init__("\n".join(self.problems))


def key_text(path) -> str:
    """Dotted key of a position in the configuration, e.g. ``fig2a.betas[2]``."""
    text = ""
    for part in path:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else str(part)
    return text or "<top level>"


def allowed_text(schema: Mapping) -> str:
    """Plain words for what a schema node accepts, e.g. ``'a number > 0 and <= 1e+08'``."""
    if "enum" in schema:
        return "one of " + ", ".join(repr(v) for v in schema["enum"])
    kind = schema.get("type", "value")
    words = {
        "number": "a number",
        "integer": "an integer",
        "string": "a text",
        "boolean": "true or false",
        "object": "a mapping of keys to values",
        "array": "a list",
    }
    text = words.get(kind, f"a {kind}")
    bounds = [f"{op} {schema[key]:g}" for key, op in _BOUNDS if key in schema]
    if bounds:
        text += " " + " and ".join(bounds)
    if "pattern" in schema:
        text += f" matching {schema['pattern']}"
    if kind == "array":
        if schema.get("items"):
            text += f" of {allowed_text(schema['items'])}"
        sizes = []
        if "minItems" in schema:
            sizes.append(f"at least {schema['minItems']}")
        if "maxItems" in schema:
            sizes.append(f"at most {schema['maxItems']}")
        if sizes:
            text += f", {' and '.join(sizes)} item(s)"
        if schema.get("uniqueItems"):
            text += ", no duplicates"
    return text


def _same_key(value):
    """What decides whether two list items are the same: a number's value, else its repr."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return ("number", float(value))  # (hash(-0.0) == hash(0.0) and they are equal)
    return ("other", repr(value))


def _number(value, integer: bool):
    """``value`` as the number a user meant, or None. Text is parsed (``--config`` gives text)."""
    if isinstance(value, bool):
        return None
    if isinstance(value, str):
        text = value.strip()
        try:
            value = int(text)
        except ValueError:
            try:
                value = float(text)
            except ValueError:
                return None
    if isinstance(value, int):
        return value
    if isinstance(value, float):
        if not integer:
            return value
        # A whole-number float is the integer it names (5e2 -> 500); 2.5 is not an integer.
        return int(value) if math.isfinite(value) and value.is_integer() else None
    return None


def _in_bounds(x, schema) -> bool:
    if isinstance(x, float) and math.isnan(x):
        return False
    return not (
        ("minimum" in schema and not x >= schema["minimum"])
        or ("exclusiveMinimum" in schema and not x > schema["exclusiveMinimum"])
        or ("maximum" in schema and not x <= schema["maximum"])
        or ("exclusiveMaximum" in schema and not x < schema["exclusiveMaximum"])
    )


def check_value(value, schema: Mapping, path: tuple, problems: list[str]):
    """``value`` checked against ``schema`` and normalised; each problem appended to ``problems``.

    Returns the normalised value (defaults filled in, numbers parsed); after a problem the
    value is returned as given.
    """
    unknown = set(schema) - _KNOWN
    if unknown:
        raise ValueError(f"schema of {key_text(path)}: unsupported keyword(s) {sorted(unknown)}")
    key = key_text(path)
    kind = schema.get("type")

    def bad(what=None):
        problems.append(f"{key} = {value!r}: must be {what or allowed_text(schema)}")
        return value

    if kind == "object":
        if not isinstance(value, Mapping):
            return bad(
                f"a mapping of keys to values (a section such as `{key}:` followed by indented "
                f"`key: value` lines), not a {type(value).__name__}"
            )
        known = schema.get("properties", {})
        result = {}
        for name, item in value.items():
            if name in known:
                result[name] = check_value(item, known[name], (*path, name), problems)
            elif schema.get("additionalProperties", True) is False:
                close = difflib.get_close_matches(str(name), list(known), n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                where = key_text((*path, name))
                problems.append(
                    f"{where} = {item!r}: unknown key{hint}; allowed keys here: {', '.join(known)}"
                )
            else:
                result[name] = item
        for name in schema.get("required", []):
            if name not in value:
                problems.append(f"{key_text((*path, name))}: required key missing")
        for name, sub in known.items():
            if name not in result and "default" in sub:
                # Defaults are checked too: an object's default {} gets its own keys' defaults.
                result[name] = check_value(
                    copy.deepcopy(sub["default"]), sub, (*path, name), problems
                )
        return result
    if kind == "array":
        if not isinstance(value, list):
            return bad()
        items = [
            check_value(item, schema.get("items", {}), (*path, i), problems)
            for i, item in enumerate(value)
        ]
        if len(items) < schema.get("minItems", 0):
            return bad()
        if "maxItems" in schema and len(items) > schema["maxItems"]:
            problems.append(
                f"{key} has {len(items)} items: must have at most {schema['maxItems']} "
                f"(the bound of the schema keeps the number of jobs and curves finite)"
            )
            return value
        if schema.get("uniqueItems"):
            # numbers compared as numbers: 0, 0.0 and -0.0 are one value (their reprs differ)
            seen = [_same_key(v) for v in items]
            if len(set(seen)) < len(seen):
                return bad()
        return items
    if kind in ("number", "integer"):
        x = _number(value, kind == "integer")
        if x is None or not _in_bounds(x, schema):
            return bad()
        return x
    if kind == "boolean":
        words = {"true": True, "false": False}
        x = words.get(value.strip().lower()) if isinstance(value, str) else value
        return x if isinstance(x, bool) else bad()
    if kind == "string":
        if not isinstance(value, str):
            return bad()
        if "enum" in schema and value not in schema["enum"]:
            return bad()
        if "pattern" in schema and not re.search(schema["pattern"], value):
            return bad()
        return value
    if "enum" in schema and value not in schema["enum"]:
        return bad()
    return value


# ---------------------------------------------------------------------------------------------
# Checks the schema cannot express.
# ---------------------------------------------------------------------------------------------
def _get(config, path):
    node = config
    for part in path:
        if not isinstance(node, Mapping) or part not in node:
            return None
        node = node[part]
    return node


def _real(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


# Scene parameters of the configuration, checked with the package's own scene checks so that
# the workflow never admits a value the solver refuses.
SCENE_KEYS: dict[tuple, Callable] = {
    ("fig2a", "alpha_min"): partial(check, "alpha"),
    ("fig2a", "alpha_max"): partial(check, "alpha"),
    ("fig2a", "betas"): partial(check, "beta"),
    ("fig3", "sweep", "alphas"): partial(check, "alpha"),
    ("fig3", "sweep", "beta_min"): partial(check, "beta"),
    ("fig3", "sweep", "beta_max"): partial(check, "beta"),
    ("fig3", "compression", "alpha"): partial(check, "alpha"),
    ("fig3", "compression", "betas"): partial(check, "beta"),
    ("fig4", "sweep", "alpha_min"): partial(check, "alpha"),
    ("fig4", "sweep", "alpha_max"): partial(check, "alpha"),
    ("fig5", "b", "alpha_min"): partial(check, "alpha"),
    ("fig5", "b", "alpha_max"): partial(check, "alpha"),
    ("fig6", "n_masses"): partial(check, "n_masses"),
    ("fig6", "sweep", "beta"): partial(check, "beta"),
    ("fig7", "beta"): partial(check, "beta"),
    ("fig7", "xis"): partial(check, "xi"),
    ("fig7", "alpha_min"): partial(check, "alpha"),
    ("fig7", "alpha_max"): partial(check, "alpha"),
    ("fig7", "traces", "xis"): partial(check, "xi"),
    ("fig7", "traces", "alphas"): partial(check, "alpha"),
    ("fig9", "v0_min"): partial(check, "v0"),
    ("fig9", "v0_max"): partial(check, "v0"),
    ("fig9", "alphas"): partial(check, "alpha"),
    ("fig9", "chain_alpha"): partial(check, "alpha"),
    ("fig9", "chain_n"): partial(check, "n_masses"),
}

# Ranges that must be increasing: (section, low key, high key).
ORDERED_RANGES = (
    (("fig2a",), "alpha_min", "alpha_max"),
    (("approx",), "alpha_min", "alpha_max"),
    (("approx",), "finite_alpha_min", "finite_alpha_max"),
    (("approx",), "plot_alpha_min", "plot_alpha_max"),
    (("fig3", "sweep"), "beta_min", "beta_max"),
    (("fig4", "sweep"), "alpha_min", "alpha_max"),
    (("fig5", "a"), "x_min", "x_max"),
    (("fig5", "b"), "alpha_min", "alpha_max"),
    (("fig6", "sweep"), "x_min", "x_max"),
    (("fig7",), "alpha_min", "alpha_max"),
    (("fig9",), "v0_min", "v0_max"),
)

# Chunked sweeps: (section, grid points key, chunk key, list of curves key); jobs = curves x chunks.
CHUNKED_SWEEPS = (
    (("fig2a",), "n_alpha", "chunk_size", "betas"),
    (("fig7",), "n_alpha", "chunk_size", "xis"),
)


def n_chunks(n_points: int, chunk_size: int) -> int:
    """Chunks of a grid of ``n_points`` (neighbouring chunks share their boundary point)."""
    return math.ceil((n_points - 1) / chunk_size)


def _scene_checks(config, problems):
    for path, check_one in SCENE_KEYS.items():
        value = _get(config, path)
        for item in value if isinstance(value, list) else [value]:
            if item is None:
                continue
            try:
                check_one(item)
            except SceneError as error:
                problems.append(f"{key_text(path)} = {value!r}: {error}")
                break


def _range_checks(config, problems):
    for where, lo_key, hi_key in ORDERED_RANGES:
        section = _get(config, where)
        if not isinstance(section, Mapping):
            continue
        lo, hi = section.get(lo_key), section.get(hi_key)
        if _real(lo) and _real(hi) and not lo < hi:
            name = key_text(where)
            problems.append(
                f"{name}.{hi_key} = {hi!r}: must be greater than {name}.{lo_key} = {lo!r}"
            )


def _job_checks(config, problems):
    for where, n_key, size_key, curves_key in CHUNKED_SWEEPS:
        section = _get(config, where)
        if not isinstance(section, Mapping):
            continue
        n, size, curves = section.get(n_key), section.get(size_key), section.get(curves_key)
        if isinstance(n, int) and isinstance(size, int) and isinstance(curves, list) and size > 0:
            jobs = n_chunks(n, size) * len(curves)
            if jobs > MAX_JOBS:
                name = key_text(where)
                problems.append(
                    f"{name}.{size_key} = {size!r}: makes {jobs} simulate jobs "
                    f"({len(curves)} {curves_key} x ceil(({n_key} - 1)/{size_key}) chunks), "
                    f"more than the bound of {MAX_JOBS}: raise {name}.{size_key} or lower "
                    f"{name}.{n_key}"
                )


def _method_checks(config, problems):
    """A forced method must fit every beta of fig2a: asked of the solver table itself."""
    betas = _get(config, ("fig2a", "betas"))
    numeric = [b for b in betas if _real(b) is not None] if isinstance(betas, list) else []
    method = config.get("method", "auto")
    if method == "auto" or not isinstance(method, str):
        return
    from restitution.solvers.methods import METHODS  # (numpy, pandas: only when one is forced)

    if method not in METHODS:
        return  # (the schema names the allowed methods)
    for b in numeric:
        reason = METHODS[method].applies(Chain.paper(1.0, b))
        if reason is not None:
            problems.append(
                f"method = {method!r} does not fit fig2a.betas = {betas!r} (beta = {b!r}): {reason}"
            )
            return


def _law_checks(config, problems):
    fig4 = config.get("fig4")
    for name, panel in sorted(fig4.items()) if isinstance(fig4, Mapping) else []:
        if name == "sweep" or not isinstance(panel, Mapping):
            continue
        etas = panel.get("etas", [panel.get("eta")])
        drs = panel.get("drs", [panel.get("dr")])
        for eta in etas if isinstance(etas, list) else []:
            for dr in drs if isinstance(drs, list) else []:
                if _real(eta) and _real(dr) and dr < (1 - eta) / 2:
                    problems.append(
                        f"fig4.{name}: DR = {dr!r} with eta = {eta!r}: DR must be >= "
                        f"(1 - eta)/2 = {(1 - eta) / 2:g} (the residual dent would be negative)"
                    )
    spring = _get(config, ("fig5", "spring"))
    if isinstance(spring, Mapping):
        ks, beta, theta0 = (spring.get(k) for k in ("ks_over_k1", "beta", "theta0_deg"))
        if _real(ks) and _real(beta) and _real(theta0) and beta > 0:
            ratio, cap = ks / beta, math.tan(math.radians(theta0)) ** 2
            if not ratio < cap:
                problems.append(
                    f"fig5.spring: ks_over_k1/beta = {ratio:g} must be < tan(theta0)**2 = {cap:g} "
                    "(the scissor's rest slope must stay below the cap k2)"
                )
    bracket = _get(config, ("fig3", "compression", "marginal_bracket"))
    if isinstance(bracket, list) and len(bracket) == 2 and all(map(_real, bracket)):
        if not bracket[0] < bracket[1]:
            problems.append(
                f"fig3.compression.marginal_bracket = {bracket!r}: must be [low, high] with "
                "low < high"
            )


def fig9_chains(fig9: Mapping) -> list[tuple[str, Chain]]:
    """(label, Chain) of every curve of Fig. 9, at a rigid wall: the two-mass chains of
    ``alphas`` and the uniform chains of ``chain_n`` (``Chain.paper``, so omega = 1)."""
    chains = [(f"alpha = {a:g}", Chain.paper(a)) for a in fig9["alphas"]]
    chains += [(f"N = {n}", Chain.paper(fig9["chain_alpha"], n_masses=n)) for n in fig9["chain_n"]]
    return chains


def _hertz_checks(config, problems):
    """Every curve of Fig. 9 must be a scene the solvers take at both ends of its V0 grid (the
    Hertz slope against the first spring, the frequency spread): asked of ``Chain`` itself."""
    fig9 = config.get("fig9")
    if not isinstance(fig9, Mapping):
        return
    for label, chain in fig9_chains(fig9):
        for key in ("v0_min", "v0_max"):
            try:
                Chain(chain.masses, chain.springs, v0=fig9[key],
                      contact={"law": "hertz", "k": fig9["k_hertz"]})  # fmt: skip
            except SceneError as error:
                problems.append(
                    f"fig9.k_hertz = {fig9['k_hertz']!r} with fig9.{key} = {fig9[key]!r} "
                    f"({label}): {error}"
                )
                return


def check_config(config: Mapping, schema: Mapping) -> dict:
    """Check ``config`` against ``schema`` and the cross-key rules; return it normalised.

    Parameters
    ----------
    config : mapping
        The merged configuration (config file, ``--configfile`` and ``--config``).
    schema : mapping
        The workflow's configuration schema, loaded from YAML.

    Returns
    -------
    dict
        A normalised copy: defaults filled in, numbers given as text parsed, whole-number
        floats of integer keys turned into integers.

    Raises
    ------
    ConfigError
        Listing every problem, one line each (key, value, allowed range).

    Examples
    --------
    >>> schema = {"type": "object", "additionalProperties": False, "properties": {
    ...     "max_events": {"type": "integer", "minimum": 1, "maximum": 10**8, "default": 10}}}
    >>> check_config({"max_events": 5e2}, schema)
    {'max_events': 500}
    >>> try:
    ...     check_config({"max_event": 5}, schema)
    ... except ConfigError as error:
    ...     print(error.problems[0][:50])
    max_event = 5: unknown key (did you mean 'max_even
    """
    problems: list[str] = []
    result = check_value(dict(config), schema, (), problems)
    _range_checks(result, problems)
    _method_checks(result, problems)
    _law_checks(result, problems)
    if not problems:
        # Once every value has its type and range (else the same value would be named twice).
        _scene_checks(result, problems)
        _job_checks(result, problems)
    if not problems:
        _hertz_checks(result, problems)
    if problems:
        raise ConfigError(problems)
    return result
