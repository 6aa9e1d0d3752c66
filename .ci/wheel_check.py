"""Install the package as a user gets it and run it: the check behind `make wheel-check`.

Builds the sdist and, from the sdist, the wheel (``uv build``: proves the sdist is complete),
checks that both carry the style file, ``py.typed`` and LICENSE, installs the wheel (not
editable, core dependencies only) into a fresh virtual environment outside the source tree, checks
that snakemake is *not* there, and runs from that environment:

- ``restitution --version`` (the installed version must equal pyproject.toml's),
- ``restitution cor --alpha 0.7 --json`` (valid JSON with a COR in (0, 1)),
- ``restitution batch scenes.csv -o out.parquet`` (a parquet table is written),
- ``solve_many`` on rigid-wall scenes below alpha*_1, against the closed form (1 - a)/(1 + a),
- ``restitution.plotting.use_style()`` (the installed style file is found and applied).

Usage: python .ci/wheel_check.py [--workdir DIR] (default: a temporary directory, removed).
Dependencies come from the registry, pinned by requirements.lock (so uv's cache usually serves
them); with no registry reachable, uv retries offline from its cache.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
import tomllib
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# Files a user's install needs besides the modules (package data and the license).
WHEEL_MEMBERS = ("restitution/restitution.mplstyle", "restitution/py.typed")
SDIST_MEMBERS = ("src/restitution/restitution.mplstyle", "src/restitution/py.typed", "LICENSE")

# Runs inside the fresh environment: solve_many against the closed form, then the style file.
PROBE = r"""
import json, sys
import numpy as np, pandas as pd
import matplotlib as mpl
import restitution
from restitution import plotting
alpha = np.array([0.05, 0.2, 0.5, 0.69])  # below alpha*_1 = 0.697...: one contact, closed form
table = restitution.solve_many(pd.DataFrame({"alpha": alpha, "beta": 0.0}))
expected = (1 - alpha) / (1 + alpha)
error = float(np.max(np.abs(table["cor"].to_numpy() - expected)))
assert error < 1e-12, f"solve_many COR off the closed form (1-a)/(1+a) by {error:.3g}"
assert (table["status"] == "ok").all(), table["status"].tolist()

mpl.rcParams["font.size"] = 99.0
plotting.use_style()
assert mpl.rcParams["font.size"] == 8.0, "use_style() did not apply restitution.mplstyle"
print(json.dumps({"version": restitution.__version__, "solve_many_max_error": error,
                  "style": str(plotting.STYLE), "module": restitution.__file__}))
"""


def pyproject_version() -> str:
    with open(ROOT / "pyproject.toml", "rb") as f:
        return tomllib.load(f)["project"]["version"]


def find_uv() -> str:
    """uv next to the running interpreter (the Makefile installs it into .venv), else on PATH."""
    here = Path(sys.executable).parent / "uv"
    if here.exists():
        return str(here)
    found = shutil.which("uv")
    if found is None:
        sys.exit("wheel_check: uv not found (run `make env`: it installs uv into .venv)")
    return found


def run(cmd: list[str], **kwargs) -> subprocess.CompletedProcess:
    shown = ["<probe script>" if "\n" in str(c) else str(c) for c in cmd]
    print("$", " ".join(shown), flush=True)
    result = subprocess.run(cmd, capture_output=True, text=True, **kwargs)
    if result.stdout.strip():
        print(result.stdout.rstrip())
    if result.returncode != 0:
        print(result.stderr.rstrip(), file=sys.stderr)
    return result


def check(result: subprocess.CompletedProcess, what: str) -> str:
    if result.returncode != 0:
        sys.exit(f"wheel_check: {what} failed (exit {result.returncode})")
    return result.stdout


def user_env() -> dict[str, str]:
    """The environment of a user's shell: no source tree on the path, bytecode allowed."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["MPLBACKEND"] = "Agg"
    return env


