"""Flank tolerance classes of ISO 1328-1:2013 (cylindrical gears): the single-pitch tolerance f_pT of a stated class,
the bound of the transmission-error amplitude of a tolerance study (``docs/probabilities.md``)."""

from __future__ import annotations

import math

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


def single_pitch_tolerance(grade: int, diameter_mm: float, module_mm: float) -> float:
    """f_pT in um: ISO 1328-1:2013, formula (5), f_pT = (0.001 d + 0.4 m_n + 5) (sqrt 2)^(A - 5) for class A,
    rounded by :func:`rounded`; outside the standard's classes or scope a :class:`ValueError`."""
    if grade not in GRADES:
        raise ValueError(f"grade = {grade!r} is not allowed: an integer from 1 to 11 (ISO 1328-1:2013 classes)")
    for name, value, (lo, hi) in (("d", diameter_mm, DIAMETER_MM), ("m_n", module_mm, MODULE_MM)):
        if not lo <= value <= hi:
            raise ValueError(f"{name} = {value} mm is outside the scope of ISO 1328-1:2013 ({lo}-{hi} mm)")
    return rounded((0.001 * diameter_mm + 0.4 * module_mm + 5.0) * math.sqrt(2.0) ** (grade - 5))


def te_amplitude_bound(grade: int, z1: int, z2: int, module_mm: float) -> float:
    """The largest transmission-error amplitude e (um) of a pair of class ``grade``: the larger of its two
    gears' single-pitch tolerances (reference diameters z m)."""
    return max(single_pitch_tolerance(grade, z * module_mm, module_mm) for z in (z1, z2))
