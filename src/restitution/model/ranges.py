"""What every module of the package may import: it imports nothing of the package itself, so
the scene model (restitution.model.chain) and the laws' packing (restitution.model.laws), which
must not
import each other, share these without an import cycle."""

import math
import numbers
import sys
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np


class SceneError(ValueError):
    """A scene parameter is outside its allowed range."""


# The largest chain accepted: the range declared for the paper's n_masses. Every scene also has a
# work budget counted in operations inside the kernels, which ends a sequence that would run too
# long with an honest status (never a silent result).
MAX_MASSES = 512


def missing_cell(v) -> bool:
    """A missing table cell: None, NaN or pandas' NA (what a parquet null becomes with
    ``dtype_backend="pyarrow"``); a law or setting cell then takes its default."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return True
    # Only a loaded pandas can have made its NA: no import of pandas (0.2 s) for a CLI call.
    pandas = sys.modules.get("pandas")
    return pandas is not None and v is pandas.NA


def missing_list(v) -> bool:
    """A missing list cell (dashpots): None, NaN or blank text."""
    return missing_cell(v) or (isinstance(v, str) and v.strip() == "")


@dataclass(frozen=True)
class Range:
    """An allowed interval [low, high] (``low_open``: (low, ...; ``high_open``: ..., high));
    ``text`` is how it reads in an error message."""

    low: float
    high: float
    low_open: bool
    text: str
    integer: bool = False
    high_open: bool = False

    def contains(self, x: float) -> bool:
        """Scalar membership, plain Python (the fast path of ``chain.check``)."""
        above = x > self.low if self.low_open else x >= self.low
        below = x < self.high if self.high_open else x <= self.high
        return above and below and (not self.integer or x.is_integer())

    def accepts(self, x: np.ndarray) -> np.ndarray:
        """Vectorised membership (NaN is never in range)."""
        above = x > self.low if self.low_open else x >= self.low
        ok = above & ((x < self.high) if self.high_open else (x <= self.high))
        if self.integer:
            ok &= np.floor(x) == x
        return ok


# Most contacts a history may record: its rows (48 bytes each) are allocated before the solve,
# so max_events with history=True (and for trajectory) is bounded by what can be allocated.
HISTORY_MAX_EVENTS = 10_000_000

# The one table of parameter ranges: the scene (restitution.model.chain checks them, the workflow's
# configuration check calls ``chain.check``), the laws (restitution.model.laws) and the settings.
RANGES = {
    # Below 1e-8 the linear kernels lose the light masses to round-off (alpha = 5e-324 gave garbage
    # rows marked ok); 1e-8 is also the floor of the mass ratios of the general form (RATIOS).
    "alpha": Range(1e-8, 1e8, False, "in [1e-8, 1e8]"),
    "beta": Range(0.0, 1e6, False, "in [0, 1e6] (0 = rigid wall)"),
    "xi": Range(0.0, 1e3, False, "in [0, 1e3]"),
    "n_masses": Range(2, MAX_MASSES, False, f"an integer in [2, {MAX_MASSES}]", integer=True),
    # Any consistent units, within 200 decades so that the scaling to the kernels' units
    # (products of two of them) cannot overflow; their ratios have ranges of their own (RATIOS).
    "masses": Range(1e-100, 1e100, False, "in [1e-100, 1e100]", integer=False),
    "springs": Range(1e-100, 1e100, False, "in [1e-100, 1e100]"),
    "dashpots": Range(0.0, 1e100, False, "in [0, 1e100]"),
    "k_contact": Range(0.0, math.inf, True, "> 0 (math.inf = rigid wall)"),
    # Below 1e-6 the plastic law's kappa ~ v0**(1 - eta) and the Hertz contact's stiffness
    # ~ v0**0.4 leave float64's range or make the contact so soft that no work budget finishes
    # it (tests/test_nonlinear_chain.py); one range for every law, linear ones included.
    "v0": Range(1e-6, 1e6, False, "in [1e-6, 1e6]"),
    "max_events": Range(1, 2**62, False, "a positive integer", integer=True),
    # A given initial state (docs/general-chains.md): approach velocities (positive: towards the
    # wall) within v0's range of magnitudes, link extensions within the masses' and springs'
    # 200 decades; their ratios to the centre of mass's approach have ranges of their own
    # (chain.INITIAL_RATIO).
    "velocities": Range(-1e6, 1e6, False, "in [-1e6, 1e6] (positive: towards the wall)"),
    "stretches": Range(-1e100, 1e100, False, "in [-1e100, 1e100] (positive: stretched)"),
    "rtol": Range(1e-14, 1e-2, False, "in [1e-14, 1e-2]"),
    "step": Range(0.0, 0.25, True, "in (0, 0.25]"),
    # Law parameters (restitution.model.laws; their combinations are checked there).
    "eta": Range(0.0, 10.0, True, "in (0, 10]"),
    "dr": Range(0.0, 1.0, False, "in [0, 1)", high_open=True),
    # L and corner set the corner stroke dc = corner * 2 L cos(theta_lock) and its stiffening
    # k2/dc: from the smallest floats (5e-324) dc was 0 and k2/dc overflowed.
    "L": Range(1e-6, 1e6, False, "in [1e-6, 1e6]"),
    # Within 1e-3 of 0 or pi/2 the scissor degenerates: its rest slope ks*cot(theta0)**2 needs
    # ks_ratio below tan(theta0)**2 ~ 1e-6, and next to pi/2 the lock angle meets theta0 (the
    # corner stroke 2 L cos(theta_lock) is 0 in float64 within 3e-8 of pi/2).
    "theta0": Range(1e-3, math.pi / 2 - 1e-3, False, "in [1e-3, pi/2 - 1e-3] (radians)"),
    "ks_ratio": Range(0.0, math.inf, True, "> 0 (and below tan(theta0)**2)"),
    "corner": Range(1e-3, 100.0, False, "in [1e-3, 100]"),
}


def _show(value) -> str:
    """repr of a value as a user typed it (numpy scalars shown as plain Python numbers), cut to
    one short line (a 400-digit integer or a long list would bury the message)."""
    text = repr(value.item() if isinstance(value, np.generic) else value)
    text = " ".join(text.split())
    return text if len(text) <= 80 else text[:60] + " ... " + text[-12:]


def _real(value) -> float | None:
    """``value`` as a float if it is one real number (int, float, Decimal, Fraction, numpy
    scalar; a huge integer becomes inf, which no finite range accepts), else None: booleans,
    text, complex numbers (their imaginary part would be dropped), arrays and containers."""
    if isinstance(value, (bool, np.bool_, str, bytes, complex, np.complexfloating)):
        return None
    if isinstance(value, np.ndarray):
        if value.ndim != 0:
            return None
        if value.dtype.kind == "O":  # the object it holds, read as that object would be
            return _real(value.item())
        # float() would parse a text array (np.array("0.5")) and read a boolean one as 0 or 1
        return _real(value[()]) if value.dtype.kind in "fiu" else None
    if not isinstance(value, (numbers.Real, np.number)):
        try:  # other real types (e.g. Decimal): through float, but never a container
            if np.ndim(value) != 0 or isinstance(value, (Mapping, list, tuple, set)):
                return None
            return float(value)
        except (TypeError, ValueError, OverflowError):
            return None
    try:
        return float(value)
    except OverflowError:  # an integer beyond float64
        return math.inf if value > 0 else -math.inf
    except (TypeError, ValueError):
        return None
