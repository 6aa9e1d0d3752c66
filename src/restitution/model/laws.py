"""Force laws: the contact laws (rigid, linear, plastic of Section 3.1, Hertz) and the link laws
(linear, the scissor spring of Section 3.2); how to add one: docs/guides/adding-a-law.md.

Units are those of docs/physics.md (m1 = 1, omega = 1 from the *nominal* k2 = alpha/(1+alpha)),
except that the impact speed ``v0`` is a parameter: both laws make the response velocity
dependent, so lengths are in units of V_ref/omega with V_ref = 1 and the masses start at -v0.

Every law is packed into a small float64 array (``contact_params`` / ``structure_params``) read by
the numba kernels through the scalar functions below, which are plain ``@njit`` functions and so
also callable from Python (``reference.py`` uses them unchanged).

Plastic contact (Sec. 3.1)
--------------------------
Penetration x = -u1. Loading (x beyond the largest penetration so far, xmax): F = kappa*x**eta.
Unloading and reloading: linear with slope k1 = k2/beta from (xmax, Fmax): F = Fmax - k1*(xmax-x),
so the residual dent xp = xmax - Fmax/k1 persists between contacts (contact iff x > xp), and a
reload past xmax continues on the power law (extra dissipation).

DR -> kappa. The paper defines DR through m1's first rebound, i.e. m1 alone hitting the wall at
v0: loading stores m1*v0**2/2 = kappa*xmax**(eta+1)/(eta+1) = Fmax*xmax/(eta+1), and the linear
unloading returns Fmax**2/(2*k1) = (1 - DR)*m1*v0**2/2. Hence, in closed form,

    Fmax  = v0*sqrt((1 - DR)*k1*m1),   xmax = (eta + 1)*m1*v0**2/(2*Fmax),   kappa = Fmax/xmax**eta.

The dent xp = xmax - Fmax/k1 must be >= 0, i.e. 1 - DR <= (1 + eta)/2: for a concave loading
curve (eta < 1) a linear unloading line cannot return more than (1+eta)/2 of the energy, so
DR >= (1 - eta)/2 is required (checked). DR = 0, eta = 1 gives kappa = k1: the linear contact.
At fixed DR, eta, beta, kappa scales as v0**(1 - eta); the map u -> s*u, v0 -> s*v0,
kappa -> kappa*s**(1-eta) leaves the equations invariant, so kappa has no effect on the COR at
fixed DR (the paper's observation for Fig. 4(c)) -- an exact similarity, tested.

Hertz contact
-------------
F = k_h*x**1.5 for x > 0 (a sphere on a flat), elastic, potential 0.4*k_h*x**2.5. One mass m at
V0 stays in contact t_c = C*(m/k_h)**0.4*V0**-0.2 with C = 2*I*(5/4)**0.4 = 3.218065 and
I = (2/5)*B(2/5, 1/2) (tests/test_hertz.py). The COR of a chain depends on V0 through the
contact's effective stiffness ~ k_h**0.8 * V0**0.4.

Kelvin-Voigt contact
--------------------
F = max(0, k*x + c*x') for x > 0 (a spring and a dashpot in parallel). The contact ends where
the force returns to zero, k*x + c*x' = 0, while x > 0 (a linear event of the state), not where
the gap closes; m1 then flies free, and a new contact starts where x rises through 0 or where
k*x + c*x' rises through 0 again while x > 0. The contact's work on m1 is all dissipated (the
spring's k*x**2/2 left at the force-zero end is lost in the massless surface's own relaxation).
One mass: the COR of Schwager and Poeschel (2007), not exp(-z*pi/sqrt(1 - z**2))
(tests/test_kelvin_voigt.py). c is a dashpot (force per speed: kernel unit m1*omega). Every
phase is linear, so on linear links the exact method solves it (``piecewise``:
restitution.kernels.exact_chain, "Kelvin-Voigt contact"; tests/test_kelvin_voigt_exact.py);
the numerical methods take it as any other law.

Hunt-Crossley contact
---------------------
F = k*x**n*(1 + 1.5*alpha*x') for x > 0 (Hunt and Crossley 1975; n = 1.5 by default), packed
with lam = 1.5*alpha. k is a force per length**n (its unit depends on n: ``_hc_k_unit``), alpha
an inverse speed (the user's speed unit is the kernels'). m1 never moves faster than
v0*sqrt(M/m1), so 1.5*alpha*v0*sqrt(M/m1) < 1 (checked) keeps 1 + lam*x' > 0: the force ends at
x = 0, where the kernels integrate the contact's ends in sigma = sqrt(x) as for Hertz.

General chains
--------------
A chain's laws are given as specifications, {"law": name, parameters...}: contact laws in
``CONTACT_LAWS`` (rigid; linear k; plastic k = unloading slope, eta, dr; hertz k = k_h;
kelvin_voigt k, c; hunt_crossley k, n, alpha), link
laws in ``LINK_LAWS`` (linear: the link's spring; scissor L, ks, theta0, corner with the link's
spring as the cap slope). ``pack_contact`` / ``pack_link`` check and pack them; the tables also
give each dimensional parameter's unit for ``to_kernel_units``.

Handled ranges: v0 in [1e-6, 1e6]; the first spring over the contact's (effective) stiffness
in [1e-12, 1e6] (``check_contact_ratio``: linear k, plastic unloading slope and loading secant,
Hertz slope at m1's depth); mass ratios up to 1e8. Outside them the contact is too soft to
finish within the work budget or too stiff for a step above round-off, so they are rejected.

Scissor spring (Sec. 3.2, Eq. 24)
---------------------------------
Extension x = u2 - u1 (> 0: the frame is pulled). With cos(theta) = cos(theta0) + x/(2L),
F = 2*ks*L*cos(theta)*(sin(theta0)/sin(theta) - 1), potential U = 2*ks*L**2*(sin(theta) -
sin(theta0))**2 (closed form, so the energy account needs no quadrature). Explicit in x: no root
solve, hence no stall near the lock angle. Slope F' = ks*(sin(theta0)/sin(theta)**3 - 1).

* Tension: the slope grows without bound as theta -> 0; it is capped at k2 (= beta*k1, the paper's
  redefinition): beyond x_cap, where F' = k2, the law continues linearly with slope k2.
* Compression: the slope vanishes at the lock angle sin(theta)**3 = sin(theta0). Beyond it the
  corner pads touch (paper: "quadric or other form"); we use a quadratic stiffening, slope
  kc*delta (delta = compression past the lock), continuous (C1) at the lock, reaching the cap k2
  when the pads have taken ``corner`` times the remaining geometric stroke to the flat bars
  (2*L*cos(theta_lock)), and linear with slope k2 beyond. corner = 1 (default) makes the
  stiffening purely geometric: no new length scale, cap reached exactly at the flat position.
* theta0 = pi/4 by default: then F'(0) = ks*cot(theta0)**2 = ks, so ks is the small-amplitude
  stiffness, and the lock (theta = 63.0 deg) and the tension cap are both well inside the stroke.
  ks is given as ks_ratio = ks/k2 (Fig. 5(b): beta = 1, ks = k1/100, i.e. ks_ratio = 0.01).
  The rest slope must stay below the cap: ks_ratio*cot(theta0)**2 < 1 (checked).
"""

