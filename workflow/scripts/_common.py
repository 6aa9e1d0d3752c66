"""Shared start-up for every workflow script: logging into the rule's log, numba threads, progress.

Usage at the top of a script's ``if __name__ == "__main__":`` block::

    from _common import setup

    log = setup(snakemake)  # noqa: F821 (``snakemake`` is injected by Snakemake)

- Python logging (and warnings) go to the rule's ``log:`` file; an uncaught exception is written
  there with its traceback before the job fails (and still printed to stderr).
- ``NUMBA_NUM_THREADS`` and ``numba.set_num_threads`` follow the rule's ``threads``: Snakemake sets
  OMP/MKL thread variables from ``threads:`` but not numba's, so ``-c2`` would oversubscribe.
- ``NUMBA_CACHE_DIR`` defaults to the project cache ``.cache/numba`` (cleared by ``make clean``
  and CI).
- ``show_progress()`` is True only when stderr is a terminal, so logs and CI stay free of bars.

Scripts read ``snakemake.params`` (the config subtree their rule passes), never
``snakemake.config``; their work is a ``main(...)`` function that notebooks can call directly.
The analysis they run is the package's (``restitution.analysis.sweeps``: one refined-sweep body,
one definition of a COR minimum); the workflow glue they share besides start-up is
``chunk_alphas`` (one job's share of a chunked alpha grid of the config) and ``log_minima`` (the
log line of a minima table).
"""

from __future__ import annotations

import logging
import os
import sys
import time
from pathlib import Path

LOG_FORMAT = "%(asctime)s %(levelname)s %(name)s: %(message)s"


def project_root() -> Path:
    """The repository root: Snakemake runs jobs with the working directory at the workflow root."""
    return Path.cwd()


def configure_numba(threads: int) -> int:
    """Cap numba's thread pool at ``threads`` (call before heavy work); return the count used."""
    threads = max(1, int(threads))
    os.environ.setdefault("NUMBA_CACHE_DIR", str(project_root() / ".cache" / "numba"))
    os.environ.setdefault("NUMBA_NUM_THREADS", str(threads))
    import numba

    used = min(threads, numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(used)
    return used


def configure_logging(log_path: str | os.PathLike | None, name: str) -> logging.Logger:
    """Send logging and warnings to ``log_path`` (stderr when None); log uncaught exceptions."""
    if log_path:
        Path(log_path).parent.mkdir(parents=True, exist_ok=True)
        handler: logging.Handler = logging.FileHandler(log_path, mode="w", encoding="utf-8")
    else:
        handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter(LOG_FORMAT))
    root = logging.getLogger()
    for old in list(root.handlers):
        root.removeHandler(old)
    root.addHandler(handler)
    root.setLevel(logging.INFO)
    for noisy in ("numba", "matplotlib", "PIL", "fontTools"):
        logging.getLogger(noisy).setLevel(logging.WARNING)
    logging.captureWarnings(True)
    logger = logging.getLogger(name)

    def excepthook(kind, value, tb):
        logger.critical("uncaught exception, job failed", exc_info=(kind, value, tb))
        handler.flush()
        sys.__excepthook__(kind, value, tb)

    sys.excepthook = excepthook
    return logger


def show_progress() -> bool:
    """Progress bars only on an interactive terminal (never in logs or CI)."""
    return sys.stderr.isatty()


def setup(snakemake, numba: bool = True) -> logging.Logger:
    """Logging into ``snakemake.log[0]``; numba threads from ``snakemake.threads`` if ``numba``.

    Scripts that never run a kernel (plotting) pass ``numba=False`` and skip importing numba.
    """
    log_path = snakemake.log[0] if len(snakemake.log) else None
    logger = configure_logging(log_path, f"restitution.workflow.{snakemake.rule}")
    os.environ.setdefault("NUMBA_CACHE_DIR", str(project_root() / ".cache" / "numba"))
    used = configure_numba(snakemake.threads) if numba else 0
    logger.info(
        "rule %s, wildcards %s, threads %d, numba threads %s",
        snakemake.rule,
        dict(snakemake.wildcards.items()),
        snakemake.threads,
        used or "not used",
    )
    return logger


def chunk_alphas(grid: dict, chunk: int):
    """Alphas of chunk ``chunk`` of a config grid (``alpha_min``, ``alpha_max``, ``n_alpha``,
    ``chunk_size``: config fig2a, fig7), the boundary point shared with the next chunk."""
    from restitution.analysis import sweeps

    alphas = sweeps.log_grid(grid["alpha_min"], grid["alpha_max"], grid["n_alpha"])
    return sweeps.chunk(alphas, grid["chunk_size"], chunk)


def log_minima(logger: logging.Logger, minima, by: str, along: str = "alpha") -> None:
    """One log line per curve of a minima table (``sweeps.local_minima``): its (along, COR)."""
    for key, group in minima.groupby(by):
        listed = ", ".join(
            f"({a:.6g}, {c:.6f})" for a, c in zip(group[along], group["cor"], strict=True)
        )
        logger.info("%s %g: %d minima (%s, COR): %s", by, key, len(group), along, listed[:400])


class Timer:
    """``with Timer(log, "what"):`` logs the wall time of a block."""

    def __init__(self, logger: logging.Logger, what: str):
        self.logger, self.what = logger, what

    def __enter__(self):
        self.start = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.start
        self.logger.info("%s: %.2f s", self.what, self.seconds)
        return False
