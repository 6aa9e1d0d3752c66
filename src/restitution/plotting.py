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
import re
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


def save_outputs(fig: Figure, png_path, pdf_path, logger=None, audit: bool = True) -> list[Path]:
    """Write a rule's png and pdf outputs (which must share a stem) with ``save_figure``.

    With ``audit`` (the default) the figure is first checked against the house rules
    (:func:`check_figure`: text size, one colour one meaning); a figure that breaks one fails.
    """
    if audit:
        check_figure(fig)
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
ALPHA_COLOURS = {2.0: "#8C510A", 2.2: "#DDAA33", 2.5: "#01665E", 100.0: "#5AB4AC", 200.0: "#543005"}
ALPHA_EXTRA = ("#BF812D", "#003C30", "#999999")

# Everything that is none of beta, xi, alpha -- the number of masses N (Fig. 6), the plastic
# law's eta and DR (Fig. 4), the role of a curve (exact, the paper's law, our fit: Figs. 2(b)-(d)),
# a design family (Fig. 8(b)), a solver in the benchmarks -- is drawn in black and greys told apart
# by line style and marker, so that no chromatic colour means two things (black and grey are
# neutral: black is also beta = 0). eta takes SERIES_STYLES, DR (in the same figure)
# MARKED_STYLES. Bar lengths L and impact speeds V0 (Fig. 5 only) have colour sets of their own
# (ColorBrewer's Set1 with Tol's dark blue, and sequential purples), each at least 0.2 (RGB
# distance) from every colour of the three sets.
SERIES_STYLES = (
    {"color": "#000000", "ls": "-"},
    {"color": "#4D4D4D", "ls": (0, (4, 1.5))},
    {"color": "#000000", "ls": (0, (1, 1.2))},
    {"color": "#6E6E6E", "ls": (0, (6, 1.5, 1, 1.5))},
    {"color": "#262626", "ls": (0, (2.5, 1, 1, 1, 1, 1))},
    {"color": "#9A9A9A", "ls": "-"},
)
#: Categories drawn with markers (DR in Fig. 4(b), design families, benchmark methods): greys and
#: black, a marker and a line style each.
MARKED_STYLES = (
    {"color": "#000000", "ls": "-", "marker": "o"},
    {"color": "#4D4D4D", "ls": (0, (4, 1.5)), "marker": "s"},
    {"color": "#000000", "ls": (0, (1, 1.2)), "marker": "^"},
    {"color": "#6E6E6E", "ls": (0, (6, 1.5, 1, 1.5)), "marker": "D"},
    {"color": "#262626", "ls": (0, (2.5, 1, 1, 1, 1, 1)), "marker": "v"},
    {"color": "#8A8A8A", "ls": "-", "marker": "P"},
    {"color": "#000000", "ls": (0, (3, 1, 1, 1)), "marker": "<"},
    {"color": "#5A5A5A", "ls": (0, (1, 2)), "marker": ">"},
    {"color": "#8A8A8A", "ls": (0, (5, 2)), "marker": "X"},
)
#: A reference curve the others are read against (the exact COR, a linear law, a limit branch):
#: a light grey band under the data.
REFERENCE_STYLE = {"color": "0.75", "lw": 2.4, "ls": "-"}
#: The role of a curve in a comparison of models.
ROLE_STYLES = {
    "exact": {"color": "#000000", "marker": "o", "mfc": "none", "ls": "none", "ms": 2.5},
    "paper": {"color": "#5A5A5A", "ls": (0, (4, 2)), "lw": 0.9},
    "paper_alt": {"color": "#8A8A8A", "ls": (0, (6, 1.5, 1, 1.5)), "lw": 0.9},
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


def marked_style(index: int) -> dict:
    """Marker and line style number ``index`` of MARKED_STYLES (cycling)."""
    return dict(MARKED_STYLES[index % len(MARKED_STYLES)])


#: Axis labels of the collision duration in the paper's two normalisations, in one style.
T_COL_LABELS = {
    "2pi": r"collision duration $\omega t_\mathrm{col} / 2\pi$",
    "omega": r"collision duration $\omega t_\mathrm{col}$",
}
#: The one axis label of the coefficient of restitution (a qualifier goes before it: "smallest").
COR_LABEL = "COR $e$"
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


# ---------------------------------------------------------------------------------------------
# The rules every workflow figure keeps, checked on its artists when it is saved (save_outputs):
# text no smaller than MIN_TEXT_PT at the figure's printed size, and one colour one meaning -- an
# artist whose label names one beta, xi or alpha (e.g. "$\\xi = 0.3$"; a label that starts with
# "_" names it without a legend entry) has that value's colour, and an artist that names none of
# them takes no colour of their sets.
# ---------------------------------------------------------------------------------------------
#: Smallest text (points) at the figure's printed size: the report shows figures at that size.
MIN_TEXT_PT = 7.0
PARAMETER_SETS = {
    "beta": (BETA_COLOURS, BETA_EXTRA),
    "xi": (XI_COLOURS, XI_EXTRA),
    "alpha": (ALPHA_COLOURS, ALPHA_EXTRA),
}
_NAMED = re.compile(
    r"\\(beta|xi|alpha)\s*=\s*"
    r"(?:10\^\{?(?P<exp>[-+]?\d+)\}?|(?P<num>[-+]?\d+(?:\.\d*)?(?:e[-+]?\d+)?))"
    r"(?![\d./_^])"
)


class FigureRuleError(ValueError):
    """A figure breaks a house rule (text size, one colour one meaning); lists every problem."""


def named_values(label: str) -> list[tuple[str, float]]:
    """The (parameter, value) pairs a label names: ``$\\beta = 10^{-3}$`` -> [("beta", 0.001)].

    >>> named_values(r"$\\xi = 0.3$, $\\alpha = 100$")
    [('xi', 0.3), ('alpha', 100.0)]
    >>> named_values(r"mass ratio $\\alpha = m_2/m_1$")
    []
    """
    out = []
    for m in _NAMED.finditer(label or ""):
        value = 10.0 ** int(m["exp"]) if m["exp"] is not None else float(m["num"])
        out.append((m.group(1), value))
    return out


def _hex(colour) -> str | None:
    from matplotlib.colors import to_hex

    try:
        return to_hex(colour, keep_alpha=False).lower()
    except ValueError:
        return None


def _is_chromatic(colour: str) -> bool:
    from matplotlib.colors import to_rgb

    r, g, b = to_rgb(colour)
    return max(r, g, b) - min(r, g, b) > 0.05


def _artist_colours(artist) -> set[str]:
    """The colours an artist is drawn in (line, marker edge and face; a collection's faces and
    edges); colour-mapped artists (an image, a mesh, a scatter with values) have none here."""
    from matplotlib.collections import Collection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    colours = []
    if isinstance(artist, Line2D):
        colours.append(artist.get_color())
        if artist.get_marker() not in (None, "None", "none", ""):
            colours += [artist.get_markeredgecolor(), artist.get_markerfacecolor()]
    elif isinstance(artist, Collection):
        if artist.get_array() is not None:
            return set()
        colours += list(artist.get_facecolor()) + list(artist.get_edgecolor())
    elif isinstance(artist, Patch):
        colours += [artist.get_facecolor(), artist.get_edgecolor()]
    out = set()
    for c in colours:
        if isinstance(c, str) and c.lower() == "none":
            continue
        if not isinstance(c, str) and len(c) == 4 and c[3] == 0:
            continue
        h = _hex(c)
        if h is not None:
            out.add(h)
    return out


def expected_colour(parameter: str, value: float) -> str | None:
    """The colour of ``value`` in ``parameter``'s table; None if the table has no such value."""
    table, _extra = PARAMETER_SETS[parameter]
    for key, colour in table.items():
        if math.isclose(key, value, rel_tol=1e-9, abs_tol=1e-15):
            return colour.lower()
    return None


def audit_figure(fig: Figure, min_text_pt: float = MIN_TEXT_PT) -> list[str]:
    """Every place where ``fig`` breaks a house rule, as sentences (empty: none).

    - a visible, non-empty text (tick label, legend, title, annotation) smaller than
      ``min_text_pt`` points;
    - an artist whose label names one beta, xi or alpha (legend entries and hidden ``_`` labels)
      drawn in a chromatic colour other than that value's (a value outside the table: any colour
      of that parameter's extra set);
    - an artist that names none of them drawn in a colour of the beta, xi or alpha sets.
    """
    from matplotlib.text import Text

    fig.draw_without_rendering()  # tick labels and legends take their final text
    problems = []
    for text in fig.findobj(Text):
        if not text.get_visible() or not text.get_text().strip():
            continue
        if text.get_fontsize() < min_text_pt - 1e-9:
            problems.append(
                f"text {text.get_text()!r} is {text.get_fontsize():.2g} pt (< {min_text_pt:g} pt)"
            )
    owner = {}
    for name, (table, extra) in PARAMETER_SETS.items():
        for colour in [*table.values(), *extra]:
            owner[colour.lower()] = name
    for ax in fig.axes:
        for artist in [*ax.lines, *ax.collections, *ax.patches]:
            colours = {c for c in _artist_colours(artist) if _is_chromatic(c)}
            if not colours:
                continue
            label = artist.get_label() or ""
            named = named_values(label)
            if not named:
                for c in sorted(colours & set(owner)):
                    problems.append(
                        f"{type(artist).__name__} {label!r} names no {owner[c]} but is drawn in "
                        f"{c}, a {owner[c]} colour"
                    )
                continue
            allowed = set()
            for parameter, value in named:
                colour = expected_colour(parameter, value)
                extra = PARAMETER_SETS[parameter][1]
                allowed |= {colour} if colour else {c.lower() for c in extra}
            wrong = colours - allowed
            if wrong:
                problems.append(
                    f"{type(artist).__name__} {label!r} is drawn in {sorted(wrong)}, "
                    f"not the colour of {', '.join(f'{p} = {v:g}' for p, v in named)} "
                    f"({sorted(allowed)})"
                )
    return problems


def check_figure(fig: Figure, min_text_pt: float = MIN_TEXT_PT) -> None:
    """Raise FigureRuleError listing every problem :func:`audit_figure` finds."""
    problems = audit_figure(fig, min_text_pt)
    if problems:
        raise FigureRuleError("figure breaks the house rules:\n  " + "\n  ".join(problems))


# ---------------------------------------------------------------------------------------------
# Trajectories (restitution.trajectory) in the house style: one grey/black line style per mass
# (SERIES_STYLES: a mass index is none of beta, xi, alpha), contacts as light grey bands, impacts
# at a rigid wall as dotted vertical lines.
# ---------------------------------------------------------------------------------------------
#: Band behind the curves while m1 is in contact with a finite contact law.
CONTACT_STYLE = {"color": "0.88", "lw": 0, "zorder": 0}
#: An impact at a rigid wall (an instant).
IMPACT_STYLE = {"color": "0.55", "lw": 0.6, "ls": (0, (1, 1.5)), "zorder": 0}
_QUANTITIES = {
    "u": ("u", "position", "length"),
    "v": ("v", "velocity", "speed"),
}


def _unit(units, key: str) -> str:
    unit = (units or {}).get(key)
    return f" ({unit})" if unit else ""


def trajectory_labels(frame, what: str = "u", units=None) -> tuple[str, str]:
    """(x label, y label) of a ``trajectory`` table: the paper's scaled symbols when the scene's
    units are the kernels' (``frame.attrs["scaled"]``: m_1 = 1, omega = 1, V0 = 1), else the
    quantity with the unit ``units`` gives for it (keys ``t``, ``length``, ``speed``, ``force``;
    the scene's own units are not recorded by the model)."""
    scaled = bool(frame.attrs.get("scaled", False))
    if what == "f_contact":
        y = (r"contact force $F / (m_1 V_0 \omega)$" if scaled
             else "contact force $F$" + _unit(units, "force"))  # fmt: skip
    else:
        sym, name, key = _QUANTITIES[what]
        if scaled:
            y = rf"{name} $\omega {sym}_i / V_0$" if what == "u" else rf"{name} ${sym}_i / V_0$"
        else:
            y = f"{name} ${sym}_i$" + _unit(units, key)
    x = r"time $\omega t$" if scaled else "time $t$" + _unit(units, "t")
    return x, y


def _contact_spans(frame) -> tuple[list, list]:
    """([(start, end)] of contacts, [impact times]) within the table: from its event rows, else
    (the exact kernels of a linear contact record none) from the samples with a contact force."""
    t = frame["t"].to_numpy()
    event = frame["event"].to_numpy()
    impacts = list(t[event == "impact"])
    starts, ends = list(t[event == "contact_start"]), list(t[event == "contact_end"])
    if starts or ends:
        if ends and (not starts or ends[0] < starts[0]):
            starts.insert(0, t.min())  # the table begins inside a contact
        if len(ends) < len(starts):
            ends.append(t.max())  # ... or ends inside one
        return list(zip(starts, ends, strict=False)), impacts
    on = (frame["f_contact"].to_numpy() > 0) & (event == "sample")
    spans, i = [], 0
    while i < len(t):
        if on[i]:
            j = i
            while j + 1 < len(t) and on[j + 1]:
                j += 1
            spans.append((t[max(i - 1, 0)], t[min(j + 1, len(t) - 1)]))
            i = j + 1
        else:
            i += 1
    return spans, impacts


def plot_trajectory(frame, ax=None, what: str = "u", units=None, masses=None, legend=True):
    """Draw a ``restitution.trajectory`` table against time; return the Axes.

    Contacts with a finite contact law are shaded (from the table's ``contact_start`` /
    ``contact_end`` rows, or from its samples with a contact force), impacts at a rigid wall are
    dotted vertical lines; each mass has a line style of SERIES_STYLES.

    Parameters
    ----------
    frame : DataFrame
        A table of ``restitution.trajectory`` (its sample and event rows; the curves pass through
        both, so a contact's start and end are drawn where they happened).
    ax : matplotlib Axes, optional
        Where to draw; by default a new single-column figure in the house style
        (``new_figure``; the figure is ``ax.figure``).
    what : {"u", "v", "f_contact"}
        Positions u_i, velocities v_i of every mass, or the contact force on m_1.
    units : mapping, optional
        Unit names for the axis labels (keys ``t``, ``length``, ``speed``, ``force``), e.g.
        ``{"t": "s", "length": "m"}``; ignored for the paper's scaled scenes, whose labels are
        the scaled symbols.
    masses : sequence of int, optional
        The masses to draw (1-based; default all).
    legend : bool
        A legend naming the masses (for more than one curve).

    Returns
    -------
    matplotlib Axes
        The axes drawn on.

    Examples
    --------
    >>> import restitution
    >>> from restitution.plotting import plot_trajectory
    >>> f = restitution.trajectory(alpha=2.0, beta=0.1, times=[0.0, 1.0, 2.0])
    >>> ax = plot_trajectory(f, what="v")
    >>> ax.get_ylabel()
    'velocity $v_i / V_0$'
    """
    if what not in (*_QUANTITIES, "f_contact"):
        raise ValueError(f"what must be 'u', 'v' or 'f_contact'; got {what!r}")
    if ax is None:
        ax = new_figure().add_subplot()
    n = sum(1 for c in frame.columns if c.startswith("u_"))
    chosen = list(range(1, n + 1)) if masses is None else [int(i) for i in masses]
    for i in chosen:
        if not 1 <= i <= n:
            raise ValueError(f"masses must be numbers in 1..{n}; got {i!r}")
    t = frame["t"].to_numpy()
    spans, impacts = _contact_spans(frame)
    for k, (a, b) in enumerate(spans):
        ax.axvspan(a, b, **CONTACT_STYLE, label="_contact" if k else "contact")
    for k, ti in enumerate(impacts):
        ax.axvline(ti, **IMPACT_STYLE, label="_impact" if k else "impact")
    if what == "f_contact":
        ax.plot(t, frame["f_contact"].to_numpy(), **series_style(0), label="$F$")
    else:
        # at an impact the velocity jumps: the curve shows the velocity after it
        for k, i in enumerate(chosen):
            ax.plot(t, frame[f"{what}_{i}"].to_numpy(), **series_style(k), label=f"${what}_{i}$")
    ax.set_xlim(t.min(), t.max())
    x_label, y_label = trajectory_labels(frame, what, units)
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    if legend and (len(chosen) > 1 or spans or impacts):
        ax.legend(loc="best")
    return ax
