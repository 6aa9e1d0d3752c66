"""A user's own parameter study, defined in a YAML file (docs/study.md): parse, check, solve.

A study names a scene (the paper's ``alpha, beta, xi, n_masses`` or a general chain's
``masses, springs, dashpots, k_contact``), one or two axes (the first is the x axis of the
plots; the second gives one curve per value) and the quantities to plot::

    name: heavy_rear
    scene: {beta: 0.01}
    axes:
      - {param: alpha, logspace: {start: 0.1, stop: 100, num: 200}}
      - {param: xi, values: [0.0, 0.3, 1.0]}
    outputs: [cor, n_collisions]

:func:`check_study` checks a parsed mapping against :data:`STUDY_SCHEMA` with the same plain
Python checks as the workflow configuration (``restitution_workflow.config_check``), then checks
every
scene value the axes produce with the package's scene checks, before any work. :func:`solve_curve`
solves one curve (or one chunk of it) and refines it: between grid neighbours whose contact count
differs the bracket is bisected (the COR cusps), and around every interior grid minimum of the
COR with the same count on both sides the minimum is narrowed by a pattern search.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd

from restitution.analysis.sweeps import interior_minima
from restitution.model.chain import SceneError, check
from restitution_workflow.config_check import MAX_JOBS, ConfigError, check_value, n_chunks

__all__ = [
    "OUTPUTS",
    "STUDY_SCHEMA",
    "Study",
    "StudyError",
    "check_study",
    "front_page",
    "load_study",
    "solve_curve",
]

# Result columns a study can plot, with their axis labels.
OUTPUTS = {
    "cor": "coefficient of restitution $e$",
    "n_collisions": "number of contacts",
    "omega_t_col": r"collision time $\omega t_\mathrm{col}$",
    "e_translational": "translational energy fraction",
    "e_vibrational": "vibrational energy fraction",
    "e_dissipated": "dissipated energy fraction",
}
PAPER_PARAMS = {
    "alpha": partial(check, "alpha"),
    "beta": partial(check, "beta"),
    "xi": partial(check, "xi"),
}
CHAIN_LISTS = ("masses", "springs", "dashpots")
PARAM = re.compile(r"^(alpha|beta|xi|n_masses|k_contact|(masses|springs|dashpots)\[(\d+)\])$")
MAX_POINTS = 100_000  # grid points of one axis
# Minima of one curve closer than this fraction of the first axis' span (log span for a log axis)
# are one minimum in minima.csv (the deepest kept): far below the finest grid spacing,
# 1/(MAX_POINTS - 1) of the span, and far above the ~1e-8 relative round-off width of a smooth
# minimum, inside which the COR's round-off makes several local minima of the same depth.
MINIMA_MERGE = 1e-6
_NUMBER = {"type": "number", "minimum": -1e300, "maximum": math.inf}  # ranges: scene checks
_SPACE = {
    "type": "object",
    "additionalProperties": False,
    "required": ["start", "stop", "num"],
    "properties": {
        "start": _NUMBER,
        "stop": _NUMBER,
        "num": {"type": "integer", "minimum": 2, "maximum": MAX_POINTS},
    },
}
_LIST = {"type": "array", "minItems": 2, "maxItems": 512, "items": _NUMBER}
# Axis text (one line; matplotlib mathtext between $...$ is checked when the study is read).
_LABEL = {
    "type": "string",
    "pattern": r"^[^\n\r]{1,80}$",
    "description": "the axis text of the plots and the report (one line, 1-80 characters; "
    "$...$ is matplotlib mathtext); default: the parameter's name, e.g. "
    "'mass ratio $\\alpha = m_2/m_1$' or 'mass $m_3$ (masses[2])'",
}
_UNIT = {
    "type": "string",
    "pattern": r"^[^\n\r]{0,40}$",
    "default": "",
    "description": "the unit of the axis values, shown as 'label [unit]' and after each curve's "
    "value (0-40 characters); only for a general chain's own quantities (masses[i], springs[i], "
    "dashpots[i], k_contact): the paper's parameters are ratios; default: none",
}

# The schema of a study file (workflow/schemas/study.schema.yaml is the same, for reading).
STUDY_SCHEMA = {
    "type": "object",
    "additionalProperties": False,
    "required": ["name", "axes"],
    "properties": {
        "name": {"type": "string", "pattern": r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$"},
        "description": {"type": "string", "default": ""},
        "units": {
            "type": "string",
            "pattern": r"^[^\n\r]{0,120}$",
            "default": "",
            "description": "the units of a general chain's values in words, e.g. 'SI: kg, N/m, "
            "N s/m; V0 = 1 m/s' (one line, at most 120 characters), shown on the report's front "
            "page; the paper's scene is non-dimensional and takes none; default: not stated",
        },
        "scene": {
            "type": "object",
            "additionalProperties": False,
            "default": {},
            "properties": {
                "alpha": _NUMBER,
                "beta": _NUMBER,
                "xi": _NUMBER,
                "n_masses": {"type": "integer", "minimum": 2, "maximum": 512},
                "masses": _LIST,
                "springs": {**_LIST, "minItems": 1},
                "dashpots": {**_LIST, "minItems": 1},
                "k_contact": {"type": "number", "exclusiveMinimum": 0, "maximum": math.inf},
            },
        },
        "axes": {
            "type": "array",
            "minItems": 1,
            "maxItems": 2,
            "items": {
                "type": "object",
                "additionalProperties": False,
                "required": ["param"],
                "properties": {
                    "param": {"type": "string", "pattern": PARAM.pattern},
                    "values": {
                        "type": "array",
                        "minItems": 1,
                        "maxItems": MAX_POINTS,
                        "uniqueItems": True,
                        "items": _NUMBER,
                    },
                    "linspace": _SPACE,
                    "logspace": _SPACE,
                    "label": _LABEL,
                    "unit": _UNIT,
                },
            },
        },
        "outputs": {
            "type": "array",
            "minItems": 1,
            "maxItems": len(OUTPUTS),
            "uniqueItems": True,
            "items": {"type": "string", "enum": list(OUTPUTS)},
            "default": ["cor", "n_collisions"],
        },
        "refine_steps": {"type": "integer", "minimum": 0, "maximum": 60, "default": 30},
        "chunk_size": {"type": "integer", "minimum": 2, "maximum": 1_000_000, "default": 500},
        "method": {"type": "string", "enum": ["auto", "impulsive", "piecewise"], "default": "auto"},
        "max_events": {"type": "integer", "minimum": 1, "maximum": 100_000_000, "default": 100000},
    },
}


class StudyError(ValueError):
    """The study file has problems; ``problems`` lists them, one line each."""

    def __init__(self, problems: list[str], source: str = "study"):
        self.problems = list(problems)
        super().__init__(f"Invalid {source}:\n  " + "\n  ".join(self.problems))


@dataclass(frozen=True)
class Axis:
    """One axis: the parameter it sets, its values, and whether it is drawn (and refined) on a
    log scale (``logspace``, or ``values`` all positive and spanning more than a decade)."""

    param: str
    values: np.ndarray
    log: bool
    label: str = ""  # the axis text; "" = default_label(param)
    unit: str = ""

    @property
    def refinable(self) -> bool:
        return self.param != "n_masses"

    @property
    def title(self) -> str:
        """Axis text of the plots: the label, with ``[unit]`` when the axis has one."""
        text = self.label or default_label(self.param)
        return f"{text} [{self.unit}]" if self.unit else text

    def curve_text(self, value: float) -> str:
        """Legend text of one value of this axis, e.g. ``$\\xi = 0.3$`` or ``rear mass = 2 kg``."""
        if self.param == "k_contact" and math.isinf(value):
            return "rigid wall"
        if not self.label and self.param in _SYMBOLS:
            return f"${_SYMBOLS[self.param]} = {value:g}$"
        return f"{self.label or self.param} = {value:g}" + (f" {self.unit}" if self.unit else "")


# Default axis texts (matplotlib mathtext); legends use the paper's symbols.
_SYMBOLS = {"alpha": r"\alpha", "beta": r"\beta", "xi": r"\xi", "n_masses": "N"}
_DEFAULT_LABELS = {
    "alpha": r"mass ratio $\alpha = m_2/m_1$",
    "beta": r"stiffness ratio $\beta = k_2/k_1$",
    "xi": r"damping ratio $\xi$",
    "n_masses": "number of masses $N$",
    "k_contact": "contact stiffness k_contact",
}
_ELEMENT_LABELS = {
    "masses": "mass $m_{{{n}}}$ (masses[{i}])",
    "springs": "spring stiffness springs[{i}] ($m_{{{n}}}$-$m_{{{m}}}$)",
    "dashpots": "dashpot coefficient dashpots[{i}] ($m_{{{n}}}$-$m_{{{m}}}$)",
}


def default_label(param: str) -> str:
    """The axis text of a parameter when the study gives no ``label``.

    >>> default_label("masses[2]")
    'mass $m_{3}$ (masses[2])'
    """
    match = PARAM.match(param)
    if match and match.group(2):
        i = int(match.group(3))
        return _ELEMENT_LABELS[match.group(2)].format(i=i, n=i + 1, m=i + 2)
    return _DEFAULT_LABELS.get(param, param)


@dataclass(frozen=True)
class Study:
    """A checked study (see :func:`check_study`)."""

    name: str
    description: str
    scene: dict
    axes: tuple[Axis, ...]
    outputs: tuple[str, ...]
    refine_steps: int
    chunk_size: int
    method: str
    max_events: int
    units: str = ""
    raw: dict = field(repr=False, default_factory=dict)

    @property
    def general(self) -> bool:
        """True for a general chain (masses/springs/...), False for the paper's scene."""
        return _is_general(self.scene, [a.param for a in self.axes])

    @property
    def curves(self) -> np.ndarray:
        """Values of the second axis (one curve each); ``[nan]`` for a one-axis study."""
        return self.axes[1].values if len(self.axes) > 1 else np.array([math.nan])

    @property
    def n_chunks(self) -> int:
        return n_chunks(len(self.axes[0].values), self.chunk_size)

    def chunk_values(self, index: int) -> np.ndarray:
        """First-axis values of chunk ``index`` (neighbouring chunks share their boundary)."""
        values = self.axes[0].values
        start = index * self.chunk_size
        if not 0 <= start < max(len(values) - 1, 1):
            raise ValueError(f"chunk {index} is outside the first axis of {len(values)} points")
        return values[start : min(start + self.chunk_size, len(values) - 1) + 1]