from __future__ import annotations

import math

import numpy as np

from restitution.jit import njit
from restitution.model.ranges import MAX_MASSES, RANGES, SceneError, _real, _show

# Contact law kinds (contact_params[0]).
C_RIGID = 0  # beta = 0: impulsive reversal of m1's velocity
C_LINEAR = 1  # F = k1*x
C_PLASTIC = 2  # power-law loading, linear unloading/reloading
C_HERTZ = 3  # F = k_h*x**1.5 (elastic; Hertz's sphere on a flat)
C_KELVIN_VOIGT = 4  # F = max(0, k*x + c*x') for x > 0; the contact ends where F returns to 0
C_HUNT_CROSSLEY = 5  # F = k*x**n*(1 + 1.5*alpha*x') for x > 0 (Hunt and Crossley 1975)
# contact_params = [kind, k1, kappa, eta]: k1 is the law's slope scale (linear: its stiffness,
# plastic: the unloading slope, hertz: the slope at the deepest possible penetration, which sets
# the integrators' step scale); kappa, eta the power law F = kappa*x**eta (hertz: k_h, 1.5);
# kelvin_voigt: [kind, max(k, c**2/m1), k, c]; hunt_crossley: [kind, scale, k, n, 1.5*alpha].
N_CP = 5
# Contact laws without memory: the force is a function of the penetration alone, the contact
# branches (rising, falling) only record the largest penetration.
ELASTIC_CONTACTS = (C_LINEAR, C_HERTZ)
# Contact laws whose force depends on m1's velocity too (a dashpot in the contact).
VISCOUS_CONTACTS = (C_KELVIN_VOIGT, C_HUNT_CROSSLEY)
# Largest damping ratio c / (2 sqrt(k m1)) of a Kelvin-Voigt contact: the contact lasts
# ~ ln(4 z**2) / (z w0) while x' relaxes at the rate 2 z w0, so the work per contact grows with z.
ZETA_CONTACT_MAX = 1e3

# Structure law kinds (structure_params[0]).
S_LINEAR = 0
S_SCISSOR = 1
# structure_params indices
SP_KIND, SP_K2, SP_KS, SP_L, SP_C0, SP_S0 = 0, 1, 2, 3, 4, 5
SP_XLOCK, SP_FLOCK, SP_ULOCK, SP_KC, SP_DC = 6, 7, 8, 9, 10
SP_XCAP, SP_FCAP, SP_UCAP = 11, 12, 13
N_SP = 14

THETA0_DEFAULT = math.pi / 4
CORNER_DEFAULT = 1.0


def _num(name, value, allowed):
    """One finite real number (wrong types and huge integers: SceneError naming ``name``)."""
    x = _real(value)
    if x is None:
        raise SceneError(f"{name} must be a number {allowed}; got {_show(value)}")
    if not math.isfinite(x):
        raise SceneError(f"{name} must be a finite number {allowed}; got {_show(value)}")
    return x


def _ranged(name: str, value, what: str = "") -> float:
    """A law parameter checked against its entry of the one range table (``_base.RANGES``)."""
    r = RANGES[name]
    x = _num(name, value, r.text)
    if not r.contains(x):
        raise SceneError(f"{name}{what} must be {r.text}; got {_show(value)}")
    return x


def check_eta(value) -> float:
    return _ranged("eta", value)


def check_dr(value, eta: float = 1.0) -> float:
    x = _ranged("dr", value, " (nominal dissipation ratio)")
    low = max(0.0, (1.0 - eta) / 2.0)
    if x < low - 1e-15:
        raise SceneError(
            f"dr must be in [{low:g}, 1) for eta={eta:g}: a power-law loading with eta < 1 and a "
            f"linear unloading cannot return more than (1 + eta)/2 of the energy (the residual "
            f"dent would be negative); got {_show(value)}"
        )
    return x


V0_MIN, V0_MAX = RANGES["v0"].low, RANGES["v0"].high


def check_v0(value) -> float:
    """Impact speed in RANGES["v0"] = [1e-6, 1e6] (below 1e-6 the plastic law's kappa
    ~ v0**(1 - eta) and the Hertz contact's stiffness ~ v0**0.4 leave float64's range or make
    the contact so soft that no work budget finishes it; see tests/test_nonlinear_chain.py)."""
    return _ranged("v0", value, " (impact speed)")


# Ratio of the first structural spring to the contact's stiffness (the paper's beta) that the
# numerical methods handle; for the nonlinear laws the contact's stiffness is its loading
# secant (plastic) or its slope at m1's deepest penetration (Hertz). Outside: the contact
# phase needs more than the work budget (too soft) or a step below round-off (too stiff).
BETA_NL_MIN, BETA_NL_MAX = 1e-12, 1e6
# Mass ratios (alpha; in a chain any two masses) the numerical methods finish within their work
# budget (alpha = 1e-300 ran 30 s to a failure; 1e8 finishes in seconds).
ALPHA_NL_MIN, ALPHA_NL_MAX = 1e-8, 1e8


def check_contact_ratio(name: str, ratio: float, what: str) -> float:
    """beta-like ratio k_link1 / k_contact_effective within [BETA_NL_MIN, BETA_NL_MAX]."""
    if not BETA_NL_MIN <= ratio <= BETA_NL_MAX:
        raise SceneError(
            f"{name}: the first spring over the contact's {what} is {ratio:.3g}; it must be in "
            f"[{BETA_NL_MIN:g}, {BETA_NL_MAX:g}] (the range of beta the numerical methods handle)"
        )
    return ratio


