"""Command line: ``restitution cor`` for one scene, ``restitution batch`` for a table of scenes,
``restitution warmup`` to compile every kernel into numba's cache ahead of the first call."""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import time
from pathlib import Path

from restitution.kernels.constants import MAX_EVENTS_DEFAULT

EXIT_OK = 0  # every scene finished (status ok)
EXIT_INTERNAL = 1  # an unexpected error (a bug: please report it with the traceback)
EXIT_INPUT = 2  # bad input or an I/O error: nothing was solved or nothing was written
EXIT_NOT_OK = 3  # the results were written, but some scene is not ok (see its status)
EXIT_SIGNAL = 128  # + the signal number when interrupted (130 for Ctrl-C, 143 for SIGTERM)

EXIT_CODES = f"""exit codes:
  {EXIT_OK}    every scene finished (status ok)
  {EXIT_INTERNAL}    unexpected internal error (please report it)
  {EXIT_INPUT}    bad input or I/O error (message on stderr; nothing written)
  {EXIT_NOT_OK}    results written, but some scene is not ok (see its status)
  130  interrupted (Ctrl-C); no partial output is left
  143  terminated (SIGTERM); no partial output is left"""


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("restitution")
    except PackageNotFoundError:
        return "0+unknown"


def _floats(text: str) -> list[float]:
    """'1,0.5,2' or '1;0.5;2' -> [1.0, 0.5, 2.0] (spaces fine)."""
    parts = [p.strip() for p in text.replace(";", ",").split(",")]
    try:
        return [float(p) for p in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers such as 1,0.5,2; got {text!r}"
        ) from None


def _json(text: str):
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        example = '{"law": "hertz", "k": 50}'
        raise argparse.ArgumentTypeError(
            f"expected JSON such as '{example}'; got {text!r}"
        ) from None


class _MethodNames:
    """``methods.NAMES`` for argparse's ``choices``, imported when first used.

    ``restitution.solvers.methods`` imports numpy and pandas; ``restitution --help`` must not wait
    for
    them. argparse looks into ``choices`` only when --method is given or the cor subcommand's
    help is formatted (the metavar is fixed so that ``add_argument`` does not list them).
    """

    def _names(self) -> tuple[str, ...]:
        from restitution.solvers.methods import NAMES

        return NAMES

    def __contains__(self, value) -> bool:
        return value in self._names()

    def __iter__(self):
        return iter(self._names())


