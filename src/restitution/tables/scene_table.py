"""Strict reading of scene tables: every column known, every cell checked, before any work.

Rules (the same for ``solve_many`` and ``restitution batch``):

* column names are strings without surrounding whitespace, each at most once;
* a column not in ``COLUMNS`` (nor in the caller's ``keep``) is an error that suggests the
  nearest known name ("did you mean 'beta'?");
* the paper's form (``alpha``...) and the general form (``masses``...) are not mixed;
* numbers must be numbers: booleans, text and NaN in a numeric column are errors naming the row
  and the column (a missing optional cell, NaN in a law or setting column, takes its default);
* list cells (``masses``, ``springs``, ``dashpots``) are lists or ``;``-separated text (spaces
  inside a cell are fine); law cells (``contact``, ``links``) are mappings / lists of mappings
  (parquet structs) or their JSON text;
* per-row settings ``rtol`` and ``step`` are honoured for rows solved by a method that reads
  them (``rtol``: adaptive, reference; ``step``: verlet) and refused on any other row (where
  they would silently do nothing).
"""

from __future__ import annotations

import difflib
import json
import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from restitution.model.chain import Chain, SceneError, check_column, paper_with_laws
from restitution.model.ranges import _real, _show, missing_cell, missing_list
from restitution.model.units import kernel_params
from restitution.solvers import methods as M
from restitution.solvers.result import RESULT_COLUMNS, T_COL
from restitution.tables import linear_rows

PAPER = ("alpha", "beta", "xi", "n_masses")
GENERAL = ("masses", "springs", "dashpots", "k_contact", "v0", "contact", "links", "velocities",
           "stretches")  # fmt: skip
LEGACY_LAWS = ("contact", "eta", "dr", "structure", "L", "ks_ratio", "theta0", "corner", "v0")
SETTINGS = ("method", "rtol", "step")
COLUMNS = tuple(dict.fromkeys((*PAPER, *GENERAL, *LEGACY_LAWS, *SETTINGS)))
DEFAULTS = {"beta": 0.0, "xi": 0.0, "n_masses": 2}
# The columns of one form only (v0 and contact belong to both): with the other form's an error.
GENERAL_ONLY = tuple(c for c in GENERAL if c not in LEGACY_LAWS)
PAPER_ONLY = (*PAPER, *(c for c in LEGACY_LAWS if c not in GENERAL))


def _row(frame, i) -> str:
    return f"row {frame.index[i]!r}"


def check_columns(frame, keep=()) -> None:
    """Column names: strings, unique, no stray whitespace, all known (or kept)."""
    if not isinstance(frame, pd.DataFrame):
        raise SceneError(f"expected a pandas DataFrame of scenes; got {type(frame).__name__}")
    keep = set(keep)
    seen = set()
    for name in frame.columns:
        if not isinstance(name, str):
            raise SceneError(f"column names must be text; got {name!r}")
        if name != name.strip():
            raise SceneError(f"column {name!r} has stray whitespace in its name; remove it")
        if name in seen:
            raise SceneError(f"column {name!r} appears more than once")
        seen.add(name)
    clash = [c for c in (*RESULT_COLUMNS, T_COL) if c in seen and c != "method"]
    if clash:
        raise SceneError(f"the scene table already has result columns {clash}; drop them first")
    unknown = [c for c in frame.columns if c not in COLUMNS and c not in keep]
    if unknown:
        hints = []
        for c in unknown:
            near = difflib.get_close_matches(c, COLUMNS, n=1, cutoff=0.6)
            hints.append(f"{c!r}" + (f" (did you mean {near[0]!r}?)" if near else ""))
        raise SceneError(
            f"unknown column(s) {', '.join(hints)}; known: {', '.join(COLUMNS)} "
            "(pass keep=[...] / --keep to carry other columns through)"
        )


def parse_list(name: str, cell, where: str):
    """A list cell: a sequence, or ';'-separated text (spaces fine)."""
    if isinstance(cell, str):
        parts = [p.strip() for p in cell.split(";")]
        if parts == [""]:
            raise SceneError(f"{name} must not be empty ({where})")
        try:
            return [float(p) for p in parts]
        except ValueError:
            raise SceneError(
                f"{name} must be ';'-separated numbers, e.g. '1; 0.5; 2'; got {cell!r} ({where})"
            ) from None
    if missing_cell(cell):
        raise SceneError(f"{name} is missing ({where})")
    if _real(cell) is not None:  # one number: a one-entry list (a CSV cell "1.0" of a two-mass
        return [cell]  # chain's springs is read as a number, also from our own CSV output)
    return cell


