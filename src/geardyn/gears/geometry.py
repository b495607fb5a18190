"""Involute spur-pair geometry of internal and external pairs (paper 1, Sec. 3.2) in mm and rad: gear 1 the planet
or pinion, gear 2 the annulus (Chinese sign convention) or wheel, shifts broadcasting arrays (docs/geometry.md)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geardyn import libm

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class GearPair:
    """A spur pair with profile shift: teeth z1, z2, module (mm), shifts x1, x2 (annulus: Chinese
    convention), pressure angle (deg), ha*, c*, internal or external, facewidth (mm, for the stiffness)
    and external tip shortening (docs/geometry.md, "The pair")."""

    z1: int
    z2: int
    module: float
    x1: float
    x2: float
    pressure_angle_deg: float = 20.0
    addendum: float = 1.0
    clearance: float = 0.25
    internal: bool = True
    facewidth: float = 20.0
    tip_shortening: bool = True

    def __post_init__(self) -> None:
        if int(self.z1) != self.z1 or int(self.z2) != self.z2 or self.z1 < 1 or self.z2 < 1:
            raise ValueError(f"tooth counts must be positive integers, got z1={self.z1}, z2={self.z2}")
        if self.internal and self.z2 - self.z1 < 1:
            raise ValueError(f"internal pair needs z2 - z1 >= 1, got z1={self.z1}, z2={self.z2}")
        if not self.module > 0:
            raise ValueError(f"module must be > 0 mm, got {self.module}")
        if not 0.0 < self.pressure_angle_deg < 45.0:
            raise ValueError(f"pressure angle must be in (0, 45) deg, got {self.pressure_angle_deg}")

    @property
    def alpha(self) -> float:
        """Reference pressure angle a in rad."""
        return math.radians(self.pressure_angle_deg)

    @property
    def sigma(self) -> int:
        """+1 for an external pair, -1 for an internal pair."""
        return -1 if self.internal else 1

    @property
    def names(self) -> tuple[str, str]:
        """Role names used in constraint keys: (planet, annulus) or (pinion, wheel)."""
        return ("planet", "annulus") if self.internal else ("pinion", "wheel")


@dataclass(frozen=True)
class ShaperCutter:
    """Pinion-type shaper cutter that generates the annulus: teeth z0, shift x0 (ordinary convention),
    addendum ha0* (None: ha* + c* of the pair, the standard root depth)."""

    teeth: int
    shift: float = 0.0
    addendum: float | None = None


def involute(alpha: ArrayLike) -> FloatArray:
    """inv a = tan a - a (a in rad)."""
    a = np.asarray(alpha, dtype=float)
    return libm.tan(a) - a


def inverse_involute(value: ArrayLike, *, tol: float = 1e-15, max_iter: int = 60) -> FloatArray:
    """Angle a in (-pi/2, pi/2) with inv a = value, vectorised: monotone Newton from an upper bound, each value stopping
    on its own step, so an array gives the bits of each value alone (docs/geometry.md, "Inverse involute")."""
    if np.ndim(value) == 0:
        return np.float64(_inverse_involute_scalar(float(value), tol, max_iter))  # type: ignore[arg-type,return-value]
    v = np.asarray(value, dtype=float)
    y = np.abs(v)
    a = np.minimum(libm.cbrt(3.0 * y), libm.arctan(y + np.pi / 2)).ravel()
    yf = y.ravel()
    todo = np.flatnonzero(~np.isnan(yf))  # NaN stays NaN
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(max_iter):
            if todo.size == 0:
                break
            at, yt = a[todo], yf[todo]
            t = libm.tan(at)
            step = np.where(at > 0, (t - at - yt) / (t * t), 0.0)
            at = at - step
            a[todo] = at
            todo = todo[~((np.abs(step) <= tol * np.maximum(at, 1e-300)) | ~np.isfinite(step))]
    return np.sign(v) * a.reshape(v.shape)


def _inverse_involute_scalar(v: float, tol: float, max_iter: int) -> float:
    """:func:`inverse_involute` of one value, step for step as the array path does for each of its values."""
    if math.isnan(v):
        return math.nan
    y = abs(v)
    a = math.cbrt(3.0 * y)
    b = math.atan(y + np.pi / 2)
    a = b if b < a else a  # np.minimum (no NaN here)
    for _ in range(max_iter):
        t = math.tan(a)
        step = (t - a - y) / (t * t) if a > 0 else 0.0
        a = a - step
        if abs(step) <= tol * max(a, 1e-300) or not math.isfinite(step):
            break
    return math.copysign(1.0, v) * a if v != 0.0 else 0.0 * a


def with_shifts(base: GearPair, x1: ArrayLike, x2: ArrayLike) -> GearPair:
    """Copy of ``base`` whose shifts are arrays (broadcast by numpy) for vectorised evaluation."""
    return dataclasses.replace(base, x1=np.asarray(x1, dtype=float), x2=np.asarray(x2, dtype=float))  # type: ignore[arg-type]


def shifts(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """(x1, x2) of ``pair`` as float arrays."""
    return np.asarray(pair.x1, dtype=float), np.asarray(pair.x2, dtype=float)


# --- Centre distance and pressure angle ---


def reference_centre_distance(pair: GearPair) -> float:
    """a = m (z2 + z1) / 2 (external) or m (z2 - z1) / 2 (internal), mm (paper 1: 3.5 x 3 / 2 = 5.25 mm)."""
    return pair.module * (pair.z2 + pair.sigma * pair.z1) / 2.0


def working_pressure_angle(pair: GearPair) -> FloatArray:
    """Working pressure angle a' in rad from the no-backlash condition (docs/geometry.md, "Formulas");
    NaN where inv a' <= 0: no positive working angle exists and the teeth cannot mesh."""
    inv_w = working_involute(pair)
    return np.where(inv_w > 0.0, inverse_involute(np.maximum(inv_w, 0.0)), np.nan)


