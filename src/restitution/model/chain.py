"""The scene model: any one-dimensional chain of masses, springs and dashpots hitting a wall.

A chain has masses m_1..m_N (m_1 touches the wall), one spring per neighbouring pair (link i joins
m_i and m_{i+1}; stiffness ``springs[i]``, linear or the scissor law), an optional dashpot per
link (coefficient ``dashpots[i]``), a contact law at the wall and the approach speed V0. At t = 0
every mass moves towards the wall at -V0 with every spring unstretched, unless an initial state
is given (``velocities``, ``stretches``: then V0 is the centre of mass's approach speed).

Units are the user's (any consistent set). The kernels work in scaled units: m_1 = 1, V0 = 1 and
omega = 1 with omega**2 = k_12/m_1 + k_12/m_2 (k_12 = springs[0]); ``Chain.scaled`` gives

    m_i / m_1,  k_i / (m_1 omega**2),  c_i / (m_1 omega),  k_contact / (m_1 omega**2),

times scale as omega * t and positions as u / (V0 / omega). The unit-free summaries are

    alpha = m_2 / m_1,  beta = k_12 / k_contact (0: rigid wall),  xi = c_12 omega / (2 k_12).

The paper's scenes are the preset ``Chain.paper(alpha, beta, xi, n_masses)``: m = [1, alpha, ...,
alpha], every spring alpha/(1 + alpha), a dashpot 2 xi k on the first link only, k_contact =
k/beta. Every range check of a scene parameter lives in this module (``RANGES``), once, with a
scalar form (``check``) and a vectorised form for table columns (``check_column``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from restitution.model.ranges import (
    MAX_MASSES,
    RANGES,
    Range,
    SceneError,
    _real,
    _show,
    missing_cell,
)
from restitution.model.units import kernel_params

# The one table of parameter ranges (``RANGES``, with ``Range``) lives in ``_base`` so that
# ``restitution.model.laws`` reads the same table; it is checked here (``check``, ``check_column``).
# The ratios the kernels see (their units: m_1 = 1, omega = 1), with the ranges of the paper's form:
# m_i/m_1 and k_i/k_12 like alpha, beta = k_12/k_contact like beta, and a damping ratio per link
# c_i omega / (2 k_12) like xi (for the first link it is the paper's xi). Checked in log space.
RATIOS = {
    "masses[i]/masses[0]": (1e-8, 1e8),
    "springs[i]/springs[0]": (1e-8, 1e8),
    "beta = springs[0]/k_contact": (0.0, 1e6),
    "damping ratio dashpots[i]*omega/(2*springs[0])": (0.0, 1e3),
}


def _pow10(x: float) -> str:
    """10**x as text, for any x (the ratio may be outside the floats)."""
    e = math.floor(x)
    return f"{10.0 ** (x - e):.3g}e{e:+d}"


def _check_ratios(m: np.ndarray, k: np.ndarray, c: np.ndarray, kc: float) -> None:
    """Raise SceneError naming the first ratio outside RATIOS (values already in their ranges)."""
    lm, lk = np.log10(m), np.log10(k)
    # log10(omega) = (log k_12 - log m_1 + log(1 + m_1/m_2)) / 2, without forming k/m.
    lw = 0.5 * (lk[0] - lm[0] + math.log10(1.0 + 10.0 ** min(lm[0] - lm[1], 300.0)))
    checks = (
        ("masses[i]/masses[0]", lm - lm[0]),
        ("springs[i]/springs[0]", lk - lk[0]),
        ("beta = springs[0]/k_contact", [lk[0] - math.log10(kc)] if math.isfinite(kc) else []),
        (
            "damping ratio dashpots[i]*omega/(2*springs[0])",
            [math.log10(x) + lw - math.log10(2.0) - lk[0] for x in c if x > 0.0],
        ),
    )
    for name, logs in checks:
        low, high = RATIOS[name]
        for i, x in enumerate(logs):
            if x > math.log10(high) * (1 + 1e-12) or (
                low > 0.0 and x < math.log10(low) * (1 + 1e-12)
            ):
                raise SceneError(
                    f"{name} must be in [{low:g}, {high:g}]; got {_pow10(x)}"
                    + (f" (i = {i})" if "[i]" in name else "")
                )


# Array parameters must be finite even where the range's upper end is inf (k_contact may be inf).
_FINITE = {"masses", "springs", "dashpots", "velocities", "stretches"}

# Largest |velocities[i]| and |stretches[i]| * omega relative to the centre of mass's approach
# speed V0 (the kernels' units of speed and length): like the mass and spring ratios (RATIOS), a
# state spread over more decades is round-off to the kernels.
INITIAL_RATIO = 1e8


def _initial_state(m, k, velocities, stretches, v0):
    """(velocities, stretches, v0) of a scene's initial state, checked: None, None and v0 for
    the uniform approach (also when it is given as equal velocities and zero stretches, so that
    it runs, bit for bit, as the default scene), else the arrays and the centre of mass's
    approach speed as v0. SceneError naming the parameter and its range."""
    n = len(m)
    vel = None if velocities is None else _as_array("velocities", velocities)
    if vel is not None and len(vel) != n:
        raise SceneError(
            f"velocities must have {n} entries (one per mass, len(masses)); got {len(vel)}"
        )
    st = None if stretches is None else _as_array("stretches", stretches, n - 1)
    if st is not None and not st.any():
        st = None  # unstretched: the default
    if vel is not None and v0 != 1.0:
        raise SceneError(
            "give either v0 (every mass approaching at v0) or velocities (one per mass), not "
            f"both; got v0={v0!r}"
        )
    if vel is None:
        if st is None:
            return None, None, v0
        vel = np.full(n, v0)
    if st is None and (vel == vel[0]).all() and vel[0] > 0.0:
        return None, None, check("v0", float(vel[0]))  # the uniform approach at vel[0]
    if vel[0] == 0.0:
        raise SceneError(
            "velocities[0] must not be 0: m_1 starts touching the wall, and at rest there it is "
            "neither hitting it (velocities[0] > 0) nor leaving it (< 0)"
        )
    # The centre of mass's approach speed (given v0 itself when only stretches are given)
    vc = v0 if velocities is None else math.fsum(m * vel) / math.fsum(m)
    r = RANGES["v0"]
    if not (r.contains(vc) and math.isfinite(vc)):
        raise SceneError(
            "the centre of mass must approach the wall: sum(masses*velocities)/sum(masses) must "
            f"be {r.text}; got {vc:.6g}"
        )
    big = np.abs(vel) / vc
    if big.max() > INITIAL_RATIO:
        i = int(np.argmax(big))
        raise SceneError(
            f"velocities[{i}] / (the centre of mass's approach speed) must be in "
            f"[-{INITIAL_RATIO:g}, {INITIAL_RATIO:g}]; got {vel[i] / vc:.3g}"
        )
    if st is not None:
        w = math.sqrt(k[0] / m[0] + k[0] / m[1])
        big = np.abs(st) * w / vc
        if not big.max() <= INITIAL_RATIO:
            i = int(np.argmax(big))
            raise SceneError(
                f"stretches[{i}] * omega / (the centre of mass's approach speed) must be at most "
                f"{INITIAL_RATIO:g} in size; got {big[i]:.3g}"
            )
    vel.setflags(write=False)
    if st is not None:
        st.setflags(write=False)
    return vel, st, vc


def check(name: str, value):
    """``value`` as float (int for integer ranges) if it is in ``RANGES[name]``; else SceneError
    naming the parameter and its range (wrong types included: None, text, bool, complex,
    containers; a real number of another type, e.g. Decimal, is read as its float)."""
    r = RANGES[name]
    t = type(value)
    if t is int and r.integer:  # compared exactly (2**62 + 1 would round to 2**62 as a float)
        if r.low <= value <= r.high:
            return value
        raise SceneError(f"{name} must be {r.text}; got {_show(value)}")
    if t is float or t is int:  # fast path: plain Python numbers (NaN fails every comparison)
        try:
            x = float(value)
        except OverflowError:
            raise SceneError(f"{name} must be {r.text}; got {_show(value)}") from None
        if r.contains(x) and (name not in _FINITE or math.isfinite(x)):
            return int(x) if r.integer else x
        raise SceneError(f"{name} must be {r.text}; got {value!r}")
    x = _real(value)
    if x is None or not r.contains(x) or (name in _FINITE and not math.isfinite(x)):
        raise SceneError(f"{name} must be {r.text}; got {_show(value)}")
    return int(x) if r.integer else x


def check_column(name: str, values: np.ndarray, index=None) -> np.ndarray:
    """A column of a scene table checked against ``RANGES[name]`` in one vectorised pass.

    Returns float64 (int64 for integer ranges); raises SceneError naming the first bad row.
    Numeric columns are read as they are; an object column (e.g. decimals from a parquet
    decimal column) cell by cell as ``check`` reads a value; complex, boolean and text columns
    are refused (a complex cell's imaginary part would be dropped).
    """
    r = RANGES[name]
    values = np.asarray(values)
    if values.dtype.kind in "fiu":
        x = values.astype(np.float64, copy=False)
        ok = r.accepts(x)
    else:  # object, bool, complex or string columns: every cell must be one real number
        x = np.full(len(values), np.nan)
        ok = np.zeros(len(values), dtype=bool)
        for i, v in enumerate(values):
            xi = _real(v)
            if xi is None:
                break
            x[i] = xi
            ok[i] = bool(r.accepts(x[i]))
            if not ok[i]:
                break
    if name in _FINITE:
        ok &= np.isfinite(x)
    if not ok.all():
        i = int(np.flatnonzero(~ok)[0])
        where = i if index is None else index[i]
        raise SceneError(f"{name} must be {r.text}; got {_show(values[i])} (row {where!r})")
    return x.astype(np.int64) if r.integer else x


def _as_array(name: str, values, length: int | None = None) -> np.ndarray:
    """A list parameter as float64; SceneError for empty, ragged, non-numeric or out-of-range."""
    # the common cases at once (a solve of one scene costs tens of microseconds)
    if type(values) is np.ndarray and values.dtype == np.float64 and values.ndim == 1:
        seq = values
        x = values.copy()  # (the Chain's own copy: it is made read-only)
    elif type(values) is list and all(type(v) is float for v in values):
        seq = values
        x = np.array(values, dtype=np.float64)
    else:
        seq, x = _parsed(name, values)
    if x.size == 0:
        raise SceneError(f"{name} must not be empty")
    r = RANGES[name]
    bad = ~(r.accepts(x) & np.isfinite(x))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise SceneError(f"{name}[{i}] must be {r.text}; got {_show(seq[i])}")
    if length is not None and len(x) != length:
        raise SceneError(
            f"{name} must have {length} entries (one per link, len(masses) - 1); got {len(x)}"
        )
    return x


def _parsed(name: str, values) -> tuple[list, np.ndarray]:
    """Any other sequence of real numbers: its elements, and each as float64 by ``_real``."""
    try:  # (a ragged nested list makes numpy raise)
        flat = not isinstance(values, (str, bytes, Mapping)) and np.ndim(values) == 1
    except (TypeError, ValueError):
        flat = False
    if not flat:
        raise SceneError(f"{name} must be a list of numbers; got {_show(values)}")
    seq = list(values)
    x = np.empty(len(seq))
    for i, v in enumerate(seq):
        xi = _real(v)
        if xi is None:
            raise SceneError(
                f"{name} must be a list of numbers; got {_show(values)} ({name}[{i}] is {_show(v)})"
            )
        x[i] = xi
    return seq, x


def _law(kind: str, spec, where: str) -> dict:
    """A law specification as a plain dict {"law": name, params...}: the name checked against
    the laws' own tables (``laws.CONTACT_LAWS``, ``laws.LINK_LAWS``: a new law is declared there
    and nowhere else), the parameters by the law's packer in ``restitution.model.laws``."""
    from restitution.model import laws  # (imports numba: only once a law is given)

    allowed = tuple(laws.CONTACT_LAWS if kind == "contact" else laws.LINK_LAWS)
    if isinstance(spec, str):
        spec = {"law": spec}
    if not isinstance(spec, Mapping) or "law" not in spec:
        raise SceneError(f"{where} must be a mapping with a key 'law'; got {_show(spec)}")
    if not isinstance(spec["law"], str) or spec["law"] not in allowed:
        raise SceneError(
            f"{where}: {kind} law must be one of {', '.join(map(repr, allowed))}; "
            f"got {_show(spec['law'])}"
        )
    return {k: v for k, v in spec.items() if v is not None}


