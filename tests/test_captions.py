"""Captions state no number by hand: every number comes from the run (config or result tables).

The report's captions are Jinja templates (workflow/report/*.rst); the render rules fill them with
the configuration, the paper's printed values (config/paper_values.yaml) and numbers computed
from the result tables they draw (workflow/scripts/render_caption.py). A number typed into a
template would go stale when the configuration or the code changes, so the only numbers a
template may type itself are

- equation, figure and section numbers ("Eq. 24", "Eqs. 19-22", "Fig. 3(b)", "Sect. 3.1"),
- digits inside names (k1, m2, alpha*_1, DP5(4), results/fig7/minima.csv),
- the integers 0, 1 and 2 of formulas ("1 + alpha", "2 pi", "(1 - s)^2", "beta = 0"),
- a value of config/config.yaml.

A number the paper prints is read from config/paper_values.yaml (``paper.<key>`` in the captions
render_caption.py writes, ``snakemake.params.paper[...]`` in those Snakemake renders), never typed:
a typed copy would not follow a correction of that file.

Everything inside a Jinja expression, statement or comment is filled in at render time.
"""

import math
import re
from pathlib import Path

import pytest
import yaml

REPO = Path(__file__).resolve().parents[1]
REPORT = REPO / "workflow" / "report"
#: The front page is written by hand around the reproduction table (not a figure caption).
NOT_CAPTIONS = {"workflow.rst"}
FORMULA_INTEGERS = {0.0, 1.0, 2.0}

JINJA = re.compile(r"\{\{.*?\}\}|\{%.*?%\}|\{#.*?#\}", re.S)
REFERENCE = re.compile(
    r"\b(?:Eqs?|Figs?|Sects?|Sec|Section|Sections|Appendix)\.?\s*"
    r"\d+(?:\.\d+)?(?:\([a-d]\))?(?:\s*(?:-|,|and|to)\s*\d+(?:\.\d+)?(?:\([a-d]\))?)*"
    r"(?:\([a-d]\)(?:\s*-\s*\([a-d]\))?)?"
)
NAME = re.compile(r"[A-Za-z_][A-Za-z_*#]*\d+(?:\(\d+\))?[\w.]*")
NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?%?")


def _flatten(value):
    if isinstance(value, dict):
        for sub in value.values():
            yield from _flatten(sub)
    elif isinstance(value, list):
        for sub in value:
            yield from _flatten(sub)
    else:
        yield value


def allowed_values() -> set[float]:
    """Numbers of config/config.yaml and the formula integers (not the paper's printed values)."""
    values = set(FORMULA_INTEGERS)
    config = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    for value in _flatten(config):
        try:
            values.add(float(str(value).rstrip("%")))
        except ValueError:
            continue
    return values


def typed_numbers(text: str) -> list[str]:
    """The numbers a template types itself (outside Jinja, references and names)."""
    text = JINJA.sub(" ", text)
    text = REFERENCE.sub(" ", text)
    text = NAME.sub(" ", text)
    return NUMBER.findall(text)


def stray_numbers(text: str, allowed: set[float]) -> list[str]:
    """Typed numbers that are none of the allowed values."""
    stray = []
    for token in typed_numbers(text):
        value = float(token.rstrip("%"))
        if not any(math.isclose(value, a, rel_tol=1e-12, abs_tol=0) for a in allowed):
            stray.append(token)
    return stray


TEMPLATES = sorted(p for p in REPORT.glob("*.rst") if p.name not in NOT_CAPTIONS)


@pytest.mark.parametrize("path", TEMPLATES, ids=[p.name for p in TEMPLATES])
def test_caption_types_no_number_of_its_own(path):
    stray = stray_numbers(path.read_text(), allowed_values())
    assert not stray, f"{path.name}: typed numbers {stray}; take them from the data or config"


def test_the_check_catches_a_typed_result():
    allowed = allowed_values()
    caption = "The paper's model misses by up to 0.33 (Eqs. 19-22, Fig. 2(d), k1, alpha*_1)."
    assert stray_numbers(caption, allowed) == ["0.33"]
    assert stray_numbers("slope {{ data.slope }} of Fig. 7(c), Sect. 3.4", allowed) == []
    assert stray_numbers("beta = 0 and 2 pi, DP5(4), results/fig7/minima.csv", allowed) == []
    assert stray_numbers("it grows by a factor of about 1.58", allowed) == ["1.58"]
    # A number the paper prints (config/paper_values.yaml) is read from there, never typed.
    assert stray_numbers("compare with the paper's 0.178 and 0.710", allowed) == ["0.178", "0.710"]
    assert stray_numbers("the paper's {{ paper.rigid_min1_cor }}", allowed) == []


def test_paper_values_are_printed_strings():
    """Every paper value is a string as printed (so "0.710" keeps its last digit)."""
    paper = yaml.safe_load((REPO / "config" / "paper_values.yaml").read_text())
    assert paper and all(isinstance(v, str) for v in paper.values()), paper