# Frequency spread a chain may have for the explicit integrators: the fastest rate (Gershgorin
# bound with the contact's slope scale, dashpot rates c (1/m_i + 1/m_i+1)) over the slowest
# (each link's and the contact's own rate). The cost grows with it (steps ~ spread per
# slow period): beyond 1e3 in-range chains ran out of the work budget (tests/
# test_nonlinear_chain.py draws the ranges); stiff chains need the exact linear kernels.
SPREAD_MAX = 1e3


def check_frequency_spread(m, lk, c, cp, v0: float) -> float:
    """Fastest over slowest rate of a packed chain (kernel units); SceneError beyond SPREAD_MAX.

    The slowest rates: each link's sqrt(k (1/m_i + 1/m_i+1)) (the scissor's rest slope) and the
    contact's sqrt(k_eff / total mass), k_eff its stiffness for m1 alone at v0.
    """
    n = len(m)
    hi2, lo = 0.0, math.inf
    for i in range(n):
        row = 0.0
        if i > 0:
            row += 2.0 * lk[i - 1][SP_K2]
        if i < n - 1:
            row += 2.0 * lk[i][SP_K2]
        if i == 0 and cp[0] != C_RIGID:
            row += cp[1]
        hi2 = max(hi2, row / m[i])
    hi = math.sqrt(hi2)
    for i in range(n - 1):
        inv = 1.0 / m[i] + 1.0 / m[i + 1]
        hi = max(hi, c[i] * inv)
        k_soft = lk[i][SP_K2] if lk[i][SP_KIND] == S_LINEAR else structure_slope(lk[i], 0.0)
        lo = min(lo, math.sqrt(k_soft * inv))
    k_eff = effective_stiffness(cp, v0)
    if k_eff == k_eff:
        lo = min(lo, math.sqrt(k_eff / sum(m)))
    spread = hi / lo
    if not spread <= SPREAD_MAX:
        shown = f"{spread:.3g}"
        if float(shown) <= SPREAD_MAX:  # (1000.2 is not "1e+03")
            shown = repr(spread)
        raise SceneError(
            f"the chain's frequency spread (fastest rate: springs, contact, dashpots; over the "
            f"slowest link) is {shown}; it must be at most {SPREAD_MAX:g} for the numerical "
            f"methods "
            f"(narrow the ratios of masses, springs and the contact stiffness)"
        )
    return spread


def effective_stiffness(cp, v0: float) -> float:
    """The packed contact law's stiffness for m1 alone hitting it at v0 (kernel units): the
    linear k, Hertz's slope at m1's depth, the plastic loading secant; NaN for the rigid wall."""
    if cp[0] == C_LINEAR:
        return cp[1]
    if cp[0] == C_KELVIN_VOIGT:
        return cp[2]
    if cp[0] == C_HERTZ:
        return hertz_slope_at_depth(cp[2], v0)
    if cp[0] == C_HUNT_CROSSLEY:
        return power_slope_at_depth(cp[2], cp[3], v0)
    if cp[0] == C_PLASTIC:
        eta = cp[3]
        xmax = ((eta + 1.0) * v0 * v0 / (2.0 * cp[2])) ** (1.0 / (eta + 1.0))
        return cp[2] * xmax**eta / xmax
    return math.nan


def plastic_loading_secant(dr: float, eta: float, k1: float) -> float:
    """Secant Fmax/xmax of the power-law loading of m1 alone: 2 (1 - DR) k1 / (eta + 1)."""
    return 2.0 * (1.0 - dr) * k1 / (eta + 1.0)


def hertz_slope_at_depth(k_h: float, v0: float, m1: float = 1.0) -> float:
    """Hertz slope 1.5 k_h sqrt(x) at m1's deepest penetration alone, (5 m1 v0**2/(4 k_h))**0.4."""
    x1 = (1.25 * m1 * v0 * v0 / k_h) ** 0.4
    return 1.5 * k_h * math.sqrt(x1)


def power_slope_at_depth(k: float, n: float, v0: float, m1: float = 1.0) -> float:
    """Slope n k x**(n - 1) of the elastic power law k x**n at the depth where m1 alone at v0
    would stop on it: k x**(n + 1)/(n + 1) = m1 v0**2/2."""
    x1 = ((n + 1.0) * m1 * v0 * v0 / (2.0 * k)) ** (1.0 / (n + 1.0))
    return n * k * x1 ** (n - 1.0)


def check_L(value) -> float:  # noqa: N802 - the paper's symbol
    return _ranged("L", value, " (scissor bar length)")


def check_theta0(value) -> float:
    return _ranged("theta0", value)


def check_ks_ratio(value, theta0: float = THETA0_DEFAULT) -> float:
    cap = math.tan(theta0) ** 2
    x = _num("ks_ratio", value, f"in (0, tan(theta0)**2 = {cap:.6g})")
    if not 0.0 < x < cap:
        raise SceneError(
            f"ks_ratio (= ks/k2) must be in (0, tan(theta0)**2 = {cap:.6g}) so that the scissor's "
            f"rest slope ks*cot(theta0)**2 stays below the cap k2; got {_show(value)}"
        )
    return x


def check_corner(value) -> float:
    return _ranged("corner", value, " (stroke fraction to reach the cap)")


def plastic_kappa(dr: float, eta: float, k1: float, v0: float = 1.0, m1: float = 1.0) -> float:
    """kappa of the power-law loading that gives m1 alone the rebound 1 - DR (module docstring).

    Returns kappa such that m1 hitting the wall at ``v0`` leaves with speed v0*sqrt(1 - DR).
    """
    fmax = v0 * math.sqrt((1.0 - dr) * k1 * m1)
    xmax = (eta + 1.0) * m1 * v0 * v0 / (2.0 * fmax)
    return fmax / xmax**eta


def contact_params(kind: int, k1: float = 0.0, kappa: float = 0.0, eta: float = 1.0) -> np.ndarray:
    cp = np.zeros(N_CP)
    cp[0], cp[1], cp[2], cp[3] = kind, k1, kappa, eta
    return cp