# Bounds of a study file, so that reading it costs at most a fraction of a second: its size
# (100,000 axis values fit in ~2 MB), the aliases it may use (a study needs none; a
# 'billion laughs' file of nested aliases expands 427 bytes into 10**9 values) and the number of
# values it expands to, aliases followed (checked on the node graph before anything is built).
MAX_STUDY_BYTES = 4 * 2**20
MAX_ALIASES = 100
MAX_NODES = 1_000_000


def load_study(path) -> Study:
    """Read and check a study file (YAML). Needs PyYAML (the workflow's dependencies).

    The file is read within bounds (``MAX_STUDY_BYTES``, ``MAX_ALIASES``, ``MAX_NODES``): a
    larger file or one whose aliases expand it beyond them is refused before it is built.
    """
    path = Path(path)
    source = f"study file {path}"
    try:
        size = path.stat().st_size
        if size > MAX_STUDY_BYTES:
            raise StudyError(
                [f"it has {size:,} bytes; a study file may have at most {MAX_STUDY_BYTES:,}"],
                source,
            )
        text = path.read_text()
    except OSError as error:
        raise StudyError([f"cannot read it: {error.strerror}"], source) from None
    except UnicodeDecodeError as error:
        raise StudyError([f"not UTF-8 text ({error.reason})"], source) from None
    return check_study(_bounded_yaml(text, source), source)


