"""The KHV torsional model of paper 1 (Li et al. 2013, Eqs. 1-6 and 11-16), corrected (docs/model.md): everything
dimensionless made by one function, :func:`dimensionless`, and held in the frozen :class:`Coefficients`."""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any, Literal

import numpy as np

from geardyn.gears.stiffness import ParabolicStiffness
from geardyn.solve import base as layout

#: Paper 1 Eq. (13): displacement scale b_c = 1 um.
B_C = 1.0e-6

StiffnessForm = Literal["corrected", "printed"]
FrequencyMode = Literal["physical", "dimensionless"]
StiffnessMode = Literal["time_varying", "mean"]


@dataclass(frozen=True)
class KHVParameters:
    """Physical parameters of the KHV drive (SI units; docs/model.md, "Parameters"): every field required, a
    design states them and a paper's values live in :mod:`geardyn.papers`."""

    eps: float
    k_c: float
    r_bV: float = field(metadata={"units": "m"})
    r_bH: float = field(metadata={"units": "m"})
    I_D: float = field(metadata={"units": "kg m2"})
    I_H: float = field(metadata={"units": "kg m2"})
    I_V: float = field(metadata={"units": "kg m2"})
    I_L: float = field(metadata={"units": "kg m2"})
    m_V: float = field(metadata={"units": "kg"})
    K_DH: float = field(metadata={"units": "N m rad-1"})
    K_VL: float = field(metadata={"units": "N m rad-1"})
    zeta: float = field(metadata={"units": "1"})
    eta: float = field(metadata={"units": "1"})
    T_D: float = field(metadata={"units": "N m"})
    T_L: float = field(metadata={"units": "N m"})
    backlash: float = field(metadata={"units": "m"})
    te_amplitude: float = field(metadata={"units": "m"})
    te_phase: float = field(metadata={"units": "rad"})
    z_annulus: int = field(metadata={"units": "1"})
    input_speed_rpm: float = field(metadata={"units": "rpm"})
    omega_bar: float = field(metadata={"units": "1"})
    pressure_angle_deg: float  # of the pair; enters M_H through a = r_bH / cos(alpha)

    def stiffness(self, form: StiffnessForm = "corrected") -> ParabolicStiffness:
        """Parabolic k(t) of Eq. (9) with k' = k_C / 1.5 (Sec. 3.3)."""
        return ParabolicStiffness(self.eps, self.k_c / 1.5, form)


@dataclass(frozen=True)
class Options:
    """Model variants (all switches that change the equations, not the numbers)."""

    stiffness_form: StiffnessForm = "corrected"
    frequency_mode: FrequencyMode = "dimensionless"
    stiffness_mode: StiffnessMode = "time_varying"
    backlash: bool = True
    transmission_error: bool = True

    def __post_init__(self) -> None:
        for name, allowed in (
            ("stiffness_form", ("corrected", "printed")),
            ("frequency_mode", ("physical", "dimensionless")),
            ("stiffness_mode", ("time_varying", "mean")),
        ):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name}={getattr(self, name)!r}; allowed: {allowed}")


# Any: as dataclasses.field, the field's default (any type) and its other arguments pass through.
def _stored(units: str, long_name: str, **kw: Any) -> Any:
    """A :class:`Coefficients` field stored per point in sweep cubes, with its units and long name."""
    return field(metadata={"cf": (units, long_name)}, **kw)