def _parser() -> argparse.ArgumentParser:
    fmt = argparse.RawDescriptionHelpFormatter
    p = argparse.ArgumentParser(
        prog="restitution",
        description="Coefficient of restitution of a mass-spring chain hitting a wall.",
        epilog=EXIT_CODES,
        formatter_class=fmt,
    )
    p.add_argument("--version", action="version", version=f"restitution {_version()}")
    sub = p.add_subparsers(dest="command", required=True)

    cor = sub.add_parser(
        "cor",
        help="solve one scene",
        description="Solve one scene: the paper's form (--alpha ...) or a general chain "
        "(--masses ... --springs ...).",
        epilog=EXIT_CODES,
        formatter_class=fmt,
    )
    paper = cor.add_argument_group("the paper's form (m1 = V0 = omega = 1)")
    paper.add_argument("--alpha", type=float, help="mass ratio m2/m1, in [1e-8, 1e8]")
    # (defaults None: an option of the other form is refused, not ignored; solve's defaults)
    paper.add_argument("--beta", type=float, help="k2/k1 in [0, 1e6]; 0 (default): rigid wall")
    paper.add_argument("--xi", type=float, help="damping ratio in [0, 1e3] (default 0)")
    paper.add_argument("--n-masses", type=int, help="masses in the chain, [2, 512] (default 2)")
    general = cor.add_argument_group("a general chain (any consistent units)")
    general.add_argument("--masses", type=_floats, help="m1,...,mN (> 0); m1 touches the wall")
    general.add_argument("--springs", type=_floats, help="k12,...,k(N-1)N (> 0)")
    general.add_argument("--dashpots", type=_floats, help="c12,...,c(N-1)N (>= 0; default 0)")
    general.add_argument("--k-contact", type=float,
                         help="contact stiffness (> 0); inf (default): rigid wall")  # fmt: skip
    general.add_argument(
        "--contact-law",
        dest="contact_spec",
        type=_json,
        help='JSON, e.g. {"law": "hertz", "k": 50}',
    )
    general.add_argument("--links", type=_json, help='JSON list, e.g. [{"law": "linear"}, ...]')
    general.add_argument(
        "--velocities",
        type=_floats,
        help="initial velocities v1,...,vN, positive towards the wall (instead of --v0; a list "
        "that starts with a minus sign is written --velocities=-0.2,1)",
    )
    general.add_argument(
        "--stretches", type=_floats, help="initial link extensions s12,...,s(N-1)N (default 0)"
    )
    cor.add_argument(
        "--method",
        default="auto",
        choices=_MethodNames(),
        metavar="METHOD",
        help="solver: %(choices)s (default: %(default)s)",
    )
    cor.add_argument("--max-events", type=int, default=MAX_EVENTS_DEFAULT, help="contact budget")
    law = cor.add_argument_group(
        "nonlinear laws and numerical methods in the paper's form (two masses)"
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

    batch = sub.add_parser(
        "batch",
        help="solve every row of a .csv or .parquet table",
        description="Solve every row of a scene table. Columns: the paper's form (alpha; "
        "optional beta, xi, n_masses) or a general chain (masses, springs, optional dashpots as "
        "lists, in CSV ';'-separated; k_contact, v0, contact, links), optional method, rtol, "
        "step. Any other column is an error unless named with --keep.",
        epilog=EXIT_CODES,
        formatter_class=fmt,
    )
    batch.add_argument("input", type=Path, help="the scene table (.csv or .parquet)")
    batch.add_argument("-o", "--output", type=Path, required=True, help="OUT.csv or OUT.parquet")
    batch.add_argument(
        "--max-events", type=int, default=MAX_EVENTS_DEFAULT, help="contact budget per row"
    )
    batch.add_argument("--keep", default="", help="comma-separated columns carried through")
    batch.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="progress bar with ETA on stderr (default: on when stderr is a terminal)",
    )
    batch.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        help="no progress bar and no summary line (warnings and errors are still printed)",
    )
    warm = sub.add_parser(
        "warmup",
        help="compile every kernel into numba's cache (seconds per kernel)",
        description="Compile every numba kernel into the cache every entry point shares, so "
        "that no later first call waits for a compilation; prints the seconds each kind of "
        "scene took (a compile with a cold cache, a load with a warm one).",
    )
    warm.add_argument(
        "-j",
        "--jobs",
        type=int,
        choices=(1, 2),
        default=None,
        help="processes compiling at once (default: 2 where there are 2 or more cores)",
    )
    return p


def _warmup(args) -> int:
    import os
    import time

    from restitution.warmup import warmup

    jobs = args.jobs if args.jobs is not None else min(2, os.cpu_count() or 1)
    print(f"numba cache: {os.environ.get('NUMBA_CACHE_DIR')} ({jobs} process(es))", flush=True)
    t0 = time.perf_counter()
    times = warmup(lambda label, s: print(f"  {s:7.1f} s  {label}", flush=True), jobs=jobs)
    print(
        f"  {time.perf_counter() - t0:7.1f} s  in all ({sum(s for _, s in times):.1f} s of steps)",
        flush=True,
    )
    return EXIT_OK


def _clean(value):
    """JSON-ready: NaN -> null, inf -> the string 'inf' (JSON has no infinities)."""
    if isinstance(value, float):
        if math.isnan(value):
            return None
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_clean(v) for v in value]
    return value


def _cor(args) -> int:
    from restitution.api import solve
    from restitution.model.chain import SceneError

    law_keys = ("contact", "eta", "dr", "structure", "L", "ks_ratio", "theta0", "corner", "v0")
    paper = {
        k: getattr(args, k) for k in ("beta", "xi", "n_masses") if getattr(args, k) is not None
    }
    law = {k: getattr(args, k) for k in (*law_keys, "rtol", "step") if getattr(args, k) is not None}
    common = dict(method=args.method, history=args.history, max_events=args.max_events)
    # the general form's options (attribute: flag)
    general_opts = {
        "dashpots": "dashpots",
        "k_contact": "k-contact",
        "contact_spec": "contact-law",
        "links": "links",
        "velocities": "velocities",
        "stretches": "stretches",
    }
    if args.masses is not None or args.springs is not None:
        if args.alpha is not None:
            raise SceneError("give either --alpha (the paper's form) or --masses/--springs")
        extra = {k: law.pop(k) for k in ("v0", "rtol", "step") if k in law}
        stray = sorted([*paper, *law])
        if stray:
            raise SceneError(
                f"--{', --'.join(k.replace('_', '-') for k in stray)}: options of the paper's "
                "form; a general chain takes --dashpots, --k-contact, --contact-law and --links"
            )
        general = {k: getattr(args, k) for k in general_opts if getattr(args, k) is not None}
        general["contact"] = general.pop("contact_spec", None)
        r = solve(masses=args.masses, springs=args.springs, **general, **extra, **common)
    else:
        if args.alpha is None:
            raise SceneError("give --alpha (the paper's form) or --masses and --springs")
        stray = [opt for k, opt in general_opts.items() if getattr(args, k) is not None]
        if stray:
            raise SceneError(
                f"--{', --'.join(stray)}: need a general chain (--masses ...); the paper's "
                "form takes --beta, --xi, --n-masses and the law options"
            )
        r = solve(alpha=args.alpha, **paper, **common, **law)
    if args.json:
        print(json.dumps(_clean(r.to_dict(history=args.history))))
    else:
        print(f"cor              {r.cor:.15g}")
        print(f"n_collisions     {r.n_collisions}")
        print(f"omega_t_col      {r.omega_t_col:.15g}")
        print(f"t_col            {r.t_col:.15g}")
        print(f"e_translational  {r.e_translational:.15g}")
        print(f"e_vibrational    {r.e_vibrational:.15g}")
        print(f"e_dissipated     {r.e_dissipated:.15g}")
        print(f"method           {r.method}")
        print(f"status           {r.status}")
        print(f"error_estimate   {r.error_estimate:.3g}")
        if args.history and r.history is not None:
            print(r.history.to_string())
    return EXIT_OK if r.success else EXIT_NOT_OK


