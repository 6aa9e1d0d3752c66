"""The documentation runs: every ```python block of README.md and docs/**/*.md is executed, and
every `restitution ...` and `python -c ...` line of their shell blocks is run (small inputs).

Conventions in the Markdown (invisible in the rendered pages):

- Blocks run in order, per file, in one fresh namespace, in a temporary working directory.
- ``<!-- no-run: reason -->`` right before a block skips it (fragments of a source change, runs
  of minutes); the reason is required and few blocks may carry it (``MAX_SKIPPED``).
- ``<!-- source: PATH -->`` right before a block says it is an excerpt of that file of the
  repository (the guides quote the package): its lines must appear there, in order, consecutive.
- ``<!-- file: NAME -->`` right before a block writes it to NAME in that directory first (a YAML
  study the next Python block reads).
- ``expression  # -> EXPECTED`` (or ``print(...)  # -> EXPECTED``) checks the value's ``repr``
  (or the printed line) against EXPECTED, where ``...`` stands for any characters (doctest's
  ELLIPSIS); text after ``; `` is commentary. ``0.178467...`` thus pins six digits.
"""

from __future__ import annotations

import ast
import contextlib
import io
import re
import shlex
import subprocess
import sys
import textwrap
import types
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FILES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
MAX_SKIPPED = 8  # blocks marked no-run, in all files together

FENCE = re.compile(r"^(?P<indent> *)```(?P<lang>[\w-]*)[^\n]*\n(?P<body>.*?)^(?P=indent)```",
                   re.S | re.M)  # fmt: skip
MARKER = re.compile(r"<!--\s*(?P<kind>no-run|file|source):\s*(?P<arg>.*?)\s*-->\s*$")
EXPECT = re.compile(r"#\s*->\s*(?P<expected>.*?)\s*(?:;\s.*)?$")