def _bounded_yaml(text: str, source: str):
    """``yaml.safe_load(text)`` within MAX_ALIASES aliases and MAX_NODES expanded nodes."""
    import yaml  # only here: the core package does not depend on PyYAML

    class Loader(yaml.SafeLoader):
        aliases = 0

        def construct_mapping(self, node, deep=False):
            # a key given twice would silently keep its last value (merge keys '<<' excepted:
            # their keys are meant to be overridden)
            seen: dict = {}
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = self.construct_object(key_node, deep=True)
                line = key_node.start_mark.line + 1
                try:
                    twice = key in seen
                except TypeError:  # an unhashable key: SafeLoader's own error follows
                    continue
                if twice:
                    raise StudyError(
                        [f"key {key!r} is given twice in one mapping (lines {seen[key]} and "
                         f"{line}); give it once"], source,
                    )  # fmt: skip
                seen[key] = line
            return super().construct_mapping(node, deep)

        def compose_node(self, parent, index):
            if self.check_event(yaml.AliasEvent):
                Loader.aliases += 1
                if Loader.aliases > MAX_ALIASES:
                    raise StudyError(
                        [f"it uses more than {MAX_ALIASES} YAML aliases (*name); write the values"],
                        source,
                    )
            return super().compose_node(parent, index)

    loader = Loader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _expanded_size(node, source)
        return loader.construct_document(node)
    except yaml.YAMLError as error:
        raise StudyError([f"not valid YAML: {error}".replace("\n", " ")], source) from None
    finally:
        loader.dispose()


def _expanded_size(root, source: str) -> int:
    """Nodes of the YAML graph with every alias expanded (each distinct node visited once);
    StudyError past MAX_NODES or for a node that contains itself."""
    import yaml

    sizes: dict[int, int] = {}
    open_nodes: set[int] = set()
    stack = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if done:
            children = _children(node, yaml)
            sizes[key] = 1 + sum(sizes[id(c)] for c in children)
            open_nodes.discard(key)
            if sizes[key] > MAX_NODES:
                raise StudyError(
                    [f"it expands to more than {MAX_NODES:,} values (aliases followed)"], source
                )
            continue
        if key in sizes:
            continue
        if key in open_nodes:
            raise StudyError(["a YAML alias refers to a node that contains it"], source)
        open_nodes.add(key)
        stack.append((node, True))
        stack.extend((c, False) for c in _children(node, yaml) if id(c) not in sizes)
    return sizes[id(root)]


def _children(node, yaml) -> list:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    return []


