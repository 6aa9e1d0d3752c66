"""No import cycle inside the package, function-level imports included (a lazy import only hides
a cycle until the import order changes): the module graph must sort topologically."""

import ast
import graphlib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src" / "restitution"


def _modules() -> dict:
    mods = {}
    for path in ROOT.rglob("*.py"):
        parts = ("restitution", *path.relative_to(ROOT).with_suffix("").parts)
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        mods[name] = path
    return mods


def _imports(name: str, path: Path, mods: dict) -> set:
    """Modules of the package that ``name`` imports anywhere in its source."""
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            subs = {f"{target}.{a.name}" for a in node.names} & mods.keys()
            found |= subs or ({target} & mods.keys())
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names} & mods.keys()
    return found - {name}


def test_the_module_graph_has_no_cycle():
    mods = _modules()
    graph = {name: _imports(name, path, mods) for name, path in mods.items()}
    assert (
        "restitution.kernels.exact_chain" in graph["restitution.kernels.paper_chain"]
    )  # the parse works
    graphlib.TopologicalSorter(graph).static_order()  # raises CycleError naming the cycle


# The package's layers from the ground up (restitution/__init__.py describes them): a module
# imports only from its own layer or the layers below.
LAYERS = (
    ("restitution.jit",),
    ("restitution.model",),
    ("restitution.kernels",),
    ("restitution.solvers",),
    ("restitution.tables",),
    ("restitution.api", "restitution.trajectories"),
    ("restitution.analysis",),
    ("restitution.plotting", "restitution.warmup", "restitution.cli", "restitution"),
)


def _floor(name: str) -> int:
    for floor, members in enumerate(LAYERS):
        for member in members:
            if name == member or name.startswith(member + ".") and member != "restitution":
                return floor
    raise AssertionError(f"{name} is in no layer of LAYERS: place it")


def test_every_import_runs_down_the_layers():
    mods = _modules()
    upward = [
        f"{name} -> {target}"
        for name, path in mods.items()
        for target in _imports(name, path, mods)
        if _floor(target) > _floor(name)
    ]
    assert upward == []


def test_the_workflow_support_is_not_imported_by_the_library():
    """src/restitution_workflow is not in the wheel: the library must never import it."""
    for path in ROOT.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            else:
                continue
            assert not any(n.split(".")[0] == "restitution_workflow" for n in names), path
