"""numba kernels. Plain-Python wrappers (restitution.api) validate input and call them."""
