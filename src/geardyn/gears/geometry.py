"""Involute spur-pair geometry for internal and external pairs (paper 1, Sec. 3.2; docs/findings.md).

Units: lengths in mm, angles in rad (names ending ``_deg`` are in degrees). Gear 1 is the
pinion (the planet V of paper 1), gear 2 the annulus (internal pair) or the wheel (external pair).

Sign convention
---------------
External pairs use the ordinary convention: positive ``x`` moves the tool away from the gear
centre, thickens the tooth and enlarges the tip circle.

Internal pairs use the Chinese-textbook convention for the annulus (docs/findings.md, "Internal pair
sign convention"): positive ``x2`` enlarges the annulus tip circle and *thins* its tooth::

    da2 = d2 - 2 (ha* - x2) m,      s2 = m (pi/2 - 2 x2 tan a),
    inv a' = 2 (x2 - x1) tan a / (z2 - z1) + inv a.

This equals ISO 21771 with a negative annulus tooth count and ``x2_iso = -x2``.  Internally every
formula is written once with ``sigma = +1`` (external) or ``-1`` (internal): ``z2 -> sigma z2``,
``x2 -> sigma x2``, so the same functions serve both kinds of pair.

Vectorisation
-------------
Every function accepts a :class:`GearPair` whose ``x1``/``x2`` are floats *or* numpy arrays that
broadcast (see :func:`with_shifts`); scalars give numpy scalars.  :func:`constraint_grid`
evaluates all constraints on an (x1, x2) grid at once.

Sources
-------
* Paper 1: Li et al. (2013), Sec. 3.2 and Fig. 3 (closed graph after Zhang 2011, ref. [26]).
* SDP/SI-KHK, "Elements of Metric Gear Technology", Sec. 5.2-5.3, Eqs. (5-6)-(5-10) and
  Table 5-4 (http://www.sdp-si.com/D785/HTML1/D785T043_3.html and ..._4.html).
* Chinese closed-graph criteria (overlap interference G_s, radial/trimming interference, root
  transition-curve interference), as in Zhang (2011) and the Chinese gear handbooks; the
  trimming formula is the same as KHK Eqs. (5-9)/(5-10).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from geardyn import libm

FloatArray = NDArray[np.float64]

__all__ = [
    "GearPair",
    "ShaperCutter",
    "base_diameters",
    "centre_distance_modification",
    "constraint_grid",
    "constraint_info",
    "constraints",
    "contact_ratio",
    "default_cutter",
    "describe",
    "inverse_involute",
    "involute",
    "involute_interference",
    "overlap_interference",
    "pitch_diameters",
    "radial_interference",
    "reference_centre_distance",
    "root_diameters",
    "root_interference",
    "tip_diameters",
    "tip_pressure_angles",
    "tip_thickness",
    "trimming_interference",
    "undercut_margin",
    "violations",
    "with_shifts",
    "working_centre_distance",
    "working_pitch_diameters",
    "working_pressure_angle",
    "x2_on_overlap_boundary",
    "x2_on_overlap_boundary_many",
]


@dataclass(frozen=True)
class GearPair:
    """A spur pair with profile shift.

    Attributes
    ----------
    z1: pinion / planet teeth.
    z2: annulus (``internal=True``) or wheel teeth.
    module: mm.
    x1: pinion / planet profile-shift coefficient (-).
    x2: annulus / wheel profile-shift coefficient (-); for an annulus the Chinese convention
        (positive enlarges the annulus tip circle and thins its tooth).
    pressure_angle_deg: reference (tool) pressure angle, degrees.
    addendum: addendum coefficient ha* (-).
    clearance: bottom clearance coefficient c* (-).
    internal: True for a planet-annulus pair.
    facewidth: mm (carried for the stiffness model; not used by the geometry).
    tip_shortening: external pairs only.  True (default) shortens both tips by
        ``(x1 + x2 - y) m`` so that the standard bottom clearance c* m is kept at the working
        centre distance (KHK/SDP-SI profile-shifted spur example and Chinese practice,
        ``da = d + 2 (ha* + x - dy) m``).  False keeps ``da = d + 2 (ha* + x) m``.
        Internal pairs are never shortened (docs/findings.md, "Working angle, centre distance, tip
        diameters, contact ratio").
    """

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
    """Pinion-type shaper cutter that generates the annulus (internal pairs).

    ``teeth`` z0, ``shift`` x0 (ordinary convention), ``addendum`` ha0* (None: ha* + c* of the
    pair, i.e. the cutter cuts the standard root depth).
    """

    teeth: int
    shift: float = 0.0
    addendum: float | None = None


def involute(alpha: ArrayLike) -> FloatArray:
    """inv a = tan a - a (a in rad)."""
    a = np.asarray(alpha, dtype=float)
    return cast(FloatArray, libm.tan(a) - a)


def inverse_involute(value: ArrayLike, *, tol: float = 1e-15, max_iter: int = 60) -> FloatArray:
    """Angle a in (-pi/2, pi/2) with inv a = value, vectorised.

    Newton's method on the convex increasing f(a) = tan a - a - v, started at an upper bound
    of the root, converges monotonically: tan a - a >= a^3 / 3 gives a* <= (3 v)^(1/3), and
    tan(atan(v + pi/2)) - atan(v + pi/2) >= v gives a* <= atan(v + pi/2).  inv is odd, so
    negative values map to negative angles.
    """
    v = np.asarray(value, dtype=float)
    s = np.sign(v)
    y = np.abs(v)
    a = np.minimum(libm.cbrt(3.0 * y), libm.arctan(y + np.pi / 2))
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(max_iter):
            t = libm.tan(a)
            step = np.where(a > 0, (t - a - y) / (t * t), 0.0)
            a = a - step
            if np.all(np.abs(step) <= tol * np.maximum(a, 1e-300)) or np.all(~np.isfinite(step)):
                break
    return cast(FloatArray, s * a)


def with_shifts(base: GearPair, x1: ArrayLike, x2: ArrayLike) -> GearPair:
    """Copy of ``base`` whose shifts are arrays (broadcast by numpy) for vectorised evaluation."""
    return dataclasses.replace(
        base, x1=cast(float, np.asarray(x1, dtype=float)), x2=cast(float, np.asarray(x2, dtype=float))
    )


def _x(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    return np.asarray(pair.x1, dtype=float), np.asarray(pair.x2, dtype=float)


# --------------------------------------------------------------------------------------------
# Centre distance and pressure angle
# --------------------------------------------------------------------------------------------


def reference_centre_distance(pair: GearPair) -> float:
    """a = m (z2 + z1) / 2 (external) or m (z2 - z1) / 2 (internal), mm (paper 1: 3.5 x 3 / 2 = 5.25 mm)."""
    return pair.module * (pair.z2 + pair.sigma * pair.z1) / 2.0


def working_pressure_angle(pair: GearPair) -> FloatArray:
    """Working pressure angle a' in rad from the no-backlash condition.

    External: inv a' = 2 (x1 + x2) tan a / (z1 + z2) + inv a.
    Internal: inv a' = 2 (x2 - x1) tan a / (z2 - z1) + inv a (KHK Sec. 5.1; docs/findings.md, "Working
    angle, centre distance, tip diameters, contact ratio").
    NaN where inv a' <= 0: no positive working angle exists and the teeth cannot mesh.
    """
    x1, x2 = _x(pair)
    s = pair.sigma
    inv_w = 2.0 * (x2 + s * x1) * math.tan(pair.alpha) / (pair.z2 + s * pair.z1) + involute(pair.alpha)
    return cast(FloatArray, np.where(inv_w > 0.0, inverse_involute(np.maximum(inv_w, 0.0)), np.nan))


def working_centre_distance(pair: GearPair) -> FloatArray:
    """a' = a cos a / cos a' in mm."""
    return cast(
        FloatArray,
        reference_centre_distance(pair) * math.cos(pair.alpha) / np.cos(working_pressure_angle(pair)),
    )


def centre_distance_modification(pair: GearPair) -> FloatArray:
    """Centre-distance modification coefficient y = (a' - a) / m (-)."""
    return cast(FloatArray, (working_centre_distance(pair) - reference_centre_distance(pair)) / pair.module)


# --------------------------------------------------------------------------------------------
# Diameters
# --------------------------------------------------------------------------------------------


def pitch_diameters(pair: GearPair) -> tuple[float, float]:
    """Reference diameters d = z m, mm."""
    return pair.z1 * pair.module, pair.z2 * pair.module


def base_diameters(pair: GearPair) -> tuple[float, float]:
    """Base diameters db = d cos a, mm."""
    d1, d2 = pitch_diameters(pair)
    c = math.cos(pair.alpha)
    return d1 * c, d2 * c


def working_pitch_diameters(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Working pitch diameters d' = d cos a / cos a', mm."""
    d1, d2 = pitch_diameters(pair)
    r = math.cos(pair.alpha) / np.cos(working_pressure_angle(pair))
    return d1 * r, d2 * r


def _tip_shortening(pair: GearPair) -> FloatArray:
    """Tip-shortening coefficient dy = x1 + x2 - y for external pairs (0 for internal)."""
    x1, x2 = _x(pair)
    if pair.internal or not pair.tip_shortening:
        return np.zeros(np.broadcast(x1, x2).shape)
    return cast(FloatArray, x1 + x2 - centre_distance_modification(pair))


def tip_diameters(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Tip diameters (da1, da2) in mm.

    Internal (docs/findings.md, "Working angle, centre distance, tip diameters, contact ratio"):
    da1 = d1 + 2 (ha* + x1) m, da2 = d2 - 2 (ha* - x2) m, no shortening.
    External: da = d + 2 (ha* + x - dy) m with dy = x1 + x2 - y when ``tip_shortening`` (default)
    keeps the standard clearance c* m; dy = 0 otherwise.
    """
    x1, x2 = _x(pair)
    d1, d2 = pitch_diameters(pair)
    m, ha = pair.module, pair.addendum
    dy = _tip_shortening(pair)
    da1 = d1 + 2.0 * (ha + x1 - dy) * m
    if pair.internal:
        da2 = d2 - 2.0 * (ha - x2) * m
    else:
        da2 = d2 + 2.0 * (ha + x2 - dy) * m
    return cast(FloatArray, da1), cast(FloatArray, da2)


def root_diameters(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Root diameters (df1, df2) in mm, rack-equivalent generation.

    df1 = d1 - 2 (ha* + c* - x1) m.  External wheel: df2 = d2 - 2 (ha* + c* - x2) m.
    Annulus: df2 = d2 + 2 (ha* + c* + x2) m.  A shaper-cut root is really 2 a0' + da0, which is
    close to this (equal when x2 = x0 = 0 and ha0* = ha* + c*); no constraint uses df.
    """
    x1, x2 = _x(pair)
    d1, d2 = pitch_diameters(pair)
    m, h = pair.module, pair.addendum + pair.clearance
    df1 = d1 - 2.0 * (h - x1) * m
    df2 = d2 + 2.0 * (h + x2) * m if pair.internal else d2 - 2.0 * (h - x2) * m
    return cast(FloatArray, df1), cast(FloatArray, df2)


def _acos_ratio(db: float, da: ArrayLike) -> FloatArray:
    """arccos(db / da); NaN where the circle lies inside the base circle."""
    with np.errstate(invalid="ignore", divide="ignore"):
        r = db / np.asarray(da, dtype=float)
        return cast(FloatArray, np.where(r <= 1.0, libm.arccos(np.minimum(r, 1.0)), np.nan))


def tip_pressure_angles(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Pressure angles at the tip circles, aa = arccos(db / da), rad (NaN if da < db)."""
    db1, db2 = base_diameters(pair)
    da1, da2 = tip_diameters(pair)
    return _acos_ratio(db1, da1), _acos_ratio(db2, da2)


# --------------------------------------------------------------------------------------------
# Contact ratio and interference
# --------------------------------------------------------------------------------------------


def contact_ratio(pair: GearPair) -> FloatArray:
    """Transverse contact ratio (paper 1 Sec. 3.2 line 1; checked against KHK Table 5-4, docs/findings.md).

    eps = [z1 (tan aa1 - tan a') + sigma z2 (tan aa2 - tan a')] / (2 pi), sigma = -1 internal.
    """
    aw = working_pressure_angle(pair)
    aa1, aa2 = tip_pressure_angles(pair)
    tw = libm.tan(aw)
    return cast(
        FloatArray,
        (pair.z1 * (libm.tan(aa1) - tw) + pair.sigma * pair.z2 * (libm.tan(aa2) - tw)) / (2.0 * np.pi),
    )


def overlap_interference(pair: GearPair) -> FloatArray:
    """Tooth-profile overlap interference G_s (internal pairs), rad; >= 0 is feasible.

    G_s = z1 (inv aa1 + d1) - z2 (inv aa2 + d2) + (z2 - z1) inv a', with
    cos d1 = (ra2^2 - ra1^2 - a'^2) / (2 ra1 a'),  cos d2 = (ra2^2 - ra1^2 + a'^2) / (2 ra2 a').
    Identical to KHK's trochoid-interference condition, Eqs. (5-6)/(5-7), multiplied by z2.
    When the two tip circles do not intersect the cosines are clipped to [-1, 1].
    """
    if not pair.internal:
        raise ValueError("overlap interference G_s applies to internal pairs only")
    aw = working_pressure_angle(pair)
    a_w = working_centre_distance(pair)
    da1, da2 = tip_diameters(pair)
    ra1, ra2 = da1 / 2.0, da2 / 2.0
    aa1, aa2 = tip_pressure_angles(pair)
    c1 = np.clip((ra2**2 - ra1**2 - a_w**2) / (2.0 * ra1 * a_w), -1.0, 1.0)
    c2 = np.clip((ra2**2 - ra1**2 + a_w**2) / (2.0 * ra2 * a_w), -1.0, 1.0)
    d1, d2 = libm.arccos(c1), libm.arccos(c2)
    return cast(
        FloatArray,
        pair.z1 * (involute(aa1) + d1) - pair.z2 * (involute(aa2) + d2) + (pair.z2 - pair.z1) * involute(aw),
    )


def _lowest_contact_roll(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Roll distances (mm along the line of action) of the deepest contact point on each gear.

    Measured from that gear's tangent point N on the line of action:
    rho1 = rb1 [tan a' - sigma (z2/z1)(tan aa2 - tan a')]  (start set by the mating tip),
    rho2 = rb2 [tan a' - (z1/z2)(tan aa1 - tan a')]          (external wheel only).
    """
    db1, db2 = base_diameters(pair)
    aw = working_pressure_angle(pair)
    aa1, aa2 = tip_pressure_angles(pair)
    tw = libm.tan(aw)
    rho1 = db1 / 2.0 * (tw - pair.sigma * pair.z2 / pair.z1 * (libm.tan(aa2) - tw))
    rho2 = db2 / 2.0 * (tw - pair.z1 / pair.z2 * (libm.tan(aa1) - tw))
    return cast(FloatArray, rho1), cast(FloatArray, rho2)


def involute_interference(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Signed involute-interference margins (mm) for (gear 1, gear 2); >= 0 is feasible.

    Gear 1 (planet/pinion): distance along the line of action from its tangent point N1 to the
    contact point set by the mating tip circle.  Negative: the mating tip works below the base
    circle of gear 1.  For an internal pair this is KHK's condition z1/z2 >= 1 - tan aa2/tan a'
    (SDP/SI Sec. 5.2(a)) multiplied by rb1 tan a'.
    Gear 2: external wheel - the same distance from N2; annulus - ra2 - rb2, the annulus tip
    circle must lie outside its base circle (the planet tip contact lies beyond the pitch point
    and can never pass N2, which is the far end of the line of action).
    """
    rho1, rho2 = _lowest_contact_roll(pair)
    if pair.internal:
        _, da2 = tip_diameters(pair)
        _, db2 = base_diameters(pair)
        return rho1, cast(FloatArray, (da2 - db2) / 2.0)
    return rho1, rho2


def _rack_form_roll(pair: GearPair, which: int) -> FloatArray:
    """Roll distance rb tan aF (mm) of the lowest involute point generated by a rack cutter.

    tan aF = tan a - 4 (ha* - x) / (z sin 2a), taking the straight flank of the rack to reach
    the depth ha* m (the remaining c* m is the tool tip fillet), standard Chinese-textbook rule.
    """
    x1, x2 = _x(pair)
    z, x = (pair.z1, x1) if which == 1 else (pair.z2, x2)
    db = (base_diameters(pair))[which - 1]
    a = pair.alpha
    tan_f = math.tan(a) - 4.0 * (pair.addendum - x) / (z * math.sin(2.0 * a))
    return cast(FloatArray, db / 2.0 * tan_f)


def undercut_margin(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Undercut margins (mm along the line of action) for rack-cut gears.

    rb tan aF >= 0  <=>  x >= ha* - z sin^2(a) / 2 (no undercut).  The annulus (internal) is
    shaper-cut and cannot be undercut in this sense: its entry is +inf.
    """
    u1 = _rack_form_roll(pair, 1)
    if pair.internal:
        return u1, cast(FloatArray, np.full(np.shape(u1), np.inf))
    return u1, _rack_form_roll(pair, 2)


def _cutting_mesh(pair: GearPair, cutter: ShaperCutter | None) -> tuple[ShaperCutter, float, FloatArray, float]:
    """Shaper-cutter data for the annulus: (cutter, ha0*, inv a0', da0 in mm).

    Cutting mesh without backlash: inv a0' = 2 (x2 - x0) tan a / (z2 - z0) + inv a;
    cutter tip diameter da0 = m (z0 + 2 (ha0* + x0)).
    """
    cut = cutter if cutter is not None else default_cutter(pair)
    if cut.teeth >= pair.z2:
        raise ValueError(f"cutter teeth z0={cut.teeth} must be fewer than annulus teeth z2={pair.z2}")
    _, x2 = _x(pair)
    m, a = pair.module, pair.alpha
    ha0 = cut.addendum if cut.addendum is not None else pair.addendum + pair.clearance
    inv_w0 = 2.0 * (x2 - cut.shift) * math.tan(a) / (pair.z2 - cut.teeth) + involute(a)
    da0 = m * (cut.teeth + 2.0 * (ha0 + cut.shift))
    return cut, ha0, cast(FloatArray, inv_w0), da0


def root_interference(pair: GearPair, cutter: ShaperCutter | None = None) -> tuple[FloatArray, FloatArray]:
    """Root (transition-curve) interference margins, mm along the line of action; >= 0 feasible.

    Gear 1 (rack-cut planet/pinion): its involute starts at the form point rb1 tan aF1 (see
    :func:`undercut_margin`); the mating tip must not reach below it:
    margin1 = rho1 - rb1 tan aF1, i.e. (Chinese textbook form, divided by rb1)
    tan a' - sigma (z2/z1)(tan aa2 - tan a') >= tan a - 4 (ha* - x1) / (z1 sin 2a).
    Gear 2, external wheel: the same with the indices swapped.
    Gear 2, shaper-cut annulus: the annulus involute ends where the cutter tip left it, at roll
    distance rb2 tan a0' + rb0 (tan aa0 - tan a0') from N2; the planet tip contact lies at
    rb2 tan a' + rb1 (tan aa1 - tan a').  Margin = difference (mm); divided by m cos a / 2 it is
    the Chinese condition z0 tan aa0 - (z0 - z2) tan a0' >= z1 tan aa1 - (z1 - z2) tan a'.
    """
    rho1, rho2 = _lowest_contact_roll(pair)
    m1 = rho1 - _rack_form_roll(pair, 1)
    if not pair.internal:
        return cast(FloatArray, m1), cast(FloatArray, rho2 - _rack_form_roll(pair, 2))
    cut, _, inv_w0, da0 = _cutting_mesh(pair, cutter)
    c = math.cos(pair.alpha)
    rb0 = cut.teeth * pair.module * c / 2.0
    db1, db2 = base_diameters(pair)
    rb1, rb2 = db1 / 2.0, db2 / 2.0
    t_w0 = libm.tan(inverse_involute(inv_w0))
    t_a0 = math.tan(math.acos(rb0 / (da0 / 2.0)))
    t_w = libm.tan(working_pressure_angle(pair))
    aa1, _ = tip_pressure_angles(pair)
    form2 = rb2 * t_w0 + rb0 * (t_a0 - t_w0)
    contact2 = rb2 * t_w + rb1 * (libm.tan(aa1) - t_w)
    return cast(FloatArray, m1), cast(FloatArray, form2 - contact2)


def tip_thickness(pair: GearPair) -> tuple[FloatArray, FloatArray]:
    """Transverse tooth thickness on the tip circles (sa1, sa2), mm.

    External tooth: sa = da (s / d + inv a - inv aa), s = m (pi/2 + 2 x tan a).
    Annulus tooth (teeth thin towards the centre): sa2 = da2 (s2 / d2 - inv a + inv aa2),
    s2 = m (pi/2 - 2 x2 tan a) (Chinese convention).
    """
    x1, x2 = _x(pair)
    d1, d2 = pitch_diameters(pair)
    da1, da2 = tip_diameters(pair)
    aa1, aa2 = tip_pressure_angles(pair)
    m, a = pair.module, pair.alpha
    inv_a = involute(a)
    s1 = m * (np.pi / 2 + 2.0 * x1 * math.tan(a))
    sa1 = da1 * (s1 / d1 + inv_a - involute(aa1))
    if pair.internal:
        s2 = m * (np.pi / 2 - 2.0 * x2 * math.tan(a))
        sa2 = da2 * (s2 / d2 - inv_a + involute(aa2))
    else:
        s2 = m * (np.pi / 2 + 2.0 * x2 * math.tan(a))
        sa2 = da2 * (s2 / d2 + inv_a - involute(aa2))
    return cast(FloatArray, sa1), cast(FloatArray, sa2)


def _trimming(
    z_small: int,
    z_big: int,
    da_small: ArrayLike,
    da_big: ArrayLike,
    db_small: float,
    db_big: float,
    inv_w: ArrayLike,
) -> FloatArray:
    """Radial (trimming) interference margin of an internal mesh, rad.

    KHK Eqs. (5-9)/(5-10) (also the Chinese "radial interference" G_s'):
    G = z1 (t1 + inv aa1 - inv a') - z2 (t2 + inv aa2 - inv a') >= 0, with
    t1 = asin sqrt[(1 - (cos aa1/cos aa2)^2) / (1 - (z1/z2)^2)],
    t2 = asin sqrt[((cos aa2/cos aa1)^2 - 1) / ((z2/z1)^2 - 1)].
    """
    aa1 = _acos_ratio(db_small, da_small)
    aa2 = _acos_ratio(db_big, da_big)
    q = (np.cos(aa1) / np.cos(aa2)) ** 2
    with np.errstate(invalid="ignore"):
        t1 = libm.arcsin(np.sqrt(np.clip((1.0 - q) / (1.0 - (z_small / z_big) ** 2), 0.0, 1.0)))
        t2 = libm.arcsin(np.sqrt(np.clip((1.0 / q - 1.0) / ((z_big / z_small) ** 2 - 1.0), 0.0, 1.0)))
    return cast(
        FloatArray,
        z_small * (t1 + involute(aa1) - inv_w) - z_big * (t2 + involute(aa2) - inv_w),
    )


def radial_interference(pair: GearPair) -> FloatArray:
    """Radial (assembly) interference of the planet-annulus pair, KHK Eq. (5-9), rad.

    Negative means the planet cannot be moved radially into mesh and must be assembled
    axially.  KHK Table 5-4 notes that this is the normal case for tooth differences 1-8, so it
    is reported by :func:`describe` but is not a feasibility constraint.
    """
    if not pair.internal:
        raise ValueError("radial interference applies to internal pairs only")
    da1, da2 = tip_diameters(pair)
    db1, db2 = base_diameters(pair)
    return _trimming(pair.z1, pair.z2, da1, da2, db1, db2, involute(working_pressure_angle(pair)))


def default_cutter(pair: GearPair) -> ShaperCutter:
    """Assumed shaper cutter when none is configured: nominal 100 mm reference diameter, x0 = 0.

    z0 = round(100 / m) (29 teeth for m = 3.5 mm), or z2 // 2 if that is not below z2; addendum
    ha* + c*.  Paper 1 does not give the cutter; this is a documented assumption
    (docs/geometry.md), and the trimming and annulus-root margins depend strongly on it.
    """
    z0 = max(10, round(100.0 / pair.module))
    if z0 >= pair.z2:
        z0 = pair.z2 // 2
    return ShaperCutter(teeth=z0, shift=0.0, addendum=None)


def trimming_interference(pair: GearPair, cutter: ShaperCutter | None = None) -> FloatArray:
    """Trimming (radial-feed) interference of the shaper-cut annulus, rad; >= 0 feasible.

    While the annulus is cut by a pinion-type shaper cutter fed radially to depth, the cutter's
    tips must not trim the annulus teeth: KHK Eqs. (5-9)/(5-10) (SDP/SI Sec. 5.2(c): "This type
    of interference can occur in the process of cutting an internal gear with a pinion cutter"),
    the Chinese "径向切入顶切" check, with the cutter as the small gear at the cutting centre
    distance: inv a0' = 2 (x2 - x0) tan a / (z2 - z0) + inv a, cutter tip diameter
    da0 = m (z0 + 2 (ha0* + x0)), annulus tip da2 as in :func:`tip_diameters`.
    """
    if not pair.internal:
        raise ValueError("trimming interference applies to internal pairs only")
    cut, _, inv_w0, da0 = _cutting_mesh(pair, cutter)
    _, da2 = tip_diameters(pair)
    db0 = cut.teeth * pair.module * math.cos(pair.alpha)
    _, db2 = base_diameters(pair)
    return _trimming(cut.teeth, pair.z2, np.full(np.shape(da2), da0), da2, db0, db2, inv_w0)


# --------------------------------------------------------------------------------------------
# Constraint set
# --------------------------------------------------------------------------------------------

#: name -> (units, long_name); filled for both internal and external role names.
_INFO: dict[str, tuple[str, str]] = {
    "contact_ratio_margin": ("1", "transverse contact ratio minus required minimum (eps - eps_min)"),
    "overlap_interference": ("rad", "tooth-profile overlap interference G_s"),
    "trimming_interference_annulus": ("rad", "shaper-cutter trimming (radial-feed) interference of the annulus"),
}
for _g in ("planet", "annulus", "pinion", "wheel"):
    _INFO[f"involute_interference_{_g}"] = ("mm", f"involute interference margin of the {_g}")
    _INFO[f"root_interference_{_g}"] = ("mm", f"root transition-curve interference margin of the {_g}")
    _INFO[f"undercut_{_g}"] = ("mm", f"undercut margin of the {_g} (rack-cut), rb tan aF")
    _INFO[f"tip_thickness_{_g}"] = ("mm", f"tip thickness of the {_g} minus required minimum")


def constraint_info(name: str) -> tuple[str, str]:
    """(units, long_name) of a constraint returned by :func:`constraints`."""
    return _INFO[name]


def constraint_grid(
    pair: GearPair,
    *,
    min_tip_thickness: float = 0.25,
    min_contact_ratio: float = 1.0,
    cutter: ShaperCutter | None = None,
) -> dict[str, FloatArray]:
    """All constraints as signed margins (>= 0 satisfied); shifts may be broadcasting arrays.

    Keys (internal pair; an external pair uses pinion/wheel and drops the annulus-only rows):
    ``contact_ratio_margin`` = eps - eps_min (line 1),
    ``overlap_interference`` = G_s (line 4 boundary; the binding constraint),
    ``involute_interference_planet``/``_annulus`` (mm, line 2),
    ``root_interference_planet`` (mm, line 2), ``undercut_planet`` (mm),
    ``tip_thickness_planet``/``_annulus`` = sa - s_min m (mm, line 3),
    ``trimming_interference_annulus`` (rad, line 3).
    """
    n1, n2 = pair.names
    out: dict[str, FloatArray] = {"contact_ratio_margin": contact_ratio(pair) - min_contact_ratio}
    if pair.internal:
        out["overlap_interference"] = overlap_interference(pair)
    i1, i2 = involute_interference(pair)
    out[f"involute_interference_{n1}"] = i1
    out[f"involute_interference_{n2}"] = i2
    r1, r2 = root_interference(pair, cutter)
    u1, u2 = undercut_margin(pair)
    out[f"root_interference_{n1}"] = r1
    out[f"root_interference_{n2}"] = r2
    out[f"undercut_{n1}"] = u1
    if not pair.internal:
        out[f"undercut_{n2}"] = u2
    sa1, sa2 = tip_thickness(pair)
    smin = min_tip_thickness * pair.module
    out[f"tip_thickness_{n1}"] = cast(FloatArray, sa1 - smin)
    out[f"tip_thickness_{n2}"] = cast(FloatArray, sa2 - smin)
    if pair.internal:
        out["trimming_interference_annulus"] = trimming_interference(pair, cutter)
    shape = np.broadcast(*_x(pair)).shape
    return {k: cast(FloatArray, np.broadcast_to(np.asarray(v, dtype=float), shape)) for k, v in out.items()}


def constraints(
    pair: GearPair,
    *,
    min_tip_thickness: float = 0.25,
    min_contact_ratio: float = 1.0,
    cutter: ShaperCutter | None = None,
) -> dict[str, float]:
    """Every constraint of one design as a float margin; >= 0 means satisfied.

    ``min_tip_thickness`` is s_min in modules (0.25 m or 0.4 m are the usual choices).
    See :func:`constraint_grid` for the names.
    """
    grid = constraint_grid(
        pair, min_tip_thickness=min_tip_thickness, min_contact_ratio=min_contact_ratio, cutter=cutter
    )
    return {k: float(v) for k, v in grid.items()}


def violations(pair: GearPair, **kwargs: Any) -> list[str]:
    """Names of the constraints that fail (margin < 0 or not a number)."""
    return [k for k, v in constraints(pair, **kwargs).items() if not v >= 0.0]


def describe(pair: GearPair, **kwargs: Any) -> dict[str, float]:
    """Derived geometry of one design for ``geardyn check-design`` (mm, deg, -)."""
    aw = float(working_pressure_angle(pair))
    da1, da2 = tip_diameters(pair)
    df1, df2 = root_diameters(pair)
    sa1, sa2 = tip_thickness(pair)
    db1, db2 = base_diameters(pair)
    out: dict[str, float] = {
        "reference_centre_distance_mm": reference_centre_distance(pair),
        "working_pressure_angle_deg": math.degrees(aw),
        "cos_working_pressure_angle": math.cos(aw),
        "working_centre_distance_mm": float(working_centre_distance(pair)),
        "centre_distance_modification": float(centre_distance_modification(pair)),
        "contact_ratio": float(contact_ratio(pair)),
        "da1_mm": float(da1),
        "da2_mm": float(da2),
        "df1_mm": float(df1),
        "df2_mm": float(df2),
        "db1_mm": db1,
        "db2_mm": db2,
        "sa1_mm": float(sa1),
        "sa2_mm": float(sa2),
    }
    if pair.internal:
        out["overlap_interference_Gs"] = float(overlap_interference(pair))
        out["radial_interference_assembly"] = float(radial_interference(pair))
    out.update({f"margin_{k}": v for k, v in constraints(pair, **kwargs).items()})
    return out


# --------------------------------------------------------------------------------------------
# Line 4: the G_s = 0 boundary
# --------------------------------------------------------------------------------------------


def _gs_scalar(base: GearPair, x1: float, x2: float) -> float:
    return float(overlap_interference(dataclasses.replace(base, x1=x1, x2=x2)))


def x2_on_overlap_boundary(x1: float, base: GearPair, *, xtol: float = 1e-12) -> float:
    """Annulus shift x2 with G_s(x1, x2) = 0 ("line 4", the design point for a given x1).

    G_s increases with x2 at fixed x1 (larger a' and a larger annulus tip circle pull the tips
    apart), so the root is bracketed by stepping x2 upwards from x1 - 0.5 and solved with brentq.
    Raises ``ValueError`` when no root exists: G_s is already positive where the pair first meshes
    (strongly negative x1), or never changes sign.
    """
    if not base.internal:
        raise ValueError("the G_s = 0 boundary applies to internal pairs only")
    lo = float(x1) - 0.5
    g_lo = _gs_scalar(base, x1, lo)
    step = 0.25
    hi = lo
    for _ in range(200):
        hi = lo + step
        g_hi = _gs_scalar(base, x1, hi)
        if np.isfinite(g_hi) and g_hi > 0:
            break
        lo, g_lo = hi, g_hi
    else:
        raise ValueError(f"G_s has no sign change for x1 = {x1} between x2 = {x1 - 0.5} and {hi}")
    if not (np.isfinite(g_lo) and g_lo < 0):
        raise ValueError(
            f"G_s = {g_hi:.4g} > 0 already at x2 = {hi:.4g}, the first x2 at which it is defined for x1 = {x1}"
        )
    return float(brentq(lambda x2: _gs_scalar(base, x1, x2), lo, hi, xtol=xtol, rtol=4 * np.finfo(float).eps))


def x2_on_overlap_boundary_many(x1: ArrayLike, base: GearPair) -> FloatArray:
    """Vectorised :func:`x2_on_overlap_boundary` (one brentq per x1 value)."""
    arr = np.asarray(x1, dtype=float)
    out = np.array([x2_on_overlap_boundary(float(v), base) for v in arr.ravel()])
    return cast(FloatArray, out.reshape(arr.shape))
