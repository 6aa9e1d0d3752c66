"""The package as a user installs it: distributions, metadata, one version, the notebooks lab.

The wheel test builds the sdist and the wheel with uv into a temporary folder, installs the wheel
(not editable, core dependencies only) into a fresh virtual environment and runs the CLI,
``solve_many`` against the closed form and ``use_style()`` there (``.ci/wheel_check.py`` does the
work and exits non-zero naming what failed). The lab test starts JupyterLab from
``.venv-notebooks`` headless and probes it over HTTP; it needs that environment (``make
notebooks-env``) and is skipped, saying so, without it.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
VERSION = PYPROJECT["project"]["version"]


def _imported(node) -> set[str]:
    if isinstance(node, ast.Import):
        return {alias.name.split(".")[0] for alias in node.names}
    if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
        return {node.module.split(".")[0]}
    return set()


def _src_imports() -> tuple[set[str], set[str]]:
    """Top-level modules imported under src/restitution (parsed, not grepped): (at import time,
    only inside functions). A function-level import is an optional feature's (e.g. PyYAML for
    restitution_workflow.study.load_study), needed only when that function runs."""
    eager: set[str] = set()
    lazy: set[str] = set()
    for path in (ROOT / "src" / "restitution").rglob("*.py"):
        tree = ast.parse(path.read_text(), filename=str(path))
        inner = set()
        for func in ast.walk(tree):
            if isinstance(func, (ast.FunctionDef, ast.AsyncFunctionDef)):
                inner.update(id(n) for n in ast.walk(func))
        for node in ast.walk(tree):
            (lazy if id(node) in inner else eager).update(_imported(node))
    return eager, lazy - eager


def _requirement_name(spec: str) -> str:
    return re.split(r"[\s\[<>=!~;]", spec, maxsplit=1)[0].lower()


def test_core_dependencies_are_what_src_imports():
    """Every third-party import of src/ is a core dependency, and nothing else is."""
    eager, lazy = _src_imports()
    ours = set(sys.stdlib_module_names) | {"restitution"}
    third_party, optional = eager - ours, lazy - ours
    declared = {_requirement_name(d) for d in PYPROJECT["project"]["dependencies"]}
    # Core = everything imported at import time, plus what functions import that is declared
    # core (tqdm for progress bars); nothing else.
    assert third_party <= declared <= third_party | optional, (
        f"src/ imports {sorted(third_party)} at import time and {sorted(optional)} inside "
        f"functions; pyproject.toml's core dependencies are {sorted(declared)}: workflow, "
        "notebook and test tools belong in the extras"
    )
    # A function-level import outside the core must come from an extra (PyPI name of the module).
    extras = {
        _requirement_name(d)
        for group in PYPROJECT["project"]["optional-dependencies"].values()
        for d in group
    }
    pypi = {"yaml": "pyyaml"}
    assert {pypi.get(m, m) for m in optional - declared} <= extras, optional


def test_extras_cover_the_environments():
    extras = PYPROJECT["project"]["optional-dependencies"]
    names = {k: {_requirement_name(d) for d in v} for k, v in extras.items()}
    assert {"workflow", "test", "notebooks", "cluster", "docs"} <= set(names)
    assert "snakemake" in names["workflow"]
    assert {"jupyterlab", "jupytext", "ipympl", "ipykernel"} <= names["notebooks"]
    assert "snakemake-executor-plugin-slurm" in names["cluster"]


def test_locks_pin_the_same_versions():
    """Every package the three lock files share has one pin (the locks are constrained)."""

    def pins(name: str) -> dict[str, str]:
        text = (ROOT / name).read_text()
        return dict(re.findall(r"^([A-Za-z0-9_.\-]+)==(\S+)", text, flags=re.M))

    main = pins("requirements.lock")
    for other in ("requirements-cluster.lock", "requirements-notebooks.lock"):
        theirs = pins(other)
        differ = {k: (main[k], v) for k, v in theirs.items() if k in main and main[k] != v}
        assert not differ, f"{other} pins differently from requirements.lock: {differ}"
    assert "snakemake" in main and "mkdocs" in main and "jupyterlab" not in main
    assert "jupyterlab" in pins("requirements-notebooks.lock")


def test_one_version_everywhere():
    """pyproject.toml is the source; CHANGELOG, CITATION.cff and the installed metadata agree."""
    import restitution

    changelog = (ROOT / "CHANGELOG.md").read_text()
    releases = re.findall(r"^## \[(\d+\.\d+\.\d+)\]", changelog, flags=re.M)
    assert releases and releases[0] == VERSION, f"CHANGELOG.md's newest release {releases[:1]}"
    citation = (ROOT / "CITATION.cff").read_text()
    assert re.search(rf"^version: ['\"]?{re.escape(VERSION)}['\"]?$", citation, flags=re.M)
    assert restitution.__version__ == VERSION, (
        f"installed metadata says {restitution.__version__}: rerun `make env` after a version bump"
    )
    init = (ROOT / "src" / "restitution" / "__init__.py").read_text()
    # A release number typed in the package would be a second source ("0+unknown", the fallback
    # for an uninstalled source tree, is not one).
    typed = re.search(r"__version__\s*=\s*['\"]\d+\.\d+", init)
    assert typed is None, f"version typed in __init__.py: {typed.group(0)}"


def test_package_data_declared():
    data = PYPROJECT["tool"]["setuptools"]["package-data"]["restitution"]
    assert {"restitution.mplstyle", "py.typed"} <= set(data)
    for name in data:
        assert (ROOT / "src" / "restitution" / name).is_file(), name
    assert "LICENSE" in PYPROJECT["project"]["license-files"]
    assert "MIT License" in (ROOT / "LICENSE").read_text()


@pytest.mark.slow
def test_built_wheel_runs_without_snakemake(tmp_path):
    """Build, install non-editable into a fresh venv without the extras, run CLI and library."""
    result = subprocess.run(
        [sys.executable, str(ROOT / ".ci" / "wheel_check.py"), "--workdir", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-4000:]
    assert "snakemake: not installed" in result.stdout
    assert f"restitution-{VERSION}-py3-none-any.whl" in result.stdout
    record = [line for line in result.stdout.splitlines() if line.startswith('{"alpha": 0.7')]
    assert record, "no JSON line from `restitution cor --alpha 0.7 --json`"
    assert "wheel_check: ok" in result.stdout


LAB_PYTHON = ROOT / ".venv-notebooks" / "bin" / "python"


@pytest.mark.slow
@pytest.mark.skipif(
    not LAB_PYTHON.exists(), reason="no .venv-notebooks (make notebooks-env builds it)"
)
def test_lab_serves_the_notebook():
    """`make lab`'s command, headless: JupyterLab answers over HTTP and lists the notebook."""
    result = subprocess.run(
        [str(LAB_PYTHON), str(ROOT / ".ci" / "lab_check.py")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-4000:]
    assert "cor_explorer.py" in result.stdout


def test_no_references_outside_the_repository():
    """README and docs/ never point to files that are not in the repository."""
    texts = [ROOT / "README.md", ROOT / "CONTRIBUTING.md", *sorted((ROOT / "docs").rglob("*.md"))]
    bad = re.compile(r"DESIGN\.md|/work/|shared folder|\bpaper/")
    hits = [
        f"{p.relative_to(ROOT)}: {m.group(0)}" for p in texts for m in bad.finditer(p.read_text())
    ]
    assert not hits, hits


def test_docs_nav_files_exist():
    """Every page in mkdocs.yml's nav is in docs/, and every docs page is in the nav."""
    text = (ROOT / "mkdocs.yml").read_text()
    nav = text[text.index("\nnav:") :]
    pages = re.findall(r":\s*([\w/.-]+\.md)\s*$", nav, flags=re.M)
    assert "index.md" in pages and "api.md" in pages
    missing = {p for p in pages if not (ROOT / "docs" / p).is_file()}
    assert not missing, f"nav entries without a page: {sorted(missing)}"
    on_disk = {str(p.relative_to(ROOT / "docs")) for p in (ROOT / "docs").rglob("*.md")}
    assert on_disk <= set(pages), f"docs pages not in the nav: {sorted(on_disk - set(pages))}"
