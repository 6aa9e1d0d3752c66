"""restitution.jit: one compiled specialisation per plain argument types."""

import numpy as np
import pytest

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


@njit(error_model="numpy")
def _row_sum(row, scale):
    s = 0.0
    for k in range(row.shape[0]):
        s += scale * row[k] / (1.0 + k)
    return s


def _leaf_py(M, out, scale):
    # a row view passed to another kernel on one branch: the pattern of the step loops'
    # right-hand side (a linear link inline, another law through its row)
    for i in range(M.shape[0]):
        out[i] = _row_sum(M[i], scale) if M[i, 0] > 0.0 else scale
    return out[0]


_leaf = njit(error_model="numpy", refcount=False)(_leaf_py)
_counted_leaf = njit(error_model="numpy")(_leaf_py)


def _refcount_calls(kernel):
    cres = kernel.overloads[kernel.signatures[0]]
    body = str(cres.library._final_module.get_function(cres.fndesc.llvm_func_name))
    return body.count("@NRT_incref") + body.count("@NRT_decref")


def test_refcount_false_compiles_without_reference_counts():
    """The step loops' leaf kernels are compiled without numba's reference counts of their array
    arguments (two atomic operations per array and call; restitution.jit.njit)."""
    M, out = np.array([[1.0, 8.0], [-2.0, 8.0], [3.5, 8.0]]), np.zeros(3)
    assert _leaf(M, out, 2.0) == 10.0 and list(out) == [10.0, 2.0, 15.0]
    assert _counted_leaf(M, out, 3.0) == 15.0 and list(out) == [15.0, 3.0, 22.5]
    assert _refcount_calls(_counted_leaf) > 0  # the same code with them: the check can fail
    assert _refcount_calls(_leaf) == 0


def test_refcount_false_refuses_to_return_an_array():
    """A kernel without reference counts returning an array would hand its caller a reference
    it never took (a freed array later): refused when compiled. (numba itself refuses a new
    array or a view; an argument returned as it is, alone or in a tuple, is refused here.)"""

    @njit(refcount=False)
    def same(y):
        return y

    @njit(refcount=False)
    def pair(y):
        return 1.0, y

    for kernel in (same, pair):
        with pytest.raises(TypeError, match="refcount=False returns an array"):
            kernel(np.ones(3))
