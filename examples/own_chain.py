"""Your own chain, in your units: COR, contacts, energy split, contact time and a trajectory plot.

    python examples/own_chain.py [OUT]    # OUT: a folder for the outputs (default: a temp dir)
    python examples/own_chain.py OUT --masses 1 1 --springs 100 --k-contact inf

The chain below is a 200 g striker (m1, touching the wall) with two 50 g masses behind it, joined
by 2 kN/m springs, the first link damped, hitting a wall of contact stiffness 50 kN/m at 1.5 m/s.
Any consistent units work; these are SI. Writes OUT/result.json and OUT/trajectory.{png,pdf}.
"""

import argparse
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

import restitution
from restitution import plotting

# The example's chain (SI units); the command line replaces any part of it.
EXAMPLE = {"masses": [0.2, 0.05, 0.05], "springs": [2000.0, 2000.0], "dashpots": [0.5, 0.0]}
parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("out", nargs="?", help="folder for the outputs (default: a new temp dir)")
parser.add_argument("--masses", type=float, nargs="+", default=EXAMPLE["masses"])  # kg
parser.add_argument("--springs", type=float, nargs="+", default=EXAMPLE["springs"])  # N/m
parser.add_argument("--dashpots", type=float, nargs="+", help="N s/m, one per link (default: "
                    "the example's for its chain, none for yours)")  # fmt: skip
parser.add_argument("--k-contact", type=float, default=5e4)  # N/m; inf = rigid wall
parser.add_argument("--v0", type=float, default=1.5)  # m/s, the approach speed
parser.add_argument("--no-plot", action="store_true", help="skip the trajectory plot")
args = parser.parse_args()


def fail(message: str):
    """One line on stderr and exit code 2 (bad input), as the command line `restitution` does."""
    print(f"{parser.prog}: error: {message}", file=sys.stderr)
    raise SystemExit(2)


if args.out is not None and Path(args.out).exists() and not Path(args.out).is_dir():
    fail(f"OUT {args.out} exists and is not a folder; give a folder for the outputs")
dashpots = args.dashpots
if dashpots is None:
    own = args.masses != EXAMPLE["masses"]
    dashpots = [0.0] * (len(args.masses) - 1) if own else EXAMPLE["dashpots"]

# One call: the scene is checked (clear errors for bad values), solved exactly where it can be.
try:
    result = restitution.solve(
        masses=args.masses,
        springs=args.springs,
        dashpots=dashpots,
        k_contact=args.k_contact,  # math.inf: a rigid wall
        v0=args.v0,
    )
except restitution.SceneError as error:  # a bad value: its message names it and its range
    fail(str(error))
out = Path(args.out or tempfile.mkdtemp(prefix="restitution-chain-"))
out.mkdir(parents=True, exist_ok=True)
summary = {
    "cor": result.cor,  # centre-of-mass velocity after the last separation / v0
    "n_collisions": result.n_collisions,  # separate contact intervals
    "t_col_s": result.t_col,  # first contact to last separation, in seconds (your time unit)
    "v_after_m_per_s": result.cor * args.v0,  # centre of mass, away from the wall
    # Where the initial kinetic energy went (fractions adding up to 1):
    "e_translational": result.e_translational,  # = cor**2, the rebound
    "e_vibrational": result.e_vibrational,  # left ringing in the springs
    "e_dissipated": result.e_dissipated,  # burnt in the dashpots
    "method": result.method,
    "status": result.status,
}
(out / "result.json").write_text(json.dumps(summary, indent=2))
for key, value in summary.items():
    print(f"{key:>16}: {value:.6g}" if isinstance(value, float) else f"{key:>16}: {value}")

if not args.no_plot:
    # Positions (m) of every mass from the first contact to twice the contact time (s).
    times = np.linspace(0.0, 2.0 * result.t_col if result.t_col > 0 else 1.0, 600)
    path = restitution.trajectory(
        masses=args.masses,
        springs=args.springs,
        dashpots=dashpots,
        k_contact=args.k_contact,
        v0=args.v0,
        times=times,
    )
    fig = plotting.new_figure("single", aspect=0.72)
    ax = fig.add_subplot()
    n = len(args.masses)
    for i in range(1, n + 1):
        ax.plot(path["t"] * 1e3, path[f"u_{i}"] * 1e3, label=f"$m_{i}$", lw=0.9,
                **plotting.series_style(i - 1))  # fmt: skip
    ax.axhline(0.0, color="0.3", lw=0.6)  # the wall (m1 touches it at u_1 = 0)
    ax.set_xlabel("time since first contact [ms]")
    ax.set_ylabel("position [mm] (0: at first contact)")
    ax.legend(loc="best")
    plotting.check_figure(fig)  # the house rules: text size, one colour one meaning
    for written in plotting.save_figure(fig, out / "trajectory"):
        print(f"{'wrote':>16}: {written}")
print(f"{'wrote':>16}: {out / 'result.json'}")
if math.isinf(args.k_contact):
    print("(rigid wall: contacts are instantaneous impacts)")
