"""The numba kernels: exact event-driven solutions of the piecewise-linear scenes
(``rigid2``, ``paper_chain``, ``exact_chain``, with root location in ``locator`` and the
round-off check in ``replica``), the time-stepping of nonlinear phases (``stepping`` over
``integrators``), and the output row layout they share (``layout``). Plain-Python wrappers in
``restitution.solvers`` validate input and call them."""
