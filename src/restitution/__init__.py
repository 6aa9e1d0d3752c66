"""restitution: the coefficient of restitution of mass-spring chains hitting a wall.

Reference implementation of *The unexpectedly small coefficient of restitution of a
two-degree-of-freedom mass-spring system and its implications*. ``solve`` gives one scene (the
paper's form or any chain), ``solve_many`` a table of scenes, ``trajectory`` the motion of one
scene; ``Chain`` is the scene model and ``methods.METHODS`` the solver table.
"""

from importlib.metadata import PackageNotFoundError, version

from .compiling import ensure_cache

ensure_cache()  # before any kernel is defined: a foreign or read-only NUMBA_CACHE_DIR

from .api import solve, solve_many  # noqa: E402
from .chain import Chain, SceneError  # noqa: E402
from .result import Result  # noqa: E402
from .scene import Scene  # noqa: E402
from .trajectory import trajectory  # noqa: E402

try:
    __version__ = version("restitution")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"

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
