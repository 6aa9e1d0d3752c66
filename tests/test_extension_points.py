"""The extension points of docs/guides/adding-a-law.md and adding-a-method.md, tested.

Each guide ends with two tables: the places a new law (method) touches, and the places that name
particular laws (methods) but that a new one leaves alone. This file reads them, the one list of
places, and checks that

- every place exists;
- every definition in ``src/restitution`` that names a particular law or method is in one of the
  tables (a new place cannot go unlisted) and every untouched place still names one;
- a toy method added through exactly its rows (one row of ``METHODS``) is run by ``solve``,
  ``solve_many`` and ``restitution cor`` and agrees with ``impulsive``: the toy is a slow
  pure-Python event loop for two masses at a rigid wall (closed-form free flight, impulsive
  reversal of m1's velocity, the next contact by a scan and brentq) that shares no code with
  the kernels;
- a toy contact law (the cubic F = k x^3, elastic) added through exactly its rows in ``laws.py``
  is run by ``solve``, ``solve_many`` and ``restitution cor`` and agrees with an independent
  ``solve_ivp`` integration written here.

The laws are compiled into the kernels (and into numba's cache), so a law can only be added
before the kernels are imported, and compiling them again for it would take minutes: the toy
law is added in a child process with numba's JIT disabled, where the kernels run as Python and
call the laws as they are (``NUMBA_DISABLE_JIT``; a scene takes a second).
"""

import ast
import contextlib
import io
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import restitution
from restitution import SceneError
from restitution.kernels import layout as L
from restitution.solvers import methods as M

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "src" / "restitution"
GUIDES = REPO / "docs" / "guides"
LAW_GUIDE, METHOD_GUIDE = "adding-a-law.md", "adding-a-method.md"
_ROW = re.compile(r"^\|\s*`([^`]+)`\s*\|\s*(.*?)\s*\|\s*$")


# ----------------------------------------------------------------------------------------------
# The guides' tables of places
# ----------------------------------------------------------------------------------------------
def places(guide: str, kind: str, table: str = "places") -> dict:
    """{place: when (or why)} of the guide's table ``<!-- table: kind -->``; a place is a path
    of the repository, or ``path::name`` for a definition in it."""
    text = (GUIDES / guide).read_text()
    found = re.search(rf"<!-- {table}: {kind} -->\n(.*?)<!-- /{table} -->", text, re.S)
    assert found, f"{guide} has no table '{table}: {kind}'"
    rows = [_ROW.match(line) for line in found.group(1).splitlines()]
    return {r.group(1): r.group(2) for r in rows if r}


def _when(text: str) -> str:
    """The keyword a table's ``when`` column starts with (every, elastic, memory, ...)."""
    return re.match(r"\w+", text).group()


def _top_level(path: Path) -> dict:
    """{name: node} of the top-level definitions of a Python file (def, class, assignment)."""
    out = {}
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            out[node.name] = node
        elif isinstance(node, ast.Assign):
            out.update({t.id: node for t in node.targets if isinstance(t, ast.Name)})
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            out[node.target.id] = node
    return out


def _naming(ids: set, words: set) -> set:
    """``path::name`` of every top-level definition in src/restitution whose code (docstrings
    aside) uses one of the names ``ids`` or the string constants ``words``."""
    found = set()
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text())
        docs = {
            id(n.value)
            for n in ast.walk(tree)
            if isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant)
        }
        for name, node in _top_level(path).items():
            for sub in ast.walk(node):
                used = (
                    (isinstance(sub, ast.Name) and sub.id in ids)
                    or (isinstance(sub, ast.Attribute) and sub.attr in ids)
                    or (
                        isinstance(sub, ast.Constant) and id(sub) not in docs and sub.value in words
                    )
                )
                if used:
                    found.add(f"{path.relative_to(REPO)}::{name}")
                    break
    return found


def _law_names(kind: str) -> tuple[set, set]:
    """The id constants (C_..., S_...) of the laws of ``kind`` and their names as words, but
    'rigid' and 'linear' (words of too many other meanings)."""
    from restitution.model import laws

    table, prefix = (laws.CONTACT_LAWS, "C_") if kind == "contact" else (laws.LINK_LAWS, "S_")
    ids = {entry[0] for entry in table.values()}
    consts = {n for n in vars(laws) if n.startswith(prefix) and getattr(laws, n) in ids}
    return consts, set(table) - {"rigid", "linear"}


