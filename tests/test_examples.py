"""The scripts of examples/ run as a user runs them (a subprocess, outputs under a folder given on
the command line) and give the numbers closed forms give: two equal masses at a rigid wall
rebound with COR 1 after 2 contacts, t_col = pi sqrt(m / 2k) apart; the paper's first COR
minimum at a rigid wall is alpha* = 0.697123, e = 0.178465 (Eqs. 10-11)."""

import json
import math
import re
import subprocess
import sys

import pandas as pd
import pytest

from conftest import REPO, snakemake_env
from restitution.tables.io import read_provenance, read_table

PNG = b"\x89PNG\r\n\x1a\n"


def run_example(name: str, *args, cwd) -> str:
    """Run examples/<name> from ``cwd``; fail with its output if it fails. Returns stdout."""
    before = _examples_state()
    result = subprocess.run([sys.executable, str(REPO / "examples" / name), *map(str, args)],
                            cwd=cwd, env=snakemake_env(), capture_output=True, text=True,
                            timeout=900)  # fmt: skip
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-5000:]
    assert _examples_state() == before, "an example wrote into the repository"
    return result.stdout


def _examples_state() -> str:
    """Every file under examples/, ignored ones included (a script writes only under OUT)."""
    return subprocess.run(["git", "status", "--porcelain", "--ignored", "examples"], cwd=REPO,
                          capture_output=True, text=True, check=True).stdout  # fmt: skip


def test_own_chain(tmp_path):
    out = tmp_path / "chain"
    printed = run_example("own_chain.py", out, cwd=tmp_path)
    result = json.loads((out / "result.json").read_text())
    assert result["status"] == "ok" and "t_col_s" in printed
    energies = result["e_translational"] + result["e_vibrational"] + result["e_dissipated"]
    assert energies == pytest.approx(1.0, abs=1e-9)
    assert result["e_translational"] == pytest.approx(result["cor"] ** 2, abs=1e-12)
    assert result["e_dissipated"] > 0  # the example's first link is damped
    assert result["v_after_m_per_s"] == pytest.approx(result["cor"] * 1.5, rel=1e-12)
    for suffix in ("png", "pdf"):
        assert (out / f"trajectory.{suffix}").stat().st_size > 1000
    assert (out / "trajectory.png").read_bytes()[:8] == PNG

    # Two equal masses m on a spring k at a rigid wall: COR 1, 2 contacts, t_col = pi sqrt(m/2k).
    out = tmp_path / "equal"
    run_example("own_chain.py", out, "--masses", 0.25, 0.25, "--springs", 400, "--k-contact",
                "inf", "--no-plot", cwd=tmp_path)  # fmt: skip
    result = json.loads((out / "result.json").read_text())
    assert result["cor"] == pytest.approx(1.0, abs=1e-12) and result["n_collisions"] == 2
    assert result["t_col_s"] == pytest.approx(math.pi * math.sqrt(0.25 / 800.0), rel=1e-12)
    assert result["e_vibrational"] == pytest.approx(0.0, abs=1e-12)
    assert not (out / "trajectory.png").exists()


def test_table_sweep(tmp_path):
    out = tmp_path / "sweep"
    run_example("table_sweep.py", out, "--n-alpha", 21, cwd=tmp_path)
    table = read_table(out / "sweep.parquet", require_provenance=True)
    assert len(table) == 21 * 4 and (table["status"] == "ok").all()
    assert read_provenance(out / "sweep.parquet")["config"]["beta"] == [0.0, 1e-3, 1e-2, 1e-1]
    rigid = table[table["beta"] == 0.0]
    one = rigid.loc[(rigid["alpha"] - 1.0).abs().idxmin()]  # 0.1 * 100**(10/20)
    assert one["alpha"] == pytest.approx(1.0, abs=1e-12)
    assert one["cor"] == pytest.approx(1.0, abs=1e-9) and one["n_collisions"] == 2
    # No grid point goes below the rigid wall's smallest COR (paper Eq. 11).
    assert rigid["cor"].min() >= 0.178465 - 1e-6
    assert (out / "cor_vs_alpha.png").read_bytes()[:8] == PNG
    assert (out / "cor_vs_alpha.pdf").stat().st_size > 1000