def scissor_params(k2: float, ks: float, L: float, theta0: float, corner: float = 1.0):  # noqa: N803
    """Pack the scissor law (module docstring), precomputing lock, corner and cap points."""
    s0, c0 = math.sin(theta0), math.cos(theta0)
    sp = np.zeros(N_SP)
    sp[SP_KIND], sp[SP_K2], sp[SP_KS], sp[SP_L], sp[SP_C0], sp[SP_S0] = S_SCISSOR, k2, ks, L, c0, s0
    # Lock: sin^3 = sin(theta0), slope 0.
    s_l = s0 ** (1.0 / 3.0)
    c_l = math.sqrt(max(0.0, 1.0 - s_l * s_l))
    sp[SP_XLOCK] = 2.0 * L * (c_l - c0)
    sp[SP_FLOCK] = 2.0 * ks * L * c_l * (s0 / s_l - 1.0)
    sp[SP_ULOCK] = 2.0 * ks * L * L * (s_l - s0) ** 2
    dc = corner * 2.0 * L * c_l  # pad compression at which the slope reaches k2
    sp[SP_DC], sp[SP_KC] = dc, k2 / dc
    # Cap: ks*(s0/s^3 - 1) = k2.
    s_c = (ks * s0 / (ks + k2)) ** (1.0 / 3.0)
    c_c = math.sqrt(1.0 - s_c * s_c)
    sp[SP_XCAP] = 2.0 * L * (c_c - c0)
    sp[SP_FCAP] = 2.0 * ks * L * c_c * (s0 / s_c - 1.0)
    sp[SP_UCAP] = 2.0 * ks * L * L * (s_c - s0) ** 2
    return sp


def linear_structure_params(k2: float) -> np.ndarray:
    sp = np.zeros(N_SP)
    sp[SP_KIND], sp[SP_K2] = S_LINEAR, k2
    return sp


def hertz_params(k_h: float, v0: float = 1.0, total_mass: float = 1.0) -> np.ndarray:
    """Pack the Hertz law F = k_h*x**1.5 (kernel units, see the module docstring).

    cp[1], the slope scale, is the slope 1.5*k_h*sqrt(x) at the deepest penetration the whole
    initial energy (total_mass*v0**2/2 = 0.4*k_h*x**2.5) could reach: an upper bound.
    """
    e0 = 0.5 * total_mass * v0 * v0
    x_deep = (2.5 * e0 / k_h) ** 0.4
    return contact_params(C_HERTZ, 1.5 * k_h * math.sqrt(x_deep), k_h, 1.5)


def kelvin_voigt_params(k: float, c: float, m1: float = 1.0) -> np.ndarray:
    """Pack the Kelvin-Voigt law F = k*x + c*x' (kernel units; m1 the first mass).

    cp[1], the slope scale, is max(k, c**2/m1): the square of m1's fastest rate on the contact,
    max(w0, c/m1), times m1 (the overdamped rate ~ c/m1 sets the step where it exceeds w0)."""
    cp = contact_params(C_KELVIN_VOIGT, max(k, c * c / m1), k, 0.0)
    cp[3] = c
    return cp


def hunt_crossley_params(
    k: float, n: float, alpha: float, v0: float = 1.0, total_mass: float = 1.0
):
    """Pack the Hunt-Crossley law F = k x**n (1 + 1.5 alpha x') (kernel units, m1 = 1).

    cp[1], the slope scale: the larger of twice the elastic slope n k x**(n - 1) and the square of
    the damping rate 1.5 alpha k x**n at the deepest penetration the whole initial energy could
    reach (k x**(n + 1)/(n + 1) = total_mass v0**2/2)."""
    x_deep = ((n + 1.0) * total_mass * v0 * v0 / (2.0 * k)) ** (1.0 / (n + 1.0))
    lam = 1.5 * alpha
    scale = max(2.0 * n * k * x_deep ** (n - 1.0), (lam * k * x_deep**n) ** 2)
    cp = contact_params(C_HUNT_CROSSLEY, scale, k, n)
    cp[4] = lam
    return cp


HC_N_DEFAULT = 1.5


def check_hc_n(name: str, value) -> float:
    """The Hunt-Crossley exponent n in [1, 10] (below 1 the slope at x = 0 is unbounded)."""
    x = _num(name, value, "in [1, 10]")
    if not 1.0 <= x <= 10.0:
        raise SceneError(f"{name} must be in [1, 10]; got {_show(value)}")
    return x


def _hc_k_unit(spec: dict, where: str) -> tuple:
    """Unit of the Hunt-Crossley k (force per length**n): m1 omega**(1 + n)."""
    n = spec.get("n")
    if n is None or (isinstance(n, float) and math.isnan(n)):  # not given: the default
        n = HC_N_DEFAULT
    return (1, 1.0 + check_hc_n(f"{where}.n", n))


def check_damping(name: str, value) -> float:
    """A contact dashpot: finite, >= 0 (kernel units)."""
    x = _num(name, value, "in [0, inf)")
    if not x >= 0.0:
        raise SceneError(f"{name} must be a finite number >= 0; got {_show(value)}")
    return x


def check_stiffness(name: str, value, high: float = 1e12) -> float:
    """A stiffness-like law parameter: finite, in (0, high] (kernel units)."""
    x = _num(name, value, f"in (0, {high:g}]")
    if not 0.0 < x <= high:
        raise SceneError(f"{name} must be in (0, {high:g}]; got {_show(value)}")
    return x


# ----------------------------------------------------------------------------------------------
# Law specifications of a general chain: {"law": name, parameters...} (kernel units: m1 = 1,
# omega = 1, lengths in V_ref/omega). Each entry: parameter names -> packer(spec, k_link, v0, M).
# ----------------------------------------------------------------------------------------------