def _is_general(scene: Mapping, params) -> bool:
    names = set(scene) | {re.sub(r"\[\d+\]$", "", p) for p in params}
    return bool(names & {*CHAIN_LISTS, "k_contact"})


def _axis_values(axis: Mapping, where: str, problems: list[str]) -> tuple[np.ndarray, bool]:
    given = [k for k in ("values", "linspace", "logspace") if k in axis]
    if len(given) != 1:
        problems.append(
            f"{where}: give exactly one of values, linspace, logspace (got {given or 'none'})"
        )
        return np.array([]), False
    kind = given[0]
    if kind == "values":
        values = np.array(axis["values"], dtype=float)
        log = bool(len(values) > 1 and values.min() > 0 and values.max() / values.min() > 10)
        return values, log
    spec = axis[kind]
    start, stop, num = spec["start"], spec["stop"], spec["num"]
    if not start < stop:
        problems.append(f"{where}.{kind}.stop = {stop!r}: must be greater than start = {start!r}")
        return np.array([]), False
    if kind == "logspace":
        if not start > 0:
            problems.append(f"{where}.logspace.start = {start!r}: must be > 0 (a log axis)")
            return np.array([]), False
        values, log = np.geomspace(start, stop, num), True
    else:
        values, log = np.linspace(start, stop, num), False
    # float64 may not hold num distinct values between start and stop (stop one ulp above
    # start): the grid would solve one scene num times
    distinct = len(np.unique(values))
    if distinct < num:
        problems.append(
            f"{where}.{kind}: its {num} values are not distinct ({distinct} different ones "
            f"between start = {start!r} and stop = {stop!r}); widen the range or lower num"
        )
        return np.array([]), False
    return values, log


def _check_scene_values(study_scene, bad_keys, axes, general, whole) -> list[str]:
    """Every scene the axes produce, checked once per axis value with the package's checks.

    ``study_scene`` holds the scene keys that passed the schema (``bad_keys`` the others, already
    reported), ``axes`` the axes that did; ``whole`` says nothing of scene or axes was reported,
    so that the checks of the whole (a required key, the chain at the corners) can run.
    Returns the problems found."""
    problems: list[str] = []
    if general:
        for name in ("masses", "springs"):
            if name not in study_scene and name not in bad_keys:
                problems.append(f"scene.{name}: required for a general chain (masses[i] etc.)")
        structure = "masses" in study_scene and "springs" in study_scene
        lengths = {}
        if structure:
            n = len(study_scene["masses"])
            lengths = {"springs": n - 1, "dashpots": n - 1}
            for name, length in lengths.items():
                if name in study_scene and len(study_scene[name]) != length:
                    structure = False
                    problems.append(
                        f"scene.{name} = {study_scene[name]!r}: must have {length} items "
                        f"(one per neighbouring pair of the {n} masses)"
                    )
        for axis in axes if structure else ():
            match = PARAM.match(axis.param)
            if match.group(2):
                size = len(study_scene.get(match.group(2), [])) or lengths[match.group(2)]
                index = int(match.group(3))
                if index >= size:
                    structure = False
                    problems.append(
                        f"axes: param = {axis.param!r}: index must be < {size} "
                        f"({match.group(2)} has {size} items, counted from 0)"
                    )
        checks = {
            "masses": ("> 0", lambda v: math.isfinite(v) and v > 0),
            "springs": ("> 0", lambda v: math.isfinite(v) and v > 0),
            "dashpots": (">= 0", lambda v: math.isfinite(v) and v >= 0),
            "k_contact": ("> 0 (.inf: rigid wall)", lambda v: v > 0),
        }
        values = {k: list(v) if isinstance(v, list) else v for k, v in study_scene.items()}
        sources = [(f"scene.{k}", k, v) for k, v in values.items()]
        for axis in axes:
            match = PARAM.match(axis.param)
            name = match.group(2) or axis.param
            sources.append((f"axis {axis.param}", name, list(axis.values)))
        for where, name, items in sources:
            if name not in checks:
                problems.append(
                    f"{where}: {name} is a parameter of the paper's scene, not of a "
                    "general chain (use masses, springs, dashpots, k_contact)"
                )
                continue
            allowed, ok = checks[name]
            for v in items if isinstance(items, list) else [items]:
                if not ok(float(v)):
                    problems.append(f"{where} = {float(v)!r}: {name} must be {allowed}")
                    break
        if whole and structure and not problems:
            _check_chain_corners(study_scene, axes, problems)
        return problems
    if whole and "alpha" not in study_scene and "alpha" not in [a.param for a in axes]:
        problems.append("scene.alpha: required (in scene or as an axis) for the paper's scene")
    checks = {**PAPER_PARAMS, "n_masses": partial(check, "n_masses")}
    for name, value in study_scene.items():
        try:
            checks[name](value)
        except SceneError as error:
            problems.append(f"scene.{name} = {value!r}: {error}")
    for axis in axes:
        for v in axis.values:
            try:
                checks[axis.param](int(v) if axis.param == "n_masses" and v == int(v) else v)
            except SceneError as error:
                problems.append(f"axis {axis.param} = {float(v)!r}: {error}")
                break
    return problems


