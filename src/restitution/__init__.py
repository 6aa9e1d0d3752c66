"""restitution: the coefficient of restitution of mass-spring systems hitting a wall.

Reference implementation of *The unexpectedly small coefficient of restitution of a
two-degree-of-freedom mass-spring system and its implications*. ``solve`` gives one scene,
``solve_many`` a table of scenes; the conventions are in the README.
"""

from importlib.metadata import PackageNotFoundError, version

from .api import solve, solve_many
from .result import Result
from .scene import Scene, SceneError

try:
    __version__ = version("restitution")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"

__all__ = ["Result", "Scene", "SceneError", "solve", "solve_many", "__version__"]