@dataclass(frozen=True)
class Coefficients:
    """Every dimensionless number of the model (paper 1 Eq. 13, corrected; docs/model.md, section 3);
    hashable and storable."""

    mu_D: float = _stored("1", "drive mass M_D / M_VH")
    mu_H: float = _stored("1", "carrier mass M_H / M_VH")
    mu_V: float = _stored("1", "planet mass M_V / M_VH")
    mu_L: float = _stored("1", "load mass M_L / M_VH")
    k_DH: float = _stored("1", "input shaft stiffness / k_mean")
    k_VL: float = _stored("1", "output shaft stiffness / k_mean")
    c_DH: float = _stored("1", "input shaft damping / (M_VH w_n)")
    c_VL: float = _stored("1", "output shaft damping / (M_VH w_n)")
    c_m: float = _stored("1", "mesh damping / (M_VH w_n)")
    P_D: float = _stored("1", "drive force / (k_mean b_c)")
    P_L: float = _stored("1", "load force / (k_mean b_c)")
    b: float = _stored("1", "half backlash / b_c")
    e: float = _stored("1", "TE amplitude / b_c")
    phi: float = _stored("rad", "TE phase")
    omega: float = _stored("1", "mesh frequency w_m / w_n")
    eps: float = _stored("1", "contact ratio")
    stiffness_form: str = "corrected"
    stiffness_mode: str = "time_varying"
    backlash_on: bool = True
    # provenance (not used by the equations): w_n in rad/s and k_mean in N/m
    omega_n: float = _stored("rad s-1", "natural-frequency scale w_n", default=float("nan"))
    k_mean: float = _stored("N m-1", "mean mesh stiffness", default=float("nan"))

    # --- storage -------------------------------------------------------------------------
    def as_dict(self) -> dict[str, float | str | int]:
        """Plain dict (bools as int) fit for netCDF attributes."""
        d = asdict(self)
        d["backlash_on"] = int(self.backlash_on)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> Coefficients:
        names = {f.name for f in fields(cls)}
        kw = {k: d[k].item() if isinstance(d[k], np.generic) else d[k] for k in names if k in d}
        kw["backlash_on"] = bool(kw.get("backlash_on", True))
        return cls(**kw)

    def replace(self, **changes) -> Coefficients:
        """A copy with ``changes``.  A copy that changes none of the masses, shaft stiffnesses and loads
        shares this instance's static force balance (:func:`static_deflection`: the same linear solve, so
        the same bits): the rows of a map over b, e or w solve it once per column."""
        new = replace(self, **changes)
        if _BALANCE_FIELDS.isdisjoint(changes):
            new.__dict__["_static_balance"] = self._static_balance
        return new

    # --- derived -------------------------------------------------------------------------
    @property
    def period(self) -> float:
        """Mesh period T = 2 pi / omega in dimensionless time."""
        return 2.0 * math.pi / self.omega

    @property
    def te_forcing(self) -> float:
        """Amplitude of -e''(tau) / b_c in the X_VH equation: e_bar omega^2."""
        return self.e * self.omega**2

    def stiffness_polys(self) -> np.ndarray:
        """kappa(s) on the two zones [0, f] and [f, 1] (f = eps - floor(eps)) as rows (a, b, c): a s^2 + b s + c."""
        return _stiffness_polys(float(self.eps), self.stiffness_form, self.stiffness_mode).copy()

    def kappa(self, s: np.ndarray) -> np.ndarray:
        """Normalised mesh stiffness at mesh phase s (periods), right-continuous at the jumps."""
        s = np.mod(np.asarray(s, dtype=float), 1.0)
        p = self.stiffness_polys()
        return np.where(s < self.eps - math.floor(self.eps), np.polyval(p[0], s), np.polyval(p[1], s))

    def matrices(self) -> dict[str, np.ndarray | float]:
        """The 3-DOF dimensionless system (Eq. 16, docs/model.md section 3): K, C (3x3, shafts only), g (mesh
        coupling), p (constant loads) and ``te`` (the TE forcing amplitude of the second row)."""
        mu_DH, mu_VL = self.mu_D * self.mu_H / (self.mu_D + self.mu_H), self.mu_V * self.mu_L / (self.mu_V + self.mu_L)

        def shafts(dh: float, vl: float) -> np.ndarray:
            """The shaft terms (stiffness or damping) of the input (dh) and output (vl) shafts."""
            t11, t21, t23, t33 = _shaft_terms(dh, vl, self.mu_H, self.mu_V, mu_DH, mu_VL)
            return np.array([[t11, 0.0, 0.0], [t21, 0.0, t23], [0.0, 0.0, t33]])

        return {
            "K": shafts(self.k_DH, self.k_VL),
            "C": shafts(self.c_DH, self.c_VL),
            "g": np.array([1.0 / self.mu_H, 1.0, 1.0 / self.mu_V]),
            "p": np.array([self.P_D / self.mu_D, 0.0, self.P_L / self.mu_L]),
            "te": self.te_forcing,
        }

    def kernel_array(self) -> np.ndarray:
        """Flat float64 array read by the solver, in the named order of :data:`geardyn.solve.base.LAYOUT`
        (computed once per instance: the labeller and the response measures both read it; a copy)."""
        return self._kernel_array.copy()

    def static_state(self) -> np.ndarray:
        """The static deflection at rest (:func:`static_deflection`): the solver's default start (computed
        once per instance, like :meth:`kernel_array`; a copy)."""
        return self._static_state.copy()

    @functools.cached_property
    def _static_state(self) -> np.ndarray:
        return static_deflection(self)

    @functools.cached_property
    def _static_balance(self) -> tuple[float, float, float]:
        """(x1, x3, F) of :func:`static_deflection`, a function of :data:`_BALANCE_FIELDS` only: solved once
        per distinct value of them (a continuation in b, e or w meets one, each step a new instance)."""
        key = tuple(getattr(self, f) for f in _BALANCE_ORDER)
        found = _BALANCES.get(key)
        if found is None:
            m = self.matrices()
            K, g, p = (np.asarray(m[k]) for k in "Kgp")
            A = np.array([[K[0, 0], 0.0, g[0]], [K[1, 0], K[1, 2], g[1]], [0.0, K[2, 2], g[2]]])
            x1, x3, F = np.linalg.solve(A, p)
            found = float(x1), float(x3), float(F)
            if len(_BALANCES) >= 1024:
                _BALANCES.clear()
            _BALANCES[key] = found
        return found

    @functools.cached_property
    def _kernel_array(self) -> np.ndarray:
        # the entries of matrices() by the same operations (the same bits), at their places in LAYOUT
        mu_DH, mu_VL = self.mu_D * self.mu_H / (self.mu_D + self.mu_H), self.mu_V * self.mu_L / (self.mu_V + self.mu_L)
        mu_H, mu_V, at = self.mu_H, self.mu_V, layout
        a = np.empty(len(at.LAYOUT))
        a[[at.K11, at.K21, at.K23, at.K33]] = _shaft_terms(self.k_DH, self.k_VL, mu_H, mu_V, mu_DH, mu_VL)
        a[[at.C11, at.C21, at.C23, at.C33]] = _shaft_terms(self.c_DH, self.c_VL, mu_H, mu_V, mu_DH, mu_VL)
        a[[at.G1, at.G3, at.P1, at.P3]] = 1.0 / mu_H, 1.0 / mu_V, self.P_D / self.mu_D, self.P_L / self.mu_L
        a[[at.CM, at.B, at.TE, at.PHI, at.T]] = self.c_m, self.b, self.te_forcing, self.phi, self.period
        a[[at.BACKLASH_ON, at.EPS]] = 1.0 if self.backlash_on else 0.0, self.eps
        return a


