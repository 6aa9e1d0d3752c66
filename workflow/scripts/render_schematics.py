"""Render the model schematics: Fig. 1 (two masses at the wall) and Fig. 6(a) (chain of N masses).

Drawn with matplotlib patches and lines in data coordinates (1 unit = 1 cm at print size, equal
aspect), so the output depends only on this file and the house style:

- the wall, hatched, at the left, with its displacement u0;
- the contact spring k1 (zig-zag) between the wall and m1, which acts only in compression
  (m1 is in contact when u1 < 0); beta = k2/k1;
- masses as boxes (m1 small, m2 = alpha*m1 larger), structural springs k2 (zig-zag) between
  neighbours and, in Fig. 1, the optional dashpot c of Sec. 3.4 (grey) in parallel with k2;
- the approach velocity V0 towards the wall and the displacements u_i, positive away from the wall.

The rule's ``params.model`` picks the drawing: ``two_mass`` (Fig. 1) or ``chain`` (Fig. 6(a)).
"""

import numpy as np
from matplotlib.patches import FancyArrowPatch, Rectangle

INK = "black"
GREY = "0.45"
LW = 0.9


def spring(ax, x0, x1, y, coils=5, amplitude=0.16, lead=0.22, label=None, label_dy=0.3):
    """A zig-zag spring from (x0, y) to (x1, y) with straight leads, labelled above."""
    length = x1 - x0
    lead = min(lead, 0.2 * length)
    zig = np.linspace(x0 + lead, x1 - lead, 2 * coils + 1)
    ys = y + amplitude * np.array([0.0] + [(-1) ** k for k in range(2 * coils - 1)] + [0.0])
    xs = np.concatenate([[x0], zig, [x1]])
    ys = np.concatenate([[y], ys, [y]])
    ax.plot(xs, ys, color=INK, lw=LW, solid_joinstyle="miter", zorder=3)
    if label:
        ax.text((x0 + x1) / 2, y + label_dy, label, ha="center", va="bottom", fontsize=9)


def dashpot(ax, x0, x1, y, label=None, color=GREY):
    """A dashpot (cylinder open to the right, piston) from (x0, y) to (x1, y), labelled below."""
    mid = (x0 + x1) / 2
    w, h = 0.5, 0.26
    cyl_left = mid - w / 2
    ax.plot([x0, cyl_left], [y, y], color=color, lw=LW, zorder=3)
    ax.plot(
        [cyl_left + w, cyl_left, cyl_left, cyl_left + w],
        [y + h / 2, y + h / 2, y - h / 2, y - h / 2],
        color=color,
        lw=LW,
        zorder=3,
    )
    piston = cyl_left + 0.6 * w
    ax.plot([piston, piston], [y - 0.38 * h, y + 0.38 * h], color=color, lw=1.4 * LW, zorder=3)
    ax.plot([piston, x1], [y, y], color=color, lw=LW, zorder=3)
    if label:
        ax.text(mid, y - h / 2 - 0.1, label, ha="center", va="top", fontsize=8, color=color)


def mass(ax, x, y, width, height, label):
    """A mass as a box with its lower-left corner at (x, y), its name inside."""
    ax.add_patch(Rectangle((x, y), width, height, facecolor="0.93", edgecolor=INK, lw=LW, zorder=4))
    ax.text(x + width / 2, y + height / 2, label, ha="center", va="center", fontsize=10, zorder=5)


def wall(ax, x, y0, y1, depth=0.28):
    """A hatched rigid wall whose face is the vertical line x, from y0 to y1."""
    ax.add_patch(
        Rectangle(
            (x - depth, y0),
            depth,
            y1 - y0,
            facecolor="white",
            edgecolor=INK,
            hatch="////",
            lw=0,
            zorder=2,
        )
    )
    ax.plot([x, x], [y0, y1], color=INK, lw=1.4 * LW, zorder=3)


def arrow(ax, start, end, color=INK, lw=LW, style="-|>"):
    ax.add_patch(
        FancyArrowPatch(
            start,
            end,
            arrowstyle=style,
            mutation_scale=8,
            color=color,
            lw=lw,
            zorder=6,
            shrinkA=0,
            shrinkB=0,
        )
    )


def displacement(ax, x, y, label, length=0.55):
    """A short tick at x with an arrow to the right (positive = away from the wall) and a label."""
    ax.plot([x, x], [y - 0.1, y + 0.1], color=INK, lw=0.7, zorder=6)
    arrow(ax, (x, y), (x + length, y), lw=0.7)
    ax.text(x + length + 0.06, y, label, ha="left", va="center", fontsize=9)


def velocity(ax, x_centre, y, length=0.7, label=True):
    """The approach velocity V0 (towards the wall) of a body centred at x_centre."""
    arrow(ax, (x_centre + length / 2, y), (x_centre - length / 2, y), lw=1.1)
    if label:
        ax.text(x_centre, y - 0.08, r"$V_0$", ha="center", va="top", fontsize=9)


