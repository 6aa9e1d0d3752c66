"""restitution.plotting.plot_trajectory and Result.plot: what they draw, in the house style."""

import math

import numpy as np
import pytest
from matplotlib.collections import PolyCollection
from matplotlib.patches import Rectangle

from restitution import Chain, solve, trajectory
from restitution.plotting import audit_figure, plot_trajectory

HERTZ3 = dict(masses=[1.0, 0.5, 2.0], springs=[0.3, 1.2], contact={"law": "hertz", "k": 50.0})


def _bands(ax):
    """(x0, x1) of the shaded bands (axvspan: a Rectangle, or a Polygon in newer matplotlib)."""
    out = []
    for p in [*ax.patches, *[c for c in ax.collections if isinstance(c, PolyCollection)]]:
        if isinstance(p, Rectangle):
            out.append((p.get_x(), p.get_x() + p.get_width()))
        else:
            xy = p.get_xy() if hasattr(p, "get_xy") else p.get_paths()[0].vertices
            out.append((xy[:, 0].min(), xy[:, 0].max()))
    return sorted(out)


def test_positions_of_every_mass_with_contacts_shaded():
    ch = Chain(**HERTZ3)
    f = trajectory(ch, np.linspace(0.0, 11.0, 200))
    ax = plot_trajectory(f, units={"t": "s", "length": "m"})
    curves = [ln for ln in ax.lines if not ln.get_label().startswith("_")]
    assert [ln.get_label() for ln in curves] == ["$u_1$", "$u_2$", "$u_3$"]
    for i, ln in enumerate(curves):
        np.testing.assert_array_equal(ln.get_xdata(), f["t"].to_numpy())
        np.testing.assert_array_equal(ln.get_ydata(), f[f"u_{i + 1}"].to_numpy())
    starts = f.loc[f["event"] == "contact_start", "t"].to_numpy()
    ends = f.loc[f["event"] == "contact_end", "t"].to_numpy()
    assert len(starts) == len(ends) == 3
    assert np.ravel(_bands(ax)) == pytest.approx(np.ravel([starts, ends], order="F"), abs=1e-12)
    assert ax.get_xlim() == (0.0, 11.0)
    assert ax.get_xlabel() == "time $t$ (s)" and ax.get_ylabel() == "position $u_i$ (m)"
    assert audit_figure(ax.figure) == []


def test_velocities_and_impacts_at_a_rigid_wall():
    f = trajectory(alpha=2.0, structure="scissor", times=np.linspace(0.0, 12.0, 100))
    ax = plot_trajectory(f, what="v", masses=[2])
    assert [ln.get_label() for ln in ax.lines if ln.get_label()[0] != "_"][-1] == "$v_2$"
    impacts = f.loc[f["event"] == "impact", "t"].to_numpy()
    vertical = [ln for ln in ax.lines if "impact" in ln.get_label()]
    assert [ln.get_xdata()[0] for ln in vertical] == pytest.approx(list(impacts))
    assert len(impacts) >= 2 and _bands(ax) == []
    assert ax.get_xlabel() == r"time $\omega t$"  # the paper's scaled units
    assert ax.get_ylabel() == r"velocity $v_i / V_0$"
    assert audit_figure(ax.figure) == []


def test_force_of_an_exact_linear_contact_bands_from_its_samples():
    f = trajectory(alpha=2.0, beta=0.1, times=np.linspace(0.0, 8.0, 161))
    ax = plot_trajectory(f, what="f_contact")
    r = solve(alpha=2.0, beta=0.1, history=True).history
    bands = _bands(ax)
    assert len(bands) == len(r) == 2
    for (a, b), start, end in zip(bands, r["t_start"], r["t_end"], strict=True):
        assert a <= start + 1e-12 and b >= end and b - a < end - start + 2 * 8.0 / 160
    np.testing.assert_array_equal(ax.lines[-1].get_ydata(), f["f_contact"].to_numpy())
    with pytest.raises(ValueError, match="what must be"):
        plot_trajectory(f, what="x")
    with pytest.raises(ValueError, match="masses must be"):
        plot_trajectory(f, masses=[3])


def test_result_plot_draws_the_contact_history():
    ch = Chain(**HERTZ3, v0=2.0)
    r = solve(ch, history=True)
    ax = r.plot()
    start = next(ln for ln in ax.lines if ln.get_label() == "start")
    end = next(ln for ln in ax.lines if ln.get_label() == "end")
    np.testing.assert_array_equal(start.get_xdata(), r.history["t_start"].to_numpy())
    np.testing.assert_array_equal(start.get_ydata(), r.history["velocity_in"].to_numpy())
    np.testing.assert_array_equal(end.get_ydata(), r.history["velocity_out"].to_numpy())
    assert end.get_ydata()[0] == pytest.approx(2.0 * r.history["v1_out"].iat[0], rel=1e-15)
    cor = next(ln for ln in ax.lines if ln.get_label() == r"$e\,V_0$")
    assert cor.get_ydata()[0] == pytest.approx(2.0 * r.cor, rel=1e-15)
    assert len(_bands(ax)) == r.n_collisions
    assert ax.get_xlabel() == "time $t$"
    assert audit_figure(ax.figure) == []
    with pytest.raises(ValueError, match="history=True"):
        solve(ch).plot()


def test_result_plot_of_a_rigid_wall_marks_its_impacts():
    r = solve(alpha=5.0, history=True)
    ax = r.plot()
    lines = [ln for ln in ax.lines if "impact" in ln.get_label()]
    assert len(lines) == r.n_collisions and _bands(ax) == []
    assert ax.get_xlabel() == r"time $\omega t$" and math.isfinite(r.cor)
