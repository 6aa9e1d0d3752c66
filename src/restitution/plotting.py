"""House plotting helpers: one style, headless and byte-for-byte reproducible figures.

>>> from restitution import plotting
>>> plotting.use_style()
>>> fig = plotting.new_figure()
>>> ax = fig.add_subplot()
>>> paths = plotting.save_figure(fig, "figures/example")  # doctest: +SKIP

Figures are drawn on matplotlib's Agg canvas without pyplot, so no display and no global state
are needed, and ``save_figure`` strips timestamps from the pdf (``CreationDate``) so rendering the
same data twice gives identical files.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

import matplotlib as mpl
import matplotlib.style
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

STYLE = Path(__file__).with_name("restitution.mplstyle")

#: Widths of a journal page in inches: one column, one and a half, full width.
WIDTHS = {"single": 3.4, "onehalf": 5.0, "double": 7.0}

#: Metadata per format: no dates, so the bytes depend only on the data and library versions.
METADATA = {
    "png": {"Software": None},
    "pdf": {"CreationDate": None, "ModDate": None},
    "svg": {"Date": None},
}


def use_style() -> None:
    """Apply the house style (``restitution.mplstyle``) to matplotlib's global settings."""
    mpl.style.use(STYLE)


def new_figure(width: str | float = "single", aspect: float = 0.76, **kwargs) -> Figure:
    """A Figure on an Agg canvas in the house style; ``width`` a key of WIDTHS or inches.

    ``aspect`` is height / width. Extra keyword arguments go to :class:`matplotlib.figure.Figure`.
    """
    use_style()
    w = WIDTHS[width] if isinstance(width, str) else float(width)
    fig = Figure(figsize=(w, w * aspect), **kwargs)
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, stem, formats: Iterable[str] = ("png", "pdf")) -> list[Path]:
    """Write ``fig`` to ``stem.<format>`` for each format, deterministically; return the paths.

    >>> save_figure(new_figure(), "/tmp/empty")  # doctest: +SKIP
    [PosixPath('/tmp/empty.png'), PosixPath('/tmp/empty.pdf')]
    """
    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    paths = []
    with mpl.rc_context({"svg.hashsalt": "restitution"}):
        for fmt in formats:
            path = stem.with_name(f"{stem.name}.{fmt}")
            fig.savefig(path, format=fmt, metadata=METADATA.get(fmt))
            paths.append(path)
    return paths


def save_outputs(fig: Figure, png_path, pdf_path, logger=None) -> list[Path]:
    """Write a rule's png and pdf outputs (which must share a stem) with ``save_figure``."""
    stem = Path(png_path).with_suffix("")
    if Path(pdf_path).with_suffix("") != stem:
        raise ValueError(f"png and pdf outputs must share a stem: {png_path}, {pdf_path}")
    paths = save_figure(fig, stem, formats=("png", "pdf"))
    for path in paths:
        if logger is not None:
            logger.info("wrote %s", path)
    return paths