def finish(ax, x0, x1, y0, y1):
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_axis_off()


def draw_two_mass(plotting):
    """Fig. 1: wall, contact spring k1, m1, structural spring k2 (and dashpot c), m2."""
    fig = plotting.new_figure("single", aspect=0.42)
    fig.set_layout_engine("none")
    ax = fig.add_axes([0, 0, 1, 1])
    y = 1.0  # spring axis
    wall(ax, 0.0, -0.2, 2.3)
    m1_x, m1_w, m1_h = 1.25, 0.8, 0.8
    m2_x, m2_w, m2_h = 3.75, 1.4, 1.3
    spring(ax, 0.0, m1_x, y, coils=4, label=r"$k_1$")
    mass(ax, m1_x, y - m1_h / 2, m1_w, m1_h, r"$m_1$")
    # Structural spring above the axis, dashpot below: in parallel between m1 and m2.
    spring(ax, m1_x + m1_w, m2_x, y + 0.2, coils=5, amplitude=0.13, label=r"$k_2$", label_dy=0.22)
    dashpot(ax, m1_x + m1_w, m2_x, y - 0.22, label=r"$c$")
    mass(ax, m2_x, y - m2_h / 2, m2_w, m2_h, r"$m_2 = \alpha m_1$")
    top = 2.05
    displacement(ax, 0.0, top, r"$u_0$")
    displacement(ax, m1_x + m1_w / 2, top, r"$u_1$")
    displacement(ax, m2_x + m2_w / 2, top, r"$u_2$")
    below = y - m2_h / 2 - 0.2
    velocity(ax, m1_x + m1_w / 2, below)
    velocity(ax, m2_x + m2_w / 2, below)
    finish(ax, -0.4, 5.3, below - 0.45, 2.35)
    return fig


def draw_chain(plotting):
    """Fig. 6(a): wall, contact spring k1, m1, then m2 ... mN (all alpha*m1) joined by k2."""
    fig = plotting.new_figure("onehalf", aspect=0.3)
    fig.set_layout_engine("none")
    ax = fig.add_axes([0, 0, 1, 1])
    y = 1.0
    wall(ax, 0.0, -0.4, 2.1)
    m1_w, m_w = 0.7, 0.9
    gap = 1.05
    x = 1.1
    spring(ax, 0.0, x, y, coils=4, label=r"$k_1$")
    mass(ax, x, y - m1_w / 2, m1_w, m1_w, r"$m_1$")
    x += m1_w
    names = [r"$m_2$", r"$m_3$", None, r"$m_N$"]
    centres = {}
    for name in names:
        if name is None:
            # Ellipsis standing for m4 ... m(N-1) and their springs; the last k2 follows it.
            spring(ax, x, x + 0.45, y, coils=2, amplitude=0.13, lead=0.05)
            ax.text(x + 0.8, y, r"$\cdots$", ha="center", va="center", fontsize=12)
            x += 1.2
            continue
        spring(ax, x, x + gap, y, coils=4, amplitude=0.13, label=r"$k_2$", label_dy=0.22)
        x += gap
        mass(ax, x, y - m_w / 2, m_w, m_w, name)
        centres[name] = x + m_w / 2
        x += m_w
    right = x
    ax.text(
        (centres[r"$m_2$"] + right) / 2 - 0.2,
        y - m_w / 2 - 0.22,
        r"$m_2 = m_3 = \cdots = m_N = \alpha m_1$",
        ha="center",
        va="top",
        fontsize=8.5,
    )
    top = 1.85
    displacement(ax, 0.0, top, r"$u_0$")
    displacement(ax, 1.1 + m1_w / 2, top, r"$u_1$")
    displacement(ax, centres[r"$m_2$"], top, r"$u_2$")
    displacement(ax, centres[r"$m_N$"], top, r"$u_N$")
    below = y - m_w / 2 - 0.75
    for centre in [1.1 + m1_w / 2, *centres.values()]:
        velocity(ax, centre, below, length=0.6)
    finish(ax, -0.4, right + 0.2, below - 0.42, 2.2)
    return fig


DRAWINGS = {"two_mass": draw_two_mass, "chain": draw_chain}


def main(model, png_path, pdf_path, logger):

    from restitution import plotting

    if model not in DRAWINGS:
        raise ValueError(f"unknown schematic {model!r}: one of {sorted(DRAWINGS)}")
    fig = DRAWINGS[model](plotting)
    plotting.save_outputs(fig, png_path, pdf_path, logger)


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake, numba=False)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "render"):
        main(
            snakemake.params.model,  # noqa: F821
            snakemake.output.png,  # noqa: F821
            snakemake.output.pdf,  # noqa: F821
            log,
        )