def same_file(a: Path, b: Path) -> bool:
    """True if two paths name the same file (symlinks and relative paths resolved)."""
    if a.resolve() == b.resolve():
        return True
    try:
        return b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def batch_summary(status, seconds: float, output: Path) -> str:
    """The one line ``restitution batch`` prints on stderr once the table is written.

    E.g. ``restitution: 120 rows in 3.4 s (118 ok, 2 event_budget_exhausted) -> out.parquet``;
    statuses other than ok in decreasing count.
    """
    counts = status.value_counts()
    ok = int(counts.pop("ok")) if "ok" in counts.index else 0
    parts = [f"{ok} ok", *(f"{int(n)} {s}" for s, n in counts.items())]
    rows = "row" if len(status) == 1 else "rows"
    return f"restitution: {len(status)} {rows} in {seconds:.1f} s ({', '.join(parts)}) -> {output}"


def _batch(args) -> int:
    from restitution.api import solve_many
    from restitution.model.chain import SceneError
    from restitution.tables.io import read_table, write_table

    if args.output.suffix not in (".csv", ".parquet"):
        raise SceneError(f"output must end in .csv or .parquet; got {args.output}")
    if same_file(args.input, args.output):
        raise SceneError(
            f"the output {args.output} is the input table {args.input}: refusing to overwrite "
            "the scenes with their results; choose another output"
        )
    start = time.perf_counter()
    frame = read_table(args.input, what="scene table")
    keep = [c.strip() for c in args.keep.split(",") if c.strip()]
    progress = sys.stderr.isatty() if args.progress is None else args.progress
    progress = progress and not args.quiet
    result = solve_many(frame, max_events=args.max_events, progress=progress, keep=keep)
    write_table(result, args.output)
    if not args.quiet:
        print(batch_summary(result["status"], time.perf_counter() - start, args.output),
              file=sys.stderr)  # fmt: skip
    bad = result["status"] != "ok"
    if bad.any():
        counts = result.loc[bad, "status"].value_counts()
        print(
            f"warning: {int(bad.sum())} of {len(result)} rows did not finish cleanly "
            f"({', '.join(f'{n} {s}' for s, n in counts.items())}; see the status column)",
            file=sys.stderr,
        )
        return EXIT_NOT_OK
    return EXIT_OK


def _on_sigterm(signum, frame):
    # Raised inside the main thread: write_table's finally removes its temporary file.
    raise SystemExit(EXIT_SIGNAL + signum)


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from restitution.model.chain import SceneError

    errors = (SceneError,)
    if args.command == "batch":  # tables (pandas, pyarrow: 0.3 s of imports) only where read
        from restitution.tables.io import TableError

        errors = (SceneError, TableError)
    previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        if args.command == "warmup":
            return _warmup(args)
        return _cor(args) if args.command == "cor" else _batch(args)
    except errors as e:
        print(f"restitution: error: {e}", file=sys.stderr)
        return EXIT_INPUT
    except OSError as e:  # reading the input: one line, not a traceback
        print(f"restitution: error: {e.filename or ''}: {e.strerror or e}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print("restitution: interrupted", file=sys.stderr)
        return EXIT_SIGNAL + signal.SIGINT
    finally:
        signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