def build(uv: str, out: Path) -> tuple[Path, Path]:
    check(run([uv, "build", "--out-dir", str(out), str(ROOT)]), "uv build")
    wheels, sdists = sorted(out.glob("*.whl")), sorted(out.glob("*.tar.gz"))
    if len(wheels) != 1 or len(sdists) != 1:
        sys.exit(f"wheel_check: expected one wheel and one sdist in {out}, got {wheels + sdists}")
    wheel, sdist = wheels[0], sdists[0]
    names = zipfile.ZipFile(wheel).namelist()
    missing = [m for m in WHEEL_MEMBERS if m not in names]
    if not any(n.endswith(".dist-info/licenses/LICENSE") for n in names):
        missing.append("*.dist-info/licenses/LICENSE")
    with tarfile.open(sdist) as tar:
        sdist_names = {n.split("/", 1)[1] for n in tar.getnames() if "/" in n}
    missing += [f"sdist:{m}" for m in SDIST_MEMBERS if m not in sdist_names]
    if missing:
        sys.exit(f"wheel_check: missing from the distributions: {missing}")
    print(f"wheel {wheel.name} and sdist {sdist.name} carry {WHEEL_MEMBERS} and LICENSE")
    return wheel, sdist


def install(uv: str, wheel: Path, venv: Path) -> Path:
    check(run([uv, "venv", "--quiet", "--python", sys.executable, str(venv)]), "uv venv")
    python = venv / "bin" / "python"
    cmd = [uv, "pip", "install", "--quiet", "--python", str(python), str(wheel)]
    cmd += ["--constraint", str(ROOT / "requirements.lock")]
    if run(cmd).returncode != 0:
        print("wheel_check: retrying from uv's cache only (--offline)")
        check(run([*cmd, "--offline"]), "installing the wheel")
    return python


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--workdir", type=Path, help="keep the build and venv here")
    args = parser.parse_args(argv)
    work = args.workdir or Path(tempfile.mkdtemp(prefix="wheel-check-"))
    work.mkdir(parents=True, exist_ok=True)
    try:
        uv = find_uv()
        expected = pyproject_version()
        wheel, _ = build(uv, work / "dist")
        python = install(uv, wheel, work / "venv")
        bindir = python.parent
        env = user_env()
        # Run from the work directory so that the source tree is not importable by accident.
        kw = {"cwd": work, "env": env}

        probe = run(
            [str(python), "-c", "import importlib.util as u; print(u.find_spec('snakemake'))"], **kw
        )
        if check(probe, "looking for snakemake").strip() != "None":
            sys.exit("wheel_check: snakemake is installed by the wheel's core dependencies")
        print("snakemake: not installed (as intended)")

        version = run([str(bindir / "restitution"), "--version"], **kw)
        if version.returncode == 0:
            if expected not in version.stdout:
                sys.exit(
                    f"wheel_check: restitution --version says {version.stdout!r}, not {expected}"
                )
        else:
            # The CLI flag is not in this build yet: the version must still be the installed one.
            print(
                "wheel_check: `restitution --version` not supported by this CLI; checking "
                "restitution.__version__ instead"
            )
            got = check(
                run(
                    [str(python), "-c", "import restitution; print(restitution.__version__)"], **kw
                ),
                "import restitution",
            ).strip()
            if got != expected:
                sys.exit(f"wheel_check: installed version {got!r} != pyproject.toml's {expected!r}")

        out = check(
            run([str(bindir / "restitution"), "cor", "--alpha", "0.7", "--json"], **kw),
            "restitution cor --alpha 0.7 --json",
        )
        record = json.loads(out)
        if not 0.0 < float(record["cor"]) < 1.0:
            sys.exit(f"wheel_check: COR out of (0, 1): {record}")

        # A table in, a parquet table out (pyarrow, provenance) through the installed CLI.
        (work / "scenes.csv").write_text("alpha,beta\n0.5,0.0\n2.0,0.01\n")
        check(
            run([str(bindir / "restitution"), "batch", "scenes.csv", "-o", "out.parquet"], **kw),
            "restitution batch scenes.csv -o out.parquet",
        )
        if not (work / "out.parquet").is_file():
            sys.exit("wheel_check: restitution batch wrote no out.parquet")

        result = json.loads(
            check(run([str(python), "-c", PROBE], **kw), "solve_many and use_style")
        )
        if not result["module"].startswith(str(venv_root(python))):
            sys.exit(f"wheel_check: restitution imported from {result['module']}, not the venv")
        if result["version"] != expected:
            sys.exit(f"wheel_check: __version__ {result['version']!r} != {expected!r}")
        print(f"wheel_check: ok (restitution {expected} from {wheel.name}, without snakemake)")
        return 0
    finally:
        if args.workdir is None:
            shutil.rmtree(work, ignore_errors=True)


def venv_root(python: Path) -> Path:
    return python.parent.parent.resolve()


if __name__ == "__main__":
    sys.exit(main())