@dataclass
class Block:
    path: Path
    line: int  # of the opening fence, 1-based
    lang: str
    code: str
    marker: tuple[str, str] | None  # ("no-run", reason), ("file", name), ("source", path)

    def __str__(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def blocks(path: Path) -> list[Block]:
    text = path.read_text()
    found = []
    for m in FENCE.finditer(text):
        before = text[: m.start()].rstrip("\n ").rsplit("\n", 1)[-1]
        mark = MARKER.search(before)
        code = textwrap.dedent(m.group("body"))
        line = text.count("\n", 0, m.start()) + 1
        marker = (mark["kind"], mark["arg"]) if mark else None
        found.append(Block(path, line, m.group("lang"), code, marker))
    return found


ALL = [b for path in FILES for b in blocks(path)]
PYTHON = [b for b in ALL if b.lang == "python"]
SHELL = [b for b in ALL if b.lang in ("bash", "sh", "")]


def _matches(expected: str, got: str) -> bool:
    pattern = ".*".join(re.escape(part) for part in expected.split("..."))
    return re.fullmatch(pattern, got, re.S) is not None


def run_block(block: Block, namespace: dict) -> int:
    """Executes the block statement by statement; returns how many outputs it checked."""
    lines = block.code.splitlines()
    checked = 0
    for node in ast.parse(block.code, filename=str(block)).body:
        comments = [EXPECT.search(lines[i]) for i in range(node.lineno - 1, node.end_lineno)]
        expect = next((c["expected"] for c in comments if c), None)
        where = f"{block.path.name}:{block.line + node.lineno}"
        if expect is None:
            exec(compile(ast.Module([node], []), where, "exec"), namespace)
            continue
        assert isinstance(node, ast.Expr), f"{where}: '# ->' follows an expression"
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            value = eval(compile(ast.Expression(node.value), where, "eval"), namespace)
        printed = out.getvalue().rstrip("\n")
        got = printed if printed or value is None else repr(value)
        assert _matches(expect, got), f"{where}: expected {expect!r}, got {got!r}"
        checked += 1
    return checked


@pytest.mark.parametrize(
    "path", [p for p in FILES if any(b.path == p for b in PYTHON)], ids=lambda p: p.name
)
def test_python_blocks_run(path, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "__doc_example__"}
    for block in [b for b in ALL if b.path == path]:
        if block.marker and block.marker[0] == "file":
            (tmp_path / block.marker[1]).write_text(block.code)
        elif block.lang == "python" and not block.marker:
            run_block(block, namespace)


def test_few_blocks_are_skipped_and_each_says_why():
    skipped = [b for b in ALL if b.marker and b.marker[0] == "no-run"]
    assert all(b.lang == "python" for b in skipped), [str(b) for b in skipped]
    assert all(len(b.marker[1]) >= 10 for b in skipped), [str(b) for b in skipped]
    assert len(skipped) <= MAX_SKIPPED, [str(b) for b in skipped]
    run = [b for b in PYTHON if not b.marker]
    assert len(run) >= 8  # the extraction found the blocks
    for b in (b for b in ALL if b.marker and b.marker[0] == "file"):
        assert re.fullmatch(r"[\w.-]+", b.marker[1]), f"{b}: a plain file name"
    quoted = [b for b in ALL if b.marker and b.marker[0] == "source"]
    assert len(quoted) >= 4 and all(b.lang == "python" for b in quoted)


@pytest.mark.parametrize("block", [b for b in ALL if b.marker and b.marker[0] == "source"], ids=str)
def test_quoted_source_is_in_its_file(block):
    source = [line.strip() for line in (ROOT / block.marker[1]).read_text().splitlines()]
    quoted = [line.strip() for line in block.code.splitlines() if line.strip()]
    starts = [i for i, line in enumerate(source) if line == quoted[0]]
    assert any(source[i : i + len(quoted)] == quoted for i in starts), (
        f"{block}: not found in {block.marker[1]} (update the excerpt)"
    )


def test_output_convention():
    assert _matches("0.178467...", "0.1784671234") and not _matches("0.178467...", "0.17847")
    assert _matches("'adaptive'", "'adaptive'") and not _matches("'adaptive'", "'adaptive+x'")
    block = Block(ROOT / "x.md", 1, "python", "x = 2\nx / 3  # -> 0.666...; two thirds\n", None)
    assert run_block(block, {}) == 1
    block.code = "print(1, 2 / 3)  # -> 1 0.66...\n"
    assert run_block(block, {}) == 1
    block.code = "x = 2\nx / 3  # -> 0.67...\n"
    with pytest.raises(AssertionError, match="expected '0.67...', got '0.6666"):
        run_block(block, {})


def test_docs_check_outputs():
    """The convention is used: the docs pin their printed values."""
    lines = [line for b in PYTHON if not b.marker for line in b.code.splitlines()]
    assert sum(EXPECT.search(line) is not None for line in lines) >= 7


# --- command lines ---------------------------------------------------------------------------


def cli_lines() -> list[tuple[Block, list[str]]]:
    found = []
    for block in SHELL:
        for line in block.code.splitlines():
            words = shlex.split(line, comments=True)
            if words[:1] == ["restitution"] or words[:2] == ["python", "-c"]:
                found.append((block, words))
    return found


CLI = cli_lines()


def test_docs_have_command_lines():
    subcommands = {words[1] for _, words in CLI if words[0] == "restitution"}
    assert len(CLI) >= 6 and subcommands >= {"cor", "batch", "--version"}


@pytest.mark.parametrize("block, words", CLI, ids=[f"{b}:{' '.join(w)}" for b, w in CLI])
def test_command_lines_in_docs_run(block, words, tmp_path):
    """Each documented command exits 0; a batch input it names is written first (two scenes)."""
    if words[1:2] == ["batch"] and not (tmp_path / words[2]).exists():
        (tmp_path / words[2]).write_text("alpha,beta\n0.5,0.0\n2.0,0.01\n")
    command = [sys.executable, *words[1:]]  # python -c ...: this interpreter
    if words[0] == "restitution":
        command[1:1] = ["-m", "restitution.cli"]
    p = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, f"{block}: {shlex.join(words)}\n{p.stderr}"


# --- the API reference -----------------------------------------------------------------------

# Modules of the package that docs/api.md does not render, and why. Every other module is.
NOT_IN_API = {
    "restitution.api": "its solve and solve_many are rendered under restitution",
    "restitution.model.chain": "its Chain is rendered under restitution",
    "restitution.model.ranges": "its SceneError is rendered under restitution; RANGES in docs",
    "restitution.solvers.result": "its Result is rendered under restitution",
    "restitution.trajectories": "its trajectory is rendered under restitution",
    "restitution.tables.linear_rows": "internal: the column-wise fast path of solve_many",
    "restitution.kernels": "the numba kernels, internal (docs/guides/adding-a-method.md)",
    "restitution.solvers.numerical": "internal: the numerical methods' runners (methods)",
    "restitution.solvers.exact": "internal: the exact methods' runners (adding-a-method.md)",
    "restitution.warmup": "behind `restitution warmup` (docs/install.md)",
    "restitution.jit": "internal: the numba decorator of the kernels (docs/install.md)",
}


def api_directives() -> dict[str, list[str] | None]:
    """docs/api.md's ``::: module`` directives -> their ``members:`` list (None: all)."""
    text = (ROOT / "docs" / "api.md").read_text()
    found = {}
    for m in re.finditer(r"^::: ([\w.]+)\n((?:    .*\n)*)", text, re.M):
        members = re.search(r"members: \[(.*)\]", m.group(2))
        found[m.group(1)] = [s.strip() for s in members[1].split(",")] if members else None
    return found


def test_api_reference_renders_every_public_name():
    import restitution

    directives = api_directives()
    package = directives["restitution"]
    for name in restitution.__all__:
        if name == "__version__":
            assert "`restitution.__version__`" in (ROOT / "docs" / "api.md").read_text()
            continue
        value = getattr(restitution, name)
        if isinstance(value, types.ModuleType):  # restitution.design: its module's directive
            assert value.__name__ in directives, f"docs/api.md: {value.__name__}"
            continue
        defined = f"{value.__module__}.{name}"  # rendered on its own
        assert name in package or defined in directives, f"docs/api.md: restitution.{name}"
    assert set(package) <= set(restitution.__all__), "members that are not public"
    precise = directives["restitution.solvers.precise"]
    assert precise is None or "solve_precise" in precise
    for module in (
        "restitution.solvers.methods",
        "restitution_workflow.study",
        "restitution.analysis.cormap",
    ):
        assert module in directives


def test_api_reference_covers_every_module():
    """Every module of the library is rendered or listed in NOT_IN_API (the kernels as one)."""
    src = ROOT / "src" / "restitution"
    modules = set()
    for p in src.rglob("*.py"):
        parts = ("restitution", *p.relative_to(src).with_suffix("").parts)
        if parts[-1].startswith("_") or parts[1] == "kernels":
            continue
        modules.add(".".join(parts))
    modules.add("restitution.kernels")
    documented = set(api_directives()) & modules  # module directives (not functions)
    assert not documented & NOT_IN_API.keys(), "rendered and listed as not rendered"
    assert modules - documented - NOT_IN_API.keys() == set(), "add them to docs/api.md"
    assert NOT_IN_API.keys() <= modules  # no stale entries


# --- installation ----------------------------------------------------------------------------


def test_install_page_lists_the_core_dependencies_of_pyproject():
    import tomllib

    declared = {}
    for req in tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]:
        name, version = re.fullmatch(r"([\w-]+)>=([\d.]+)", req).groups()
        declared[name] = version
    text = (ROOT / "docs" / "install.md").read_text()
    table = dict(re.findall(r"^\| ([\w-]+) \| >= ([\d.]+) \|", text, re.M))
    assert table == declared
    readme = next(line for line in (ROOT / "README.md").read_text().splitlines()
                  if line.startswith("pip install . "))  # fmt: skip
    assert re.findall(r"[\w-]+", readme.split("core:")[1]) == list(declared)


# --- sizes the docs state --------------------------------------------------------------------


def test_index_counts_are_the_workflows():
    """docs/index.md's panel and job counts of `make all`, computed here (no typed numbers)."""
    from conftest import run_snakemake

    text = " ".join((ROOT / "docs" / "index.md").read_text().split())
    panels = int(re.search(r"draws the (\d+) figure panels in `figures/`", text)[1])
    jobs = int(re.search(r"(\d+) Snakemake jobs from a clean state", text)[1])
    assert panels == len(list((ROOT / "figures").glob("fig*.png")))
    result = run_snakemake("-n", "--forceall", "all", "--quiet", "rules")
    assert result.returncode == 0, result.stderr
    assert jobs == int(re.search(r"^total\s+(\d+)$", result.stdout, re.M)[1])
