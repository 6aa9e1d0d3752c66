"""Run a snippet against the package as it was at another commit (for before/after scripts).

``export(ref)`` writes ``git archive REF src`` into a temporary folder (no worktree, nothing in
the repository changes); ``run(src, code, payload)`` runs ``code`` in a fresh interpreter with
that ``src`` first on the path and its own numba cache, ``payload`` as JSON on stdin, and returns
its stdout. Two versions of the package cannot share one process, hence the subprocess.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def export(ref: str, into: str | None = None) -> Path:
    """The ``src`` folder of commit ``ref`` under a new temporary folder; returns that folder."""
    where = Path(into or tempfile.mkdtemp(prefix="then-"))
    blob = subprocess.run(
        ["git", "-C", str(ROOT), "archive", ref, "src"], check=True, capture_output=True
    ).stdout
    with tarfile.open(fileobj=io.BytesIO(blob)) as tar:
        tar.extractall(where, filter="data")
    return where


def run(tree: Path | None, code: str, payload: str = "", threads: int | None = None) -> str:
    """stdout of ``code`` run with ``tree/src`` (None: this checkout's package) on the path."""
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = str(Path(tree) / "src")
        env["NUMBA_CACHE_DIR"] = str(Path(tree) / "numba-cache")
    if threads is not None:
        env["NUMBA_NUM_THREADS"] = str(threads)
    done = subprocess.run(
        [sys.executable, "-c", code],
        input=payload,
        capture_output=True,
        text=True,
        env=env,
        cwd=str(tree or ROOT),
    )
    if done.returncode != 0:
        raise RuntimeError(f"snippet failed:\n{done.stderr[-4000:]}")
    return done.stdout