TABLES = [(LAW_GUIDE, "contact"), (LAW_GUIDE, "link"), (METHOD_GUIDE, "method")]


@pytest.mark.parametrize("guide, kind", TABLES)
def test_every_place_of_the_guides_exists(guide, kind):
    rows = {**places(guide, kind), **places(guide, kind, "untouched")}
    assert len(rows) >= 5
    for place in rows:
        path, _, name = place.partition("::")
        assert (REPO / path).exists(), f"{guide}: {path} does not exist"
        if not name:
            continue
        defined = _top_level(REPO / path)
        if "<NAME>" in name:  # a new definition: the convention it follows must be in use
            pattern = re.escape(name).replace(re.escape("<NAME>"), "[A-Z0-9_]+")
            assert any(re.fullmatch(pattern, d) for d in defined), f"{guide}: no {name} in {path}"
        else:
            assert name in defined, f"{guide}: {path} defines no {name}"


@pytest.mark.parametrize("guide, kind", TABLES)
def test_every_definition_naming_a_law_or_method_is_listed(guide, kind):
    if kind == "method":
        naming = _naming(set(), set(M.METHODS))
    else:
        naming = _naming(*_law_names(kind))
    listed = set(places(guide, kind)) | set(places(guide, kind, "untouched"))
    unlisted = naming - listed
    assert not unlisted, f"{guide}: places naming a particular {kind} are not listed: {unlisted}"
    stale = set(places(guide, kind, "untouched")) - naming
    assert not stale, f"{guide}: listed as naming a {kind}, but they no longer do: {stale}"


# ----------------------------------------------------------------------------------------------
# A toy method (docs/guides/adding-a-method.md)
# ----------------------------------------------------------------------------------------------
def _toy_cor(m1: float, m2: float, k: float, max_events: int):
    """(COR, contacts, omega*t_col, status) of m1 - k - m2 hitting a rigid wall at speed 1."""
    a = m2 / m1
    w = math.sqrt(k / m1 + k / m2)
    mu = a / (1.0 + a)  # x1 = X - mu r (X: centre of mass, r = x2 - x1)
    r, rd, v1, v2 = 0.0, 0.0, -1.0, -1.0  # at the first contact: x1 = 0, spring relaxed
    t_last, contacts = 0.0, 0
    while True:
        contacts += 1
        if contacts > max_events:
            return math.nan, max_events, math.nan, L.STATUS_EVENT_BUDGET
        v1 = -v1  # the impact reverses m1's velocity
        V, rd = (v1 + a * v2) / (1.0 + a), v2 - v1
        X, amp = mu * r, math.hypot(r, rd / w)

        def x1(t, X=X, V=V, r=r, rd=rd):
            return X + V * t - mu * (r * math.cos(w * t) + rd / w * math.sin(w * t))

        # Scan for m1 back at the wall; none can come once V > 0 and X + V t > mu * amp.
        h = 1e-3 / w
        t, hit = h, None
        while not (V > 0.0 and X + V * t > mu * amp):
            if x1(t + h) < 0.0:
                hit = brentq(x1, t, t + h, xtol=1e-15, rtol=4 * np.finfo(float).eps)
                break
            t += h
        if hit is None:
            return V, contacts, w * t_last, L.STATUS_OK
        c, s = math.cos(w * hit), math.sin(w * hit)
        r, rd = r * c + rd / w * s, -r * w * s + rd * c
        v1, v2 = V - mu * rd, V + (1.0 - mu) * rd
        t_last += hit


def _run_toy(ch, opts):
    """The runner (guide step 1): a kernel-layout row in kernel units."""
    out = np.full(L.N_OUT, np.nan)
    m, k, _, _ = ch.scaled()
    cor, n, wt, status = _toy_cor(float(m[0]), float(m[1]), float(k[0]), opts.max_events)
    out[[L.OUT_COR, L.OUT_NCOL, L.OUT_TCOL, L.OUT_STATUS]] = cor, n, wt, status
    out[L.OUT_ETRANS] = cor * cor  # undamped: the rest of the energy is vibration
    out[L.OUT_EVIB], out[L.OUT_EDISS] = 1.0 - cor * cor, 0.0
    out[L.OUT_ERR], out[L.OUT_FLAGS], out[L.OUT_NEVENTS] = 1e-9, 0.0, n
    return out, None


def _toy_applies(ch):
    """Guide step 2: the scenes it solves, by the scene model's properties."""
    if ch.n_masses != 2 or not ch.linear or not ch.rigid:
        return "it solves two masses at a rigid wall with linear links only"
    if ch.dashpots.any():
        return "it has no dashpot"
    return None