# name: (law id, parameters, units). A unit (a, b) says the parameter is measured in
# m1**a * omega**b in kernel units (speeds keep the user's unit, so a length is speed/omega):
# a stiffness (force/length) is (1, 2), a Hertz constant (force/length**1.5) (1, 2.5), a length
# (0, -1); parameters not listed are unit-free.
CONTACT_LAWS = {
    "rigid": (C_RIGID, (), {}),
    "linear": (C_LINEAR, ("k",), {"k": (1, 2)}),
    "plastic": (C_PLASTIC, ("k", "eta", "dr"), {"k": (1, 2)}),
    "hertz": (C_HERTZ, ("k",), {"k": (1, 2.5)}),
    "kelvin_voigt": (C_KELVIN_VOIGT, ("k", "c"), {"k": (1, 2), "c": (1, 1)}),
    # k's unit depends on n (a function of the spec); alpha is an inverse speed (unit-free here)
    "hunt_crossley": (C_HUNT_CROSSLEY, ("k", "n", "alpha"), {"k": _hc_k_unit}),
}
# Defaults of contact law parameters.
CONTACT_DEFAULTS = {"hunt_crossley": {"n": HC_N_DEFAULT}}
LINK_LAWS = {
    "linear": (S_LINEAR, (), {}),
    "scissor": (S_SCISSOR, ("L", "ks", "theta0", "corner"), {"L": (0, -1), "ks": (1, 2)}),
}
LINK_DEFAULTS = {"theta0": THETA0_DEFAULT, "corner": CORNER_DEFAULT}


def _spec(kind: str, spec, table: dict, defaults: dict, where: str) -> tuple[str, dict]:
    """Name and parameters of a law spec, checked against its table (no unknown keys)."""
    if isinstance(spec, str):
        spec = {"law": spec}
    if not isinstance(spec, dict) or "law" not in spec:
        raise SceneError(f"{where} must be a mapping with a key 'law'; got {spec!r}")
    # a table's struct column carries every law's fields: None/NaN cells are not given
    spec = {
        k: v
        for k, v in spec.items()
        if v is not None and not (isinstance(v, float) and math.isnan(v))
    }
    name = spec.get("law")
    if not isinstance(name, str) or name not in table:
        allowed = ", ".join(map(repr, table))
        raise SceneError(f"{where}: {kind} law must be one of {allowed}; got {name!r}")
    need = table[name][1]
    unknown = sorted(set(spec) - {"law", *need})
    if unknown:
        raise SceneError(
            f"{where}: unknown parameter(s) {', '.join(unknown)} for the {name!r} law; "
            f"allowed: {', '.join(need) or 'none'}"
        )
    params = dict(defaults)
    params.update({k: v for k, v in spec.items() if k != "law"})
    missing = [k for k in need if k not in params]
    if missing:
        raise SceneError(f"{where}: the {name!r} law needs {', '.join(missing)}")
    return name, params


def pack_contact(
    spec, v0: float = 1.0, total_mass: float = 1.0, where: str = "contact", k_first: float = 1.0
):
    """Checked, packed contact law (cp) of a spec in kernel units; also returns kappa or nan.

    ``k_first`` is the first structural spring: the contact's effective stiffness must be
    within the handled beta range of it (check_contact_ratio).
    """
    law = spec.get("law") if isinstance(spec, dict) else spec
    defaults = CONTACT_DEFAULTS.get(law, {}) if isinstance(law, str) else {}
    name, p = _spec("contact", spec, CONTACT_LAWS, defaults, where)
    if name == "rigid":
        return contact_params(C_RIGID), math.nan
    if name == "linear":
        k = check_stiffness(f"{where}.k", p["k"], math.inf)
        check_contact_ratio(where, k_first / k, "stiffness")
        return contact_params(C_LINEAR, k), math.nan
    if name == "hertz":
        k = check_stiffness(f"{where}.k", p["k"], math.inf)
        check_contact_ratio(where, k_first / hertz_slope_at_depth(k, v0), "slope at m1's depth")
        return hertz_params(k, v0, total_mass), math.nan
    if name == "kelvin_voigt":
        k = check_stiffness(f"{where}.k", p["k"], math.inf)
        c = check_damping(f"{where}.c", p["c"])
        zeta = c / (2.0 * math.sqrt(k))  # m1 = 1 in kernel units
        if not zeta <= ZETA_CONTACT_MAX * (1.0 + 1e-12):  # (the units' rounding at the end)
            raise SceneError(
                f"{where}.c: the contact's damping ratio c / (2 sqrt(k m1)) is {zeta:.3g}; it "
                f"must be at most {ZETA_CONTACT_MAX:g} (the contact's work grows with it)"
            )
        check_contact_ratio(where, k_first / k, "stiffness")
        return kelvin_voigt_params(k, c), math.nan
    if name == "hunt_crossley":
        k = check_stiffness(f"{where}.k", p["k"], math.inf)
        n = check_hc_n(f"{where}.n", p["n"])
        alpha = check_damping(f"{where}.alpha", p["alpha"])
        # m1 never moves faster than v0 sqrt(M/m1) (the energy only falls): below 1 here the
        # factor 1 + 1.5 alpha x' stays > 0, so the force ends at x = 0 and never pulls
        bound = 1.5 * alpha * v0 * math.sqrt(total_mass)
        if not bound < 1.0:
            raise SceneError(
                f"{where}.alpha: 1.5 alpha v0 sqrt(M/m1) is {bound:.3g}; it must be below 1, so "
                f"that m1 cannot leave faster than 1/(1.5 alpha), where the force "
                f"k x**n (1 + 1.5 alpha x') would end before x = 0 (not handled)"
            )
        check_contact_ratio(where, k_first / power_slope_at_depth(k, n, v0), "slope at m1's depth")
        return hunt_crossley_params(k, n, alpha, v0, total_mass), math.nan
    # plastic: k is the unloading slope; kappa follows from DR (module docstring)
    k1 = check_stiffness(f"{where}.k", p["k"], math.inf)
    try:
        eta = check_eta(p["eta"])
        dr = check_dr(p["dr"], eta)
    except SceneError as e:
        raise SceneError(f"{where}: {e}") from None
    check_contact_ratio(where, k_first / k1, "unloading slope")
    check_contact_ratio(where, k_first / plastic_loading_secant(dr, eta, k1), "loading secant")
    kappa = plastic_kappa(dr, eta, k1, v0)
    if not (math.isfinite(kappa) and kappa > 0.0):
        raise SceneError(
            f"{where}: the plastic law's kappa = {kappa!r} is not a positive finite number for "
            f"v0 = {v0!r}, eta = {eta!r} (kappa ~ v0**(1 - eta)); use a v0 closer to 1"
        )
    return contact_params(C_PLASTIC, k1, kappa, eta), kappa


