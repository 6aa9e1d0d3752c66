"""The numba kernels: exact event-driven solutions of the piecewise-linear scenes
(``rigid2``, ``paper_chain``, ``exact_chain``, with event location in ``locator`` and the
round-off check in ``replica``), the time-stepping of nonlinear phases (``stepping`` over
``integrators``), and what they share: the root finders (``roots``), the numbers more than one
of them uses (``constants``) and the output row layout (``layout``). Plain-Python wrappers in
``restitution.solvers`` validate input and call them."""
