"""Command line: ``restitution cor`` for one scene, ``restitution batch`` for a table of scenes."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from .scene import METHODS, SceneError


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="restitution",
        description="Coefficient of restitution of a mass-spring chain hitting a wall "
        "(non-dimensional: m1 = V0 = omega = 1).",
    )
    sub = p.add_subparsers(dest="command", required=True)

    cor = sub.add_parser("cor", help="solve one scene")
    cor.add_argument("--alpha", type=float, required=True, help="mass ratio m2/m1, in (0, 1e8]")
    cor.add_argument("--beta", type=float, default=0.0, help="k2/k1 in [0, 1e6]; 0: rigid wall")
    cor.add_argument("--xi", type=float, default=0.0, help="damping ratio in [0, 1e3]")
    cor.add_argument("--n-masses", type=int, default=2, help="masses in the chain, in [2, 512]")
    cor.add_argument("--method", default="auto", choices=METHODS)
    cor.add_argument("--max-events", type=int, default=100_000, help="contact budget")
    law = cor.add_argument_group(
        "nonlinear laws and numerical methods (two masses; see restitution.nonlinear)"
    )
    law.add_argument("--contact", choices=("linear", "plastic"), help="contact law")
    law.add_argument("--eta", type=float, help="plastic loading exponent, in (0, 10]")
    law.add_argument("--dr", type=float, help="nominal dissipation ratio, in [(1-eta)/2, 1)")
    law.add_argument("--structure", choices=("linear", "scissor"), help="structural spring")
    law.add_argument("--L", dest="L", type=float, help="scissor bar length (> 0)")
    law.add_argument("--ks-ratio", type=float, help="scissor spring ks/k2")
    law.add_argument("--theta0", type=float, help="scissor rest half angle, in (0, pi/2)")
    law.add_argument("--corner", type=float, help="scissor corner-stiffening stroke fraction")
    law.add_argument("--v0", type=float, help="impact speed (nonlinear laws depend on it)")
    law.add_argument("--rtol", type=float, help="adaptive/reference relative tolerance")
    law.add_argument("--step", type=float, help="Verlet step, fraction of the shortest period")
    cor.add_argument("--history", action="store_true", help="also print every contact")
    cor.add_argument("--json", action="store_true", help="print one JSON object")

    batch = sub.add_parser("batch", help="solve every row of a .csv or .parquet table")
    batch.add_argument(
        "input", type=Path, help="table with a column alpha; optional beta, xi, n_masses, method"
    )
    batch.add_argument("-o", "--output", type=Path, required=True, help="OUT.csv or OUT.parquet")
    batch.add_argument("--max-events", type=int, default=100_000, help="contact budget per row")
    batch.add_argument("--progress", action="store_true", help="show a progress bar")
    return p


def _cor(args) -> int:
    from .api import solve

    law_keys = ("contact", "eta", "dr", "structure", "L", "ks_ratio", "theta0", "corner", "v0")
    law = {k: getattr(args, k) for k in (*law_keys, "rtol", "step") if getattr(args, k) is not None}
    r = solve(
        alpha=args.alpha,
        beta=args.beta,
        xi=args.xi,
        n_masses=args.n_masses,
        method=args.method,
        history=args.history,
        max_events=args.max_events,
        **law,
    )
    if args.json:
        d = r.to_dict(history=args.history)
        print(
            json.dumps(
                {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in d.items()}
            )
        )
    else:
        print(f"cor              {r.cor:.15g}")
        print(f"n_collisions     {r.n_collisions}")
        print(f"omega_t_col      {r.omega_t_col:.15g}")
        print(f"e_translational  {r.e_translational:.15g}")
        print(f"e_vibrational    {r.e_vibrational:.15g}")
        print(f"e_dissipated     {r.e_dissipated:.15g}")
        print(f"method           {r.method}")
        print(f"status           {r.status}")
        print(f"error_estimate   {r.error_estimate:.3g}")
        if args.history and r.history is not None:
            print(r.history.to_string())
    return 0 if r.success else 3


def _batch(args) -> int:
    from .api import solve_many
    from .io import read_table, write_table

    if args.output.suffix not in (".csv", ".parquet"):
        raise SceneError(f"output must end in .csv or .parquet; got {args.output}")
    frame = read_table(args.input)
    result = solve_many(frame, max_events=args.max_events, progress=args.progress)
    write_table(result, args.output)
    bad = result["status"] != "ok"
    if bad.any():
        print(
            f"warning: {int(bad.sum())} of {len(result)} rows did not finish cleanly "
            f"(see the status column)",
            file=sys.stderr,
        )
        return 3
    return 0


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from .io import TableError

    try:
        return _cor(args) if args.command == "cor" else _batch(args)
    except (SceneError, TableError) as e:
        print(f"restitution: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