def pack_link(spec, k_link: float, where: str = "link") -> np.ndarray:
    """Checked, packed structural link law (a structure_params row) of a spec.

    The link's spring stiffness ``k_link`` is the linear law's stiffness and the scissor's cap
    slope (the paper's k2); the scissor's ``ks`` is its own stiffness, < k_link*tan(theta0)**2.
    """
    name, p = _spec("link", spec, LINK_LAWS, LINK_DEFAULTS, where)
    if name == "linear":
        return linear_structure_params(k_link)
    try:
        L_ = check_L(p["L"])
        theta0 = check_theta0(p["theta0"])
        ks = check_stiffness("ks (in units m1 omega**2 of the first link)", p["ks"])
        check_ks_ratio(ks / k_link, theta0)
        corner = check_corner(p["corner"])
    except SceneError as e:
        raise SceneError(f"{where}: {e}") from None
    return scissor_params(k_link, ks, L_, theta0, corner)


# ----------------------------------------------------------------------------------------------
# Scalar laws (numba; callable from Python). mem = contact memory, see kernels/stepping.py.
# ----------------------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy", refcount=False)
def _scissor_angle(sp, x):
    """cos(theta), sin(theta) and sin(theta) - sin(theta0) at extension x, the last without
    cancellation: sin - sin0 = (cos0**2 - cos**2)/(sin + sin0) = -d (cos + cos0)/(sin + sin0),
    d = cos - cos0 = x/(2L). (The plain difference lost all digits for |x| < 1e-8 L.)"""
    d = x / (2.0 * sp[SP_L])
    c = sp[SP_C0] + d
    if c >= 1.0:
        c = 1.0
        d = 1.0 - sp[SP_C0]
    s = math.sqrt(max(1.0 - c * c, 0.0))
    return c, s, -d * (c + sp[SP_C0]) / (s + sp[SP_S0])


@njit(cache=True, error_model="numpy", refcount=False)
def structure_force(sp, x):
    """Structural force F2(x) (> 0 in tension); the force on m1 is +F2, on m2 is -F2."""
    k2 = sp[SP_K2]
    if sp[SP_KIND] == S_LINEAR:
        return k2 * x
    if x >= sp[SP_XCAP]:
        return sp[SP_FCAP] + k2 * (x - sp[SP_XCAP])
    if x >= sp[SP_XLOCK]:
        c, s, ds = _scissor_angle(sp, x)
        return 2.0 * sp[SP_KS] * sp[SP_L] * c * (-ds / max(s, 1e-150))
    d = sp[SP_XLOCK] - x
    dc = sp[SP_DC]
    if d <= dc:
        return sp[SP_FLOCK] - 0.5 * sp[SP_KC] * d * d
    return sp[SP_FLOCK] - 0.5 * k2 * dc - k2 * (d - dc)


# Scissor branches, from compression to tension: past the pads' cap (linear, slope k2), the pads
# (quadratic), the bars (Eq. 24), the tension cap (linear, slope k2). The law is C1 but not C2 at
# the three points between them, so the adaptive integrator holds a link on one branch's formula
# for a whole step and stops on these points as events (kernels/integrators.py).
SB_FLAT, SB_PADS, SB_BARS, SB_CAP = 0, 1, 2, 3


@njit(cache=True, error_model="numpy", refcount=False)
def scissor_branch(sp, x):
    """The branch that holds extension x, with ``structure_force``'s own tie rule (a point
    belongs to the branch above it)."""
    if x >= sp[SP_XCAP]:
        return SB_CAP
    if x >= sp[SP_XLOCK]:
        return SB_BARS
    if sp[SP_XLOCK] - x <= sp[SP_DC]:
        return SB_PADS
    return SB_FLAT


@njit(cache=True, error_model="numpy", refcount=False)
def scissor_point(sp, j):
    """Extension of the point between branches j and j + 1 (j = 0, 1, 2); -inf / inf beyond."""
    if j < 0:
        return -math.inf
    if j == 0:
        return sp[SP_XLOCK] - sp[SP_DC]
    if j == 1:
        return sp[SP_XLOCK]
    if j == 2:
        return sp[SP_XCAP]
    return math.inf


@njit(cache=True, error_model="numpy", refcount=False)
def scissor_force_on(sp, x, br):
    """The scissor force by branch ``br``'s formula at any x: each formula is analytic across
    its own ends, so a step held on one branch sees a smooth law (``structure_force`` picks the
    branch by x)."""
    k2 = sp[SP_K2]
    if br == SB_CAP:
        return sp[SP_FCAP] + k2 * (x - sp[SP_XCAP])
    if br == SB_BARS:
        c, s, ds = _scissor_angle(sp, x)
        return 2.0 * sp[SP_KS] * sp[SP_L] * c * (-ds / max(s, 1e-150))
    d = sp[SP_XLOCK] - x
    dc = sp[SP_DC]
    if br == SB_PADS:
        return sp[SP_FLOCK] - 0.5 * sp[SP_KC] * d * d
    return sp[SP_FLOCK] - 0.5 * k2 * dc - k2 * (d - dc)


@njit(cache=True, error_model="numpy", refcount=False)
def structure_energy(sp, x):
    """Potential U2(x) = integral of F2 from 0 to x (closed form on every branch)."""
    k2 = sp[SP_K2]
    if sp[SP_KIND] == S_LINEAR:
        return 0.5 * k2 * x * x
    if x >= sp[SP_XCAP]:
        e = x - sp[SP_XCAP]
        return sp[SP_UCAP] + sp[SP_FCAP] * e + 0.5 * k2 * e * e
    if x >= sp[SP_XLOCK]:
        _, _, ds = _scissor_angle(sp, x)
        return 2.0 * sp[SP_KS] * sp[SP_L] ** 2 * ds * ds
    d = sp[SP_XLOCK] - x
    dc = sp[SP_DC]
    fl = sp[SP_FLOCK]
    if d <= dc:
        return sp[SP_ULOCK] - (fl * d - sp[SP_KC] * d * d * d / 6.0)
    udc = sp[SP_ULOCK] - (fl * dc - k2 * dc * dc / 6.0)
    fdc = fl - 0.5 * k2 * dc
    e = d - dc
    return udc - (fdc * e - 0.5 * k2 * e * e)


