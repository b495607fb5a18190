"""Flank tolerance classes of ISO 1328-1:2013 (cylindrical gears) and the backlash of a pair from its tooth thickness
and centre distance allowances: the bounds of the transmission-error amplitude e and the half backlash b of a
tolerance study (``docs/probabilities.md``).

Formula numbers are those of ISO 1328-1:2013, clause 5.3 (the class-5 value times (sqrt 2)^(A - 5), 5.2.2; rounded
by 5.2.3): (5) single pitch f_pT, (7) profile slope f_HaT, (8) profile form f_faT, (9) total profile
F_aT = sqrt(f_HaT^2 + f_faT^2) of the unrounded parts."""

from __future__ import annotations

import math
from collections.abc import Callable

#: The flank tolerance classes of ISO 1328-1:2013 (1 the finest, 11 the coarsest).
GRADES = range(1, 12)
#: The standard's scope (its formulae are not to be extrapolated): reference diameter d and normal module m_n
#: in mm.
DIAMETER_MM = (5.0, 15000.0)
MODULE_MM = (0.5, 70.0)


def rounded(value_um: float) -> float:
    """ISO 1328-1:2013, 5.2.3: a tolerance above 10 um to the nearest micrometre, from 5 to 10 um to the
    nearest 0.5 um, below 5 um to the nearest 0.1 um (halves away from zero)."""
    step = 1.0 if value_um > 10.0 else 0.5 if value_um >= 5.0 else 0.1
    return round(math.floor(value_um / step + 0.5) * step, 1)


def _step(grade: int, diameter_mm: float, module_mm: float) -> float:
    """(sqrt 2)^(A - 5) of class A (5.2.2) after checking the class and the standard's scope."""
    if grade not in GRADES:
        raise ValueError(f"grade = {grade!r} is not allowed: an integer from 1 to 11 (ISO 1328-1:2013 classes)")
    for name, value, (lo, hi) in (("d", diameter_mm, DIAMETER_MM), ("m_n", module_mm, MODULE_MM)):
        if not lo <= value <= hi:
            raise ValueError(f"{name} = {value} mm is outside the scope of ISO 1328-1:2013 ({lo}-{hi} mm)")
    return math.sqrt(2.0) ** (grade - 5)


def single_pitch_tolerance(grade: int, diameter_mm: float, module_mm: float) -> float:
    """f_pT in um: ISO 1328-1:2013, formula (5), f_pT = (0.001 d + 0.4 m_n + 5) (sqrt 2)^(A - 5) for class A,
    rounded by :func:`rounded`; outside the standard's classes or scope a :class:`ValueError`."""
    return rounded((0.001 * diameter_mm + 0.4 * module_mm + 5.0) * _step(grade, diameter_mm, module_mm))


def profile_slope_tolerance(grade: int, diameter_mm: float, module_mm: float) -> float:
    """f_HaT in um: ISO 1328-1:2013, formula (7), f_HaT = (0.4 m_n + 0.001 d + 4) (sqrt 2)^(A - 5), rounded."""
    return rounded((0.4 * module_mm + 0.001 * diameter_mm + 4.0) * _step(grade, diameter_mm, module_mm))


def profile_form_tolerance(grade: int, diameter_mm: float, module_mm: float) -> float:
    """f_faT in um: ISO 1328-1:2013, formula (8), f_faT = (0.55 m_n + 5) (sqrt 2)^(A - 5), rounded."""
    return rounded((0.55 * module_mm + 5.0) * _step(grade, diameter_mm, module_mm))


def total_profile_tolerance(grade: int, diameter_mm: float, module_mm: float) -> float:
    """F_aT in um: ISO 1328-1:2013, formula (9), F_aT = sqrt(f_HaT^2 + f_faT^2) of the unrounded (7) and (8),
    then rounded."""
    step = _step(grade, diameter_mm, module_mm)
    slope, form = (0.4 * module_mm + 0.001 * diameter_mm + 4.0) * step, (0.55 * module_mm + 5.0) * step
    return rounded(math.hypot(slope, form))


#: The tolerance whose band bounds the mesh-frequency transmission error of one gear: ``profile`` (the total
#: profile tolerance F_aT, the default: profile deviations repeat on every tooth, so they excite the mesh
#: frequency) or ``single_pitch`` (f_pT, which varies in sign from tooth to tooth and excites shaft orders).
TE_TOLERANCES: dict[str, Callable[[int, float, float], float]] = {
    "profile": total_profile_tolerance,
    "single_pitch": single_pitch_tolerance,
}
#: How the two gears' bands add: ``rss`` (root-sum-square, independent deviations; the default) or ``sum`` (the
#: worst case, both at their limits in phase).
COMBINE = {"rss": math.hypot, "sum": lambda a, b: a + b}


def te_amplitude_bound(
    grade: int, z1: int, z2: int, module_mm: float, tolerance: str = "profile", combine: str = "rss"
) -> float:
    """The largest transmission-error amplitude e (um) of a pair of class ``grade``: half the combined band of
    the two gears' ``tolerance`` (:data:`TE_TOLERANCES`, reference diameters z m) added by ``combine``
    (:data:`COMBINE`): a sinusoid of amplitude e spans a band of 2 e."""
    if tolerance not in TE_TOLERANCES or combine not in COMBINE:
        raise ValueError(
            f"tolerance = {tolerance!r}, combine = {combine!r} is not allowed: "
            f"tolerance one of {sorted(TE_TOLERANCES)}, combine one of {sorted(COMBINE)}"
        )
    band = TE_TOLERANCES[tolerance]
    return 0.5 * COMBINE[combine](*(band(grade, z * module_mm, module_mm) for z in (z1, z2)))


def backlash_range(
    thickness_um: tuple[tuple[float, float], tuple[float, float]],
    centre_distance_um: float,
    pressure_angle_deg: float,
    working_angle_deg: float,
) -> tuple[float, float]:
    """The range (um) of the half backlash b along the line of action of a pair from the two gears' tooth
    thickness allowances (upper, lower; um, negative thins a tooth; the annulus's thins its tooth, that is it
    widens its spaces) and a centre distance allowance +- A_a (um), by the relations of DIN 3967 and
    ISO/TR 10064-2 for the normal backlash: j_n = -(E_sn1 + E_sn2) cos a_n +- 2 A_a sin a_w (an internal pair's
    backlash shrinks as the centre distance grows, an external one's widens: with a symmetric +- A_a the
    extremes are the same); b = j_n / 2."""
    (up1, lo1), (up2, lo2) = thickness_um
    if up1 < lo1 or up2 < lo2 or centre_distance_um < 0:
        raise ValueError(
            f"tooth thickness allowances = {thickness_um!r}, centre distance allowance = {centre_distance_um!r} "
            "is not allowed: each gear's [upper, lower] with upper >= lower, and A_a >= 0"
        )
    cos_a, sin_w = math.cos(math.radians(pressure_angle_deg)), math.sin(math.radians(working_angle_deg))
    low = -(up1 + up2) * cos_a - 2.0 * centre_distance_um * sin_w
    high = -(lo1 + lo2) * cos_a + 2.0 * centre_distance_um * sin_w
    if low <= 0.0:
        raise ValueError(
            f"tooth thickness allowances = {thickness_um!r} um give a smallest backlash j_n = {low:.3g} um: "
            "not allowed, upper allowances negative enough for j_n > 0 at the centre distance tolerance"
        )
    return 0.5 * low, 0.5 * high
