"""restitution: the coefficient of restitution of mass-spring chains hitting a wall.

Reference implementation of *The unexpectedly small coefficient of restitution of a
two-degree-of-freedom mass-spring system and its implications*. ``solve`` gives one scene (the
paper's form or any chain), ``solve_many`` a table of scenes, ``trajectory`` the motion of one
scene; ``Chain`` is the scene model and ``methods.METHODS`` the solver table.
"""

from importlib.metadata import PackageNotFoundError, version

from .api import solve, solve_many
from .chain import Chain, SceneError
from .result import Result
from .scene import Scene
from .trajectory import trajectory

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