@njit(cache=True, error_model="numpy", refcount=False)
def structure_slope(sp, x):
    """Tangent stiffness dF2/dx (<= k2 everywhere by construction)."""
    k2 = sp[SP_K2]
    if sp[SP_KIND] == S_LINEAR or x >= sp[SP_XCAP]:
        return k2
    if x >= sp[SP_XLOCK]:
        c = min(1.0, sp[SP_C0] + x / (2.0 * sp[SP_L]))
        s = math.sqrt(max(1.0 - c * c, 1e-300))
        return sp[SP_KS] * (sp[SP_S0] / (s * s * s) - 1.0)
    d = sp[SP_XLOCK] - x
    return min(k2, sp[SP_KC] * d)


@njit(cache=True, error_model="numpy", refcount=False)
def structure_extent(sp, energy, sign):
    """Largest |x| on side ``sign`` (+1 tension, -1 compression) with U2(x) <= energy."""
    if energy <= 0.0:
        return 0.0
    if sp[SP_KIND] == S_LINEAR:
        return math.sqrt(2.0 * energy / sp[SP_K2])
    # U2 is monotone on each side; the linear cap gives an upper bracket.
    hi = 1.0
    while structure_energy(sp, sign * hi) < energy:
        hi *= 2.0
    lo = 0.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if structure_energy(sp, sign * mid) < energy:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * hi:
            break
    return hi


@njit(cache=True, error_model="numpy", refcount=False)
def contact_elastic(cp):
    """True for a contact law without memory (ELASTIC_CONTACTS)."""
    return cp[0] == C_LINEAR or cp[0] == C_HERTZ


@njit(cache=True, error_model="numpy", refcount=False)
def contact_viscous(cp):
    """True for a contact law whose force depends on m1's velocity (VISCOUS_CONTACTS)."""
    return cp[0] == C_KELVIN_VOIGT or cp[0] == C_HUNT_CROSSLEY


@njit(cache=True, error_model="numpy", refcount=False)
def contact_params_ok(cp):
    """The kernels' own guard of a packed contact law (finite, positive where it must be)."""
    kind = cp[0]
    if kind == C_RIGID:
        return True
    if not (cp[1] > 0.0 and cp[1] < math.inf):
        return False
    if kind == C_PLASTIC or kind == C_HERTZ:  # F = cp[2] * x**cp[3]
        return cp[2] > 0.0 and cp[2] < math.inf and cp[3] > 0.0 and cp[3] < math.inf
    if kind == C_KELVIN_VOIGT:  # F = cp[2] * x + cp[3] * x'
        return cp[2] > 0.0 and cp[2] < math.inf and cp[3] >= 0.0 and cp[3] < math.inf
    if kind == C_HUNT_CROSSLEY:  # F = cp[2] * x**cp[3] * (1 + cp[4] * x')
        return (
            cp[2] > 0.0 and cp[2] < math.inf and cp[3] >= 1.0 and cp[3] < math.inf
            and cp[4] >= 0.0 and cp[4] < math.inf
        )  # fmt: skip
    return kind == C_LINEAR


@njit(cache=True, error_model="numpy", refcount=False)
def contact_force(cp, branch, xmax, fmax, x, xd):
    """Contact force on m1 (>= 0 pushes away from the wall) as a smooth function of x (and of
    the penetration rate xd = x' = -v1 for a viscous law).

    ``branch`` 1 = loading (power law), 0 = elastic unloading/reloading. No clipping at zero: the
    integrators evaluate the smooth continuation and locate the separation as an event (Hertz:
    0 for x <= 0, C1 there; Kelvin-Voigt: k x + c x', whose zero is the separation).
    """
    kind = cp[0]
    if kind == C_LINEAR:
        return cp[1] * x
    if kind == C_KELVIN_VOIGT:
        return cp[2] * x + cp[3] * xd
    if kind == C_HUNT_CROSSLEY:
        return cp[2] * x ** cp[3] * (1.0 + cp[4] * xd) if x > 0.0 else 0.0
    if kind == C_HERTZ:
        return cp[2] * x * math.sqrt(x) if x > 0.0 else 0.0
    if branch == 1:
        return cp[2] * max(x, 0.0) ** cp[3]
    return fmax - cp[1] * (xmax - x)


@njit(cache=True, error_model="numpy", refcount=False)
def contact_energy(cp, x):
    """Potential energy stored in an elastic contact law at penetration x (0 for plastic)."""
    if x <= 0.0:
        return 0.0
    if cp[0] == C_LINEAR:
        return 0.5 * cp[1] * x * x
    if cp[0] == C_HERTZ:
        return 0.4 * cp[2] * x * x * math.sqrt(x)
    if cp[0] == C_KELVIN_VOIGT:
        return 0.5 * cp[2] * x * x  # its spring's; the dashpot stores nothing
    if cp[0] == C_HUNT_CROSSLEY:
        return cp[2] * x ** (cp[3] + 1.0) / (cp[3] + 1.0)  # its elastic part's
    return 0.0


@njit(cache=True, error_model="numpy", refcount=False)
def contact_slope(cp, branch, xmax, x):
    if cp[0] == C_HERTZ:
        return 1.5 * cp[2] * math.sqrt(x) if x > 0.0 else 0.0
    if cp[0] == C_KELVIN_VOIGT:
        return cp[2]
    if cp[0] == C_HUNT_CROSSLEY:  # of the elastic part (x' = 0)
        return cp[3] * cp[2] * x ** (cp[3] - 1.0) if x > 0.0 else 0.0
    if cp[0] == C_LINEAR or branch == 0:
        return cp[1]
    if x <= 0.0:
        return cp[1]
    return min(cp[2] * cp[3] * x ** (cp[3] - 1.0), 1e3 * cp[1])


@njit(cache=True, error_model="numpy", refcount=False)
def contact_hysteretic(cp, xmax, fmax, x, xd):
    """Path-following force for explicit schemes (Verlet), clipped at 0, at penetration x and
    its rate xd = x'; returns (F, xmax, fmax)."""
    if cp[0] == C_KELVIN_VOIGT:
        return (max(0.0, cp[2] * x + cp[3] * xd) if x > 0.0 else 0.0), xmax, fmax
    if cp[0] == C_HUNT_CROSSLEY:
        f = cp[2] * x ** cp[3] * (1.0 + cp[4] * xd) if x > 0.0 else 0.0
        return max(0.0, f), xmax, fmax
    if cp[0] == C_LINEAR:
        return max(0.0, cp[1] * x), xmax, fmax
    if cp[0] == C_HERTZ:
        return (cp[2] * x * math.sqrt(x) if x > 0.0 else 0.0), xmax, fmax
    if x >= xmax:
        f = cp[2] * x ** cp[3]
        return f, x, f
    return max(0.0, fmax - cp[1] * (xmax - x)), xmax, fmax