def _check_chain_corners(study_scene, axes, problems) -> None:
    """The general chains a study makes, checked whole by ``restitution.Chain`` (ranges of every
    value and of their ratios, RATIOS) at every corner of the axes' box: each ratio is monotone
    in each single parameter, so its extremes over the grid are at the corners."""
    import itertools

    from restitution.model.chain import Chain

    n = len(study_scene["masses"])
    base = {
        "masses": [float(v) for v in study_scene["masses"]],
        "springs": [float(v) for v in study_scene["springs"]],
        "dashpots": [float(v) for v in study_scene.get("dashpots", [0.0] * (n - 1))],
        "k_contact": float(study_scene.get("k_contact", math.inf)),
    }
    ends = [sorted({float(a.values.min()), float(a.values.max())}) for a in axes]
    for corner in itertools.product(*ends):
        scene = {k: list(v) if isinstance(v, list) else v for k, v in base.items()}
        for axis, value in zip(axes, corner, strict=True):
            match = PARAM.match(axis.param)
            if match.group(2):
                scene[match.group(2)][int(match.group(3))] = value
            else:
                scene[axis.param] = value
        try:
            Chain(scene["masses"], scene["springs"], scene["dashpots"], scene["k_contact"])
        except SceneError as error:
            at = ", ".join(f"{a.param} = {v!r}" for a, v in zip(axes, corner, strict=True))
            problems.append(f"axes: the chain at {at}: {error}")
            return


def _mathtext_problem(text: str) -> str | None:
    """Why matplotlib cannot draw ``text`` (mathtext between ``$...$``), or None."""
    if "$" not in text:
        return None
    if text.replace(r"\$", "").count("$") % 2:
        return "an odd number of $ (mathtext goes between two $; write \\$ for a dollar sign)"
    from matplotlib.mathtext import MathTextParser

    try:
        MathTextParser("path").parse(text)
    except ValueError as error:
        reason = str(error).strip().splitlines()[-1]
        reason = re.sub(r"^\w*Exception: ", "", reason)
        return f"matplotlib cannot draw it as mathtext ({reason.split('  (at char')[0][:120]})"
    return None


def _concerns(problem: str, key: str, below: bool = True) -> bool:
    """Whether ``problem`` (a line of check_value) is about ``key`` (or, with ``below``, about a
    key inside it: ``scene.alpha`` is inside ``scene``, ``axes[0].param`` inside ``axes[0]``)."""
    if not problem.startswith(key):
        return False
    rest = problem[len(key) : len(key) + 1]
    return rest in (" ", ":") or (below and rest in (".", "["))


RATIO_PARAMS = ("alpha", "beta", "xi", "n_masses")


