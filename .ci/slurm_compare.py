"""Check that two runs of the workflow wrote the same tables under results/.

Usage: python .ci/slurm_compare.py LOCAL_DIR SLURM_DIR

Every .parquet and .csv file under LOCAL_DIR/results must exist under SLURM_DIR/results and the
other way round, with the same columns, dtypes and values (exactly: NaN equals NaN in the same
place, no tolerance) and, for parquet, the same schema metadata: the pandas block and the
restitution provenance (package version, git commit, config and its hash, library versions,
methods summary). Nothing is ignored, because none of it may differ: the provenance holds no
timestamp, host name or path, and both runs use the same code, configuration and library pins.
Exit status 1 with one line per difference.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq

PATTERNS = ("*.parquet", "*.csv")


def tables(root: Path) -> set[str]:
    """Paths of the result tables below root/results, relative to root."""
    found = set()
    for pattern in PATTERNS:
        found |= {str(p.relative_to(root)) for p in (root / "results").rglob(pattern)}
    return found


def decoded(metadata: dict | None) -> dict:
    """Schema metadata with JSON values parsed, so a difference can be named by key."""
    out = {}
    for key, value in (metadata or {}).items():
        try:
            out[key.decode()] = json.loads(value)
        except ValueError:
            out[key.decode()] = value.decode(errors="replace")
    return out


def differing_keys(a, b, prefix="") -> list[str]:
    """Dotted keys whose values differ between two nested dictionaries."""
    if not (isinstance(a, dict) and isinstance(b, dict)):
        return [] if a == b else [prefix or "<value>"]
    keys = []
    for key in sorted(set(a) | set(b)):
        where = f"{prefix}.{key}" if prefix else str(key)
        if key not in a or key not in b:
            keys.append(where)
        else:
            keys.extend(differing_keys(a[key], b[key], where))
    return keys


def compare(rel: str, left: Path, right: Path) -> tuple[list[str], int]:
    """Differences between one table in the two runs (empty when equal), and its row count."""
    problems = []
    if rel.endswith(".parquet"):
        schema_a, schema_b = pq.read_schema(left), pq.read_schema(right)
        if not schema_a.remove_metadata().equals(schema_b.remove_metadata()):
            problems.append(f"{rel}: schemas differ:\n{schema_a}\nvs\n{schema_b}")
        keys = differing_keys(decoded(schema_a.metadata), decoded(schema_b.metadata))
        if keys:
            problems.append(f"{rel}: schema metadata differs at {', '.join(keys)}")
        frame_a, frame_b = pd.read_parquet(left), pd.read_parquet(right)
    else:
        frame_a, frame_b = pd.read_csv(left), pd.read_csv(right)
    if frame_a.empty:
        problems.append(f"{rel}: no rows (nothing was compared)")
    try:
        pd.testing.assert_frame_equal(frame_a, frame_b, check_exact=True)
    except AssertionError as e:
        problems.append(f"{rel}: data differ: {e}")
    return problems, len(frame_a)


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    local, slurm = (Path(a) for a in argv)
    names_local, names_slurm = tables(local), tables(slurm)
    problems = [f"{rel}: only in the local run" for rel in sorted(names_local - names_slurm)]
    problems += [f"{rel}: only in the SLURM run" for rel in sorted(names_slurm - names_local)]
    if not names_local & names_slurm:
        problems.append(f"no result tables in common under {local}/results and {slurm}/results")
    common = sorted(names_local & names_slurm)
    rows = {}
    for rel in common:
        found, rows[rel] = compare(rel, local / rel, slurm / rel)
        problems += found
    if problems:
        print(f"local and SLURM runs differ ({len(problems)} problem(s)):", file=sys.stderr)
        for problem in problems:
            print(f"  {problem}", file=sys.stderr)
        return 1
    print(f"{len(common)} tables equal (data exactly; parquet schema and metadata too):")
    for rel in common:
        print(f"  {rel} ({rows[rel]} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