def parse_law(name: str, cell, where: str):
    """A law cell: a mapping (or for links a list of mappings), or its JSON text."""
    if missing_cell(cell):
        return None
    if isinstance(cell, str):
        try:
            cell = json.loads(cell)
        except json.JSONDecodeError:
            raise SceneError(
                f'{name} must be a mapping such as {{"law": "hertz", "k": 50}} or its '
                f"JSON text; got {cell!r} ({where})"
            ) from None
    if name == "links" and not isinstance(cell, Mapping):
        if isinstance(cell, (str, bytes)) or not isinstance(cell, (list, tuple, np.ndarray)):
            raise SceneError(
                f'links must be a list of law mappings such as [{{"law": "linear"}}] or its '
                f"JSON text; got {_show(cell)} ({where})"
            )
        cell = list(cell)
    return cell


class SceneTable:
    """A checked scene table: ``plan`` (a dict of arrays alpha, beta, xi, n_masses, method,
    paper, omega, one entry per row), the method of every row also as ``method_codes`` into
    ``method_names``, the Chains of a general table (``chains``; None for the paper's form)."""

    def __init__(self, frame: pd.DataFrame, keep=()):
        check_columns(frame, keep)
        self.frame = frame
        self.columns = frozenset(frame.columns)  # ``name in frame`` costs ~3 us a time
        has_paper = "alpha" in self.columns
        has_general = "masses" in self.columns or "springs" in self.columns
        if has_paper and has_general:
            raise SceneError(
                "a scene table takes either the paper's form (alpha, beta, xi, n_masses) or a "
                "general chain (masses, springs, dashpots, ...), not both"
            )
        if not has_paper and not has_general:
            raise SceneError(
                "the scene table needs a column 'alpha' (the paper's form; optional beta, xi, "
                "n_masses, method) or columns 'masses' and 'springs' (a general chain); got "
                f"columns {list(frame.columns)}"
            )
        self.settings_cols = {}
        for name in ("rtol", "step"):
            if name in self.columns:
                values = frame[name].to_numpy()
                given = ~pd.isna(values)
                if given.any():
                    check_column(name, values[given], frame.index[given])
                self.settings_cols[name] = (values, given)
        method = self._methods()
        self.method_codes = np.zeros(len(frame), dtype=np.int64)
        self.method_names = []
        if has_paper:
            self.chains = None
            self._legacy = {}
            self.plan = self._paper_plan(method)
        else:
            self.chains, self.plan = self._general(method)
        self._check_settings()

    # ------------------------------------------------------------------------------------------
    def _methods(self) -> np.ndarray:
        frame = self.frame
        if "method" not in self.columns:  # (a read-only view: no 20,000 object cells to fill)
            return np.broadcast_to(np.array("auto", dtype=object), len(frame))
        values = frame["method"].to_numpy(dtype=object)
        out = np.where(pd.isna(values), "auto", values).astype(object)
        bad = ~pd.Series(out).isin(M.NAMES).to_numpy()
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise SceneError(
                f"method must be one of {', '.join(M.NAMES)}; got {values[i]!r} "
                f"({_row(frame, i)}, column 'method')"
            )
        return out

    def _paper_plan(self, method: np.ndarray) -> pd.DataFrame:
        frame = self.frame
        n = len(frame)
        illegal = [c for c in GENERAL_ONLY if c in self.columns]
        if illegal:
            raise SceneError(f"columns {illegal} belong to the general form, not with 'alpha'")
        plan = {}
        for name in PAPER:
            if name in self.columns:
                plan[name] = check_column(name, frame[name].to_numpy(), frame.index)
            else:
                plan[name] = np.full(n, DEFAULTS[name])
        legacy = np.zeros(n, dtype=bool)
        law_cols = [c for c in LEGACY_LAWS if c in self.columns]
        for c in ("contact", "structure"):
            if c in self.columns:
                v = frame[c].to_numpy(dtype=object)
                given = ~pd.isna(v)  # (NA from a pyarrow-backed column compares as NA: mask first)
                legacy[given] |= v[given] != "linear"
        for c in ("v0", "eta", "dr", "L", "ks_ratio", "theta0", "corner"):
            if c in self.columns:  # given: the row's laws are read (and checked) row by row
                legacy |= ~pd.isna(frame[c].to_numpy(dtype=object))
        alpha, beta, xi, nm = plan["alpha"], plan["beta"], plan["xi"], plan["n_masses"]
        chosen = np.empty(n, dtype=object)
        # Linear rows: one dispatcher call per distinct (rigid wall, N, method), so the solver
        # table decides for every row at the cost of a few calls.
        lin = np.flatnonzero(~legacy)
        sel = slice(None) if len(lin) == n else lin  # (a slice, not a gather, on the usual table)
        if len(lin):
            codes = pd.factorize(method[sel])[0] if "method" in self.columns else 0
            key = (beta[sel] == 0.0) + 2 * nm[sel] + 4096 * codes
            if (key == key[0]).all():  # one group (a sweep of one N and wall): no sort
                firsts, groups = np.zeros(1, dtype=np.int64), np.zeros(len(lin), dtype=np.int64)
            else:
                _, firsts, groups = np.unique(key, return_index=True, return_inverse=True)
            for g, j in enumerate(firsts):
                i = lin[j]
                try:
                    ch = Chain._paper(alpha[i], beta[i], xi[i], int(nm[i]))
                    name = M.choose(ch, method[i]).name
                except SceneError as e:
                    raise SceneError(f"{e} ({_row(frame, i)})") from None
                rows = sel if len(firsts) == 1 else lin[groups == g]
                chosen[rows] = name
                self._method_code(rows, name)
        cells = {c: frame[c].to_numpy(dtype=object) for c in law_cols}  # (not .iat per cell)
        for i in np.flatnonzero(legacy):
            law = {c: v[i] for c, v in cells.items() if not missing_cell(v[i])}
            try:
                ch, _ = paper_with_laws(alpha[i], beta[i], xi[i], int(nm[i]), law)
                chosen[i] = M.choose(ch, method[i]).name
            except SceneError as e:
                raise SceneError(f"{e} ({_row(frame, i)})") from None
            self._method_code(i, chosen[i])
            self._legacy[i] = ch
        plan["method"] = chosen
        plan["paper"] = ~legacy
        plan["omega"] = np.ones(n)
        return plan

    def _general(self, method: np.ndarray) -> tuple[list, dict]:
        """(chains, plan) of a general table: column-wise where every row is a plainly valid
        linear chain (restitution.tables.linear_rows), else row by row."""
        kc, v0 = self._general_columns()
        self._kc, self._raw = kc, None
        self.k_contact, self.v0 = kc, v0  # the checked columns (float64)
        fast = linear_rows.read(self.frame, self.columns, kc, v0, method)
        if fast is None:
            self.chains = self._general_chains(kc, v0)
            return self.chains, self._general_plan(method)
        chains, plan, chosen, self._raw = fast
        for name in dict.fromkeys(chosen):
            self._method_code(chosen == name, name)
        plan["method"] = chosen
        return chains, plan

    def _general_columns(self) -> tuple[np.ndarray, np.ndarray]:
        """The checked k_contact and v0 columns of a general table (defaults inf and 1)."""
        frame = self.frame
        illegal = [c for c in PAPER_ONLY if c in self.columns]
        if illegal:
            raise SceneError(
                f"columns {illegal} belong to the paper's form; a general chain gives its laws "
                "in the struct columns 'contact' and 'links' (docs/general-chains.md)"
            )
        for c in ("masses", "springs"):
            if c not in self.columns:
                raise SceneError(f"a general chain table needs a column {c!r}")
        n = len(frame)
        kc = (
            check_column("k_contact", frame["k_contact"].to_numpy(), frame.index)
            if "k_contact" in self.columns
            else np.full(n, math.inf)
        )
        if "v0" in self.columns:
            v0 = check_column("v0", frame["v0"].to_numpy(), frame.index)
        else:
            v0 = np.ones(n)
        return kc, v0

    def _general_chains(self, kc: np.ndarray, v0: np.ndarray) -> list:
        frame = self.frame
        n = len(frame)
        cols = {c: frame[c].to_numpy(dtype=object) for c in GENERAL if c in self.columns}
        chains = []
        for i in range(n):
            where = _row(frame, i)
            try:
                masses = parse_list("masses", cols["masses"][i], where)
                springs = parse_list("springs", cols["springs"][i], where)
                dashpots = None
                if "dashpots" in cols and not missing_list(cols["dashpots"][i]):
                    dashpots = parse_list("dashpots", cols["dashpots"][i], where)
                contact = (
                    parse_law("contact", cols["contact"][i], where) if "contact" in cols else None
                )
                links = parse_law("links", cols["links"][i], where) if "links" in cols else None
                state = [  # the initial state's list cells (missing: the uniform approach)
                    None
                    if name not in cols or missing_list(cols[name][i])
                    else parse_list(name, cols[name][i], where)
                    for name in ("velocities", "stretches")
                ]
                chains.append(Chain(masses, springs, dashpots, kc[i], v0[i], contact, links,
                                    *state))  # fmt: skip
            except SceneError as e:
                msg = str(e)
                raise SceneError(msg if where in msg else f"{msg} ({where})") from None
        return chains

    def _general_plan(self, method: np.ndarray) -> pd.DataFrame:
        frame = self.frame
        plan = {}
        ch = self.chains
        summary = [c.paper_form for c in ch]
        plan["alpha"] = np.array([c.alpha for c in ch], dtype=float)
        plan["beta"] = np.array([c.beta for c in ch], dtype=float)
        plan["xi"] = np.array([c.xi for c in ch], dtype=float)
        plan["n_masses"] = np.array([c.n_masses for c in ch], dtype=np.int64)
        chosen = []
        for i, c in enumerate(ch):
            try:
                chosen.append(M.choose(c, method[i]).name)
            except SceneError as e:
                raise SceneError(f"{e} ({_row(frame, i)})") from None
            self._method_code(i, chosen[-1])
        plan["method"] = np.array(chosen, dtype=object)
        plan["paper"] = np.array([s is not None for s in summary], dtype=bool)
        plan["omega"] = np.array([c.omega for c in ch], dtype=float)
        return plan

    def _method_code(self, rows, name: str) -> None:
        """Record the method of ``rows`` also as a code into ``method_names`` (the result table
        builds its method column from codes: no per-row strings)."""
        if name not in self.method_names:
            self.method_names.append(name)
        self.method_codes[rows] = self.method_names.index(name)

    def _check_settings(self) -> None:
        """A setting cell on a row whose method does not read it is refused
        (``methods.check_settings``: it would do nothing)."""
        if not self.settings_cols:
            return
        for name, (_, given) in self.settings_cols.items():
            deaf = [c for c, m in enumerate(self.method_names) if name not in M.METHODS[m].settings]
            wrong = given & np.isin(self.method_codes, deaf)
            if wrong.any():
                i = int(np.flatnonzero(wrong)[0])
                try:
                    M.check_settings(M.METHODS[self.plan["method"][i]], (name,))
                except SceneError as e:
                    raise SceneError(f"{e} ({_row(self.frame, i)}, column {name!r})") from None

    # ------------------------------------------------------------------------------------------
    def scaled(self, rows: np.ndarray) -> tuple:
        """(m, k, c, n, kc) of general-table rows in the kernels' units (``Chain.scaled``, bit
        for bit), padded to the longest chain (m, k with 1, c with 0): the batch kernel's input."""
        n = self.plan["n_masses"][rows]
        nmax = int(n.max())
        if self._raw is not None:  # column-wise: the operations of Chain.scaled on every row
            m_raw, k_raw, c_raw = self._raw
            m, k, c = m_raw[rows, :nmax], k_raw[rows, : nmax - 1], c_raw[rows, : nmax - 1]
            m1, w = m[:, :1], self.plan["omega"][rows][:, None]  # (one per row, as columns)
            m, k, c, kc = kernel_params(m, k, c, self._kc[rows][:, None], m1, w)
            m[np.arange(nmax) >= n[:, None]] = 1.0  # the padding as the row-by-row path pads
            k[np.arange(nmax - 1) >= n[:, None] - 1] = 1.0
            return m, k, c, n, kc[:, 0]
        scaled = [self.chains[i].scaled() for i in rows]
        m, k, c = (
            np.ones((len(rows), nmax)),
            np.ones((len(rows), nmax - 1)),
            np.zeros((len(rows), nmax - 1)),
        )
        for j, (mj, kj, cj, _) in enumerate(scaled):
            m[j, : len(mj)], k[j, : len(kj)], c[j, : len(cj)] = mj, kj, cj
        return m, k, c, n, np.array([s[3] for s in scaled])

    def chain(self, i: int) -> Chain:
        if self.chains is not None:
            return self.chains[i]
        if i in self._legacy:
            return self._legacy[i]
        p = self.plan
        return Chain._paper(
            float(p["alpha"][i]), float(p["beta"][i]), float(p["xi"][i]), int(p["n_masses"][i])
        )

    def settings(self, i: int) -> dict:
        return {
            name: float(values[i])
            for name, (values, given) in self.settings_cols.items()
            if given[i]
        }


def scene_table(frame, keep=()) -> SceneTable:
    """The checked table (raises SceneError naming the row and column of the first bad cell)."""
    return SceneTable(frame, keep)


__all__ = ["COLUMNS", "SceneTable", "check_columns", "parse_law", "parse_list", "scene_table"]