# The places the toy method is added through (NAMES follows from METHODS when a row is written
# into the table's source; a registration at run time sets it too).
TOY_METHOD_PLACES = {"src/restitution/solvers/methods.py::METHODS"}


@pytest.fixture
def toy(monkeypatch):
    """Guide step 3: one row of the table (the batch runner solves row by row)."""
    row = M.Method("toy", False, 50, _toy_applies, _run_toy, M.row_by_row("toy"), "toy loop")
    monkeypatch.setitem(M.METHODS, "toy", row)
    monkeypatch.setattr(M, "NAMES", (*M.NAMES, "toy"))
    yield row
    M._choose_kind.cache_clear()  # the paper form's cached choices of the toy


def test_the_toy_method_takes_the_places_the_guide_lists():
    every = {p for p, when in places(METHOD_GUIDE, "method").items() if _when(when) == "every"}
    assert {p for p in every if "::" in p} == TOY_METHOD_PLACES


@pytest.mark.parametrize("alpha", [0.3, 0.45, 1.0, 2.2, 5.0, 17.0])
def test_the_toy_method_solves_through_solve_and_agrees_with_impulsive(toy, alpha):
    r = restitution.solve(alpha=alpha, method="toy")
    exact = restitution.solve(alpha=alpha)
    assert r.method == "toy" and r.status == "ok" and exact.method == "impulsive"
    assert r.n_collisions == exact.n_collisions
    assert abs(r.cor - exact.cor) <= 1e-9 + exact.error_estimate
    assert abs(r.omega_t_col - exact.omega_t_col) <= 1e-8


def test_the_toy_method_runs_in_tables_and_general_chains(toy):
    frame = pd.DataFrame({"alpha": [0.5, 2.0, 3.0], "method": ["toy", "auto", "toy"]})
    out = restitution.solve_many(frame)
    assert list(out["method"]) == ["toy", "impulsive", "toy"]
    for i in (0, 2):
        exact = restitution.solve(alpha=float(frame["alpha"].iat[i]))
        assert abs(out["cor"].iat[i] - exact.cor) <= 1e-9
    r = restitution.solve(masses=[2.0, 3.0], springs=[5.0], method="toy")  # user units
    assert abs(r.cor - restitution.solve(masses=[2.0, 3.0], springs=[5.0]).cor) <= 1e-9


def _cli(*argv) -> dict:
    """``restitution cor ... --json`` run in this process: its result, as JSON."""
    from restitution.cli import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(["cor", *argv, "--json"])
    assert code == 0, out.getvalue()
    return json.loads(out.getvalue())


def test_the_command_line_offers_and_runs_the_toy_method(toy):
    r = _cli("--alpha", "2.2", "--method", "toy")
    assert r["method"] == "toy" and r["cor"] == restitution.solve(alpha=2.2, method="toy").cor


def test_the_table_refuses_the_toy_method_where_it_does_not_apply(toy):
    with pytest.raises(SceneError, match="'toy' does not fit.*two masses at a rigid wall"):
        restitution.solve(alpha=2.0, beta=0.1, method="toy")
    with pytest.raises(SceneError, match="'toy' does not fit.*no dashpot"):
        restitution.solve(alpha=2.0, xi=0.1, method="toy")
    assert M.choose(restitution.Chain.paper(2.0)).name == "impulsive"  # auto: exact first


# ----------------------------------------------------------------------------------------------
# A toy contact law (docs/guides/adding-a-law.md)
# ----------------------------------------------------------------------------------------------
LAWS_PY = "src/restitution/model/laws.py"
# The scene: two masses (and three, for the table) on the wall F = k x**3, user units.
CUBIC = {"law": "cubic", "k": 100.0}
MASSES, SPRINGS, V0 = [1.0, 5.0], [1.0], 2.0  # four contacts
MASSES3, SPRINGS3 = [1.0, 5.0, 2.0], [1.0, 1.5]