def working_involute(pair: GearPair) -> FloatArray:
    """inv a' of the no-backlash condition (docs/geometry.md, "Formulas"); <= 0 where the teeth cannot mesh."""
    x1, x2 = shifts(pair)
    s = pair.sigma
    return 2.0 * (x2 + s * x1) * math.tan(pair.alpha) / (pair.z2 + s * pair.z1) + involute(pair.alpha)


def working_centre_distance(pair: GearPair) -> FloatArray:
    """a' = a cos a / cos a' in mm."""
    return reference_centre_distance(pair) * math.cos(pair.alpha) / np.cos(working_pressure_angle(pair))


def centre_distance_modification(pair: GearPair) -> FloatArray:
    """Centre-distance modification coefficient y = (a' - a) / m (-)."""
    return (working_centre_distance(pair) - reference_centre_distance(pair)) / pair.module


# --- Diameters ---


def pitch_diameters(pair: GearPair) -> tuple[float, float]:
    """Reference diameters d = z m, mm."""
    return pair.z1 * pair.module, pair.z2 * pair.module


def base_diameters(pair: GearPair) -> tuple[float, float]:
    """Base diameters db = d cos a, mm."""
    d1, d2 = pitch_diameters(pair)
    c = math.cos(pair.alpha)
    return d1 * c, d2 * c


def tip_diameters(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Tip diameters (da1, da2) in mm; external tips shortened by dy m when ``tip_shortening``
    (docs/geometry.md, "Formulas")."""
    x1, x2 = shifts(pair)
    d1, d2 = pitch_diameters(pair)
    m, ha = pair.module, pair.addendum
    external = not pair.internal and pair.tip_shortening  # tip shortening dy = x1 + x2 - y, 0 for internal pairs
    dy = x1 + x2 - centre_distance_modification(pair) if external else np.zeros(np.broadcast(x1, x2).shape)
    da1 = d1 + 2.0 * (ha + x1 - dy) * m
    da2 = d2 - 2.0 * (ha - x2) * m if pair.internal else d2 + 2.0 * (ha + x2 - dy) * m
    return da1, da2


def root_diameters(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Root diameters (df1, df2) in mm, rack-equivalent generation (docs/geometry.md, "Formulas"; reported
    only, no constraint uses them)."""
    x1, x2 = shifts(pair)
    d1, d2 = pitch_diameters(pair)
    m, h = pair.module, pair.addendum + pair.clearance
    df1 = d1 - 2.0 * (h - x1) * m
    df2 = d2 + 2.0 * (h + x2) * m if pair.internal else d2 - 2.0 * (h - x2) * m
    return df1, df2


def pressure_angle_at(db: float, da: ArrayLike) -> FloatArray:
    """arccos(db / da); NaN where the circle lies inside the base circle."""
    with np.errstate(invalid="ignore", divide="ignore"):
        r = db / np.asarray(da, dtype=float)
        return np.where(r <= 1.0, libm.arccos(np.minimum(r, 1.0)), np.nan)


def tip_pressure_angles(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Pressure angles at the tip circles, aa = arccos(db / da), rad (NaN if da < db)."""
    db1, db2 = base_diameters(pair)
    da1, da2 = tip_diameters(pair)
    return pressure_angle_at(db1, da1), pressure_angle_at(db2, da2)