def check_study(data, source: str = "study") -> Study:
    """Check a parsed study mapping; return the :class:`Study` or raise :class:`StudyError`.

    Every problem is listed at once, naming the key, the value and what is allowed: the schema's
    (types, ranges, unknown keys), the axes' (their grids) and the scenes' (every value each axis
    produces, and a general chain whole at the corners of the axes' box). A part with a schema
    problem is left out of the later checks (its problem is already listed); the checks of the
    whole run only when every part passed.
    """
    problems: list[str] = []
    try:
        checked = check_value(data, STUDY_SCHEMA, (), problems)
    except ConfigError as error:  # pragma: no cover - check_value collects, never raises
        problems.extend(error.problems)
        checked = None
    if not isinstance(checked, Mapping):
        raise StudyError(problems or ["the study must be a mapping of keys to values"], source)
    listed = list(problems)

    def reported(key: str, below: bool = True) -> bool:
        return any(_concerns(p, key, below) for p in listed)

    # The scene: the keys that passed the schema take part in the later checks.
    raw_scene = checked.get("scene")
    scene_whole = isinstance(raw_scene, Mapping) and not reported("scene", below=False)
    raw_scene = raw_scene if isinstance(raw_scene, Mapping) else {}
    scene = {k: v for k, v in raw_scene.items() if not reported(f"scene.{k}")}
    bad_keys = set(raw_scene) - set(scene)

    # The axes: each one whose keys passed the schema gets its grid.
    raw_axes = checked.get("axes")
    axes_whole = isinstance(raw_axes, list) and not reported("axes", below=False)
    raw_axes = raw_axes if axes_whole else []
    axes: list[Axis | None] = []
    params: list[str] = []
    for i, axis in enumerate(raw_axes):
        where = f"axes[{i}]"
        if not isinstance(axis, Mapping) or reported(where, below=False):
            axes.append(None)
            continue
        param = axis.get("param") if not reported(f"{where}.param") else None
        if param is not None:
            params.append(param)
        spaces_ok = not any(reported(f"{where}.{k}") for k in ("values", "linspace", "logspace"))
        values, log = _axis_values(axis, where, problems) if spaces_ok else (np.array([]), False)
        label = axis.get("label", "")
        if label and not reported(f"{where}.label"):
            why = _mathtext_problem(label)
            if why:
                problems.append(f"{where}.label = {label!r}: {why}")
        unit = axis.get("unit", "")
        if unit and param in RATIO_PARAMS:
            problems.append(
                f"{where}.unit = {unit!r}: {param} is a ratio of the paper's scene "
                "(non-dimensional); a unit belongs to masses[i], springs[i], dashpots[i], k_contact"
            )
        good = param is not None and len(values) > 0
        axes.append(Axis(param, values, log, label, unit) if good else None)
    conflicts = len(problems)
    if len(set(params)) < len(params):
        problems.append(f"axes: the two axes set the same parameter {params[0]!r}")
    for p in params:
        if p in raw_scene:
            problems.append(f"axes: param = {p!r} is also fixed in scene: give it in one place")
    conflicts = len(problems) > conflicts
    good_axes = [a for a in axes if a is not None]
    general = _is_general(raw_scene, params)
    units = checked.get("units", "")
    if units and not general and not reported("units"):
        problems.append(
            f"units = {units!r}: the paper's scene is non-dimensional (m1 = 1, V0 = 1, "
            "omega = 1); units describe a general chain's masses, springs, dashpots"
        )

    # Every scene value the axes produce (and, when every part passed, the whole).
    whole = (
        scene_whole and not bad_keys and axes_whole and len(good_axes) == len(raw_axes)
        and not conflicts
    )  # fmt: skip
    problems.extend(_check_scene_values(scene, bad_keys, good_axes, general, whole))

    # The grid of jobs.
    chunk_ok = not reported("chunk_size")
    if raw_axes and axes[0] is not None:
        first = len(axes[0].values)
        if first < 2:
            problems.append(f"axes[0]: the first axis needs at least 2 values (got {first})")
        elif chunk_ok and (len(axes) < 2 or axes[1] is not None):
            curves = len(axes[1].values) if len(axes) > 1 else 1
            jobs = n_chunks(first, checked["chunk_size"]) * curves
            if jobs > MAX_JOBS:
                problems.append(
                    f"chunk_size = {checked['chunk_size']}: makes {jobs} jobs ({curves} curves x "
                    f"ceil(({first} - 1)/chunk_size) chunks), more than the bound of {MAX_JOBS}: "
                    "raise chunk_size or use fewer points"
                )
    if problems:
        raise StudyError(problems, source)
    return Study(
        name=checked["name"],
        description=checked["description"],
        scene=scene,
        axes=tuple(good_axes),
        outputs=tuple(checked["outputs"]),
        refine_steps=checked["refine_steps"],
        chunk_size=checked["chunk_size"],
        method=checked["method"],
        max_events=checked["max_events"],
        units=checked["units"],
        raw=checked,
    )


# ---------------------------------------------------------------------------------------------
# The report's front page
# ---------------------------------------------------------------------------------------------
def _rst(text: str) -> str:
    """User text as reStructuredText that shows it as written: one line, every character that
    is not a letter, digit or space escaped (a backslash before one shows that character)."""
    return re.sub(r"([^\w\s]|_)", r"\\\1", " ".join(str(text).split()))


_GREEK = (
    "alpha beta gamma delta epsilon zeta eta theta kappa lambda mu nu xi pi rho sigma tau phi chi "
    "psi omega"
).split()


def _plain(label: str) -> str:
    """An axis text without its mathtext markup, for the report's text: ``$\\alpha = m_2/m_1$``
    reads ``α = m_2/m_1`` (Greek letters as such, ``$``, ``\\mathrm`` and braces dropped)."""
    import unicodedata

    def greek(match):
        name = match.group(1)
        return unicodedata.lookup(f"GREEK SMALL LETTER {'LAMDA' if name == 'lambda' else name}")

    text = re.sub(r"\\(" + "|".join(_GREEK) + r")(?![A-Za-z])", greek, label)
    text = re.sub(r"\\math(rm|it|bf)\b", "", text)
    return text.replace("$", "").replace("{", "").replace("}", "")


def _number(value: float) -> str:
    return ".inf (rigid wall)" if math.isinf(value) else f"{value:g}"


def _axis_text(axis: Axis) -> str:
    values = axis.values
    if len(values) <= 8:
        grid = "values " + ", ".join(_number(v) for v in values)
    else:
        spacing = "log-spaced" if axis.log else "evenly spaced"
        grid = f"{len(values)} values {spacing} from {values[0]:g} to {values[-1]:g}"
    unit = f" {_rst(axis.unit)}" if axis.unit else ""
    return f"``{axis.param}`` ({_rst(_plain(axis.title))}): {grid}{unit}"


