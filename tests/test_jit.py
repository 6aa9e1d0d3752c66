"""restitution.jit: one compiled specialisation per plain argument types."""

import numpy as np

from restitution.jit import njit


@njit
def _callee(x, flag, n=3, s=1.0, y=None):
    base = x * n + s if flag else x - n - s
    return base if y is None else base + y.sum()


@njit
def _caller(x):
    # literals (True, 2), keywords and omitted defaults: numba's njit compiles one
    # specialisation for each of these four calls
    return (
        _callee(x, True)
        + _callee(x, False, 2)
        + _callee(x, True, 5, 2.5)
        + _callee(x, flag=False, n=7)
    )


@njit
def _caller_array(x, y):
    return _callee(x, True, 1, 0.0, y)


def test_literal_and_omitted_arguments_share_one_specialisation():
    x = 1.5
    expected = (x * 3 + 1.0) + (x - 2 - 1.0) + (x * 5 + 2.5) + (x - 7 - 1.0)
    assert _caller(x) == expected
    assert len(_callee.signatures) == 1
    # a real difference in types (an array for None) is its own specialisation
    assert _caller_array(x, np.array([1.0, 2.0])) == x + 3.0
    assert len(_callee.signatures) == 2


def test_no_c_callable_wrapper_is_built():
    """numba builds a C-callable wrapper of every kernel unless told not to; nothing here uses
    one, and building them cost ~5 % of a cold first call (restitution.jit)."""
    x = 2.0
    assert _caller(x) == _caller.py_func(x)  # compiled (the jitted callee inside)
    for kernel in (_caller, _callee):
        cres = kernel.overloads[kernel.signatures[0]]
        names = {fn.name for fn in cres.library._final_module.functions}
        assert cres.fndesc.llvm_func_name in names  # the kernel itself is there
        assert cres.fndesc.llvm_cfunc_wrapper_name not in names
