"""``import restitution`` and ``restitution --help`` stay cheap: the package's public names and
submodules are imported on first use (module ``__getattr__``), and the command line imports the
numerical stack only once a subcommand runs."""

import importlib
import json
import subprocess
import sys
import types

import pytest

import restitution

HEAVY = ("numpy", "pandas", "scipy", "numba", "pyarrow", "matplotlib")


def _loaded_after(code: str) -> list[str]:
    """The heavy modules a fresh interpreter has imported after running ``code``."""
    probe = (
        f"{code}\nimport json, sys\nprint(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    )
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout.splitlines()[-1])


def test_import_restitution_loads_no_numerical_library():
    assert _loaded_after("import restitution") == []
    assert "numpy" in _loaded_after("import restitution\nrestitution.solve")  # the probe sees


@pytest.mark.parametrize("argv", [["--help"], ["--version"], ["batch", "--help"]])
def test_cli_help_loads_no_numerical_library(argv):
    code = (
        f"from restitution.cli import main\ntry:\n    main({argv!r})\nexcept SystemExit:\n    pass"
    )
    assert _loaded_after(code) == []


def test_cli_method_choices_are_the_solver_table():
    from restitution.solvers.methods import NAMES

    p = subprocess.run(
        [sys.executable, "-m", "restitution.cli", "cor", "--help"], capture_output=True, text=True
    )
    assert p.returncode == 0 and f"solver: {', '.join(NAMES)}" in " ".join(p.stdout.split())
    p = subprocess.run(
        [sys.executable, "-m", "restitution.cli", "cor", "--alpha", "1", "--method", "rk9"],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 2 and "invalid choice: 'rk9'" in p.stderr and "'precise'" in p.stderr


@pytest.mark.parametrize("name", restitution.__all__)
def test_every_public_name_imports(name):
    shown = f"getattr({name}, '__module__', getattr({name}, '__name__', ''))"
    probe = f"from restitution import {name}\nprint({shown})"
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    value = getattr(restitution, name)
    if name == "__version__":
        assert isinstance(value, str) and value
    elif isinstance(value, types.ModuleType):  # restitution.design
        assert p.stdout.strip() == value.__name__
    else:
        assert p.stdout.strip() == value.__module__  # the defining module, not a stand-in
        assert getattr(importlib.import_module(value.__module__), name) is value
    assert name in dir(restitution)


def test_submodules_and_unknown_names():
    assert restitution.analysis.__name__ == "restitution.analysis"  # a layer, on first access
    assert importlib.import_module("restitution.solvers.methods").METHODS
    assert not hasattr(restitution, "no_such_name")
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        restitution.no_such_name  # noqa: B018


def test_trajectory_stays_the_function_when_its_submodule_is_imported():
    probe = (
        "import restitution.trajectories, restitution, sys\n"
        "print(callable(restitution.trajectory),"
        " type(sys.modules['restitution.trajectories']))"
    )
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert p.stdout.split()[0] == "True" and "module" in p.stdout


def test_one_solve_and_the_cor_command_load_no_table_library():
    """pandas and pyarrow (0.3 s of imports) come only with tables or a history: a single
    solve, and the command line's ``cor``, do without them."""
    assert _loaded_after("import restitution\nrestitution.solve(alpha=0.5)") == [
        "numpy",
        "scipy",
        "numba",
    ]
    code = "from restitution.cli import main\nmain(['cor', '--alpha', '0.5', '--json'])"
    assert "pandas" not in _loaded_after(code) and "pyarrow" not in _loaded_after(code)
    with_history = "import restitution\nrestitution.solve(alpha=0.5, history=True)"
    assert "pandas" in _loaded_after(with_history)  # the probe sees it where it is needed


def test_a_missing_cell_is_still_pandas_na_once_pandas_is_loaded():
    import pandas as pd

    from restitution.model.ranges import missing_cell

    assert missing_cell(pd.NA) and missing_cell(None) and missing_cell(float("nan"))
    assert not missing_cell(0.0) and not missing_cell("")
