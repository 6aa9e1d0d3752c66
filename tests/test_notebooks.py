"""The analysis notebooks (jupytext percent-format .py) execute end to end on a small configuration.

Each ``notebooks/*.py`` is converted with jupytext and run by nbclient in a fresh kernel, with its
parameters (environment variables, see the notebook's first cell) set small. Its input, the
Fig. 2(a) sweep table, is written here by the package's API and
``restitution.tables.io.write_table``
into a temporary results folder, so the test needs no workflow run. The design-question cell
must find the paper's headline minimum, checked against the closed form (paper Eqs. 10-11).
"""

import subprocess
from pathlib import Path

import jupytext
import nbclient
import numpy as np
import pandas as pd
import pytest

import restitution
from restitution.analysis import sweeps
from restitution.tables.io import write_table

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "notebooks").glob("*.py"))

SMALL = {
    "NB_HEATMAP_N_ALPHA": "24",
    "NB_HEATMAP_N_BETA": "12",
    "NB_DESIGN_BETAS": "0,0.1",
    "NB_DESIGN_N_MASSES": "2,3",
    "NB_DESIGN_N_ALPHA": "40",
    "NB_REFINE_STEPS": "30",
}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """A small Fig. 2(a)-like sweep table (the columns the notebook reads), from the API."""
    root = tmp_path_factory.mktemp("results")
    alphas = sweeps.log_grid(0.5, 4.0, 60)
    frame = pd.DataFrame({"alpha": np.tile(alphas, 2), "beta": np.repeat([0.0, 0.1], alphas.size)})
    table = restitution.solve_many(frame)
    write_table(table, root / "fig2a" / "sweep.parquet", config={"test": "notebooks"})
    return root


def test_notebooks_are_reviewable_sources():
    assert NOTEBOOKS, "no notebooks/*.py"
    tracked = subprocess.run(
        ["git", "ls-files", "notebooks"], cwd=REPO, capture_output=True, text=True, check=True
    ).stdout.split()
    assert not [f for f in tracked if f.endswith(".ipynb")], "commit the .py, never an .ipynb"
    for path in NOTEBOOKS:
        text = path.read_text()
        assert "format_name: percent" in text, f"{path.name}: not a jupytext percent notebook"
        assert "numba" not in text and "njit" not in text, f"{path.name}: copies kernel code"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_executes(path, results, monkeypatch, tmp_path):
    monkeypatch.setenv("RESTITUTION_RESULTS", str(results))
    # The kernel draws with its inline backend (image/png outputs); Agg would draw nothing.
    monkeypatch.delenv("MPLBACKEND", raising=False)
    for key, value in SMALL.items():
        monkeypatch.setenv(key, value)
    notebook = jupytext.read(path)
    client = nbclient.NotebookClient(
        notebook,
        timeout=300,
        kernel_name="python3",
        resources={"metadata": {"path": str(REPO)}},
    )
    client.execute()  # raises CellExecutionError, with the cell and traceback, on any error
    text = "\n".join(
        output.get("text", "") + str(output.get("data", {}).get("text/plain", ""))
        for cell in notebook.cells
        if cell.cell_type == "code"
        for output in cell.get("outputs", [])
    )
    assert "image/png" in str(notebook.cells), "no figure was drawn"
    if path.name == "cor_explorer.py":
        assert f"results from {results}" in text
        # Design question, N = 2 at a rigid wall: alpha*_1 = 1/(1 - 2 cos x1) with tan x1 = x1
        # in (pi, 3 pi/2), and the COR there (paper Eqs. 10-11: 0.697123, 0.178465).
        assert "N = 2, beta = 0: smallest COR 0.178465 at alpha = 0.697123" in text, text
