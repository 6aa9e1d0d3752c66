"""Parquet (and CSV) tables of scenes and results: explicit schema, provenance, atomic writes."""

from __future__ import annotations

import csv
import errno
import hashlib
import json
import os
import re
import subprocess
import tempfile
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

PROVENANCE_KEY = b"restitution"

# The data contract of docs/physics.md; columns outside it keep the type pandas gives them.
CONTRACT_TYPES = {
    "alpha": pa.float64(),
    "beta": pa.float64(),
    "xi": pa.float64(),
    "n_masses": pa.int64(),
    "cor": pa.float64(),
    "n_collisions": pa.int64(),
    "omega_t_col": pa.float64(),
    "e_translational": pa.float64(),
    "e_vibrational": pa.float64(),
    "e_dissipated": pa.float64(),
    "method": pa.string(),
    "status": pa.string(),
    "error_estimate": pa.float64(),
}

_LIBRARIES = ("numpy", "scipy", "numba", "pandas", "pyarrow", "matplotlib", "snakemake")


class TableError(RuntimeError):
    """A results table is missing, truncated, corrupt or lacks its provenance."""


def config_hash(config) -> str:
    """SHA-256 of the canonical JSON of ``config`` (key order does not matter)."""
    text = json.dumps(config, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def _git_commit() -> str:
    here = Path(__file__).resolve().parent
    try:
        sha = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=here, capture_output=True, text=True, timeout=5
        )
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=here,
            capture_output=True,
            text=True,
            timeout=5,
        )
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    if sha.returncode != 0:
        return "unknown"
    return sha.stdout.strip() + ("-dirty" if dirty.stdout.strip() else "")


def _version(name: str) -> str:
    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"


def provenance(config=None) -> dict:
    """Package version, git commit, config hash and library versions."""
    return {
        "package_version": _version("restitution"),
        "git_commit": _git_commit(),
        "config_hash": None if config is None else config_hash(config),
        "config": config,
        "libraries": {name: _version(name) for name in _LIBRARIES},
    }


def methods_summary(frame: pd.DataFrame) -> dict | None:
    """Rows and largest error estimate per method used (None for a table without results)."""
    if "method" not in frame:
        return None
    summary = {}
    for method, rows in frame.groupby("method", sort=True):
        entry = {"rows": int(len(rows))}
        if "error_estimate" in rows:
            entry["max_error_estimate"] = float(rows["error_estimate"].max())
        summary[str(method)] = entry
    return summary


def schema_for(frame: pd.DataFrame) -> pa.Schema:
    """Explicit types for the contract columns; the others as pandas infers them."""
    inferred = pa.Schema.from_pandas(frame, preserve_index=False)
    fields = [
        pa.field(f.name, CONTRACT_TYPES.get(f.name, f.type)) for f in inferred if f.name in frame
    ]
    return pa.schema(fields)


def _csv_cell(value):
    """A list cell as ';'-separated numbers, a law (mapping or list of mappings) as JSON."""
    if isinstance(value, dict):
        return json.dumps(value, default=float)
    if isinstance(value, (list, tuple, np.ndarray)):
        items = list(value)
        if any(isinstance(v, dict) for v in items):
            return json.dumps(items, default=float)
        return ";".join(repr(float(v)) for v in items)
    return value