def add_cubic_law() -> set:
    """The contact law F = k x**3 (elastic) added as a developer adds one, through the guide's
    rows ``every`` and ``elastic`` of laws.py: each edit written as a wrapper that handles the
    new id and leaves the others to the original. Returns the places it took (the id as
    ``C_<NAME>``). Must run before the kernels are imported: they bind the laws then."""
    assert "restitution.kernels.stepping" not in sys.modules, "too late: the kernels are bound"
    from restitution.model import laws

    cubic = 1 + max(e[0] for e in laws.CONTACT_LAWS.values())  # a free id
    old = dict(vars(laws))

    def slope_at_depth(k, energy):  # 3 k x**2 where k x**4 / 4 = energy
        return 3.0 * k * math.sqrt(4.0 * energy / k)

    def pack_contact(spec, v0=1.0, total_mass=1.0, where="contact", k_first=1.0):
        name, p = laws._spec("contact", spec, laws.CONTACT_LAWS, {}, where)
        if name != "cubic":
            return old["pack_contact"](spec, v0, total_mass, where, k_first)
        k = laws.check_stiffness(f"{where}.k", p["k"], math.inf)
        laws.check_contact_ratio(where, k_first / slope_at_depth(k, 0.5 * v0 * v0), "slope")
        # cp[1]: the slope where the whole initial energy would take it (an upper bound)
        scale = slope_at_depth(k, 0.5 * total_mass * v0 * v0)
        return laws.contact_params(cubic, scale, k, 3.0), math.nan

    def effective_stiffness(cp, v0):
        if cp[0] == cubic:
            return slope_at_depth(cp[2], 0.5 * v0 * v0)
        return old["effective_stiffness"](cp, v0)

    def contact_params_ok(cp):
        if cp[0] == cubic:
            return 0.0 < cp[1] < math.inf and 0.0 < cp[2] < math.inf
        return old["contact_params_ok"](cp)

    def contact_force(cp, branch, xmax, fmax, x, xd):
        if cp[0] == cubic:
            return cp[2] * x * x * x if x > 0.0 else 0.0
        return old["contact_force"](cp, branch, xmax, fmax, x, xd)

    def contact_slope(cp, branch, xmax, x):
        if cp[0] == cubic:
            return 3.0 * cp[2] * x * x if x > 0.0 else 0.0
        return old["contact_slope"](cp, branch, xmax, x)

    def contact_hysteretic(cp, xmax, fmax, x, xd):
        if cp[0] == cubic:
            return contact_force(cp, 0, xmax, fmax, x, xd), xmax, fmax
        return old["contact_hysteretic"](cp, xmax, fmax, x, xd)

    def contact_energy(cp, x):
        if cp[0] == cubic:
            return 0.25 * cp[2] * x**4 if x > 0.0 else 0.0
        return old["contact_energy"](cp, x)

    def contact_elastic(cp):
        return cp[0] == cubic or old["contact_elastic"](cp)

    edits = {
        "C_CUBIC": cubic,
        "CONTACT_LAWS": {**laws.CONTACT_LAWS, "cubic": (cubic, ("k",), {"k": (1, 4)})},
        "pack_contact": pack_contact,
        "effective_stiffness": effective_stiffness,
        "contact_params_ok": contact_params_ok,
        "contact_force": contact_force,
        "contact_slope": contact_slope,
        "contact_hysteretic": contact_hysteretic,
        "contact_energy": contact_energy,
        "ELASTIC_CONTACTS": (*laws.ELASTIC_CONTACTS, cubic),
        "contact_elastic": contact_elastic,
    }
    for name, value in edits.items():
        setattr(laws, name, value)
    return {f"{LAWS_PY}::{name.replace('CUBIC', '<NAME>')}" for name in edits}


def toy_law_child() -> None:
    """The child process (numba's JIT off): the cubic law added, then solved through every
    entry point; prints one JSON line for the test."""
    took = add_cubic_law()
    r = restitution.solve(masses=MASSES, springs=SPRINGS, contact=CUBIC, v0=V0)
    r3 = restitution.solve(masses=MASSES3, springs=SPRINGS3, contact=CUBIC, v0=V0)
    table = pd.DataFrame(
        {"masses": [MASSES, MASSES3], "springs": [SPRINGS, SPRINGS3], "contact": [CUBIC] * 2}
    )
    table["v0"] = V0
    many = restitution.solve_many(table)
    cli = _cli(
        *("--masses", ",".join(map(str, MASSES)), "--springs", ",".join(map(str, SPRINGS))),
        *("--contact-law", json.dumps(CUBIC), "--v0", str(V0)),
    )
    try:
        restitution.solve(masses=MASSES, springs=SPRINGS, contact=CUBIC, v0=V0, method="reference")
        refused = ""
    except SceneError as e:
        refused = str(e)
    print(
        json.dumps(
            {
                "took": sorted(took),
                "solve": [r.cor, r.n_collisions, r.method, r.status, r.error_estimate],
                "solve3": [r3.cor, r3.n_collisions, r3.method, r3.status],
                "many": [many["cor"].tolist(), many["method"].tolist(), many["status"].tolist()],
                "cli": [cli["cor"], cli["method"]],
                "refused": refused,
            }
        )
    )