def _shaft_terms(dh: float, vl: float, mu_H: float, mu_V: float, mu_DH: float, mu_VL: float) -> tuple[float, ...]:
    """The non-zero shaft terms of :meth:`Coefficients.matrices` (K or C): entries 11, 21, 23 and 33."""
    return dh / mu_DH, dh / mu_H, vl / mu_V, vl / mu_VL


#: Units and long names of the :class:`Coefficients` fields stored per point in sweep cubes.
COEFFICIENT_ATTRS = {f.name: f.metadata["cf"] for f in fields(Coefficients) if "cf" in f.metadata}


def physical_masses(params: KHVParameters) -> dict[str, float]:
    """Equivalent masses of Eq. (2) in kg (M_H includes the planet's translation on the crank)."""
    M_D = params.I_D / params.r_bH**2
    cos_a = math.cos(math.radians(params.pressure_angle_deg))
    M_H = (params.I_H + params.m_V * params.r_bH**2 / cos_a**2) / params.r_bH**2
    M_V, M_L = params.I_V / params.r_bV**2, params.I_L / params.r_bV**2
    return {"M_D": M_D, "M_H": M_H, "M_V": M_V, "M_L": M_L, "M_VH": M_V * M_H / (M_V + M_H)}


def dimensionless(params: KHVParameters, options: Options = Options()) -> Coefficients:
    """All dimensionless coefficients of the corrected Eq. (13)-(16); w_n = sqrt(k_mean / M_VH) with k_mean
    the exact mean of the chosen stiffness form (docs/model.md, section 3)."""
    ms = physical_masses(params)
    M_VH = ms["M_VH"]
    k_mean = params.stiffness(options.stiffness_form).mean()
    w_n = math.sqrt(k_mean / M_VH)
    k_DH, k_VL = params.K_DH / params.r_bH**2, params.K_VL / params.r_bV**2
    M_DH, M_VL = ms["M_D"] * ms["M_H"] / (ms["M_D"] + ms["M_H"]), ms["M_V"] * ms["M_L"] / (ms["M_V"] + ms["M_L"])
    c_m = 2.0 * params.zeta * math.sqrt(k_mean * M_VH)
    c_DH, c_VL = 2.0 * params.eta * math.sqrt(k_DH * M_DH), 2.0 * params.eta * math.sqrt(k_VL * M_VL)
    if options.frequency_mode == "physical":
        omega = params.z_annulus * 2.0 * math.pi * params.input_speed_rpm / 60.0 / w_n  # w_m = z_K 2 pi n / 60
    else:
        omega = params.omega_bar
    fscale = k_mean * B_C
    return Coefficients(
        mu_D=ms["M_D"] / M_VH,
        mu_H=ms["M_H"] / M_VH,
        mu_V=ms["M_V"] / M_VH,
        mu_L=ms["M_L"] / M_VH,
        k_DH=k_DH / k_mean,
        k_VL=k_VL / k_mean,
        c_DH=c_DH / (M_VH * w_n),
        c_VL=c_VL / (M_VH * w_n),
        c_m=c_m / (M_VH * w_n),
        P_D=params.T_D / params.r_bH / fscale,
        P_L=params.T_L / params.r_bV / fscale,
        b=params.backlash / B_C if options.backlash else 0.0,
        e=params.te_amplitude / B_C if options.transmission_error else 0.0,
        phi=params.te_phase,
        omega=omega,
        eps=params.eps,
        stiffness_form=options.stiffness_form,
        stiffness_mode=options.stiffness_mode,
        backlash_on=options.backlash,
        omega_n=w_n,
        k_mean=k_mean,
    )