def front_page(study: Study) -> dict:
    """What the report's front page says of ``study``, as reStructuredText (user text escaped):
    ``name``, ``folder`` (the name as is, for literals), ``description``, ``scene``, ``units``,
    ``axes`` (a list of lines), ``outputs``, ``settings``. The workflow hands it to
    workflow/report/workflow.rst (a study-only report shows it as its front page)."""
    set_by = {a.param: ("the first axis" if i == 0 else "the curves") for i, a in
              enumerate(study.axes)}  # fmt: skip
    if study.general:
        n = len(study.scene["masses"])
        parts = []
        for key in ("masses", "springs", "dashpots"):
            items = list(study.scene.get(key, [0.0] * (n - 1)))
            text = [f"{float(v):g}" for v in items]
            for param, where in set_by.items():
                match = PARAM.match(param)
                if match.group(2) == key:
                    text[int(match.group(3))] = f"({where})"
            parts.append(f"{key} = [{', '.join(text)}]")
        contact = f"({set_by['k_contact']})" if "k_contact" in set_by else None
        contact = contact or _number(float(study.scene.get("k_contact", math.inf)))
        parts.append(f"k_contact = {contact}")
        scene = (
            f"a general chain of {n} masses, m1 at the wall, every mass approaching it at "
            f"V0 = 1: {'; '.join(parts)}."
        )
        units = (
            f"{_rst(study.units)} (the study's ``units``); the COR and the energy fractions are "
            "ratios, ``omega_t_col`` is non-dimensional."
            if study.units
            else "not stated (the study file's ``units`` key): the values are in one consistent "
            "set of units, with V0 = 1 in them; the COR and the energy fractions are ratios."
        )
    else:
        values = {"alpha": None, "beta": 0.0, "xi": 0.0, "n_masses": 2, **study.scene}
        fixed = [f"{k} = {v:g}" for k, v in values.items() if k not in set_by and v is not None]
        varied = [f"{k} from {set_by[k]}" for k in values if k in set_by]
        scene = (
            "the paper's scene: m1 = 1 at the wall, m2..mN = alpha, equal springs, contact "
            "stiffness k2/beta (beta = 0: rigid wall), a dashpot of damping ratio xi between m1 "
            f"and m2; {', '.join(fixed + varied)}."
        )
        units = (
            "non-dimensional, the paper's: m1 = 1, V0 = 1, omega = 1 with omega^2 = k2/m1 + "
            "k2/m2; alpha, beta and xi are ratios."
        )
    axes = [f"x axis of every plot: {_axis_text(study.axes[0])}"]
    if len(study.axes) > 1:
        axes.append(f"one curve per value of {_axis_text(study.axes[1])}")
    refine = (
        f"refined at every change of the contact count and every smooth COR minimum "
        f"({study.refine_steps} steps)"
        if study.refine_steps and study.axes[0].refinable
        else "not refined"
    )
    return {
        "name": _rst(study.name),
        "folder": study.name,  # letters, digits, _ . - only: safe inside ``literal``
        "description": _rst(study.description.strip().rstrip(".") + ".")
        if study.description
        else "",
        "scene": scene,
        "units": units,
        "axes": axes,
        "outputs": ", ".join(f"``{o}``" for o in study.outputs),
        "settings": (
            f"method ``{study.method}``, at most {study.max_events} contacts per scene; the "
            f"first axis {refine}; minima closer than {MINIMA_MERGE:g} of its span listed once"
        ),
    }


# ---------------------------------------------------------------------------------------------
# Solving
# ---------------------------------------------------------------------------------------------
def scene_table(study: Study, first: np.ndarray, curve: float) -> pd.DataFrame:
    """The scene table (input of ``restitution.solve_many``) for first-axis values ``first`` on
    the curve whose second-axis value is ``curve`` (ignored for a one-axis study)."""
    rows = len(first)
    if study.general:
        frame = pd.DataFrame(index=range(rows))
        n = len(study.scene["masses"])
        base = {
            "masses": list(map(float, study.scene["masses"])),
            "springs": list(map(float, study.scene["springs"])),
            "dashpots": list(map(float, study.scene.get("dashpots", [0.0] * (n - 1)))),
            "k_contact": float(study.scene.get("k_contact", math.inf)),
        }
        lists = {k: [list(base[k]) for _ in range(rows)] for k in CHAIN_LISTS}
        contact = np.full(rows, base["k_contact"])
        values = [(study.axes[0].param, first)]
        if len(study.axes) > 1:
            values.append((study.axes[1].param, np.full(rows, curve)))
        for param, column in values:
            match = PARAM.match(param)
            if match.group(2):
                for r in range(rows):
                    lists[match.group(2)][r][int(match.group(3))] = float(column[r])
            else:
                contact = np.asarray(column, dtype=float)
            frame[param] = column
        for k in CHAIN_LISTS:
            frame[k] = lists[k]
        frame["k_contact"] = contact
    else:
        data = {"alpha": 1.0, "beta": 0.0, "xi": 0.0, "n_masses": 2, **study.scene}
        frame = pd.DataFrame({k: np.full(rows, v) for k, v in data.items()})
        frame[study.axes[0].param] = first
        if len(study.axes) > 1:
            frame[study.axes[1].param] = curve
        frame["n_masses"] = frame["n_masses"].astype(np.int64)
    frame["method"] = study.method
    return frame


