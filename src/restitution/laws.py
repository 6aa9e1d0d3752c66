"""Nonlinear force laws of Sections 3.1 and 3.2: plastic contact and the scissor spring.

Units are those of DESIGN.md (m1 = 1, omega = 1 from the *nominal* k2 = alpha/(1+alpha)), except
that the impact speed ``v0`` is a parameter: both laws make the response velocity dependent, so
lengths are in units of V_ref/omega with V_ref = 1 and the masses start at -v0.

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
from numba import njit

from .scene import SceneError

# Contact law kinds (contact_params[0]).
C_RIGID = 0  # beta = 0: impulsive reversal of m1's velocity
C_LINEAR = 1  # F = k1*x
C_PLASTIC = 2  # power-law loading, linear unloading/reloading
C_HERTZ = 3  # F = k_h*x**1.5 (elastic; Hertz's sphere on a flat)
# contact_params = [kind, k1, kappa, eta]: k1 is the law's slope scale (linear: its stiffness,
# plastic: the unloading slope, hertz: the slope at the deepest possible penetration, which sets
# the integrators' step scale); kappa, eta the power law F = kappa*x**eta (hertz: k_h, 1.5).
N_CP = 4
# Contact laws without memory: the force is a function of the penetration alone, the contact
# branches (rising, falling) only record the largest penetration.
ELASTIC_CONTACTS = (C_LINEAR, C_HERTZ)

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
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SceneError(f"{name} must be a number {allowed}; got {value!r}") from None
    if isinstance(value, bool) or not math.isfinite(x):
        raise SceneError(f"{name} must be a finite number {allowed}; got {value!r}")
    return x


def check_eta(value) -> float:
    x = _num("eta", value, "in (0, 10]")
    if not 0.0 < x <= 10.0:
        raise SceneError(f"eta must be in (0, 10]; got {value!r}")
    return x


def check_dr(value, eta: float = 1.0) -> float:
    x = _num("dr", value, "in [0, 1)")
    if not 0.0 <= x < 1.0:
        raise SceneError(f"dr (nominal dissipation ratio) must be in [0, 1); got {value!r}")
    low = max(0.0, (1.0 - eta) / 2.0)
    if x < low - 1e-15:
        raise SceneError(
            f"dr must be in [{low:g}, 1) for eta={eta:g}: a power-law loading with eta < 1 and a "
            f"linear unloading cannot return more than (1 + eta)/2 of the energy (the residual "
            f"dent would be negative); got {value!r}"
        )
    return x


def check_v0(value) -> float:
    x = _num("v0", value, "in (0, 1e6]")
    if not 0.0 < x <= 1e6:
        raise SceneError(f"v0 (impact speed) must be in (0, 1e6]; got {value!r}")
    return x


def check_L(value) -> float:  # noqa: N802 - the paper's symbol
    x = _num("L", value, "in (0, 1e6]")
    if not 0.0 < x <= 1e6:
        raise SceneError(f"L (scissor bar length) must be in (0, 1e6]; got {value!r}")
    return x


def check_theta0(value) -> float:
    x = _num("theta0", value, "in (0, pi/2)")
    if not 0.0 < x < math.pi / 2:
        raise SceneError(f"theta0 must be in (0, pi/2) (radians); got {value!r}")
    return x


def check_ks_ratio(value, theta0: float = THETA0_DEFAULT) -> float:
    x = _num("ks_ratio", value, "in (0, 1)")
    cap = math.tan(theta0) ** 2
    if not 0.0 < x < cap:
        raise SceneError(
            f"ks_ratio (= ks/k2) must be in (0, tan(theta0)**2 = {cap:.6g}) so that the scissor's "
            f"rest slope ks*cot(theta0)**2 stays below the cap k2; got {value!r}"
        )
    return x


def check_corner(value) -> float:
    x = _num("corner", value, "in (0, 100]")
    if not 0.0 < x <= 100.0:
        raise SceneError(
            f"corner (stroke fraction to reach the cap) must be in (0, 100]; got {value!r}"
        )
    return x


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


def check_stiffness(name: str, value, high: float = 1e12) -> float:
    """A stiffness-like law parameter: finite, in (0, high] (kernel units)."""
    x = _num(name, value, f"in (0, {high:g}]")
    if not 0.0 < x <= high:
        raise SceneError(f"{name} must be in (0, {high:g}]; got {value!r}")
    return x


# ----------------------------------------------------------------------------------------------
# Law specifications of a general chain: {"law": name, parameters...} (kernel units: m1 = 1,
# omega = 1, lengths in V_ref/omega). Each entry: parameter names -> packer(spec, k_link, v0, M).
# ----------------------------------------------------------------------------------------------

CONTACT_LAWS = {
    # name: (law id, required parameters)
    "rigid": (C_RIGID, ()),
    "linear": (C_LINEAR, ("k",)),
    "plastic": (C_PLASTIC, ("k", "eta", "dr")),
    "hertz": (C_HERTZ, ("k",)),
}
LINK_LAWS = {
    "linear": (S_LINEAR, ()),
    "scissor": (S_SCISSOR, ("L", "ks", "theta0", "corner")),
}
LINK_DEFAULTS = {"theta0": THETA0_DEFAULT, "corner": CORNER_DEFAULT}


def _spec(kind: str, spec, table: dict, defaults: dict, where: str) -> tuple[str, dict]:
    """Name and parameters of a law spec, checked against its table (no unknown keys)."""
    if isinstance(spec, str):
        spec = {"law": spec}
    if not isinstance(spec, dict) or "law" not in spec:
        raise SceneError(f"{where} must be a mapping with a key 'law'; got {spec!r}")
    name = spec["law"]
    if name not in table:
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


def pack_contact(spec, v0: float = 1.0, total_mass: float = 1.0, where: str = "contact"):
    """Checked, packed contact law (cp) of a spec in kernel units; also returns kappa or nan."""
    name, p = _spec("contact", spec, CONTACT_LAWS, {}, where)
    if name == "rigid":
        return contact_params(C_RIGID), math.nan
    if name == "linear":
        return contact_params(C_LINEAR, check_stiffness(f"{where}.k", p["k"])), math.nan
    if name == "hertz":
        return hertz_params(check_stiffness(f"{where}.k", p["k"]), v0, total_mass), math.nan
    # plastic: k is the unloading slope; kappa follows from DR (module docstring)
    k1 = check_stiffness(f"{where}.k", p["k"])
    try:
        eta = check_eta(p["eta"])
        dr = check_dr(p["dr"], eta)
    except SceneError as e:
        raise SceneError(f"{where}: {e}") from None
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
        ks = check_stiffness("ks", p["ks"])
        check_ks_ratio(ks / k_link, theta0)
        corner = check_corner(p["corner"])
    except SceneError as e:
        raise SceneError(f"{where}: {e}") from None
    return scissor_params(k_link, ks, L_, theta0, corner)


# ----------------------------------------------------------------------------------------------
# Scalar laws (numba; callable from Python). mem = contact memory, see kernels/nonlinear.py.
# ----------------------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def structure_force(sp, x):
    """Structural force F2(x) (> 0 in tension); the force on m1 is +F2, on m2 is -F2."""
    k2 = sp[SP_K2]
    if sp[SP_KIND] == S_LINEAR:
        return k2 * x
    if x >= sp[SP_XCAP]:
        return sp[SP_FCAP] + k2 * (x - sp[SP_XCAP])
    if x >= sp[SP_XLOCK]:
        c = min(1.0, sp[SP_C0] + x / (2.0 * sp[SP_L]))
        s = math.sqrt(max(1.0 - c * c, 1e-300))
        return 2.0 * sp[SP_KS] * sp[SP_L] * c * (sp[SP_S0] / s - 1.0)
    d = sp[SP_XLOCK] - x
    dc = sp[SP_DC]
    if d <= dc:
        return sp[SP_FLOCK] - 0.5 * sp[SP_KC] * d * d
    return sp[SP_FLOCK] - 0.5 * k2 * dc - k2 * (d - dc)


@njit(cache=True, error_model="numpy")
def structure_energy(sp, x):
    """Potential U2(x) = integral of F2 from 0 to x (closed form on every branch)."""
    k2 = sp[SP_K2]
    if sp[SP_KIND] == S_LINEAR:
        return 0.5 * k2 * x * x
    if x >= sp[SP_XCAP]:
        e = x - sp[SP_XCAP]
        return sp[SP_UCAP] + sp[SP_FCAP] * e + 0.5 * k2 * e * e
    if x >= sp[SP_XLOCK]:
        c = min(1.0, sp[SP_C0] + x / (2.0 * sp[SP_L]))
        s = math.sqrt(max(1.0 - c * c, 0.0))
        return 2.0 * sp[SP_KS] * sp[SP_L] ** 2 * (s - sp[SP_S0]) ** 2
    d = sp[SP_XLOCK] - x
    dc = sp[SP_DC]
    fl = sp[SP_FLOCK]
    if d <= dc:
        return sp[SP_ULOCK] - (fl * d - sp[SP_KC] * d * d * d / 6.0)
    udc = sp[SP_ULOCK] - (fl * dc - k2 * dc * dc / 6.0)
    fdc = fl - 0.5 * k2 * dc
    e = d - dc
    return udc - (fdc * e - 0.5 * k2 * e * e)


@njit(cache=True, error_model="numpy")
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


@njit(cache=True, error_model="numpy")
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


@njit(cache=True, error_model="numpy")
def contact_elastic(cp):
    """True for a contact law without memory (ELASTIC_CONTACTS)."""
    return cp[0] == C_LINEAR or cp[0] == C_HERTZ


@njit(cache=True, error_model="numpy")
def contact_force(cp, branch, xmax, fmax, x):
    """Contact force on m1 (>= 0 pushes away from the wall) as a smooth function of x.

    ``branch`` 1 = loading (power law), 0 = elastic unloading/reloading. No clipping at zero: the
    integrators evaluate the smooth continuation and locate the separation as an event (Hertz:
    0 for x <= 0, C1 there).
    """
    kind = cp[0]
    if kind == C_LINEAR:
        return cp[1] * x
    if kind == C_HERTZ:
        return cp[2] * x * math.sqrt(x) if x > 0.0 else 0.0
    if branch == 1:
        return cp[2] * max(x, 0.0) ** cp[3]
    return fmax - cp[1] * (xmax - x)


@njit(cache=True, error_model="numpy")
def contact_energy(cp, x):
    """Potential energy stored in an elastic contact law at penetration x (0 for plastic)."""
    if x <= 0.0:
        return 0.0
    if cp[0] == C_LINEAR:
        return 0.5 * cp[1] * x * x
    if cp[0] == C_HERTZ:
        return 0.4 * cp[2] * x * x * math.sqrt(x)
    return 0.0


@njit(cache=True, error_model="numpy")
def contact_slope(cp, branch, xmax, x):
    if cp[0] == C_HERTZ:
        return 1.5 * cp[2] * math.sqrt(x) if x > 0.0 else 0.0
    if cp[0] == C_LINEAR or branch == 0:
        return cp[1]
    if x <= 0.0:
        return cp[1]
    return min(cp[2] * cp[3] * x ** (cp[3] - 1.0), 1e3 * cp[1])


@njit(cache=True, error_model="numpy")
def contact_hysteretic(cp, xmax, fmax, x):
    """Path-following plastic force for explicit schemes (Verlet); returns (F, xmax, fmax)."""
    if cp[0] == C_LINEAR:
        return max(0.0, cp[1] * x), xmax, fmax
    if cp[0] == C_HERTZ:
        return (cp[2] * x * math.sqrt(x) if x > 0.0 else 0.0), xmax, fmax
    if x >= xmax:
        f = cp[2] * x ** cp[3]
        return f, x, f
    return max(0.0, fmax - cp[1] * (xmax - x)), xmax, fmax
