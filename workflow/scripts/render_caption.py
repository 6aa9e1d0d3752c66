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
    return env.from_string(template).render(snakemake=snakemake, data=data, paper=paper)


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
