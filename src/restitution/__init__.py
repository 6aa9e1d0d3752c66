"""restitution: the coefficient of restitution of mass-spring chains hitting a wall.

Reference implementation of *The unexpectedly small coefficient of restitution of a
two-degree-of-freedom mass-spring system and its implications*. ``solve`` gives one scene (the
paper's form or any chain), ``solve_many`` a table of scenes, ``trajectory`` the motion of one
scene; ``Chain`` is the scene model and ``restitution.solvers.methods.METHODS`` the solver table.

The package is split by layer, each importing only from the layers below it
(tests/test_import_graph.py checks the order):

0. ``restitution.jit`` -- the ``njit`` decorator every numba kernel is defined with;
1. ``restitution.model`` -- the scene (``Chain``), the range table, the contact and link laws;
2. ``restitution.kernels`` -- the numba kernels (exact event-driven and time-stepping);
3. ``restitution.solvers`` -- the solver table (the one place a method is chosen), its runners,
   the ``Result``;
4. ``restitution.tables`` -- strict scene tables, parquet/CSV input and output;
5. ``restitution.api`` (``solve``, ``solve_many``) and ``restitution.trajectories``
   (``trajectory``) -- the entry points;
6. ``restitution.analysis`` -- the paper's approximate model, sweeps, the grazing map, designs;
7. ``restitution.plotting`` and ``restitution.cli`` -- the house style and the command line.

The names below are imported on first use (module ``__getattr__``), so that ``import
restitution`` and the ``restitution`` command stay cheap until a solver is needed.
"""

from __future__ import annotations

import importlib

from restitution.kernels.compiling import ensure_cache

ensure_cache()  # before any kernel is defined: a foreign or read-only NUMBA_CACHE_DIR

# Public name -> the module defining it (imported on first access). ``design`` is a module.
_LAZY = {
    "Chain": "restitution.model.chain",
    "Result": "restitution.solvers.result",
    "SceneError": "restitution.model.ranges",
    "solve": "restitution.api",
    "solve_many": "restitution.api",
    "trajectory": "restitution.trajectories",
}
_MODULES = {"design": "restitution.analysis.design"}

TYPE_CHECKING = False  # (typing.TYPE_CHECKING without importing typing: 10 ms)
if TYPE_CHECKING:  # for type checkers and IDEs: the same names, imported eagerly
    from restitution.analysis import design
    from restitution.api import solve, solve_many
    from restitution.model.chain import Chain
    from restitution.model.ranges import SceneError
    from restitution.solvers.result import Result
    from restitution.trajectories import trajectory

__all__ = [
    "Chain",
    "Result",
    "SceneError",
    "design",
    "solve",
    "solve_many",
    "trajectory",
    "__version__",
]


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("restitution")
    except PackageNotFoundError:  # running from a source tree without installation
        return "0+unknown"


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
    elif name in _MODULES:
        value = importlib.import_module(_MODULES[name])
    elif name == "__version__":
        value = _version()
    elif not name.startswith("__"):  # a layer: restitution.model, restitution.solvers, ...
        try:
            value = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as e:
            if e.name != f"{__name__}.{name}":
                raise  # the submodule exists but one of its imports is missing
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value  # later accesses skip __getattr__
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
