"""What every module of the package may import: it imports nothing of the package itself, so
the scene model (restitution.chain) and the laws' packing (restitution.laws), which must not
import each other, share these without an import cycle."""

import math

from pandas import NA


class SceneError(ValueError):
    """A scene parameter is outside its allowed range."""


# The largest chain accepted: the range declared for the paper's n_masses. Every scene also has a
# work budget counted in operations inside the kernels, which ends a sequence that would run too
# long with an honest status (never a silent result).
MAX_MASSES = 512


def missing_cell(v) -> bool:
    """A missing table cell: None, NaN or pandas' NA (what a parquet null becomes with
    ``dtype_backend="pyarrow"``); a law or setting cell then takes its default."""
    return v is None or v is NA or (isinstance(v, float) and math.isnan(v))


def missing_list(v) -> bool:
    """A missing list cell (dashpots): None, NaN or blank text."""
    return missing_cell(v) or (isinstance(v, str) and v.strip() == "")
