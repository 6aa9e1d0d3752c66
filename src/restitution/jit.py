"""``njit``: numba's, with one compiled specialisation per kernel and argument types.

A kernel called from another kernel is compiled for the exact types of the call: numba keeps a
constant argument as a literal type (``0`` as Literal[int](0), ``True`` as Literal[bool](True), a
module constant as its value) and an argument left at its default as Omitted(default), so every
distinct call site compiled the kernel again. The chain kernel's event loop (``exact_chain._run``)
was compiled four times and its wrapper eight, each time with everything it calls linked in and
optimised again: most of a cold start. This dispatcher compiles the types a call from Python
would give instead (literals as their plain types, an omitted argument as its default's type),
so a kernel has one specialisation per real difference in types (an array's rank, None against an
array); the call sites convert their literals to it, as numba does for any typed call.

For the same reason the thin wrappers between an entry point and the chain's event loop
(``exact_chain._solve_units``, ``_safe_model``, ``_extrapolated``, ``_solve_stiff``,
``_solve_kv``) are ``inline="always"``: numba inlines them into their callers instead of compiling
them as kernels of their own, each of which linked and optimised the whole loop once more (about
3.5 s each; the paper chain's first call 44 s -> 37 s, the general chain's after it 15 s -> 9 s,
2026-11-26). The nonlinear stack's do the same (``stepping._adaptive``, ``_verlet``,
``_sigma_entry``, ``_leave_at_rest``, ``_contact_event``, ``integrators.event_state``,
``sigma_to_branch_point``, ``sigma_switch_branch``, and their sampled twins), and the kernels
copy arrays in loops (``restitution.kernels.copies``), not by slice assignments, which compiled
numpy's shape-mismatch message with them (2026-11-27: the plastic contact's first call
26.6 s -> 21.6 s).
"""

from __future__ import annotations

from numba import typeof, types
from numba.core import config, typing
from numba.core.registry import CPUDispatcher


def _plain(t):
    """The type a call from Python would give for an argument typed ``t`` in a kernel."""
    if isinstance(t, types.Omitted):
        return types.none if t.value is None else typeof(t.value)
    return types.unliteral(t)


def _holds_array(t) -> bool:
    if isinstance(t, types.Array):
        return True
    return isinstance(t, types.BaseTuple) and any(_holds_array(u) for u in t.types)


class _OneSpecialisation(CPUDispatcher):
    def add_overload(self, cres):
        # a kernel without reference counts must not hand an array to a counting caller, which
        # would release a reference it was never given (a freed array, later a crash)
        if not self.targetoptions.get("_nrt", True) and _holds_array(cres.signature.return_type):
            raise TypeError(
                f"{self.py_func.__qualname__}: a kernel with refcount=False returns an array"
            )
        super().add_overload(cres)

    def get_call_template(self, args, kws):
        # numba's Dispatcher.get_call_template, compiling the plain types instead of the call's
        pysig, args = self._compiler.fold_argument_types(args, kws)
        args = tuple(_plain(a) for a in args)
        if self._can_compile:
            self.compile(args)
        name = self.py_func.__name__
        template = typing.make_concrete_template(
            f"CallTemplate({name})", key=name, signatures=self.nopython_signatures
        )
        return template, pysig, args, {}


def njit(function=None, *, cache=False, refcount=True, **options):
    """``numba.njit`` (same options) with one specialisation per plain argument types (module
    docstring).

    ``refcount=False`` compiles without numba's reference counts (its private ``_nrt`` option),
    for the leaf kernels of the step loops: they neither allocate (numba refuses to compile an
    allocation without them) nor return an array (refused here). numba counts a reference to
    every array argument of every call, two atomic operations each: the right-hand side of two
    masses took 82 ns with them and 16 ns without (2026-11-27).
    """

    def decorate(f):
        if config.DISABLE_JIT:  # as numba.njit: the plain function (NUMBA_DISABLE_JIT=1)
            return f
        # no_cfunc_wrapper: numba also builds a C-callable wrapper of every kernel (for
        # numba.cfunc users and first-class function values, neither used here); dropping it cut
        # the paper chain's first call from 41 s to 39 s on a quiet machine (2026-11-27).
        target = {"nopython": True, "no_cfunc_wrapper": True, **options}
        if not refcount:
            target["_nrt"] = False
        dispatcher = _OneSpecialisation(f, targetoptions=target)
        if cache:
            dispatcher.enable_caching()
        return dispatcher

    return decorate if function is None else decorate(function)


__all__ = ["njit"]
