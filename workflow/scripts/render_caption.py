"""Write a figure's caption from its template and the numbers of this run's result tables.

Snakemake renders a report caption with the rule's input, output, params, wildcards and config
only; it cannot read a result table. So each render rule writes its own caption: the template
``workflow/report/<name>.rst`` (Jinja, as Snakemake's) is rendered here with

- ``snakemake.config`` / ``snakemake.params``: the configuration of the run,
- ``paper``: the numbers the paper prints (config/paper_values.yaml, strings as printed),
- ``data``: numbers and words (e.g. the sign of a trend) the render script computed from the
  result tables it drew,

and written to ``results/captions/<name>.rst``, the file the rule's ``report(caption=...)``
points at. Undefined names fail the job (a caption never silently loses a value). Every number a
template types itself must be an equation, figure or section number or a configuration or paper
value (tests/test_captions.py).
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import yaml

TEMPLATES = Path("workflow") / "report"


def load_paper(path) -> dict:
    """The paper's printed values (config/paper_values.yaml) as a dict of strings."""
    values = yaml.safe_load(Path(path).read_text())
    return {key: str(value) for key, value in values.items()}


def fmt(value: float, digits: int = 3) -> str:
    """A number with ``digits`` significant digits, plain notation where readable."""
    return f"{float(value):.{digits}g}"


def render(template: str, config: dict, params, data: dict, paper: dict) -> str:
    """The caption text: ``template`` rendered with StrictUndefined (a missing value fails)."""
    from jinja2 import Environment, StrictUndefined

    env = Environment(trim_blocks=True, lstrip_blocks=True, undefined=StrictUndefined)
    snakemake = SimpleNamespace(config=config, params=params)
    # A namespace, not a dict: ``data.values`` must be a value, never the dict's method.
    return env.from_string(template).render(
        snakemake=snakemake, data=SimpleNamespace(**data), paper=paper
    )


def write_caption(smk, data: dict, logger=None) -> Path:
    """Render the template named like ``smk.output.caption`` and write it there."""
    out = Path(smk.output.caption)
    template = Path(smk.input.template) if "template" in smk.input.keys() else TEMPLATES / out.name
    paper = load_paper(smk.input.paper)
    text = render(template.read_text(), smk.config, smk.params, data, paper)
    if "{{" in text or "{%" in text:
        raise ValueError(f"{template}: rendered caption still holds Jinja markup")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    if logger is not None:
        logger.info("wrote %s from %s with data %s", out, template, data)
    return out


def ordering(
    frame, key: str, first_minima, minima_counts, along: str = "alpha", value: str = "cor"
) -> dict:
    """How ``value`` orders with ``key`` across curves (one per key), as caption words.

    On the ``along`` points all curves share (the base grid; refinement points differ), the share
    of points where ``value`` falls (rises) at every step of ``key``; the mean per curve and
    whether it falls or rises with ``key``. The minima come from the table that listed them
    (``first_minima``: key -> ``along`` of the curve's first local minimum; ``minima_counts``:
    key -> its number of minima; a key missing from them has none): the first minimum of each
    curve and whether it moves to smaller or larger ``along`` as ``key`` grows, and the number of
    minima per curve.
    """
    import numpy as np

    keys = sorted(frame[key].unique())
    table = frame.pivot_table(index=along, columns=key, values=value).dropna()[keys]
    steps = np.diff(table.to_numpy(), axis=1)
    means = table.mean()
    firsts = [float(first_minima.get(k, np.nan)) for k in keys]
    counts = [int(minima_counts.get(k, 0)) for k in keys]

    def trend(values, rtol=0.0):
        values = np.asarray(values, dtype=float)
        d = np.diff(values)
        if len(d) and np.all(np.abs(d) <= rtol * np.abs(values[1:])):
            return "is constant"
        if len(d) and np.all(d < 0):
            return "falls"
        if len(d) and np.all(d > 0):
            return "rises"
        return "is not monotonic"

    return {
        "levels": ", ".join(f"{k:g}" for k in keys),
        "n_points": len(table),
        "falls_share": f"{100 * np.all(steps < 0, axis=1).mean():.0f}%" if len(keys) > 1 else "-",
        "rises_share": f"{100 * np.all(steps > 0, axis=1).mean():.0f}%" if len(keys) > 1 else "-",
        "means": ", ".join(f"{means[k]:.3f}" for k in keys),
        "mean_trend": trend(means.to_numpy()),
        "first_minima": ", ".join(fmt(a) for a in firsts),
        "first_trend": {
            "falls": "moves to smaller",
            "rises": "moves to larger",
            "is constant": "stays at the same",
        }.get(trend(firsts, rtol=1e-3), "does not move monotonically to smaller or larger"),
        "minima_counts": ", ".join(str(c) for c in counts),
        "count_trend": trend(counts),
    }