def run_example_failing(name: str, *args, cwd) -> str:
    """Run examples/<name> expecting bad input: exit code 2, its error as the last line of
    stderr, no traceback, nothing written into ``cwd``. Returns that line."""
    before = sorted(p.name for p in cwd.iterdir())
    result = subprocess.run([sys.executable, str(REPO / "examples" / name), *map(str, args)],
                            cwd=cwd, env=snakemake_env(), capture_output=True, text=True,
                            timeout=900)  # fmt: skip
    assert result.returncode == 2, result.stdout[-3000:] + result.stderr[-5000:]
    assert "Traceback" not in result.stderr, result.stderr
    assert sorted(p.name for p in cwd.iterdir()) == before
    return result.stderr.strip().splitlines()[-1]


def test_own_chain_bad_input_is_one_line(tmp_path):
    """(An existing file as OUT raised FileExistsError, a bad value a SceneError traceback.)"""
    (tmp_path / "f.txt").write_text("mine")
    line = run_example_failing("own_chain.py", "f.txt", cwd=tmp_path)
    assert line == "own_chain.py: error: OUT f.txt exists and is not a folder; give a folder " \
                   "for the outputs"  # fmt: skip
    assert (tmp_path / "f.txt").read_text() == "mine"
    line = run_example_failing("own_chain.py", "outd", "--dashpots", "-1", cwd=tmp_path)
    assert line == "own_chain.py: error: dashpots[0] must be in [0, 1e100]; got -1.0"


@pytest.mark.parametrize("n", [0, 1, -3])
def test_table_sweep_refuses_fewer_than_two_alphas(tmp_path, n):
    """(--n-alpha 0 wrote an empty table and figure, exit code 0.)"""
    line = run_example_failing("table_sweep.py", "sweep", "--n-alpha", n, cwd=tmp_path)
    assert line == f"table_sweep.py: error: --n-alpha must be at least 2 (the points of each " \
                   f"curve); got {n}"  # fmt: skip


@pytest.mark.pipeline
def test_study_example(tmp_path):
    out = tmp_path / "study"
    printed = run_example("run_study.py", out, cwd=tmp_path)
    assert "$ " in printed and "snakemake study" in printed  # the command, to copy
    results = out / "results" / "studies" / "two_mass_rod"
    sweep = read_table(results / "sweep.parquet", require_provenance=True)
    rigid = sweep[(sweep["curve_index"] == 0) & (sweep["status"] == "ok")]
    assert math.isinf(rigid["k_contact"].iloc[0])
    one = rigid.loc[(rigid["masses[1]"] - 1.0).abs().idxmin()]  # two equal masses
    assert one["cor"] == pytest.approx(1.0, abs=1e-9) and one["n_collisions"] == 2
    # m1 = 1 kg, so masses[1] is the paper's alpha: its first minimum (Eqs. 10-11).
    minima = pd.read_csv(results / "minima.csv")
    first = minima[(minima["curve_index"] == 0) & (minima["minimum"] == 1)].iloc[0]
    assert first["masses[1]"] == pytest.approx(0.697123, abs=1e-6)
    assert first["cor"] == pytest.approx(0.178465, abs=2e-6)
    for name in ("cor", "n_collisions"):
        png = out / "figures" / "studies" / "two_mass_rod" / f"{name}.png"
        assert png.read_bytes()[:8] == PNG
    html = (out / "report.html").read_text()
    page = json.loads(re.search(r'var workflow_desc = (".*?");\n', html, re.S).group(1))
    assert "Study two_mass_rod." in page and "SI: kg, N/m; V0 = 1 m/s" in page
    assert "System Message" not in page
