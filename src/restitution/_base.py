"""What every module of the package may import: it imports nothing of the package itself, so
the scene model (restitution.chain) and the laws' packing (restitution.laws), which must not
import each other, share these without an import cycle."""


class SceneError(ValueError):
    """A scene parameter is outside its allowed range."""


# The largest chain accepted: the range declared for the paper's n_masses. Every scene also has a
# work budget counted in operations inside the kernels, which ends a sequence that would run too
# long with an honest status (never a silent result).
MAX_MASSES = 512
