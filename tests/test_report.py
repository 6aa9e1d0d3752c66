"""The Snakemake report: every figure and table is in it, with a caption that names its parameters.

The inventory comes from Snakemake itself (the parsed workflow, in a subprocess): for every output
marked with ``report()`` its rule, caption file, category, and the ``params`` of its rule and of
every rule upstream of it, i.e. every configuration value the file depends on. Each figure's
caption must name each of those values through a Jinja expression (so the rendered report always
shows the values of the run) and render to valid reStructuredText. A small end-to-end run builds
a real report and checks that the captions and the reproduction table are in it.
"""

import json
import math
import re
import subprocess
import sys
from html import escape
from pathlib import Path

import pandas as pd
import pytest
import yaml

from conftest import REPO, copy_workflow, run_snakemake, snakemake_env

# Categories of the report: the paper's sections, the reproduction table, the benchmarks (#7).
SECTIONS = {
    "1": "Sect. 2: two-mass model, rigid and elastic contact",
    "2": "Sect. 2: two-mass model, rigid and elastic contact",
    "3": "Sect. 3.1: contact stiffness and plastic contact",
    "4": "Sect. 3.1: contact stiffness and plastic contact",
    "5": "Sect. 3.2: scissor structural spring",
    "6": "Sect. 3.3: chains of N masses",
    "7": "Sect. 3.4: dashpot between the masses",
    "8": "Beyond the paper",
    "9": "Beyond the paper",
}
CATEGORIES = set(SECTIONS.values()) | {"Reproduction", "Work-precision"}

# Params a caption need not name, and why: none of them changes a number in the figure.
NOT_A_PARAMETER = {
    "chunk_size": "how the grid is split into jobs; the results are identical for any value",
    "name": "selects the panel in a script shared by several panels",
    "panel": "selects the panel in a script shared by several panels (when a string)",
    "model": "selects the schematic drawn (Fig. 1 or 6(a))",
    "max_not_ok_fraction": "a pass/fail threshold of the run, not an input of the figure",
    "paper": "the paper's printed values a Snakemake-rendered caption quotes (not an input)",
    "ns": "the chain lengths one design job computes (fig8.design.all): Fig. 8(b)'s caption states "
    "those of the designs it draws, from the designs table (data.n_range)",
    "contains": "the families whose designs warm-start a family's (CONTAINS, rules/common.smk): "
    "fixed by the families, not a configuration value",
}

# Runs in a subprocess: Snakemake's API changes the working directory and its logging.
COLLECT = r"""
import json, sys
from pathlib import Path
from types import SimpleNamespace

import yaml

from docutils.core import publish_parts
from jinja2 import Environment
from snakemake.api import SnakemakeApi
from snakemake.io import get_flag_value, is_flagged
from snakemake.settings.types import ConfigSettings, OutputSettings, ResourceSettings


def flatten(value, path):
    if isinstance(value, dict):
        for key, sub in value.items():
            yield from flatten(sub, (*path, str(key)))
    elif callable(value):  # a param of the job's wildcards: no one value for the rule
        yield path, "<a function of the wildcards>"
    else:
        yield path, value


class Placeholder:
    # Stands for the numbers a render rule computes from its tables (data.<name>).

    def __getattr__(self, name):
        return f"<{name}>"


PAPER = {k: str(v) for k, v in yaml.safe_load(Path("config/paper_values.yaml").read_text()).items()}
settings = ConfigSettings(configfiles=[Path(p) for p in sys.argv[1:]])
with SnakemakeApi(OutputSettings()) as api:
    workflow = api.workflow(
        resource_settings=ResourceSettings(cores=1),
        config_settings=settings,
        snakefile=Path("Snakefile"),
    )._workflow
    rules = list(workflow.rules)

    def upstream(rule, seen):
        for item in rule.input:
            for producer in rules:
                if producer.name not in seen and producer.is_producer(str(item)):
                    seen[producer.name] = producer
                    upstream(producer, seen)
        return seen

    env = Environment(trim_blocks=True, lstrip_blocks=True)  # as snakemake's report
    entries = []
    for rule in rules:
        for item in rule.output:
            if not is_flagged(item, "report"):
                continue
            flag = get_flag_value(item, "report")
            entry = {
                "rule": rule.name, "output": str(item), "category": flag.category,
                "subcategory": flag.subcategory, "caption": None, "params": [],
            }
            if flag.caption is not None:
                path = flag.caption.get_path_or_uri(secret_free=True)
                generated = "results/captions/" in path
                # A generated caption is written by its render rule from the template of the
                # same name; here the template is rendered with placeholder data.
                template = Path("workflow/report") / Path(path).name if generated else Path(path)
                source = template.read_text()
                snakemake = SimpleNamespace(
                    config=workflow.config, params=rule.params, wildcards={}, rule=rule.name
                )
                rendered = env.from_string(source).render(
                    snakemake=snakemake, data=Placeholder(), paper=PAPER
                )
                entry["generated"] = generated
                entry["rule_outputs"] = [str(f) for f in rule.output]
                path = str(template) if generated else path
                html = publish_parts(
                    rendered, writer_name="html", settings_overrides={"report_level": 2}
                )["body"]
                entry.update(caption=path, source=source, rendered=rendered, html=html)
            for name, dep in upstream(rule, {rule.name: rule}).items():
                for key, raw in dep.params.items():
                    for path, value in flatten(raw, (key,)):
                        entry["params"].append({"rule": name, "path": list(path), "value": value})
            entries.append(entry)
    outputs = [{"rule": r.name, "output": str(f)} for r in rules for f in r.output]
    json.dump({"report": entries, "outputs": outputs}, sys.stdout)
"""