def log_axis(ax, which: str = "x") -> None:
    """Log scale with plain-number labels (0.1, 1, 10, 100) and unlabelled minor ticks."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axis = ax.xaxis if which == "x" else ax.yaxis
    (ax.set_xscale if which == "x" else ax.set_yscale)("log")
    axis.set_major_locator(LogLocator(base=10))
    axis.set_major_formatter(FuncFormatter(lambda value, _pos: f"{value:g}"))
    axis.set_minor_locator(LogLocator(base=10, subs=tuple(range(2, 10))))
    axis.set_minor_formatter(NullFormatter())


def beta_text(beta: float) -> str:
    r"""Legend text for a stiffness ratio: ``0 (rigid wall)``, ``10^{-3}``-style powers of ten."""
    if beta == 0:
        return r"$\beta = 0$ (rigid wall)"
    exponent = math.log10(beta)
    if abs(exponent - round(exponent)) < 1e-12 and round(exponent) != 0:
        return rf"$\beta = 10^{{{round(exponent)}}}$"
    return rf"$\beta = {beta:g}$"


# ---------------------------------------------------------------------------------------------
# One colour per parameter value across the whole paper. Three disjoint sets, so a colour never
# means a beta in one panel and a xi or an alpha in another: beta from Okabe & Ito's palette,
# xi from Paul Tol's "muted" palette, alpha from earth tones (brown, gold, grey, teal) that differ
# in lightness. All are distinguishable with the common colour-vision deficiencies.
# ---------------------------------------------------------------------------------------------
BETA_COLOURS = {0.0: "#000000", 1e-3: "#0072B2", 1e-2: "#009E73", 0.1: "#E69F00", 1.0: "#CC79A7"}
BETA_EXTRA = ("#56B4E9", "#D55E00", "#F0E442")
XI_COLOURS = {0.1: "#332288", 0.3: "#CC6677", 1.0: "#999933", 1.2: "#882255", 3.0: "#88CCEE"}
XI_EXTRA = ("#DDCC77", "#117733", "#AA4499")
ALPHA_COLOURS = {2.0: "#8C510A", 2.2: "#DDAA33", 2.5: "#555555", 100.0: "#5AB4AC", 200.0: "#01665E"}
ALPHA_EXTRA = ("#BF812D", "#543005", "#999999")

# Everything that is none of beta, xi, alpha -- the number of masses N (Fig. 6), the plastic
# law's eta and DR (Fig. 4), the role of a curve (exact, the paper's law, our fit: Figs. 2(b)-(d))
# -- is drawn in black and greys told apart by line style and marker, so that no chromatic colour
# means two things (black and grey are neutral: black is also beta = 0). Bar lengths L and impact
# speeds V0 (Fig. 5 only) have colour sets of their own (ColorBrewer's Set1 with Tol's dark blue,
# and sequential purples), each at least 0.2 (RGB distance) from every colour of the three sets.
SERIES_STYLES = (
    {"color": "#000000", "ls": "-"},
    {"color": "#4D4D4D", "ls": (0, (4, 1.5))},
    {"color": "#000000", "ls": (0, (1, 1.2))},
    {"color": "#6E6E6E", "ls": (0, (6, 1.5, 1, 1.5))},
    {"color": "#262626", "ls": (0, (2.5, 1, 1, 1, 1, 1))},
    {"color": "#9A9A9A", "ls": "-"},
)
#: A reference curve the others are read against (the exact COR, a linear law, a limit branch):
#: a light grey band under the data.
REFERENCE_STYLE = {"color": "0.75", "lw": 2.4, "ls": "-"}
#: The role of a curve in a comparison of models.
ROLE_STYLES = {
    "exact": {"color": "#000000", "marker": "o", "mfc": "none", "ls": "none", "ms": 2.5},
    "paper": {"color": "#5A5A5A", "ls": (0, (4, 2)), "lw": 0.9},
    "fit": {"color": "#000000", "ls": "-", "lw": 0.9},
    "fit_alt": {"color": "#000000", "ls": (0, (1, 1.2)), "lw": 0.9},
}
#: Rows whose status is not ok, when drawn (as crosses at their COR).
FAIL_STYLE = {"color": "#FF0000", "marker": "x", "ls": "none", "ms": 3}
L_COLOURS = ("#E41A1C", "#377EB8", "#4DAF4A", "#E7298A", "#004488", "#FB9A99")
V0_COLOURS = ("#C2A5CF", "#9470B8", "#40004B", "#6E2C8C")


def series_style(index: int) -> dict:
    """Line style number ``index`` of SERIES_STYLES (cycling)."""
    return dict(SERIES_STYLES[index % len(SERIES_STYLES)])


#: Axis labels of the collision duration in the paper's two normalisations, in one style.
T_COL_LABELS = {
    "2pi": r"collision duration $\omega t_\mathrm{col} / 2\pi$",
    "omega": r"collision duration $\omega t_\mathrm{col}$",
}
#: The one sign convention for the contact compression: s1 = -u1 >= 0, positive into the wall.
COMPRESSION_LABEL = r"contact compression $\omega s_1 / V_0$"


def _pick(table: dict, extra: tuple, value: float, others) -> str:
    """The colour of ``value`` in ``table``; values not in it take ``extra`` in sorted order."""
    value = float(value)
    for key, colour in table.items():
        if math.isclose(key, value, rel_tol=1e-9, abs_tol=1e-15):
            return colour
    unknown = sorted(float(v) for v in others if not any(math.isclose(k, float(v)) for k in table))
    return extra[unknown.index(value) % len(extra)] if value in unknown else extra[0]


def beta_colour(beta: float, others=()) -> str:
    """The colour of a stiffness ratio beta (``others``: all betas drawn, for unlisted ones)."""
    return _pick(BETA_COLOURS, BETA_EXTRA, beta, others or (beta,))


def xi_colour(xi: float, others=()) -> str:
    """The colour of a damping ratio xi."""
    return _pick(XI_COLOURS, XI_EXTRA, xi, others or (xi,))


def alpha_colour(alpha: float, others=()) -> str:
    """The colour of a mass ratio alpha."""
    return _pick(ALPHA_COLOURS, ALPHA_EXTRA, alpha, others or (alpha,))