def _csv_cells(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with its list and law cells in their CSV text form (scene tables read back)."""
    cols = [c for c in frame.columns if frame[c].dtype == object]
    if not cols:
        return frame
    out = frame.copy()
    for c in cols:
        out[c] = [_csv_cell(v) for v in frame[c].to_numpy()]
    return out


def _tmp_prefix(path: Path) -> str:
    # The writer's pid is part of the name so that a later run can tell a killed writer's
    # leftover (pid gone) from a file another live process is still writing.
    return f".{path.name}.{os.getpid()}."


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def clean_leftovers(path) -> list[Path]:
    """Remove temporary files of ``path`` left by writers that were killed (SIGKILL, power
    loss): hidden ``.NAME.PID.*.tmp`` files in the same directory whose PID is not running."""
    path = Path(path)
    pattern = re.compile(rf"^\.{re.escape(path.name)}\.(\d+)\..*\.tmp$")
    removed = []
    try:
        entries = list(path.parent.iterdir())
    except OSError:
        return removed
    for entry in entries:
        m = pattern.match(entry.name)
        if m and int(m.group(1)) != os.getpid() and not _pid_alive(int(m.group(1))):
            try:
                entry.unlink()
                removed.append(entry)
            except OSError:
                pass
    return removed


def _io_error(path: Path, e: OSError) -> TableError:
    """A one-line message for an operating-system error while writing ``path``."""
    reason = {
        errno.ENOSPC: "no space left on the device",
        errno.EDQUOT: "disk quota exceeded",
        errno.EACCES: "permission denied",
        errno.EPERM: "permission denied",
        errno.EROFS: "read-only file system",
        errno.ENOENT: "no such directory",
        errno.ENOTDIR: "a parent is not a directory",
    }.get(e.errno, e.strerror or str(e))
    return TableError(f"{path}: cannot write the table ({reason})")


def write_table(frame: pd.DataFrame, path, *, config=None, extra: dict | None = None) -> Path:
    """Write ``frame`` to ``path`` (.parquet with provenance, or .csv), atomically.

    The file appears under its final name only when complete (temporary file + rename), so an
    interrupted run never leaves a complete-looking table; the temporary file is removed on any
    error or exception (SIGTERM in the CLI becomes one), and a killed writer's leftover is
    removed by the next write of the same table. Operating-system errors (missing or unwritable
    directory, full disk) raise TableError with a one-line message.
    """
    path = Path(path)
    if path.suffix not in (".csv", ".parquet"):
        raise TableError(f"{path}: unsupported table format {path.suffix!r} (.parquet or .csv)")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise _io_error(path.parent, e) from None
    clean_leftovers(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=_tmp_prefix(path), suffix=".tmp", dir=path.parent)
    except OSError as e:
        raise _io_error(path, e) from None
    os.close(fd)
    try:
        if path.suffix == ".csv":
            _csv_cells(frame).to_csv(tmp, index=False)
        else:
            meta = provenance(config)
            meta["methods"] = methods_summary(frame)
            if extra:
                meta.update(extra)
            table = pa.Table.from_pandas(
                frame.reset_index(drop=True), schema=schema_for(frame), preserve_index=False
            )
            merged = dict(table.schema.metadata or {})
            merged[PROVENANCE_KEY] = json.dumps(meta, sort_keys=True, default=str).encode()
            pq.write_table(table.replace_schema_metadata(merged), tmp)
        # mkstemp creates the file 0600; give it the mode a plain open() would (umask applied).
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except OSError as e:
        raise _io_error(path, e) from None
    except (pa.ArrowException, TypeError, ValueError) as e:  # a column Arrow cannot store
        raise TableError(f"{path}: cannot write the table ({e})".replace("\n", " ")) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def read_table(
    path, *, require_provenance: bool = False, columns=(), what: str = "results file"
) -> pd.DataFrame:
    """Read a .parquet or .csv table; raise TableError naming the file when it is unusable.

    ``columns``: names the table must have (a readable file of another kind is refused by name).
    ``what``: the kind of table, as a missing file's message names it (e.g. "scene table").
    """
    path = Path(path)
    if not path.is_file():
        raise TableError(f"{path}: is a directory, not a {what}" if path.is_dir()
                         else f"{path}: no such {what}")  # fmt: skip
    try:
        if path.suffix == ".csv":
            return _require(path, _read_csv(path), columns)
        if path.suffix != ".parquet":
            raise TableError(f"{path}: unsupported table format {path.suffix!r}")
        table = pq.read_table(path)
    except (pa.ArrowException, OSError, ValueError, pd.errors.ParserError) as e:
        raise TableError(f"{path}: unreadable or truncated table ({e})") from e
    names = table.schema.names
    dup = sorted({c for c in names if names.count(c) > 1})
    if dup:
        raise TableError(f"{path}: column(s) {dup} appear more than once")
    if require_provenance and PROVENANCE_KEY not in (table.schema.metadata or {}):
        raise TableError(f"{path}: no '{PROVENANCE_KEY.decode()}' provenance in its metadata")
    return _require(path, table.to_pandas(), columns)


def _read_csv(path: Path) -> pd.DataFrame:
    """A CSV table, refusing what pandas would silently repair: a row with more or fewer fields
    than the header (it would shift or pad the columns) and a repeated column name (it would be
    renamed 'x.1')."""
    with open(path, newline="") as f:
        rows = csv.reader(f)
        header = next(rows, None)
        if header is None:
            raise TableError(f"{path}: empty file (no header line)")
        seen = set()
        for name in header:
            if name in seen:
                raise TableError(f"{path}: column {name!r} appears more than once in the header")
            seen.add(name)
        for line, row in enumerate(rows, start=2):
            if row and len(row) != len(header):
                raise TableError(
                    f"{path}: line {line} (row {line - 2}) has {len(row)} fields, the header "
                    f"has {len(header)}; a ragged row would shift or pad the columns"
                )
    return _numbers_read(pd.read_csv(path))


def _numbers_read(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with the cells of its scene parameter columns (``RANGES``) that are numbers in
    the CSV text as numbers also where another cell of the column is not: pandas then leaves
    the whole column as text, and the scene checks named the column's first cell (a good
    number, "2.0") instead of the bad one. The cells that do not parse stay text, refused by
    the checks with their row."""
    from restitution.model.ranges import RANGES

    for name in frame.columns:
        if name in RANGES and frame[name].dtype.kind not in "fiub":  # (text: str or object)
            text = frame[name]
            numbers = pd.to_numeric(text, errors="coerce")
            keep = numbers.isna() & text.notna()  # not a number: the text stays
            frame[name] = numbers.astype(object).where(~keep, text)
    return frame


def _require(path: Path, frame: pd.DataFrame, columns) -> pd.DataFrame:
    missing = [c for c in columns if c not in frame.columns]
    if missing:
        raise TableError(f"{path}: missing column(s) {missing}; it has {list(frame.columns)}")
    return frame


def read_provenance(path) -> dict:
    """The provenance dictionary stored in a parquet file's schema metadata."""
    try:
        meta = pq.read_schema(path).metadata or {}
    except (pa.ArrowException, OSError) as e:
        raise TableError(f"{path}: unreadable or truncated table ({e})") from e
    if PROVENANCE_KEY not in meta:
        raise TableError(f"{path}: no '{PROVENANCE_KEY.decode()}' provenance in its metadata")
    return json.loads(meta[PROVENANCE_KEY])