def _contact_spec(contact, kc: float, given_kc: float) -> tuple[dict | None, float]:
    """(contact law, k_contact) of a chain: the law checked by name (``_law``), its k against a
    k_contact also given (``given_kc``, inf when not); the linear laws become k_contact alone
    (contact None)."""
    if contact is None:
        return None, kc
    contact = _law("contact", contact, "contact")
    law = contact["law"]
    if law in ("rigid", "linear"):  # (the other laws' keys are checked when they are packed)
        from restitution.model import laws

        laws._spec("contact", contact, laws.CONTACT_LAWS, {}, "contact")  # no unknown keys
    k_law = contact.get("k")
    if law == "rigid":
        k_law = math.inf
    if k_law is None:
        raise SceneError(f"contact: the {law!r} law needs k (its stiffness)")
    try:
        k_law = check("k_contact", k_law)
    except SceneError:
        raise SceneError(
            f"contact.k (the {law!r} law's stiffness) must be "
            f"{RANGES['k_contact'].text}; got {_show(k_law)}"
        ) from None
    if law not in ("rigid", "linear") and not math.isfinite(k_law):
        raise SceneError(
            f"contact: the {law!r} law needs a finite k > 0 (in the paper's form: beta > 0)"
        )
    if given_kc != math.inf and kc != k_law:
        raise SceneError(
            f"k_contact = {kc!r} contradicts contact['k'] = {k_law!r}; give one of them"
        )
    if law in ("rigid", "linear"):
        return None, k_law  # the linear laws are described by k_contact alone
    return contact, k_law


