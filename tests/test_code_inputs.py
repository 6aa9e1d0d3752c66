"""Editing a module reruns exactly the jobs whose scripts can import it (issue 24).

The workflow computes each rule's code inputs (``script_code`` in workflow/rules/common.smk) by
scanning import statements. This test finds what each script reaches another way, with the
standard library's ``modulefinder`` (it follows the IMPORT_NAME instructions of the compiled
bytecode, functions included, with Python's package semantics). Then, in a scratch copy of the
workflow whose outputs are all made up to date, it touches every module of the package and every
script and reads from snakemake's dry runs (``--rerun-triggers mtime``) which touched files each
job names as its reason to rerun.
"""

import modulefinder
import os
import re
import shutil
import time
from pathlib import Path

import pytest

from conftest import REPO, copy_workflow, run_snakemake

SRC = REPO / "src"
SCRIPTS = REPO / "workflow" / "scripts"
RULE_FILES = [REPO / "Snakefile", *sorted((REPO / "workflow" / "rules").glob("*.smk"))]
# Every rule of the workflow, `all` and the optional targets with their own rules included.
TARGETS = ("all", "benchmarks", "design_extra", "study")
CONFIG = (
    "--configfile",
    "config/small.yaml",
    "--config",
    "run=paper",  # outputs at the top of the scratch copy, as the dry run names them
    "study=config/study-example.yaml",
)


def code_files(root: Path) -> list[str]:
    """Every module of the package and every workflow script, relative to ``root``."""
    files = [
        *(root / "src" / "restitution").rglob("*.py"),
        *(root / "workflow" / "scripts").glob("*.py"),
    ]
    return sorted(str(f.relative_to(root)) for f in files if "__pycache__" not in f.parts)


def rule_scripts() -> dict:
    """Rule name -> its script (None for a target rule), read from the rule files' text."""
    rules = {}
    for path in RULE_FILES:
        text = path.read_text()
        starts = [(m.start(), m.group(1)) for m in re.finditer(r"^ *rule (\w+):", text, re.M)]
        for (start, name), (end, _) in zip(starts, [*starts[1:], (len(text), "")], strict=False):
            block = text[start:end]
            script = re.search(r'\n *script:\n *"\.\./scripts/(\w+\.py)"', block)
            rules[name] = script.group(1) if script else None
            other = re.findall(r"\n *(shell|run|notebook|wrapper|cwl):", block)
            # Code run another way would need code inputs of its own: none today.
            assert not other, f"rule {name} ({path.name}) runs code through {other}"
    return rules


class LocalFinder(modulefinder.ModuleFinder):
    """ModuleFinder that reads only the package and the scripts' helpers (not numpy & co.)."""

    compiled: dict = {}  # path -> code object, shared: each file is compiled once per session

    def find_module(self, name, path, parent=None):
        # path is None for a top-level name (a package's own __init__ is looked up with a path).
        if path is None and name != "restitution" and not (SCRIPTS / f"{name}.py").is_file():
            raise ImportError(name)
        return super().find_module(name, path, parent)

    def load_module(self, fqname, fp, pathname, file_info):
        if file_info[2] != modulefinder._PY_SOURCE:
            return super().load_module(fqname, fp, pathname, file_info)
        if pathname not in self.compiled:
            self.compiled[pathname] = compile(fp.read(), pathname, "exec")
        module = self.add_module(fqname)
        module.__file__ = pathname
        self.scan_code(self.compiled[pathname], module)
        return module


def reached(script: str) -> set:
    """The script and every module it can import (any depth), relative to the repository."""
    # The script's folder first on the path, as Snakemake runs it.
    finder = LocalFinder(path=[str(SCRIPTS), str(SRC)])
    finder.run_script(str(SCRIPTS / script))
    files = {Path(m.__file__).resolve() for m in finder.modules.values() if m.__file__}
    return {str(f.relative_to(REPO)) for f in files}


def dry_run(work: Path) -> list:
    """The jobs a dry run plans: rule, inputs, outputs and the files named as updated inputs."""
    # --quiet host: the full job blocks with their reasons (the profile's listing is one line).
    quiet = ("--quiet", "host")
    result = run_snakemake("-n", *TARGETS, *CONFIG, "--rerun-triggers", "mtime", *quiet, cwd=work)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    jobs = []
    for line in result.stdout.splitlines():
        if m := re.match(r"(?:local)?rule (\w+):$", line):
            jobs.append({"rule": m.group(1), "input": [], "output": [], "updated": set()})
        elif m := re.match(r"    (input|output): (.*)", line):
            jobs[-1][m.group(1)] = m.group(2).split(", ")
        elif m := re.match(r"    reason: (.*)", line):
            for part in m.group(1).split("; "):
                if part.startswith("Updated input files: "):
                    jobs[-1]["updated"] |= set(part.split(": ", 1)[1].split(", "))
    return jobs


