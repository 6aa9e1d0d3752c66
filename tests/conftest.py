"""Shared helpers of the workflow tests: a scratch copy of the workflow and snakemake runs in it,
and workflow scripts loaded as modules."""

import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SNAKEMAKE = [sys.executable, "-m", "snakemake"]
SMALL_CONFIG = REPO / "config" / "small.yaml"


def snakemake_env() -> dict:
    env = dict(os.environ)
    # Without .pyc files every snakemake start recompiles the stack (notes/setup.md).
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env.setdefault("NUMBA_CACHE_DIR", str(REPO / ".cache" / "numba"))
    env.setdefault("MPLBACKEND", "Agg")
    return env


def copy_workflow(work: Path) -> Path:
    """Snakefile, workflow/ and config/ copied to ``work``; the package shared through a symlink."""
    work.mkdir(parents=True, exist_ok=True)
    shutil.copy(REPO / "Snakefile", work / "Snakefile")
    for folder in ("workflow", "config"):
        shutil.copytree(REPO / folder, work / folder, ignore=shutil.ignore_patterns("__pycache__"))
    (work / "src").symlink_to(REPO / "src", target_is_directory=True)
    return work


def run_snakemake(*args, cwd=REPO, timeout=600) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*SNAKEMAKE, *args],
        cwd=cwd,
        env=snakemake_env(),
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def load_script(name: str):
    """workflow/scripts/<name>.py as a module (its helpers importable, as in a Snakemake job)."""
    scripts = REPO / "workflow" / "scripts"
    sys.path.insert(0, str(scripts))
    spec = importlib.util.spec_from_file_location(name, scripts / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def solve_paper_law(
    alpha,
    beta=0.01,
    xi=0.0,
    method="adaptive",
    rtol=1e-9,
    step=0.01,
    history=False,
    account=None,
    energy_tol=None,
    free_closed=True,
    max_events=10_000,
    **law,
):
    """A paper-form scene with the law keywords of ``restitution.solve`` (contact, eta, dr,
    structure, L, ks_ratio, theta0, corner, v0) on the one numerical stack, with the knobs the
    public API does not show: the energy ``account`` (a dict filled in), ``energy_tol`` and
    ``free_closed`` (False: the free flight of two masses, and the plastic law's elastic line on an
    undamped link, integrated, not closed form)."""
    from restitution.model.chain import paper_with_laws
    from restitution.solvers import numerical

    ch, _ = paper_with_laws(alpha, beta, xi, 2, law)
    if method == "reference":
        out, hist = numerical.solve_reference_chain(
            ch, rtol, max_events, history, energy_tol=energy_tol, account=account
        )
    else:
        out, hist = numerical.solve_chain(
            ch, method, rtol, step, max_events, history, energy_tol=energy_tol,
            account=account, free_closed=free_closed,
        )  # fmt: skip
    return numerical.result(ch, out, method, hist)


def solve_general_law(
    m,
    k,
    c=None,
    contact_law="rigid",
    link_laws=None,
    v0=1.0,
    method="adaptive",
    rtol=1e-9,
    max_events=10_000,
    history=False,
    *,
    step=0.01,
    max_work=None,
    energy_tol=None,
    account=None,
):
    """A general chain (the user's units) through ``restitution.solve`` on the numerical stack;
    with ``max_work``, ``energy_tol`` or ``account`` (knobs the public API does not show) through
    a ``restitution.Chain`` and ``restitution.solvers.numerical.solve_chain``."""
    import restitution
    from restitution.solvers import numerical

    if max_work is None and energy_tol is None and account is None:
        from restitution.solvers.methods import METHODS

        # only the setting the method reads (solve refuses one that would do nothing)
        reads = METHODS[method].settings if method in METHODS else ()
        settings = {k: v for k, v in (("rtol", rtol), ("step", step)) if k in reads}
        return restitution.solve(
            masses=m, springs=k, dashpots=c, contact=contact_law, links=link_laws, v0=v0,
            method=method, max_events=max_events, history=history, **settings,
        )  # fmt: skip
    ch = restitution.Chain(m, k, c, v0=v0, contact=contact_law, links=link_laws)
    out, hist = numerical.solve_chain(
        ch, method, rtol, step, max_events, history, max_work=max_work, energy_tol=energy_tol,
        account=account,
    )  # fmt: skip
    return numerical.result(ch, out, method, hist)


def solve_general_many(masses, springs, dashpots=None, contact=None, links=None, v0=1.0, **kw):
    """Rows of general chains (one list per row; ``contact`` / ``v0`` one per row or one for
    all) through ``restitution.solve_many`` with the numerical settings ``kw`` (method, rtol,
    step) as columns and ``max_events``."""
    import pandas as pd

    import restitution

    rows = len(masses)

    def per_row(value):
        return list(value) if isinstance(value, (list, tuple)) else [value] * rows

    frame = pd.DataFrame({"masses": list(masses), "springs": list(springs)})
    if dashpots is not None:
        frame["dashpots"] = list(dashpots)
    frame["contact"] = per_row(contact if contact is not None else {"law": "rigid"})
    if links is not None:
        frame["links"] = per_row(links)
    frame["v0"] = per_row(v0)
    max_events = kw.pop("max_events", 10_000)
    frame["method"] = kw.pop("method", "adaptive")
    for name, value in kw.items():
        frame[name] = value
    return restitution.solve_many(frame, max_events=max_events)


def check_table_and_cli_agree(contact: dict, method: str = "adaptive") -> None:
    """A contact law given as a table cell (a mapping, and JSON text as a CSV cell gives it) and
    on the command line (--contact-law) gives solve()'s COR, by the method ``auto`` picks for
    it (``method``: adaptive, or piecewise for the Kelvin-Voigt contact)."""
    import contextlib
    import io
    import json

    import pandas as pd

    import restitution
    from restitution.cli import main

    one = restitution.solve(masses=[1.0, 2.0], springs=[1.0], contact=contact)
    three = restitution.solve(masses=[1.0, 0.7, 2.0], springs=[1.0, 0.5], contact=contact)
    table = pd.DataFrame(
        {
            "masses": [[1.0, 2.0], [1.0, 0.7, 2.0]],
            "springs": [[1.0], [1.0, 0.5]],
            "contact": [contact, json.dumps(contact)],
        }
    )
    many = restitution.solve_many(table)
    assert many["cor"].tolist() == [one.cor, three.cor]
    assert many["status"].tolist() == ["ok", "ok"]
    assert one.method == three.method == method and many["method"].tolist() == [method] * 2
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(
            ["cor", "--masses", "1,2", "--springs", "1", "--contact-law", json.dumps(contact),
             "--json"]
        )  # fmt: skip
    assert code == 0
    cli = json.loads(out.getvalue())
    assert cli["cor"] == one.cor and cli["method"] == method


def random_soft_chain(rng, n: int):
    """Masses and springs 0.3..3, dashpots 0..0.05 on about half the links (lists)."""
    m = rng.uniform(0.3, 3.0, n)
    k = rng.uniform(0.3, 3.0, n - 1)
    c = rng.uniform(0.0, 0.05, n - 1) * (rng.random(n - 1) < 0.5)
    return m.tolist(), k.tolist(), c.tolist()