def _refine(
    table: pd.DataFrame, evaluate: Callable, column: str, steps: int, log: bool
) -> pd.DataFrame:
    """Bisect every count change and narrow every smooth interior COR minimum of ``table``."""
    if steps == 0 or len(table) < 2:
        return table.iloc[:0]
    table = table.sort_values(column)
    x = table[column].to_numpy(dtype=float)
    count = table["n_collisions"].to_numpy()
    cor = table["cor"].to_numpy(dtype=float)
    ok = (table["status"] == "ok").to_numpy()

    def mid(a, b):
        return np.sqrt(a * b) if log else (a + b) / 2

    rows = []
    jumps = np.flatnonzero((count[1:] != count[:-1]) & ok[1:] & ok[:-1])
    lo, hi, n_lo = x[jumps], x[jumps + 1], count[jumps]
    # Interior grid minima of the COR away from a count change: smooth minima, pattern search.
    inner = interior_minima(cor)
    inner = inner[ok[inner - 1] & ok[inner] & ok[inner + 1]]
    inner = inner[(count[inner - 1] == count[inner]) & (count[inner + 1] == count[inner])]
    best, best_cor = x[inner], cor[inner]
    width = np.minimum(x[inner] - x[inner - 1], x[inner + 1] - x[inner]) / 2
    if log:
        width = np.minimum(np.log(x[inner] / x[inner - 1]), np.log(x[inner + 1] / x[inner])) / 2
    for _ in range(steps):
        points = [mid(lo, hi)]
        if len(inner):
            left = best * np.exp(-width) if log else best - width
            right = best * np.exp(width) if log else best + width
            points += [left, right]
        values = np.concatenate(points)
        if len(values) == 0:
            break
        new = evaluate(values)
        rows.append(new)
        n_new = new["n_collisions"].to_numpy()
        k = len(lo)
        same = n_new[:k] == n_lo
        lo, hi = np.where(same, points[0], lo), np.where(same, hi, points[0])
        if len(inner):
            c = new["cor"].to_numpy(dtype=float)
            m = len(inner)
            c_left, c_right = c[k : k + m], c[k + m :]
            take_left = c_left < np.minimum(best_cor, c_right)
            take_right = ~take_left & (c_right < best_cor)
            best = np.where(take_left, left, np.where(take_right, right, best))
            best_cor = np.minimum(best_cor, np.minimum(c_left, c_right))
            width = width / 2
    if not rows:
        return table.iloc[:0]
    return pd.concat(rows, ignore_index=True)


def solve_curve(study: Study, curve: float, chunk: int | None = None, logger=None) -> pd.DataFrame:
    """Solve one curve of ``study`` (one chunk of its first axis, or all of it), refined.

    Returns the scene columns, the axis columns, ``curve`` (second-axis value, NaN for one
    axis), the result columns of ``restitution.solve_many`` and ``refined`` (False on the grid).
    """
    from restitution import solve_many

    axis = study.axes[0]
    first = axis.values if chunk is None else study.chunk_values(chunk)

    # The axis columns of a general chain (e.g. "masses[2]") ride along as kept columns.
    keep = tuple(a.param for a in study.axes if a.param != "k_contact") if study.general else ()

    def evaluate(values):
        frame = scene_table(study, np.asarray(values), curve)
        return solve_many(frame, max_events=study.max_events, keep=keep)

    grid = evaluate(first).assign(refined=False)
    extra = (
        _refine(grid, evaluate, axis.param, study.refine_steps, axis.log)
        if axis.refinable
        else grid.iloc[:0]
    )
    table = (
        pd.concat([grid, extra.assign(refined=True)], ignore_index=True)
        .drop_duplicates(subset=axis.param, keep="first")
        .sort_values(axis.param, ignore_index=True)
    )
    table["curve"] = curve
    if logger is not None:
        logger.info(
            "%s: curve %g chunk %s: %d grid points, %d refined, %d not ok",
            study.name,
            curve,
            chunk,
            int((~table["refined"]).sum()),
            int(table["refined"].sum()),
            int((table["status"] != "ok").sum()),
        )
    return table
