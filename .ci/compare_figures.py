#!/usr/bin/env python3
"""Compare every committed figure with the one the workflow just regenerated (CI, issue 8).

Usage (from the repository root, after ``make all`` regenerated ``figures/``)::

    .venv/bin/python .ci/compare_figures.py                 # committed = git's HEAD
    .venv/bin/python .ci/compare_figures.py --committed DIR # committed = PNGs saved in DIR

Every ``figures/*.png`` of the committed tree (git's HEAD, or a directory of saved copies) is
compared with the regenerated ``figures/*.png`` by ``matplotlib.testing.compare.compare_images``
(RMS of the per-channel pixel difference, 0..255). Figures whose RMS exceeds ``--tol`` are listed
with the path of their difference image, as are committed figures the run did not produce and
regenerated figures that are not committed. Exit status 1 if any figure changed, 0 otherwise.
``figures/benchmarks/`` is not compared: it plots timings, which vary between runs and machines.

Tolerance (RMS on the 0-255 scale, measured with Fig. 2(a), 1020 x 734 px, on 2026-11-22): the
renders are deterministic (pinned matplotlib with its bundled FreeType, Agg backend, no
timestamps), so an unchanged figure regenerates byte-identical (RMS 0). Scaling the COR of one of
its five curves by 1 + 1e-9 still gives RMS 0 (no pixel moves); by 1 + 1e-6,
0.013; by 1 + 1e-4 (a twentieth of a pixel), 0.25; by 1 + 1e-3, 2.5; changing one legend label,
17. DEFAULT_TOL = 0.1 therefore passes only round-off-sized differences and fails any change of
the data at the 1e-4 level or above, and any change of text or style. Override it with --tol or
the environment variable FIGURE_RMS_TOL.
"""

import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

from matplotlib.testing.compare import compare_images
from matplotlib.testing.exceptions import ImageComparisonFailure

DEFAULT_TOL = 0.1


def committed_from_git(repo: Path, folder: str, out: Path, rev: str = "HEAD") -> list[Path]:
    """Write ``rev``'s ``folder/*.png`` (top level only) into ``out``; return the written paths."""
    listing = subprocess.run(
        ["git", "ls-tree", "--name-only", f"{rev}:{folder}"],
        cwd=repo,
        check=True,
        capture_output=True,
        text=True,
    ).stdout.split()
    written = []
    for name in sorted(n for n in listing if n.endswith(".png")):
        blob = subprocess.run(
            ["git", "show", f"{rev}:{folder}/{name}"], cwd=repo, check=True, capture_output=True
        ).stdout
        path = out / name
        path.write_bytes(blob)
        written.append(path)
    return written


def compare_folders(committed: Path, regenerated: Path, work: Path, tol: float) -> list[str]:
    """Problems found comparing ``committed/*.png`` with ``regenerated/*.png`` (top level).

    Both images of a pair are copied into ``work`` first, so matplotlib's difference image
    (``<name>-failed-diff.png``) lands there and never in the figures folder.
    """
    work.mkdir(parents=True, exist_ok=True)
    old = {p.name: p for p in committed.glob("*.png")}
    new = {p.name: p for p in regenerated.glob("*.png")}
    problems = [f"{name}: committed but not regenerated" for name in sorted(old.keys() - new)]
    problems += [f"{name}: regenerated but not committed" for name in sorted(new.keys() - old)]
    for name in sorted(old.keys() & new.keys()):
        expected = work / f"{Path(name).stem}-committed.png"
        actual = work / name
        shutil.copyfile(old[name], expected)
        shutil.copyfile(new[name], actual)
        try:
            result = compare_images(str(expected), str(actual), tol, in_decorator=True)
        except ImageComparisonFailure as error:  # e.g. the image size changed
            problems.append(f"{name}: {error}")
            continue
        if result is not None:
            problems.append(
                f"{name}: RMS {result['rms']:.3f} > {tol} (diff image: {result['diff']})"
            )
    return problems


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--figures", default="figures", help="regenerated figures (default: %(default)s)"
    )
    parser.add_argument(
        "--committed", type=Path, help="folder of committed PNGs (default: read them from git HEAD)"
    )
    parser.add_argument(
        "--work",
        type=Path,
        default=Path("results/figure-compare"),
        help="where the compared copies and difference images go (default: %(default)s)",
    )
    parser.add_argument(
        "--tol",
        type=float,
        default=float(os.environ.get("FIGURE_RMS_TOL", DEFAULT_TOL)),
        help="largest RMS pixel difference (0-255) that counts as unchanged (default: %(default)s)",
    )
    args = parser.parse_args(argv)
    if args.tol < 0:
        parser.error(f"--tol = {args.tol}: must be >= 0")
    figures = Path(args.figures)
    if not figures.is_dir():
        parser.error(f"--figures = {figures}: no such folder")

    if args.work.exists():
        shutil.rmtree(args.work)
    committed = args.committed
    if committed is None:
        committed = args.work / "committed"
        committed.mkdir(parents=True)
        try:
            committed_from_git(Path.cwd(), figures.as_posix(), committed)
        except (OSError, subprocess.CalledProcessError) as error:
            detail = getattr(error, "stderr", None) or ""
            if isinstance(detail, bytes):
                detail = detail.decode(errors="replace")
            print(
                f"cannot read the committed {figures}/*.png from git HEAD ({error} "
                f"{detail.strip()}): run in a git checkout or pass --committed DIR",
                file=sys.stderr,
            )
            return 1
    elif not committed.is_dir():
        parser.error(f"--committed = {committed}: no such folder")

    n_committed = len(list(committed.glob("*.png")))
    if n_committed == 0:
        print(f"no committed figures found in {committed}", file=sys.stderr)
        return 1
    problems = compare_folders(committed, figures, args.work, args.tol)
    if problems:
        print(
            f"{len(problems)} figure(s) differ from the committed ones (tol {args.tol}):",
            file=sys.stderr,
        )
        for line in problems:
            print(f"  {line}", file=sys.stderr)
        print(
            "If the change is intended, commit the regenerated figures with the code that "
            "changed them.",
            file=sys.stderr,
        )
        return 1
    print(f"all {n_committed} committed figures match the regenerated ones (RMS <= {args.tol})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