def set_mtime(paths, when):
    for path in paths:
        os.utime(path, (when, when), follow_symlinks=False)


def depths(jobs) -> dict:
    """Outputs of a job (tuple) -> its depth in the DAG: 0 without upstream jobs, else 1 + the
    deepest job whose outputs it reads."""
    producer = {f: tuple(job["output"]) for job in jobs for f in job["output"]}
    inputs = {tuple(job["output"]): job["input"] for job in jobs}
    depth = {}

    def of(key):
        if key not in depth:
            upstream = {producer[f] for f in inputs[key] if f in producer}
            depth[key] = 1 + max(map(of, upstream)) if upstream else 0
        return depth[key]

    for key in inputs:
        of(key)
    return depth


def test_modulefinder_sees_the_kernels():
    """The independent reference is not vacuous: the issue's examples are found."""
    fig2a = reached("simulate_fig2a.py")
    assert {
        "src/restitution/kernels/exact_chain.py",
        "src/restitution/kernels/locator.py",
        "src/restitution/__init__.py",
        "workflow/scripts/_common.py",
        "workflow/scripts/simulate_fig2a.py",
    } <= fig2a
    assert "src/restitution/plotting.py" not in fig2a  # restyling reruns no simulation
    assert "workflow/scripts/simulate_fig4.py" in reached("simulate_fig5.py")  # a local helper


@pytest.mark.slow  # dry runs only (~15-30 s): no job is executed
def test_touching_a_module_reruns_exactly_the_jobs_that_import_it(tmp_path):
    """Every module touched, layer by layer of the DAG: the outputs of the layers above are made
    newer than the code (so their jobs do not rerun and snakemake checks the next layer's own
    inputs instead of only saying 'updated by another job'), those of the layer checked older.
    Each of its jobs must name as updated inputs exactly the code its script reaches."""
    scripts = rule_scripts()
    assert scripts["simulate_fig2a"] == "simulate_fig2a.py" and scripts["all"] is None
    expected = {rule: reached(script) if script else set() for rule, script in scripts.items()}
    code = code_files(REPO)

    # The scratch copy, package copied (not linked: its files get touched), no output yet.
    copy_workflow(tmp_path)
    (tmp_path / "src").unlink()
    shutil.copytree(
        SRC, tmp_path / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info")
    )
    assert code_files(tmp_path) == code
    jobs = dry_run(tmp_path)
    targets = [job for job in jobs if not job["output"]]  # `all` & co. run nothing
    assert {job["rule"] for job in targets} == {"all", "benchmarks", "design_extra", "study"}
    for job in targets:
        assert not set(job["input"]) & set(code), f"target rule {job['rule']} has code inputs"
    jobs = [job for job in jobs if job["output"]]
    assert {job["rule"] for job in jobs} == {r for r, s in scripts.items() if s}, (
        "a rule has no job"
    )
    depth = depths(jobs)
    outputs = [tmp_path / f for job in jobs for f in job["output"]]
    for path in outputs:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.touch()
    start = time.time() - 10_000
    set_mtime([p for p in tmp_path.rglob("*") if not p.is_dir()], start)
    touched = start + 1000
    set_mtime([tmp_path / f for f in code], touched)

    # Outputs newer than all code: nothing to do; a module that no script reaches changes that not.
    set_mtime(outputs, touched + 100)
    assert dry_run(tmp_path) == [], "outputs newer than every input still rerun"
    unused = sorted(set(code) - set().union(*expected.values()))
    set_mtime([tmp_path / f for f in unused], touched + 200)
    assert dry_run(tmp_path) == [], f"touching {unused} (no script imports them) reruns jobs"
    set_mtime([tmp_path / f for f in unused], touched)

    hits = {}  # module -> rules that rerun for it
    for layer in range(max(depth.values()) + 1):
        for job in jobs:
            key = tuple(job["output"])
            when = touched + 100 if depth[key] < layer else touched - 100
            set_mtime([tmp_path / f for f in key], when)
        planned = {tuple(job["output"]): job for job in dry_run(tmp_path)}
        for job in jobs:
            key = tuple(job["output"])
            if depth[key] != layer:
                continue
            rule = job["rule"]
            assert key in planned, f"rule {rule}: job {key} not planned with all its code touched"
            named = planned[key]["updated"] & set(code)
            assert named == expected[rule], (
                f"rule {rule}: missing {sorted(expected[rule] - named)}, "
                f"extra {sorted(named - expected[rule])}"
            )
            for module in named:
                hits.setdefault(module, set()).add(rule)
    # Per module: touching it reruns exactly the rules whose scripts reach it.
    for module in code:
        assert hits.get(module, set()) == {r for r in scripts if module in expected[r]}, module