def to_kernel_units(spec, table: dict, m1: float, omega: float, where: str):
    """A law spec (mapping or name) with its dimensional parameters in kernel units (the
    ``units`` of its table entry); unknown laws and non-numbers are left to the packers."""
    if isinstance(spec, str):
        spec = {"law": spec}
    if not isinstance(spec, dict):
        raise SceneError(f"{where} must be a mapping like {{'law': 'linear', ...}}; got {spec!r}")
    out = dict(spec)
    law = spec.get("law")
    entry = table.get(law) if isinstance(law, str) else None
    for key, unit in (entry[2] if entry else {}).items():
        given = out.get(key)
        if given is not None:
            a, b = unit(out, where) if callable(unit) else unit
            scale = m1**a * omega**b
            x = _num(f"{where}.{key}", given, "> 0")
            # The packers check kernel values; the errors they can raise about the sign or a
            # range in kernel units are raised here, with the value and range as given.
            if x < 0.0:
                raise SceneError(f"{where}.{key} must not be negative; got {_show(given)}")
            r = RANGES.get(key) if table is LINK_LAWS else None  # (the scissor's L)
            if r is not None and not r.contains(x / scale):
                raise SceneError(
                    f"{where}.{key} must be in [{r.low * scale:.6g}, {r.high * scale:.6g}] in "
                    f"the chain's units ({r.text} in units of m1 and omega of its first link); "
                    f"got {_show(given)}"
                )
            out[key] = x / scale
    return out


# ----------------------------------------------------------------------------------------------
# A whole chain in kernel units
# ----------------------------------------------------------------------------------------------


def _vector(name, value, n=None, low=0.0, low_open=True):
    """A checked 1-d float vector: finite, > low (>= low if not low_open), length n if given."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(f"{name} must be a list of numbers; got {value!r}") from None
    if a.ndim != 1 or a.size == 0:
        raise SceneError(f"{name} must be a non-empty list of numbers; got {value!r}")
    if any(isinstance(v, bool) for v in np.ravel(np.asarray(value, dtype=object))):
        raise SceneError(f"{name} must be numbers, not booleans; got {value!r}")
    if n is not None and a.size != n:
        raise SceneError(f"{name} must have {n} entries (one per link); got {a.size}")
    rel = ">" if low_open else ">="
    bad = ~np.isfinite(a) | ((a <= low) if low_open else (a < low))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise SceneError(f"{name}[{i}] must be a finite number {rel} {low:g}; got {a[i]!r}")
    return a


def pack_chain(masses, springs, dashpots=None, contact="rigid", links=None, v0=1.0):
    """Check a chain in the user's units and pack it in kernel units; names any bad parameter.

    Returns (m, lk, c, cp, omega, kappa): masses / m1, link laws (structure_params rows),
    dashpots / (m1 omega), the contact law (pack_contact), omega**2 = k1/m1 + k1/m2 (k1 the
    first spring) and the plastic law's kappa in kernel units (nan otherwise). Kernel units:
    m1 = 1, omega = 1, speed unit = the user's (v0 enters as given), length unit = that speed
    unit / omega; so a stiffness k scales as k/(m1 omega**2), a Hertz constant k_h (force per
    length**1.5) as k_h/(m1 omega**2.5), a length L as L*omega, a dashpot c as c/(m1 omega).
    """
    m = _vector("masses", masses)
    n = m.size
    if n < 2 or n > MAX_MASSES:
        raise SceneError(f"masses must have 2 to {MAX_MASSES} entries; got {n}")
    k = _vector("springs", springs, n - 1)
    c = np.zeros(n - 1) if dashpots is None else _vector("dashpots", dashpots, n - 1, 0.0, False)
    return pack_checked(m, k, c, contact, links, v0)


def pack_checked(m, k, c, contact, links, v0: float, numerical: bool = True):
    """``pack_chain`` of float64 vectors already checked (``Chain`` checks its own: finite, >
    0, dashpots >= 0, their lengths); v0, the laws and the units are checked here, and with
    ``numerical`` the ranges the numerical methods handle (mass ratio, frequency spread): a
    chain solved exactly (a Kelvin-Voigt contact on linear links) is not held to them."""
    n = m.size
    v0 = check_v0(v0)
    m1 = m[0]
    w2 = k[0] / m[0] + k[0] / m[1]
    w = math.sqrt(w2)
    ku = m1 * w2  # stiffness unit
    ms, ks, cs = m / m1, k / ku, c / (m1 * w)
    scaled = np.concatenate([ms, ks])
    if not (np.isfinite(scaled) & (scaled > 0)).all():
        raise SceneError(
            "masses and springs span too many decades: their ratios to m1 and m1*omega**2 "
            "under- or overflow in float64"
        )
    cspec = to_kernel_units(
        contact if contact is not None else "rigid", CONTACT_LAWS, m1, w, "contact"
    )
    rest = ms[1:]
    lo, hi = rest.min(), rest.max()  # (ms[0] = 1)
    ratio = hi / min(lo, 1.0), max(hi, 1.0) / lo
    if numerical and not max(ratio) <= ALPHA_NL_MAX:
        raise SceneError(
            f"masses: the ratio of the largest to the smallest mass must be at most "
            f"{ALPHA_NL_MAX:g} for the nonlinear laws (the numerical methods' handled "
            f"range); got {max(ratio):.3g}"
        )
    cp, kappa = pack_contact(cspec, v0, float(ms.sum()), "contact", float(ks[0]))
    if links is None:
        links = ["linear"] * (n - 1)
    if isinstance(links, (str, dict)) or len(links) != n - 1:
        raise SceneError(
            f"links must be a list of {n - 1} link laws (one per spring); got {links!r}"
        )
    lk = np.zeros((n - 1, N_SP))
    for i, spec in enumerate(links):
        where = f"links[{i}]"
        s = to_kernel_units(spec, LINK_LAWS, m1, w, where)
        lk[i] = pack_link(s, ks[i], where)
    if numerical:
        check_frequency_spread(ms, lk, cs, cp, v0)
    return ms, lk, cs, cp, w, kappa
