"""The solvers: ``methods.METHODS`` (the solver table, the one place a method is chosen) and the
runners of its methods (exact kernels, the numerical methods in ``numerical``, the high-precision
``precise`` and the scipy ``reference``), with the ``Result`` every solve returns. The entry
points ``restitution.api`` and ``restitution.trajectories`` sit above this layer."""
