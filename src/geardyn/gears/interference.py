"""Contact ratio and the interference checks of a spur pair: overlap (G_s), involute, root transition curve,
undercut, tip thickness, radial and shaper-cutter trimming (paper 1, Sec. 3.2; the closed graph's lines 1-4), in the
units and conventions of :mod:`geardyn.gears.geometry`."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from geardyn import libm
from geardyn.gears import geometry as geo

# --- Contact ratio and interference ---


def contact_ratio(pair: geo.GearPair) -> geo.FloatArray:
    """Transverse contact ratio (paper 1 Sec. 3.2 line 1; docs/geometry.md, "Formulas")."""
    aw = geo.working_pressure_angle(pair)
    aa1, aa2 = geo.tip_pressure_angles(pair)
    tw = libm.tan(aw)
    return (pair.z1 * (libm.tan(aa1) - tw) + pair.sigma * pair.z2 * (libm.tan(aa2) - tw)) / (2.0 * np.pi)


def overlap_interference(pair: geo.GearPair) -> geo.FloatArray:
    """Tooth-profile overlap interference G_s (internal pairs), rad; >= 0 is feasible (KHK Eqs. (5-6)/(5-7)
    times z2; docs/geometry.md, "Formulas")."""
    if not pair.internal:
        raise ValueError("overlap interference G_s applies to internal pairs only")
    aw = geo.working_pressure_angle(pair)
    a_w = geo.working_centre_distance(pair)
    da1, da2 = geo.tip_diameters(pair)
    ra1, ra2 = da1 / 2.0, da2 / 2.0
    aa1, aa2 = geo.tip_pressure_angles(pair)
    c1 = np.clip((ra2**2 - ra1**2 - a_w**2) / (2.0 * ra1 * a_w), -1.0, 1.0)
    c2 = np.clip((ra2**2 - ra1**2 + a_w**2) / (2.0 * ra2 * a_w), -1.0, 1.0)
    d1, d2 = libm.arccos(c1), libm.arccos(c2)
    return (
        pair.z1 * (geo.involute(aa1) + d1) - pair.z2 * (geo.involute(aa2) + d2) + (pair.z2 - pair.z1) * geo.involute(aw)
    )


def _lowest_contact_roll(pair: geo.GearPair) -> tuple[geo.FloatArray, geo.FloatArray]:
    """Roll distances (mm from each gear's tangent point N) of its deepest contact point (docs/geometry.md)."""
    db1, db2 = geo.base_diameters(pair)
    aw = geo.working_pressure_angle(pair)
    aa1, aa2 = geo.tip_pressure_angles(pair)
    tw = libm.tan(aw)
    rho1 = db1 / 2.0 * (tw - pair.sigma * pair.z2 / pair.z1 * (libm.tan(aa2) - tw))
    rho2 = db2 / 2.0 * (tw - pair.z1 / pair.z2 * (libm.tan(aa1) - tw))
    return rho1, rho2


def involute_interference(pair: geo.GearPair) -> tuple[geo.FloatArray, geo.FloatArray]:
    """Signed involute-interference margins (mm) for (gear 1, gear 2); >= 0 is feasible: the roll distance
    of the deepest contact, for an annulus ra2 - rb2 (docs/geometry.md, "Formulas")."""
    rho1, rho2 = _lowest_contact_roll(pair)
    if pair.internal:
        _, da2 = geo.tip_diameters(pair)
        _, db2 = geo.base_diameters(pair)
        return rho1, (da2 - db2) / 2.0
    return rho1, rho2


def _rack_form_roll(pair: geo.GearPair, which: int) -> geo.FloatArray:
    """Roll distance rb tan aF (mm) of the lowest involute point a rack cutter generates (docs/geometry.md,
    "Choices": rack form point)."""
    x1, x2 = geo.shifts(pair)
    z, x = (pair.z1, x1) if which == 1 else (pair.z2, x2)
    db = (geo.base_diameters(pair))[which - 1]
    a = pair.alpha
    return db / 2.0 * (math.tan(a) - 4.0 * (pair.addendum - x) / (z * math.sin(2.0 * a)))


def undercut_margin(pair: geo.GearPair) -> tuple[geo.FloatArray, geo.FloatArray]:
    """Undercut margins (mm along the line of action) for rack-cut gears; +inf for the shaper-cut annulus."""
    u1 = _rack_form_roll(pair, 1)
    return u1, (np.full(np.shape(u1), np.inf) if pair.internal else _rack_form_roll(pair, 2))


def _cutting_mesh(
    pair: geo.GearPair, cutter: geo.ShaperCutter | None
) -> tuple[geo.ShaperCutter, float, geo.FloatArray, float]:
    """Shaper-cutter data for the annulus: (cutter, ha0*, inv a0', da0 in mm) of the cutting mesh."""
    cut = cutter if cutter is not None else default_cutter(pair)
    if cut.teeth >= pair.z2:
        raise ValueError(f"cutter teeth z0={cut.teeth} must be fewer than annulus teeth z2={pair.z2}")
    _, x2 = geo.shifts(pair)
    m, a = pair.module, pair.alpha
    ha0 = cut.addendum if cut.addendum is not None else pair.addendum + pair.clearance
    inv_w0 = 2.0 * (x2 - cut.shift) * math.tan(a) / (pair.z2 - cut.teeth) + geo.involute(a)
    da0 = m * (cut.teeth + 2.0 * (ha0 + cut.shift))
    return cut, ha0, inv_w0, da0


def root_interference(
    pair: geo.GearPair, cutter: geo.ShaperCutter | None = None
) -> tuple[geo.FloatArray, geo.FloatArray]:
    """Root (transition-curve) interference margins, mm along the line of action; >= 0 feasible: deepest contact minus
    the form point (rack-cut gears) or the end of the shaper-cut annulus involute (docs/geometry.md, "Formulas")."""
    rho1, rho2 = _lowest_contact_roll(pair)
    m1 = rho1 - _rack_form_roll(pair, 1)
    if not pair.internal:
        return m1, rho2 - _rack_form_roll(pair, 2)
    cut, _, inv_w0, da0 = _cutting_mesh(pair, cutter)
    rb0 = cut.teeth * pair.module * math.cos(pair.alpha) / 2.0
    db1, db2 = geo.base_diameters(pair)
    rb1, rb2 = db1 / 2.0, db2 / 2.0
    t_w0 = libm.tan(geo.inverse_involute(inv_w0))
    t_a0 = math.tan(math.acos(rb0 / (da0 / 2.0)))
    t_w = libm.tan(geo.working_pressure_angle(pair))
    aa1, _ = geo.tip_pressure_angles(pair)
    form2 = rb2 * t_w0 + rb0 * (t_a0 - t_w0)
    contact2 = rb2 * t_w + rb1 * (libm.tan(aa1) - t_w)
    return m1, form2 - contact2


def tip_thickness(pair: geo.GearPair) -> tuple[geo.FloatArray, geo.FloatArray]:
    """Transverse tooth thickness on the tip circles (sa1, sa2), mm (docs/geometry.md, "Formulas")."""
    x1, x2 = geo.shifts(pair)
    d1, d2 = geo.pitch_diameters(pair)
    da1, da2 = geo.tip_diameters(pair)
    aa1, aa2 = geo.tip_pressure_angles(pair)
    m, a = pair.module, pair.alpha
    inv_a = geo.involute(a)
    s1 = m * (np.pi / 2 + 2.0 * x1 * math.tan(a))
    sa1 = da1 * (s1 / d1 + inv_a - geo.involute(aa1))
    s, s2 = pair.sigma, m * (np.pi / 2 + pair.sigma * 2.0 * x2 * math.tan(a))  # the annulus's space is its tooth
    return sa1, da2 * (s2 / d2 + s * inv_a - s * geo.involute(aa2))


def _trimming(
    small: tuple[int, ArrayLike, float], big: tuple[int, ArrayLike, float], inv_w: ArrayLike
) -> geo.FloatArray:
    """Radial (trimming) interference margin of an internal mesh, rad: KHK Eqs. (5-9)/(5-10) (docs/geometry.md,
    "Formulas"); each gear given as (teeth, tip diameter, base diameter)."""
    (z_small, da_small, db_small), (z_big, da_big, db_big) = small, big
    aa1, aa2 = geo.pressure_angle_at(db_small, da_small), geo.pressure_angle_at(db_big, da_big)
    q = (np.cos(aa1) / np.cos(aa2)) ** 2
    with np.errstate(invalid="ignore"):
        t1 = libm.arcsin(np.sqrt(np.clip((1.0 - q) / (1.0 - (z_small / z_big) ** 2), 0.0, 1.0)))
        t2 = libm.arcsin(np.sqrt(np.clip((1.0 / q - 1.0) / ((z_big / z_small) ** 2 - 1.0), 0.0, 1.0)))
    return z_small * (t1 + geo.involute(aa1) - inv_w) - z_big * (t2 + geo.involute(aa2) - inv_w)


def radial_interference(pair: geo.GearPair) -> geo.FloatArray:
    """Radial (assembly) interference of the planet-annulus pair, KHK Eq. (5-9), rad: reported, not a
    constraint (negative is normal for tooth differences 1-8; docs/geometry.md)."""
    if not pair.internal:
        raise ValueError("radial interference applies to internal pairs only")
    da1, da2 = geo.tip_diameters(pair)
    db1, db2 = geo.base_diameters(pair)
    return _trimming((pair.z1, da1, db1), (pair.z2, da2, db2), geo.involute(geo.working_pressure_angle(pair)))


def default_cutter(pair: geo.GearPair) -> geo.ShaperCutter:
    """Assumed shaper cutter when none is configured: z0 = round(100 / m) (at least 10; z2 // 2 if not
    below z2), x0 = 0, ha0* = ha* + c* (docs/geometry.md, "Choices")."""
    z0 = max(10, round(100.0 / pair.module))
    if z0 >= pair.z2:
        z0 = pair.z2 // 2
    return geo.ShaperCutter(teeth=z0, shift=0.0, addendum=None)


def trimming_interference(pair: geo.GearPair, cutter: geo.ShaperCutter | None = None) -> geo.FloatArray:
    """Trimming (radial-feed) interference of the shaper-cut annulus, rad; >= 0 feasible: KHK Eqs.
    (5-9)/(5-10) with the cutter as the small gear at the cutting centre distance (docs/geometry.md)."""
    if not pair.internal:
        raise ValueError("trimming interference applies to internal pairs only")
    cut, _, inv_w0, da0 = _cutting_mesh(pair, cutter)
    _, da2 = geo.tip_diameters(pair)
    db0 = cut.teeth * pair.module * math.cos(pair.alpha)
    _, db2 = geo.base_diameters(pair)
    return _trimming((cut.teeth, np.full(np.shape(da2), da0), db0), (pair.z2, da2, db2), inv_w0)