def cubic_reference(m, k, kc, v0):
    """(COR, contacts) of two masses m[0] - k - m[1] (undamped) on the wall F = kc x**3, by
    solve_ivp (DOP853, rtol 1e-12). A free flight ends at m1's return to the wall, or by proof
    that it cannot return: the centre of mass X recedes (V > 0) and X - mu |r|max > 0, with
    |r|max the relative motion's conserved amplitude."""
    m1, m2 = m
    mu, w = m2 / (m1 + m2), math.sqrt(k / m1 + k / m2)
    x_deep = (2.0 * (m1 + m2) * v0 * v0 / kc) ** 0.25
    step = 2.0 * math.pi / max(w, math.sqrt(3.0 * kc * x_deep**2 / m1)) / 40.0

    def rhs(t, y, contact):
        u1, u2, v1, v2 = y
        f = k * (u2 - u1)
        wall = kc * (-u1) ** 3 if contact and u1 < 0.0 else 0.0
        return [v1, v2, (f + wall) / m1, -f / m2]

    def at_wall(t, y, contact):
        return y[0]

    at_wall.terminal = True
    y, contacts = np.array([0.0, 0.0, -v0, -v0]), 0
    while contacts < 100:
        contacts += 1
        at_wall.direction = 1.0  # leaving the wall
        opts = dict(method="DOP853", rtol=1e-12, atol=1e-14, max_step=step, events=at_wall)
        y = solve_ivp(rhs, (0.0, 1e4), y, args=(True,), **opts).y_events[0][0]
        y[0] = 0.0
        at_wall.direction = -1.0  # arriving
        while True:
            V = (m1 * y[2] + m2 * y[3]) / (m1 + m2)
            r, rd = y[1] - y[0], y[3] - y[2]
            if V > 0.0 and (m1 * y[0] + m2 * y[1]) / (m1 + m2) > mu * math.hypot(r, rd / w):
                return V / v0, contacts
            sol = solve_ivp(rhs, (0.0, 2.0 * math.pi / w), y, args=(False,), **opts)
            if sol.status == 1:  # back at the wall
                y = sol.y_events[0][0]
                y[0] = 0.0
                break
            y = sol.y[:, -1]
    raise AssertionError("no end of the contact sequence within 100 contacts")


@pytest.fixture(scope="module")
def toy_law():
    """The child's results (one process: ~10 s with the JIT off)."""
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    env["PYTHONPATH"] = os.pathsep.join([str(REPO / "src"), str(REPO / "tests")])
    done = subprocess.run(
        [sys.executable, "-c", "import test_extension_points as t; t.toy_law_child()"],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_the_toy_law_takes_exactly_the_places_the_guide_lists(toy_law):
    rows = places(LAW_GUIDE, "contact")
    kinds = {p: _when(when) for p, when in rows.items() if p.startswith(LAWS_PY)}
    listed = {p for p, kind in kinds.items() if kind in ("every", "elastic")}
    assert set(toy_law["took"]) == listed


def test_the_toy_law_is_solved_by_solve_and_agrees_with_solve_ivp(toy_law):
    cor, n, method, status, err = toy_law["solve"]
    assert method == "adaptive" and status == "ok"
    ref, n_ref = cubic_reference(MASSES, SPRINGS[0], CUBIC["k"], V0)
    assert n == n_ref >= 2  # the scene is not a single contact
    assert abs(cor - ref) <= max(1e-7, 10.0 * err), (cor, ref, err)


def test_the_toy_law_runs_in_tables_and_on_the_command_line(toy_law):
    cors, methods, statuses = toy_law["many"]
    assert methods == ["adaptive", "adaptive"] and statuses == ["ok", "ok"]
    assert cors == [toy_law["solve"][0], toy_law["solve3"][0]]  # row for row, bit for bit
    assert toy_law["cli"] == [toy_law["solve"][0], "adaptive"]


def test_the_reference_method_refuses_the_toy_law_until_it_is_written_there(toy_law):
    assert "'reference' does not fit" in toy_law["refused"]
    assert "does not implement the 'cubic' contact law" in toy_law["refused"]