def _link_specs(links, n: int) -> tuple | None:
    """The chain's link laws as a tuple of checked mappings, or None for all linear."""
    if links is None:
        return None
    if not isinstance(links, (list, tuple, np.ndarray)) or len(links) != n - 1:
        raise SceneError(
            f"links must be a list of {n - 1} law mappings (one per link); got {_show(links)}"
        )
    links = tuple(_law("link", s, f"links[{i}]") for i, s in enumerate(links))
    if all(s["law"] == "linear" and len(s) == 1 for s in links):
        return None
    return links


def _assign(chain, **fields) -> None:
    """Set fields of a frozen Chain (while it is being built)."""
    for name, value in fields.items():
        object.__setattr__(chain, name, value)


@dataclass(frozen=True, eq=False)
class Chain:
    """One validated scene (see the module docstring for the model and its units).

    Parameters
    ----------
    masses : sequence of float
        m_1..m_N, finite and > 0; N in [2, MAX_MASSES]. m_1 touches the wall.
    springs : sequence of float
        N - 1 link stiffnesses, finite and > 0 (the linear law's stiffness, the scissor's cap).
    dashpots : sequence of float, optional
        N - 1 dashpot coefficients, finite and >= 0 (default: none).
    k_contact : float
        Linear contact stiffness > 0; ``math.inf`` (default) is the rigid wall.
    v0 : float
        Approach speed in [1e-6, 1e6] (only nonlinear laws depend on it).
    contact : mapping, optional
        Contact law {"law": "rigid" | "linear" | "plastic" | "hertz", ...} (docs/general-chains.md);
        default: rigid for k_contact = inf, else linear with k = k_contact.
    links : sequence of mapping, optional
        One law per link, {"law": "linear"} or {"law": "scissor", "L", "ks", "theta0",
        "corner"}; default: all linear.
    velocities : sequence of float, optional
        N initial velocities, positive towards the wall, in [-1e6, 1e6] (default: every mass at
        v0). m_1 starts touching the wall: velocities[0] > 0 hits it at t = 0, < 0 leaves it (a
        free flight first); 0 is refused. The centre of mass must approach the wall; its
        approach speed becomes ``v0`` (so v0 is not given with velocities).
    stretches : sequence of float, optional
        N - 1 initial link extensions (positive: stretched), in length units (default: 0).
    """

    masses: np.ndarray
    springs: np.ndarray
    dashpots: np.ndarray | None = None
    k_contact: float = math.inf
    v0: float = 1.0
    contact: Mapping | None = None
    links: tuple | None = None
    velocities: np.ndarray | None = None
    stretches: np.ndarray | None = None
    # (alpha, beta, xi) when built by Chain.paper: the paper's kernels are used bit for bit.
    preset: tuple | None = field(default=None, repr=False)

    def __post_init__(self):
        m = _as_array("masses", self.masses)
        if not 2 <= len(m) <= MAX_MASSES:
            raise SceneError(
                f"masses must have between 2 and {MAX_MASSES} entries (N = 1 has no spring; "
                f"larger chains are not supported); got {len(m)}"
            )
        k = _as_array("springs", self.springs, len(m) - 1)
        c = (
            np.zeros(len(m) - 1)
            if self.dashpots is None
            else _as_array("dashpots", self.dashpots, len(m) - 1)
        )
        kc = check("k_contact", self.k_contact)
        v0 = check("v0", self.v0)
        vel, st, v0 = _initial_state(m, k, self.velocities, self.stretches, v0)
        _assign(self, velocities=vel, stretches=st)
        contact, kc = _contact_spec(self.contact, kc, self.k_contact)
        links = _link_specs(self.links, len(m))
        _assign(self, masses=m, springs=k, dashpots=c, k_contact=kc, v0=v0)
        _assign(self, contact=contact, links=links)
        for a in (m, k, c):
            a.setflags(write=False)
        # beta = k_12 / k is checked where the law's k is a stiffness (unit m1 omega**2 in its
        # table); any other k (a Hertz constant) is checked by the law, at m1's depth, in
        # pack_chain below
        stiff = True
        if contact is not None:
            from restitution.model import laws  # (already imported by _law)

            stiff = laws.CONTACT_LAWS[contact["law"]][2].get("k") == (1, 2)
        _check_ratios(m, k, c, kc if stiff else math.inf)
        self._pack_laws()

    def _pack_laws(self) -> None:
        """The laws' own parameter checks (restitution.model.laws), before any work; the pack
        is kept for the runners."""
        if self.contact is None and self.links is None:
            return
        from restitution.model.laws import pack_checked

        # A Kelvin-Voigt contact on linear links is solved exactly (piecewise linear): the
        # numerical methods' ranges apply only when one is asked for (numerical.packed).
        exact_kv = self.kelvin_voigt
        speed = self.law_speed
        packed = pack_checked(
            self.masses,
            self.springs,
            self.dashpots,
            self.contact_law,
            self.link_laws,
            speed,
            numerical=not exact_kv,
        )
        # kept for the runners: (speed, pack, whether the numerical ranges were checked)
        object.__setattr__(self, "_packed", (speed, packed, not exact_kv))

    @classmethod
    def _with_laws(cls, base: Chain, v0, contact, links) -> Chain:
        """``base``, a checked linear chain from the uniform approach (``Chain.paper``), with an
        approach speed and laws: only those are checked (``paper_with_laws``: a Chain built
        again re-checked its arrays and ratios, a third of a nonlinear solve's set-up). The
        contact law's k is base's k_contact (so its ratios stand)."""
        contact, kc = _contact_spec(contact, base.k_contact, base.k_contact)
        self = object.__new__(cls)
        _assign(self, masses=base.masses, springs=base.springs, dashpots=base.dashpots)
        _assign(self, k_contact=kc, v0=check("v0", v0), velocities=None, stretches=None)
        _assign(self, contact=contact, links=_link_specs(links, base.n_masses), preset=None)
        self._pack_laws()
        return self

    # ------------------------------------------------------------------------------------------
    @classmethod
    def paper(cls, alpha: float, beta: float = 0.0, xi: float = 0.0, n_masses: int = 2) -> Chain:
        """The paper's scene: m = [1, alpha, ..., alpha], springs alpha/(1 + alpha), a dashpot
        2 xi k on the first link, k_contact = k/beta (beta = 0: rigid wall). omega = 1."""
        alpha = check("alpha", alpha)
        beta = check("beta", beta)
        xi = check("xi", xi)
        n = check("n_masses", n_masses)
        return cls._paper(alpha, beta, xi, n)

    @classmethod
    def _paper(cls, alpha: float, beta: float, xi: float, n: int) -> Chain:
        """Chain.paper for values already checked (no second validation)."""
        self = object.__new__(cls)
        k = alpha / (1.0 + alpha)
        m = np.full(n, alpha)
        m[0] = 1.0
        ks = np.full(n - 1, k)
        c = np.zeros(n - 1)
        c[0] = 2.0 * xi * k
        for a in (m, ks, c):
            a.setflags(write=False)
        kc = math.inf if beta == 0.0 else float(k) / float(beta)  # (inf past 1e308, no warning)
        _assign(self, masses=m, springs=ks, dashpots=c, k_contact=kc, v0=1.0)
        _assign(self, contact=None, links=None, preset=(alpha, beta, xi))
        return self

    @classmethod
    def _checked(cls, m: np.ndarray, k: np.ndarray, c: np.ndarray, kc: float, v0: float) -> Chain:
        """A linear chain of float64 arrays already checked (restitution.tables.linear_rows reads
        whole
        tables column-wise): no second validation."""
        self = object.__new__(cls)
        for a in (m, k, c):
            a.setflags(write=False)
        _assign(self, masses=m, springs=k, dashpots=c, k_contact=kc, v0=v0)
        _assign(self, contact=None, links=None, preset=None)
        return self

    # ------------------------------------------------------------------------------------------
    @property
    def n_masses(self) -> int:
        return len(self.masses)

    @property
    def omega(self) -> float:
        """omega = sqrt(k_12/m_1 + k_12/m_2), the unit of frequency (1 for the paper's scenes)."""
        if self.preset is not None:
            return 1.0
        k, m = self.springs[0], self.masses
        return math.sqrt(k / m[0] + k / m[1])

    @property
    def alpha(self) -> float:
        return self.preset[0] if self.preset else float(self.masses[1] / self.masses[0])

    @property
    def beta(self) -> float:
        """k_12 / k_contact (0 for the rigid wall); the one place that decides 'rigid'."""
        if self.preset is not None:
            return self.preset[1]
        return 0.0 if self.rigid else float(self.springs[0] / self.k_contact)

    @property
    def xi(self) -> float:
        if self.preset is not None:
            return self.preset[2]
        return float(self.dashpots[0] * self.omega / (2.0 * self.springs[0]))

    @property
    def initial(self) -> bool:
        """True when the scene starts from a given initial state (velocities, stretches)."""
        return self.velocities is not None or self.stretches is not None

    @property
    def law_speed(self) -> float:
        """The speed the contact and link laws are scaled with (laws.pack_chain's v0): v0 for
        the uniform approach; from a given state sqrt(2 E0 / M), the uniform approach with the
        same energy E0 (kinetic + springs[i] stretches[i]**2 / 2), so that the laws' depth
        scales cover the energy the contact may have to take. (Scaled by the centre of mass's
        speed instead, the plastic law's loading curve, fitted to absorb M v0**2 / 2, crossed its
        unloading line where m2 brought more: its contacts created energy.)"""
        if not self.initial:
            return self.v0
        m, k = self.masses, self.springs
        vel = np.full(len(m), self.v0) if self.velocities is None else self.velocities
        st = np.zeros(len(k)) if self.stretches is None else self.stretches
        e0 = 0.5 * float(np.dot(m, vel * vel)) + 0.5 * float(np.dot(k, st * st))
        return math.sqrt(2.0 * e0 / float(m.sum()))

    def initial_state(self, length_unit: float, speed_unit: float) -> np.ndarray | None:
        """The initial state [u_1..u_N, v_1..v_N] in ``length_unit`` and ``speed_unit``, the
        kernels' sign convention (u away from the wall, v = -velocities; u_1 = 0,
        u_{i+1} - u_i = stretches[i]); None for the uniform approach."""
        if not self.initial:
            return None
        n = self.n_masses
        y0 = np.zeros(2 * n)
        if self.stretches is not None:
            y0[1:n] = np.cumsum(self.stretches) / length_unit
        vel = np.full(n, self.v0) if self.velocities is None else self.velocities
        y0[n:] = -vel / speed_unit
        return y0

    @property
    def rigid(self) -> bool:
        """A rigid wall (k_contact = inf): contacts are instants with an impulse."""
        return self.k_contact == math.inf and self.contact is None

    @property
    def linear(self) -> bool:
        """Linear contact (rigid or a spring) and linear links: the exact methods apply."""
        return self.contact is None and self.links is None

    @property
    def kelvin_voigt(self) -> bool:
        """A Kelvin-Voigt contact on linear links: piecewise linear, solved exactly
        (``solvers.exact.kv_row``)."""
        return (
            self.links is None
            and self.contact is not None
            and self.contact["law"] == "kelvin_voigt"
        )

    @property
    def paper_form(self) -> tuple | None:
        """(alpha, beta, xi, n_masses) if the chain is one of the paper's scenes up to units
        (equal masses m_2..m_N, equal springs, a dashpot on the first link only), else None."""
        if self.preset is not None:
            return (*self.preset, self.n_masses)
        if self.initial:  # (the paper's kernels start from the uniform approach only)
            return None
        m, k, c = self.masses, self.springs, self.dashpots
        if (m[1:] == m[1]).all() and (k == k[0]).all() and not c[1:].any():
            return (self.alpha, self.beta, self.xi, self.n_masses)
        return None

    def scaled(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """(m, k, c, kc) in the kernels' units m_1 = 1, omega = 1 (module docstring)."""
        if self.preset is not None:
            return self.masses, self.springs, self.dashpots, self.k_contact
        m1 = float(self.masses[0])
        return kernel_params(
            self.masses, self.springs, self.dashpots, self.k_contact, m1, self.omega
        )

    @property
    def contact_law(self) -> dict:
        """The contact law as a specification mapping (rigid and linear included)."""
        if self.contact is not None:
            return dict(self.contact)
        return {"law": "rigid"} if self.rigid else {"law": "linear", "k": self.k_contact}

    @property
    def link_laws(self) -> list[dict]:
        return (
            [{"law": "linear"}] * (self.n_masses - 1)
            if self.links is None
            else [dict(s) for s in self.links]
        )

    def to_dict(self) -> dict:
        """The scene's parameters, JSON-ready (inf k_contact stays a float)."""
        return {
            "masses": self.masses.tolist(),
            "springs": self.springs.tolist(),
            "dashpots": self.dashpots.tolist(),
            "k_contact": self.k_contact,
            "v0": self.v0,
            "contact": self.contact_law,
            "links": self.link_laws,
            "omega": self.omega,
            **(
                {
                    "velocities": None if self.velocities is None else self.velocities.tolist(),
                    "stretches": None if self.stretches is None else self.stretches.tolist(),
                }
                if self.initial
                else {}
            ),
        }


def make_chain(
    masses=None,
    springs=None,
    dashpots=None,
    k_contact=math.inf,
    v0=1.0,
    contact=None,
    links=None,
    velocities=None,
    stretches=None,
) -> Chain:
    """``Chain`` from keywords, with a clear error when the required lists are missing."""
    if masses is None or springs is None:
        raise SceneError(
            "a general chain needs masses=[m1, ..., mN] and springs=[k12, ..., k(N-1)N] "
            "(or use the paper's form alpha=..., beta=..., xi=..., n_masses=...)"
        )
    return Chain(masses, springs, dashpots, k_contact, v0, contact, links, velocities, stretches)


LAW_KEYS = ("contact", "eta", "dr", "structure", "L", "ks_ratio", "theta0", "corner", "v0")
NUMERICAL_KEYS = (*LAW_KEYS, "rtol", "step")
# The paper form's law parameters and the law that reads them (given without it: an error).
LAW_PARAMS = {"plastic": ("eta", "dr"), "scissor": ("L", "ks_ratio", "theta0", "corner")}
PAPER_CONTACTS = ("linear", "plastic")  # the paper form's contact laws (Section 3.1)
PAPER_STRUCTURES = ("linear", "scissor")  # and structural links (Section 3.2)


# What ``restitution.solve`` takes, for the message of an unknown keyword.
SOLVE_KEYWORDS = (
    "alpha, beta, xi, n_masses, method, history, max_events, masses, springs, dashpots, "
    f"k_contact, links, {', '.join(NUMERICAL_KEYS)}"
)


def paper_with_laws(
    alpha, beta, xi, n_masses, law: dict, allowed: str = SOLVE_KEYWORDS
) -> tuple[Chain, dict]:
    """A paper-form scene with the law keywords of ``restitution.solve`` (contact, eta, dr,
    structure, L, ks_ratio, theta0, corner, v0) as a Chain with law specifications, and the
    numerical settings (rtol, step) among them. ``allowed``: the caller's keywords, listed
    when one in ``law`` is unknown."""
    unknown = sorted(set(law) - set(NUMERICAL_KEYS))
    if unknown:
        raise SceneError(f"unknown scene parameter(s) {', '.join(unknown)}; allowed: {allowed}")
    for k, v in law.items():  # (a table passes only its given cells: a missing one is an error)
        if missing_cell(v):
            allowed = RANGES[k].text if k in RANGES else "a law name"
            raise SceneError(
                f"{k} must be {allowed}; got {_show(v)} (leave it out for the default)"
            )
    paper = Chain.paper(alpha, beta, xi, n_masses)
    settings = {k: law[k] for k in ("rtol", "step") if k in law}
    contact = law.get("contact", "linear")
    structure = law.get("structure", "linear")
    for key, value, allowed in (
        ("contact", contact, PAPER_CONTACTS),
        ("structure", structure, PAPER_STRUCTURES),
    ):
        if not isinstance(value, str) or value not in allowed:
            raise SceneError(
                f"{key} must be one of {', '.join(map(repr, allowed))} in the paper's form "
                f"(other laws: the general form, contact={{...}}, links=[...]); got {_show(value)}"
            )
    for key, names, needs, given in (
        ("contact", LAW_PARAMS["plastic"], "plastic", contact),
        ("structure", LAW_PARAMS["scissor"], "scissor", structure),
    ):
        stray = [k for k in names if k in law]
        if stray and given != needs:
            raise SceneError(
                f"{', '.join(stray)}: parameter(s) of the {needs!r} {key} law, which this scene "
                f"does not use ({key}={given!r}); give {key}={needs!r} or leave them out"
            )
    if contact == "linear" and structure == "linear":
        if "v0" not in law:
            return paper, settings
        return replace_v0(paper, law["v0"]), settings
    k = float(paper.springs[0])
    spec_c = None
    if contact != "linear":
        if paper.rigid:
            raise SceneError(
                f"contact={contact!r} needs beta > 0 (its unloading slope is k1 = k2/beta); "
                "got beta=0"
            )
        spec_c = {"law": contact, "k": paper.k_contact, "eta": law.get("eta", 1.0)}
        spec_c["dr"] = law.get("dr", 0.0)
    links = None
    if structure != "linear":
        from restitution.model.laws import CORNER_DEFAULT, THETA0_DEFAULT

        links = [
            {
                "law": structure,
                "L": law.get("L", 1.0),
                "ks": _ks_ratio(law.get("ks_ratio", 0.01)) * k,
                "theta0": law.get("theta0", THETA0_DEFAULT),
                "corner": law.get("corner", CORNER_DEFAULT),
            }
        ] * (paper.n_masses - 1)
    try:
        return Chain._with_laws(paper, law.get("v0", 1.0), spec_c, links), settings
    except SceneError as e:  # the paper form names its keywords, not the law's place in a chain
        raise SceneError(_PLACE.sub("", str(e))) from None


# "contact: ", "contact.", "links[0]: ", "links[0]." at the start of a law's message
_PLACE = re.compile(r"^(?:contact|links\[\d+\])(?::\s|\.)")


def _ks_ratio(value) -> float:
    """The paper form's ks_ratio as a number (its range, below tan(theta0)**2, is checked with
    the scissor law by restitution.model.laws)."""
    x = _real(value)
    if x is None or not RANGES["ks_ratio"].contains(x) or not math.isfinite(x):
        raise SceneError(f"ks_ratio must be {RANGES['ks_ratio'].text}; got {_show(value)}")
    return x


def replace_v0(ch: Chain, v0) -> Chain:
    """The same chain approaching at v0 (checked)."""
    new = object.__new__(Chain)
    new.__dict__.update(ch.__dict__)
    object.__setattr__(new, "v0", check("v0", v0))
    return new


__all__ = [
    "LAW_KEYS",
    "paper_with_laws",
    "MAX_MASSES",
    "RANGES",
    "Range",
    "Chain",
    "SceneError",
    "check",
    "check_column",
    "make_chain",
]
