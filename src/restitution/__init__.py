"""restitution: the coefficient of restitution of mass-spring chains hitting a wall.

Reference implementation of *The unexpectedly small coefficient of restitution of a
two-degree-of-freedom mass-spring system and its implications*. ``solve`` gives one scene (the
paper's form or any chain), ``solve_many`` a table of scenes, ``trajectory`` the motion of one
scene; ``Chain`` is the scene model and ``methods.METHODS`` the solver table.

The names below are imported on first use (module ``__getattr__``), so that ``import
restitution`` and the ``restitution`` command stay cheap until a solver is needed:
``restitution.solve``, ``from restitution import solve`` and ``restitution.methods`` all work
as if they had been imported here.
"""

from __future__ import annotations

import importlib
import sys
import types

from .compiling import ensure_cache

ensure_cache()  # before any kernel is defined: a foreign or read-only NUMBA_CACHE_DIR

# Public name -> the submodule defining it (imported on first access).
_LAZY = {
    "Chain": "chain",
    "Result": "result",
    "Scene": "scene",
    "SceneError": "chain",
    "solve": "api",
    "solve_many": "api",
    "trajectory": "trajectory",
}

TYPE_CHECKING = False  # (typing.TYPE_CHECKING without importing typing: 10 ms)
if TYPE_CHECKING:  # for type checkers and IDEs: the same names, imported eagerly
    from .api import solve, solve_many
    from .chain import Chain, SceneError
    from .result import Result
    from .scene import Scene
    from .trajectory import trajectory

__all__ = [
    "Chain",
    "Result",
    "Scene",
    "SceneError",
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
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    elif name == "__version__":
        value = _version()
    elif not name.startswith("__"):  # a submodule: restitution.methods, restitution.io, ...
        try:
            value = importlib.import_module(f".{name}", __name__)
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


class _Package(types.ModuleType):
    """The package module: ``restitution.trajectory`` stays the function.

    The function and its submodule share a name. Importing the submodule (``import
    restitution.trajectory``, or a first ``from restitution import trajectory``) sets the
    package's attribute to the module; this puts the function there instead, as the eager
    ``from .trajectory import trajectory`` did (the module stays in ``sys.modules``).
    """

    def __setattr__(self, name: str, value) -> None:
        if isinstance(value, types.ModuleType) and name in _LAZY and _LAZY[name] == name:
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