# --- simple closed forms -----------------------------------------------------------------


def static_deflection(coeffs: Coefficients) -> np.ndarray:
    """Static equilibrium state (6,) with the mean stiffness and no TE, the default initial state: K x + g F = p
    with F = f(x2) (kappa = 1) solved for (x1, x3, F), then x2 = F + b sign(F)."""
    x1, x3, F = coeffs._static_balance
    b = coeffs.b if coeffs.backlash_on else 0.0
    x2 = F + math.copysign(b, F) if F != 0.0 else 0.0
    return np.array([x1, x2, x3, 0.0, 0.0, 0.0])


#: The fields of :class:`Coefficients` that the static force balance reads (the K, g and p of
#: :meth:`Coefficients.matrices`).
_BALANCE_FIELDS = frozenset({"mu_D", "mu_H", "mu_V", "mu_L", "k_DH", "k_VL", "P_D", "P_L"})
_BALANCE_ORDER = tuple(sorted(_BALANCE_FIELDS))
#: (x1, x3, F) of the static force balance per value of :data:`_BALANCE_ORDER` (emptied past 1024 entries)
_BALANCES: dict[tuple, tuple[float, float, float]] = {}


def natural_frequencies(coeffs: Coefficients) -> np.ndarray:
    """Undamped natural frequencies (units of w_n, ascending) of the linearised 3-DOF system in contact
    (kappa = 1, no backlash): square roots of the eigenvalues of K + g e2^T (no rigid-body mode)."""
    m = coeffs.matrices()
    lam = np.linalg.eigvals(m["K"] + np.outer(m["g"], [0.0, 1.0, 0.0]))
    return np.sort(np.sqrt(np.abs(lam.real)))


@functools.lru_cache(maxsize=4096)
def _stiffness_polys(eps: float, form: str, mode: str) -> np.ndarray:
    """:meth:`Coefficients.stiffness_polys`, computed once per (eps, form, mode): a line of a map or sweep
    shares them, and a map's rows share its columns' (read-only; the method returns a copy)."""
    if mode == "mean":
        out = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    else:
        ps = ParabolicStiffness(eps, 1.0, form)  # type: ignore[arg-type]
        m = ps.mean()
        out = np.vstack([np.array(p) / m for p in ps.zone_polys()])
    out.setflags(write=False)
    return out