def collect(cwd=REPO, configfiles=()):
    result = subprocess.run(
        [sys.executable, "-c", COLLECT, *map(str, configfiles)],
        cwd=cwd,
        env=snakemake_env(),
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr[-5000:]
    return json.loads(result.stdout)


@pytest.fixture(scope="module")
def inventory():
    return collect()


def _figures(inventory):
    """The paper's panels, figures/figNx.png. The work-precision diagrams (figures/benchmarks/)
    are not reproductions of a panel: their captions state the settings swept, and their rules
    pass the whole ``benchmarks`` config (one timing job per family), so not every key printed
    there applies to every diagram."""
    paper = re.compile(r"figures/fig\d[a-d]?\.png")
    return [e for e in inventory["report"] if paper.fullmatch(e["output"])]


def test_every_figure_and_table_is_in_the_report(inventory):
    flagged = {e["output"] for e in inventory["report"]}
    wanted = [
        o["output"]
        for o in inventory["outputs"]
        if (o["output"].startswith("figures/") and o["output"].endswith(".png"))
        or (o["output"].startswith("results/") and o["output"].endswith((".csv", ".json")))
    ]
    assert len(wanted) >= 19 + 10, wanted  # 19 panels of Figs. 1-7 and the tables next to them
    missing = sorted(set(wanted) - flagged)
    assert not missing, f"outputs not marked with report(): {missing}"


def test_every_report_entry_has_a_caption_and_a_section(inventory):
    for entry in inventory["report"]:
        where = f"{entry['rule']}: {entry['output']}"
        assert entry["caption"] and Path(entry["caption"]).is_file(), where
        assert entry["category"] in CATEGORIES, f"{where}: category {entry['category']!r}"
        figure = re.fullmatch(r"figures/fig(\d)[a-d]?\.png", entry["output"])
        if figure:  # a paper figure: its section, and one subcategory per figure
            assert entry["category"] == SECTIONS[figure.group(1)], where
            assert entry["subcategory"] == f"Fig. {figure.group(1)}", where
            assert entry["rendered"].lstrip().startswith(f"**Fig. {figure.group(1)}"), where


def test_captions_render_to_valid_rst(inventory):
    for entry in inventory["report"]:
        assert "system-message" not in entry["html"], f"{entry['caption']}:\n{entry['html']}"
        assert "{{" not in entry["rendered"] and "{%" not in entry["rendered"], entry["caption"]


def _shown(value):
    """How Jinja prints a value: str() of the Python object (1e-09, [0.0, 0.001], 100.0)."""
    return str(value)


def test_figure_captions_name_every_parameter(inventory):
    """Each config value a figure depends on (its rule's params and those of every rule upstream)
    is printed in its caption through a Jinja expression that names the key."""
    problems = []
    figures = _figures(inventory)
    assert len(figures) >= 19
    for entry in figures:
        expressions = " ".join(
            m.group(0) for m in re.finditer(r"\{\{.*?\}\}|\{%.*?%\}", entry["source"], re.S)
        )
        for param in entry["params"]:
            key = param["path"][-1]
            value = param["value"]
            if key in NOT_A_PARAMETER and (key != "panel" or isinstance(value, str)):
                continue
            if param["path"][0] == "paper":  # params.paper = {key: printed value}
                continue
            where = f"{entry['caption']}: {param['rule']}.params.{'.'.join(param['path'])}"
            if not re.search(rf"""["'.]{re.escape(key)}\b""", expressions):
                problems.append(f"{where} is not named in a Jinja expression")
            elif _shown(value) not in entry["rendered"]:
                problems.append(f"{where} = {_shown(value)} does not appear in the caption")
    assert not problems, "\n".join(sorted(set(problems)))


# Figures whose captions state results (a trend, a minimum, a fitted slope): their render rule
# writes the caption from the tables it draws.
DATA_CAPTIONS = {"fig2a", "fig2b", "fig2c", "fig2d", "fig3a", "fig3b", "fig4b", "fig4c", "fig4d",
                 "fig5a", "fig5b", "fig6b", "fig7a", "fig7b", "fig7c", "fig7d",
                 "fig8a", "fig8b", "fig9"}  # fmt: skip


def test_result_captions_are_written_by_their_render_rule(inventory):
    """The caption the report shows is results/captions/<fig>.rst, an output of the figure's own
    render rule, rendered from workflow/report/<fig>.rst with numbers from the data."""
    seen = set()
    for entry in _figures(inventory):
        name = Path(entry["output"]).stem
        if name not in DATA_CAPTIONS:
            continue
        seen.add(name)
        assert entry.get("generated"), f"{entry['output']}: caption is not generated"
        assert f"results/captions/{name}.rst" in entry["rule_outputs"], entry["rule"]
        assert "<" in entry["rendered"] or name == "fig5a", f"{name}: caption uses no data"
    assert seen == DATA_CAPTIONS


def render_front_page(categories, config) -> tuple[str, str]:
    """workflow/report/workflow.rst rendered as Snakemake renders it (Jinja with its settings,
    the link targets of the report's categories appended, docutils' HTML writer): (rst, html)."""
    from collections import namedtuple
    from types import SimpleNamespace

    from docutils.core import publish_parts
    from jinja2 import Environment

    category = namedtuple("Category", "name")
    source = (REPO / "workflow" / "report" / "workflow.rst").read_text()
    links = "".join(f"\n.. _{c}: javascript:app.showCategory('{c}')\n" for c in categories)
    rst = (
        Environment(trim_blocks=True, lstrip_blocks=True)
        .from_string(source + links)
        .render(
            snakemake=SimpleNamespace(config=config),
            categories={category(c): {} for c in categories},
            files=[],
        )
    )
    # report_level 2: a warning on the page is a failure too (Snakemake shows errors, level 3).
    html = publish_parts(rst, writer="html", settings_overrides={"report_level": 2})
    return rst, html["html_body"]


def test_front_page_is_short_and_names_the_solver():
    """What, units, methods, links: the tables have their own pages (a long front page overflowed
    the report's pane above its top; workflow/report/style.css and make report keep it fixed).
    Links name only the categories the report has (a missing one is a docutils error)."""
    config = {"method": "auto", "max_events": 100000}
    for categories in (["Sect. 2: two-mass model", "Reproduction"], ["Sect. 2: two-mass model"]):
        rst, html = render_front_page(categories, config)
        assert "System Message" not in html, html
        assert "method ``auto``" in rst and "A reproduction of" in rst
        assert ("`Reproduction`_" in rst) == ("Reproduction" in categories)
        assert ".. csv-table::" not in rst
        assert len(rst.split()) < 350, "the front page should fit on one screen"
    style = (REPO / "workflow" / "report" / "style.css").read_text()
    assert "align-items: flex-start" in style


def test_a_study_report_has_its_own_front_page():
    """A study's report alone: its scene, units and axes (restitution_workflow.study.front_page),
    user text shown as written; with the paper's categories, the paper's page and a link to it."""
    from restitution_workflow.study import check_study, front_page

    study = check_study(
        {"name": "rear_mass_", "description": "Rear mass *sweep*, `k_c` as a curve",
         "units": "SI: kg, N/m, N s/m; V0 = 1 m/s",
         "scene": {"masses": [1.0, 0.5, 2.0], "springs": [0.3, 1.2]},
         "axes": [{"param": "masses[2]", "logspace": {"start": 0.3, "stop": 3.0, "num": 50},
                   "label": r"rear mass $m_3$", "unit": "kg"},
                  {"param": "k_contact", "values": [10.0, math.inf], "unit": "N/m"}]}
    )  # fmt: skip
    config = {"method": "auto", "max_events": 100000, "study_front": front_page(study)}
    rst, html = render_front_page(["Studies"], config)
    assert "System Message" not in html, html
    assert "A reproduction of" not in rst and "Non-dimensional" not in rst
    for text in (
        "Study rear_mass_.",  # a trailing _ would be a link without its escape
        "Rear mass *sweep*, `k_c` as a curve.",
        "a general chain of 3 masses",
        "masses = [1, 0.5, (the first axis)]",
        "k_contact = (the curves)",
        "SI: kg, N/m, N s/m; V0 = 1 m/s",
        "rear mass m_3 [kg]): 50 values log-spaced from 0.3 to 3 kg",
        "values 10, .inf (rigid wall) N/m",
        "results/studies/rear_mass_/sweep.parquet",
    ):
        assert escape(text, quote=False) in html, (text, html)
    assert len(rst.split()) < 350
    paper = check_study({"name": "p", "scene": {"beta": 0.01},
                         "axes": [{"param": "alpha", "values": [0.5, 1.0]}]})  # fmt: skip
    rst, html = render_front_page(["Studies"], {**config, "study_front": front_page(paper)})
    assert "non-dimensional, the paper" in rst and "beta = 0.01, xi = 0, n_masses = 2" in rst
    assert "System Message" not in html
    rst, html = render_front_page(["Sect. 2", "Reproduction", "Studies"], config)
    assert "A reproduction of" in rst and "`Studies`_: the user study rear" in rst
    assert "System Message" not in html, html


# --- a real report on a small configuration --------------------------------------------------

SMALL = {
    "fig2a": {
        "alpha_min": 0.5,
        "alpha_max": 4.0,
        "n_alpha": 41,
        "betas": [0.0, 0.1],
        "chunk_size": 40,
        "refine_steps": 30,
    },
    "approx": {
        "n_max": 10,
        "alpha_min": 0.1,
        "alpha_max": 5.0,
        "n_alpha": 2001,
        "n_plot": 201,
        "n_eta": 200,
        "finite_betas": [1.0],
        "finite_alpha_min": 1.0,
        "finite_alpha_max": 6.0,
        "finite_n_grid": 40,
        "finite_steps": 30,
    },
    "fig3": {"compression": {"n_times": 401, "marginal_steps": 40}},
}
SMALL_TARGETS = ("fig2a", "fig2b", "reproduction")


@pytest.mark.pipeline
def test_report_builds_on_a_small_configuration(tmp_path):
    copy_workflow(tmp_path)
    config = tmp_path / "small.yaml"
    config.write_text(yaml.safe_dump(SMALL))

    def run(*args):
        result = run_snakemake(f"--configfile={config}", *args, cwd=tmp_path, timeout=900)
        assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-5000:]

    run("-c2", *SMALL_TARGETS)
    run("--report", "report.html", *SMALL_TARGETS)
    html = (tmp_path / "report.html").read_text()

    # The front page; the reproduction table is its own page, written from this run's CSV.
    assert "A reproduction of" in html and "paper vs ours (readable page)" in html
    repro = pd.read_csv(tmp_path / "results" / "reproduction.csv")
    page = (tmp_path / "results" / "reproduction.html").read_text()
    assert page.count("<tr>") == len(repro) + 1  # the header and one row per quantity
    for row in repro.itertuples():  # every quantity with our value (6 significant digits)
        assert escape(row.quantity) in page, row.quantity
        assert f"{row.ours:.6g}" in page, (row.quantity, row.ours)
    # Captions of the figures and tables, rendered with this run's configuration.
    assert "Fig. 2(a)." in html and "Fig. 2(b)." in html and "Fig. 2(a) minima (table)" in html
    assert "[0.0, 0.1]" in html  # fig2a.betas of SMALL, printed by the Jinja caption
    assert "Reproduction table." in html
    # The generated captions carry this run's numbers: Fig. 2(a)'s rigid-wall minima and the
    # paper's values from config/paper_values.yaml.
    caption = (tmp_path / "results" / "captions" / "fig2a.rst").read_text()
    found = caption.split("this run finds", 1)[1].split("at alpha", 1)[0].split()[0].rstrip(",")
    assert found in html and "this run finds" in html
    assert (tmp_path / "results" / "reproduction.html").is_file()
    assert "Reproduction table (page)" in html
