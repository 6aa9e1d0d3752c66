"""The one conversion between the kernels' units and a scene's own (docs/physics.md).

The kernels work with m_1 = 1, V0 = 1 and omega = 1 (omega**2 = k_12/m_1 + k_12/m_2, the scene's
``Chain.omega``; 1 for the paper's form): a kernel time is omega * t, a speed v / V0, a length
u / (V0 / omega), a force F / (m_1 V0 omega), an impulse p / (m_1 V0). Results leave the
kernels through the functions below (``Result.t_col``, the ``t_col`` column of ``solve_many``,
``trajectory``, ``restitution.model.dimensional``), times enter them through ``kernel_time``,
and a chain's parameters through ``kernel_params`` (``Chain.scaled`` and its column-wise form
for tables). Each takes numbers or numpy arrays (element-wise).
"""


def kernel_time(t, omega):
    """A time of the scene (its own unit) in kernel units: omega * t."""
    return t * omega


def user_time(omega_t, omega):
    """A kernel time omega * t in the scene's own time unit."""
    return omega_t / omega


def user_speed(v, v0):
    """A kernel speed (in units of the approach speed v0) in the scene's unit."""
    return v * v0


def user_length(u, omega, v0):
    """A kernel length (in units of v0 / omega) in the scene's unit."""
    return u * (v0 / omega)


def user_force(f, m1, omega, v0):
    """A kernel force (in units of m_1 v0 omega) in the scene's unit."""
    return f * (m1 * v0 * omega)


def user_impulse(p, m1, v0):
    """A kernel impulse (in units of m_1 v0) in the scene's unit."""
    return p * (m1 * v0)


def kernel_params(m, k, c, kc, m1, omega):
    """Masses, springs, dashpots and the contact stiffness in kernel units: m / m_1,
    k / (m_1 omega**2), c / (m_1 omega), kc / (m_1 omega**2). ``m1`` and ``omega`` broadcast
    against the arrays (a table passes one per row, as columns)."""
    w2 = omega * omega
    return m / m1, k / (m1 * w2), c / (m1 * omega), kc / (m1 * w2)
